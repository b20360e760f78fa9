#include "store/file_store.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <initializer_list>

#include "core/check.h"
#include "core/error.h"
#include "core/limits.h"
#include "core/parallel.h"
#include "core/shot_keys.h"
#include "io/image_io.h"
#include "render/passes.h"
#include "store/field_file.h"
#include "store/kept_fields.h"
#include "store/mapped_passes.h"
#include "store/qa_maps.h"
#include "store/settings_manifests.h"

namespace emaki::io {

namespace fs = std::filesystem;
using pipeline::Shot;

std::string OutputPaths::layer_exr(const std::string& layer, int frame) const {
  return fmt::format("{}/layers/{}/{}_{:04d}.exr", folder, layer, layer, frame);
}
std::string OutputPaths::layer_png(const std::string& layer, int frame) const {
  return fmt::format("{}/layers/{}/{}_{:04d}.png", folder, layer, layer, frame);
}
std::string OutputPaths::layer_field(const std::string& layer, int frame) const {
  return fmt::format("{}/layers/{}/.{}_{:04d}.nnf", folder, layer, layer, frame);
}
std::string OutputPaths::composite_png(int frame) const {
  return fmt::format("{}/composite/frame_{:04d}.png", folder, frame);
}
std::string OutputPaths::composite_exr(int frame) const {
  return fmt::format("{}/composite/frame_{:04d}.exr", folder, frame);
}
std::string OutputPaths::layered_exr(int frame) const {
  return fmt::format("{}/layered/frame_{:04d}.exr", folder, frame);
}
std::string OutputPaths::mp4() const {
  return folder + "/preview.mp4";
}
std::string OutputPaths::contact_sheet() const {
  return folder + "/contact_sheet.png";
}
std::string OutputPaths::passes_file(int frame) const {
  return fmt::format("{}/passes/frame_{:04d}.passes", folder, frame);
}
std::string OutputPaths::passes_fields(int frame) const {
  return fmt::format("{}/passes/advection_{:04d}.field", folder, frame);
}

namespace {

void make_folder(const fs::path& p) {
  std::error_code ec;
  fs::create_directories(p, ec);
  if (!fs::is_directory(p, ec))
    throw Error(shot_keys::kOutputsFolder, fmt::format("cannot create folder '{}'", p.string()));
}

bool has_ext(const std::string& name, std::size_t from, std::initializer_list<const char*> exts) {
  for (const char* e : exts)
    if (name.compare(from, std::string::npos, e) == 0) return true;
  return false;
}

// "<prefix><digits><.png|.exr>": the frame files emaki writes (prefix "base_" or "frame_").
bool is_frame_name(const std::string& name, const std::string& prefix,
                   std::initializer_list<const char*> exts) {
  if (name.compare(0, prefix.size(), prefix) != 0) return false;
  std::size_t i = prefix.size();
  const std::size_t digits = i;
  while (i < name.size() && std::isdigit(static_cast<unsigned char>(name[i]))) ++i;
  return i > digits && has_ext(name, i, exts);
}

// Removes the frame files emaki wrote in `dir` (never anything else: a user's own file there
// survives).
void remove_frames(const fs::path& dir, const std::string& prefix,
                   std::initializer_list<const char*> exts) {
  std::error_code ec;
  std::vector<fs::path> doomed;
  for (const auto& entry : fs::directory_iterator(dir, ec))
    if (is_frame_name(entry.path().filename().string(), prefix, exts) && !entry.is_directory(ec))
      doomed.push_back(entry.path());
  for (const fs::path& p : doomed) fs::remove(p, ec);
}

// A layer's frame files: its PNGs and EXRs, and its hidden fields (".base_0007.nnf").
bool is_layer_file(const std::string& name, const std::string& layer) {
  return is_frame_name(name, layer + "_", {".png", ".exr"}) ||
         is_frame_name(name, "." + layer + "_", {".nnf"});
}

// The pass cache's frames and the advection fields beside them.
void remove_pass_cache(const std::string& dir) {
  remove_frames(dir, "frame_", {".passes", ".exr"});  // .exr: the cache's earlier form
  remove_frames(dir, "advection_", {".field"});
}

void remove_layer_frames(const fs::path& dir, const std::string& layer) {
  remove_frames(dir, layer + "_", {".png", ".exr"});
  remove_frames(dir, "." + layer + "_", {".nnf"});
}

bool any_frame(const fs::path& dir, const std::string& prefix,
               std::initializer_list<const char*> exts) {
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec))
    if (is_frame_name(entry.path().filename().string(), prefix, exts)) return true;
  return false;
}

std::vector<std::string> value_names(const std::string& prefix, int channels, int value_channels) {
  std::vector<std::string> n;
  if (value_channels == 1)
    n.push_back(prefix + "Y");
  else
    for (const char* c : {"R", "G", "B"}) n.push_back(prefix + c);
  if (channels > value_channels) n.push_back(prefix + "A");
  return n;
}

}  // namespace

FileStore::Manifested FileStore::manifested(const std::string& dir, Manifest want,
                                            const std::string& prefix,
                                            std::initializer_list<const char*> exts) {
  FileStore::Manifested m;
  m.want = std::move(want);
  const auto have = read_manifest((fs::path(dir) / kManifest).string());
  m.current = have && manifest_current(*have, m.want);
  if (!m.current)
    m.stale = have                           ? manifest_change(*have, m.want)
              : any_frame(dir, prefix, exts) ? "no record of the settings that made it"
                                             : "";
  return m;
}

FileStore::FileStore(const Shot& shot, StoreMode mode, StoreAccess access)
    : shot_(shot), mode_(mode), access_(access) {
  paths_.folder = shot.outputs.folder;
  const fs::path root(paths_.folder);
  if (access == StoreAccess::kInspect) {
    for (const pipeline::Layer& l : shot.layers)
      layers_[l.name] = manifested((root / "layers" / l.name).string(), layer_manifest(shot, l),
                                   l.name + "_", {".png", ".exr"});
    frames_ = manifested((root / "composite").string(), frames_manifest(shot), "frame_",
                         {".png", ".exr"});
    passes_ = manifested((root / "passes").string(), passes_manifest(shot), "frame_",
                         {".passes", ".exr"});
    return;
  }
  make_folder(root);
  // Before anything is cleaned up or written: another emaki's temporaries are not ours to remove.
  lock_ = std::make_unique<FolderLock>(paths_.folder, access == StoreAccess::kFarmTask
                                                          ? FolderLock::Kind::kShared
                                                          : FolderLock::Kind::kExclusive);
  // Farm tasks run beside each other: a temporary here may be another task's file in flight.
  const bool clean = access == StoreAccess::kAlone;
  auto clean_up = [clean](const fs::path& dir, const std::function<bool(const std::string&)>& f) {
    if (clean) remove_temporaries(dir.string(), f);
  };
  clean_up(root,
           [](const std::string& t) { return t == "contact_sheet.png" || t == "preview.mp4"; });
  for (const char* sub : {"composite", "layered"}) {
    make_folder(root / sub);
    clean_up(root / sub, [](const std::string& t) {
      return t == kManifest || is_frame_name(t, "frame_", {".png", ".exr"});
    });
  }
  for (const pipeline::Layer& l : shot.layers) {
    const fs::path dir = root / "layers" / l.name;
    make_folder(dir);
    clean_up(dir, [&](const std::string& t) { return t == kManifest || is_layer_file(t, l.name); });
    layers_[l.name] =
        manifested(dir.string(), layer_manifest(shot, l), l.name + "_", {".png", ".exr"});
  }
  frames_ =
      manifested((root / "composite").string(), frames_manifest(shot), "frame_", {".png", ".exr"});
  // The pass cache exists only where the farm made one.
  const fs::path cache = root / "passes";
  std::error_code ec;
  if (fs::is_directory(cache, ec)) {
    clean_up(cache, [](const std::string& t) {
      return t == kManifest || is_frame_name(t, "frame_", {".passes", ".exr"}) ||
             is_frame_name(t, "advection_", {".field"});
    });
  }
  passes_ = manifested(cache.string(), passes_manifest(shot), "frame_", {".passes", ".exr"});
  if (const fs::path refs = root / "references"; fs::is_directory(refs, ec))
    clean_up(refs, [](const std::string& t) {
      return t.ends_with(".passes") || t.ends_with(".exr") || t.ends_with(".digest");
    });
  // QA maps (store/qa_maps.h): qa/KIND/LAYER/frame_NNNN.png, in folders (never links) only.
  const auto folders = [](const fs::path& dir) {
    std::vector<fs::path> out;
    std::error_code e;
    for (fs::directory_iterator it(dir, e), end; !e && it != end; it.increment(e))
      if (!it->is_symlink(e) && it->is_directory(e)) out.push_back(it->path());
    return out;
  };
  for (const fs::path& kind : folders(root / "qa"))
    for (const fs::path& layer : folders(kind))
      clean_up(layer, [](const std::string& t) { return is_frame_name(t, "frame_", {".png"}); });
}

void FileStore::make_current(Manifested& m, const std::string& folder,
                             const std::function<void(const std::string&)>& remove_frames_in) {
  if (m.current) return;
  CHECK(access_ != StoreAccess::kInspect);
  if (access_ == StoreAccess::kFarmTask)
    throw Error(folder, fmt::format("is not prepared for these settings{}; the shot's prepare "
                                    "task (`emaki task prepare`) must run first",
                                    m.stale.empty() ? "" : " (" + m.stale + ")"));
  // Made with other settings: its old frames go before the new settings are recorded, so a run
  // killed in between leaves no old frame under a new manifest.
  const fs::path dir(folder);
  std::error_code ec;
  fs::remove(dir / kManifest, ec);
  remove_frames_in(folder);
  write_manifest((dir / kManifest).string(), m.want);
  m.current = true;
  m.stale.clear();
}

void FileStore::prepare() {
  CHECK(mode_ == StoreMode::kRun);
  const fs::path root(paths_.folder);
  for (const pipeline::Layer& l : shot_.layers)
    make_current(layers_.at(l.name), (root / "layers" / l.name).string(),
                 [&](const std::string& dir) { remove_layer_frames(dir, l.name); });
  make_current(frames_, (root / "composite").string(), [&](const std::string&) {
    remove_frames(root / "composite", "frame_", {".png", ".exr"});
    remove_frames(root / "layered", "frame_", {".exr"});
  });
  if (shot_.source.kind == pipeline::SourceKind::kScene) {
    make_folder(root / "passes");
    make_current(passes_, (root / "passes").string(), remove_pass_cache);
  }
}

bool FileStore::prepared(bool with_pass_cache) const {
  for (const auto& [name, m] : layers_)
    if (!m.current) return false;
  return frames_.current && (passes_.current || !with_pass_cache);
}

bool FileStore::has_passes(int frame) const {
  return passes_.current &&
         mapped_passes_complete(paths_.passes_file(frame), shot_.source.width, shot_.source.height);
}

void FileStore::write_passes(int frame, ImageView<const float> passes) {
  CHECK(access_ != StoreAccess::kInspect);
  const fs::path dir = fs::path(paths_.folder) / "passes";
  make_folder(dir);
  make_current(passes_, dir.string(), remove_pass_cache);
  write_mapped_passes(paths_.passes_file(frame), passes);
}

void FileStore::write_kept_fields(int frame, const std::vector<pipeline::KeptField>& fields) {
  CHECK(access_ != StoreAccess::kInspect);
  const fs::path dir = fs::path(paths_.folder) / "passes";
  make_folder(dir);
  make_current(passes_, dir.string(), remove_pass_cache);
  const std::string path = paths_.passes_fields(frame);
  const std::string bytes =
      encode_kept_fields(frame, shot_.source.width, shot_.source.height, fields);
  TempFile tmp(path, path);
  tmp.write(bytes.data(), bytes.size());
  tmp.commit();
}

FileStore::~FileStore() = default;

const FileStore::Manifested& FileStore::layer_state(const pipeline::Layer& layer) const {
  const auto it = layers_.find(layer.name);
  CHECK(it != layers_.end());
  return it->second;
}

bool FileStore::has_layer(const pipeline::Layer& layer, int frame) const {
  const Manifested& m = layer_state(layer);
  if (!m.current) {
    // `emaki run` redoes a stale layer; commands that only read finished layers stop.
    if (mode_ == StoreMode::kReadFinished && !m.stale.empty())
      throw Error((fs::path(paths_.folder) / "layers" / layer.name).string(),
                  fmt::format("was made with other settings ({}); {}", m.stale, kRedoHint));
    return false;
  }
  // A file cut short (a full disk, a killed copy) is not finished: it is made again.
  if (!image_file_complete(paths_.layer_exr(layer.name, frame))) return false;
  return !shot_.outputs.layer_png || image_file_complete(paths_.layer_png(layer.name, frame));
}

Image<float> FileStore::read_layer(const pipeline::Layer& layer, int frame) const {
  const std::string path = paths_.layer_exr(layer.name, frame);
  Image<float> img = read_image_float(path);
  // The file is on disk, where anything may have replaced it: what the chain and the composite
  // index must match the shot.
  const int n = layer.single_colour ? 1 : 3;
  const int w = shot_.source.width, h = shot_.source.height;
  if (img.width() != w || img.height() != h || img.channels() < n || img.channels() > n + 1)
    throw Error(path,
                fmt::format("is {}x{} with {} channels, the shot makes {}x{} with {} or {}; {}",
                            img.width(), img.height(), img.channels(), w, h, n, n + 1, kRedoHint));
  return img;
}

void FileStore::write_layer(const pipeline::Layer& layer, int frame, ImageView<const float> value) {
  CHECK(access_ != StoreAccess::kInspect);
  make_current(layers_.at(layer.name), (fs::path(paths_.folder) / "layers" / layer.name).string(),
               [&](const std::string& dir) { remove_layer_frames(dir, layer.name); });
  const int n = layer.single_colour ? 1 : 3;
  // The PNG first: the EXR is what marks the frame finished, so it is written last.
  if (shot_.outputs.layer_png) {
    WriteOptions png;
    png.format = SampleFormat::kU16;
    write_image(paths_.layer_png(layer.name, frame), value, png);
  }
  WriteOptions exr;
  exr.format = SampleFormat::kFloat;  // full float: the temporal chain resumes from it bit for bit
  exr.channel_names = value_names("", value.channels, n);
  write_image(paths_.layer_exr(layer.name, frame), value, exr);
}

void FileStore::write_qa_map(const std::string& kind, const pipeline::Layer& layer, int frame,
                             ImageView<const float> map) {
  CHECK(access_ != StoreAccess::kInspect);
  io::write_qa_map(paths_.folder, kind, layer.name, frame, map);
}

void FileStore::write_field(const pipeline::Layer& layer, int frame, ImageView<const int32_t> nnf,
                            uint64_t digest) {
  CHECK(access_ != StoreAccess::kInspect);
  CHECK_EQ(nnf.channels, 2);
  make_current(layers_.at(layer.name), (fs::path(paths_.folder) / "layers" / layer.name).string(),
               [&](const std::string& dir) { remove_layer_frames(dir, layer.name); });
  const std::string path = paths_.layer_field(layer.name, frame);
  const std::string bytes = encode_field(frame, nnf, digest);
  TempFile tmp(path, path);
  tmp.write(bytes.data(), bytes.size());
  tmp.commit();
}

void FileStore::remove_field(const pipeline::Layer& layer, int frame) {
  CHECK(access_ != StoreAccess::kInspect);
  const std::string path = paths_.layer_field(layer.name, frame);
  std::error_code ec;
  // The store's own hidden file, and only a regular file: never a folder or a link's target.
  if (fs::is_regular_file(fs::symlink_status(path, ec))) fs::remove(path, ec);
}

Image<int32_t> FileStore::read_field(const pipeline::Layer& layer, int frame,
                                     uint64_t digest) const {
  if (!layer_state(layer).current) return {};
  const std::string path = paths_.layer_field(layer.name, frame);
  const FieldKey want{frame, shot_.source.width, shot_.source.height, digest};
  std::error_code ec;
  // The size first: nothing is read for a file that cannot be this frame's field.
  if (!fs::is_regular_file(path, ec)) return {};
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec || size < kFieldHeaderBytes || size > max_field_file_bytes(want.width, want.height))
    return {};
  std::string bytes(std::size_t(size), '\0');
  std::ifstream in(path, std::ios::binary);
  // One byte more than the size said: a file that grew meanwhile is not this field.
  if (!in.read(bytes.data(), std::streamsize(size)) ||
      in.peek() != std::ifstream::traits_type::eof())
    return {};
  return decode_field(bytes.data(), bytes.size(), want);
}

bool FileStore::has_frame(int frame) const {
  if (!frames_.current) return false;
  const pipeline::Outputs& o = shot_.outputs;
  if (o.composite_png && !image_file_complete(paths_.composite_png(frame))) return false;
  if (o.composite_exr && !image_file_complete(paths_.composite_exr(frame))) return false;
  if (o.layered_exr && !image_file_complete(paths_.layered_exr(frame))) return false;
  return true;
}

std::string FileStore::working_space() const {
  return shot_.colour.get().resolve(shot_.colour.working_space(shot_.compositing.space));
}

// The composite EXRs are in the working space: its name and chromaticities in the header
// (docs/shot_file.md, "What a compositor gets").
WriteOptions FileStore::exr_options() const {
  WriteOptions wo;
  wo.format = SampleFormat::kHalf;
  const std::string space = working_space();
  wo.attributes = {{"colorSpace", space}};
  wo.chromaticities = shot_.colour.get().chromaticities(space);
  return wo;
}

void FileStore::write_frame(int frame, ImageView<const float> composite,
                            const std::vector<ImageView<const float>>& layers,
                            ImageView<const float> passes) {
  CHECK(access_ != StoreAccess::kInspect);
  const pipeline::Outputs& o = shot_.outputs;
  const fs::path root(paths_.folder);
  make_current(frames_, (root / "composite").string(), [&](const std::string&) {
    remove_frames(root / "composite", "frame_", {".png", ".exr"});
    remove_frames(root / "layered", "frame_", {".exr"});
  });
  // The composite without its (constant) alpha.
  Image<float> rgb(composite.width, composite.height, 3);
  for (int y = 0; y < composite.height; ++y)
    for (int x = 0; x < composite.width; ++x)
      for (int c = 0; c < 3; ++c) rgb(x, y, c) = composite(x, y, c);
  if (o.layered_exr) {
    std::vector<std::string> names = render::channel_names();
    int channels = passes.channels + 3;
    for (std::size_t i = 0; i < layers.size(); ++i) {
      // Prefixed: a layer may share its name with a pass ("shadow", "outline").
      const auto n = value_names("layer_" + shot_.layers[i].name + ".", layers[i].channels,
                                 shot_.layers[i].single_colour ? 1 : 3);
      names.insert(names.end(), n.begin(), n.end());
      channels += layers[i].channels;
    }
    for (const char* c : {"composite.R", "composite.G", "composite.B"}) names.push_back(c);
    Image<float> all(passes.width, passes.height, channels);
    parallel_rows(passes.height, 16, [&](int y0, int y1) {
      for (int y = y0; y < y1; ++y) {
        float* d = all.row(y);
        const float* p = passes.row(y);
        const float* c = rgb.row(y);
        for (int x = 0; x < passes.width; ++x) {
          d = std::copy_n(p + std::ptrdiff_t(x) * passes.channels, passes.channels, d);
          for (const auto& l : layers) d = std::copy_n(l.at(x, y), l.channels, d);
          d = std::copy_n(c + 3 * x, 3, d);
        }
      }
    });
    WriteOptions wo = exr_options();
    wo.channel_names = names;
    write_image(paths_.layered_exr(frame), all.cview(), wo);
  }
  if (o.composite_exr) write_image(paths_.composite_exr(frame), rgb.cview(), exr_options());
  // The PNG last: with the default outputs it is what has_frame looks for first. It goes
  // through the display and view (nothing changes when the view writes the working space).
  if (o.composite_png) {
    shot_.colour.get().to_display(rgb.view(), working_space(), shot_.colour.display,
                                  shot_.colour.view);
    WriteOptions wo;
    wo.format = SampleFormat::kU16;
    write_image(paths_.composite_png(frame), rgb.cview(), wo);
  }
}

namespace {

// A scene's frames with the pass cache in front: a cached frame is read, any other rendered.
class CachedFrames : public pipeline::FrameSource {
 public:
  CachedFrames(const Shot& shot, std::unique_ptr<pipeline::FrameSource> inner)
      : paths_{shot.outputs.folder},
        width_(shot.source.width),
        height_(shot.source.height),
        inner_(std::move(inner)) {}
  // A cached frame that is missing, cut short or unreadable is rendered instead (the cache holds
  // exactly what rendering gives): a damaged cache never stops a run, `--force` or not.
  // The file is mapped, not read (store/mapped_passes.h); one of another size is not used.
  Image<float> passes(int frame) const override {
    std::optional<Image<float>> mapped = map_passes(paths_.passes_file(frame), width_, height_);
    return mapped ? std::move(*mapped) : inner_->passes(frame);
  }
  // A file that is missing, cut short or damaged gives none: the layers compute theirs. It is
  // mapped, not read: nothing is allocated for what a file claims before it is checked.
  std::vector<pipeline::KeptField> kept_fields(int frame) const override {
    const std::string path = paths_.passes_fields(frame);
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return {};
    struct stat st {};
    void* block = ::fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && st.st_size > 0
                      ? ::mmap(nullptr, std::size_t(st.st_size), PROT_READ, MAP_PRIVATE, fd, 0)
                      : MAP_FAILED;
    ::close(fd);
    if (block == MAP_FAILED) return {};
    std::vector<pipeline::KeptField> fields =
        decode_kept_fields(block, std::size_t(st.st_size), frame, width_, height_);
    ::munmap(block, std::size_t(st.st_size));
    return fields;
  }

 private:
  OutputPaths paths_;
  int width_, height_;
  std::unique_ptr<pipeline::FrameSource> inner_;
};

}  // namespace

std::unique_ptr<pipeline::FrameSource> with_pass_cache(
    const Shot& shot, std::unique_ptr<pipeline::FrameSource> frames) {
  if (shot.source.kind != pipeline::SourceKind::kScene) return frames;
  const auto have = read_manifest((fs::path(shot.outputs.folder) / "passes" / kManifest).string());
  if (!have || !manifest_current(*have, passes_manifest(shot))) return frames;
  return std::make_unique<CachedFrames>(shot, std::move(frames));
}

}  // namespace emaki::io
