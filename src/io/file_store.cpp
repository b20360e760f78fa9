#include "io/file_store.h"

#include <fmt/format.h>

#include <filesystem>
#include <initializer_list>

#include "core/error.h"
#include "core/limits.h"
#include "io/image_io.h"
#include "io/shot_manifest.h"

namespace emaki::io {

namespace fs = std::filesystem;
using pipeline::Shot;

std::string OutputPaths::layer_exr(const std::string& layer, int frame) const {
  return fmt::format("{}/layers/{}/{}_{:04d}.exr", folder, layer, layer, frame);
}
std::string OutputPaths::layer_png(const std::string& layer, int frame) const {
  return fmt::format("{}/layers/{}/{}_{:04d}.png", folder, layer, layer, frame);
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

namespace {

void make_folder(const fs::path& p) {
  std::error_code ec;
  fs::create_directories(p, ec);
  if (!fs::is_directory(p, ec))
    throw Error("outputs.folder", fmt::format("cannot create folder '{}'", p.string()));
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

FileStore::FileStore(const Shot& shot, StoreMode mode) : shot_(shot), mode_(mode) {
  paths_.folder = shot.outputs.folder;
  const fs::path root(paths_.folder);
  make_folder(root);
  // Before anything is cleaned up or written: another emaki's temporaries are not ours to remove.
  lock_ = std::make_unique<FolderLock>(paths_.folder);
  remove_temporaries(root.string(), [](const std::string& t) {
    return t == "contact_sheet.png" || t == "preview.mp4";
  });
  for (const char* sub : {"composite", "layered"}) {
    make_folder(root / sub);
    remove_temporaries((root / sub).string(), [](const std::string& t) {
      return t == kManifest || is_frame_name(t, "frame_", {".png", ".exr"});
    });
  }
  for (const pipeline::Layer& l : shot.layers) {
    const fs::path dir = root / "layers" / l.name;
    make_folder(dir);
    remove_temporaries(dir.string(), [&](const std::string& t) {
      return t == kManifest || is_frame_name(t, l.name + "_", {".png", ".exr"});
    });
    Manifested& m = layers_[l.name];
    m.want = layer_manifest(shot, l);
    const auto have = read_manifest((dir / kManifest).string());
    m.current = have && *have == m.want;
    if (!m.current)
      m.stale = have ? manifest_difference(*have, m.want)
                : any_frame(dir, l.name + "_", {".png", ".exr"})
                    ? "no record of the settings that made it"
                    : "";
  }
  frames_.want = frames_manifest(shot);
  const auto have = read_manifest((root / "composite" / kManifest).string());
  frames_.current = have && *have == frames_.want;
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
  std::error_code ec;
  if (!fs::is_regular_file(paths_.layer_exr(layer.name, frame), ec)) return false;
  return !shot_.outputs.layer_png || fs::is_regular_file(paths_.layer_png(layer.name, frame), ec);
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
  Manifested& m = layers_.at(layer.name);
  if (!m.current) {
    // Made with other settings: its old frames go before the new settings are recorded, so a
    // run killed in between leaves no old frame under a new manifest.
    const fs::path dir = fs::path(paths_.folder) / "layers" / layer.name;
    std::error_code ec;
    fs::remove(dir / kManifest, ec);
    remove_frames(dir, layer.name + "_", {".png", ".exr"});
    write_manifest((dir / kManifest).string(), m.want);
    m.current = true;
    m.stale.clear();
  }
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

bool FileStore::has_frame(int frame) const {
  if (!frames_.current) return false;
  std::error_code ec;
  const pipeline::Outputs& o = shot_.outputs;
  if (o.composite_png && !fs::is_regular_file(paths_.composite_png(frame), ec)) return false;
  if (o.composite_exr && !fs::is_regular_file(paths_.composite_exr(frame), ec)) return false;
  if (o.layered_exr && !fs::is_regular_file(paths_.layered_exr(frame), ec)) return false;
  return true;
}

void FileStore::write_frame(int frame, ImageView<const float> composite,
                            const std::vector<ImageView<const float>>& layers,
                            ImageView<const float> passes) {
  const pipeline::Outputs& o = shot_.outputs;
  if (!frames_.current) {
    const fs::path root(paths_.folder);
    std::error_code ec;
    fs::remove(root / "composite" / kManifest, ec);
    remove_frames(root / "composite", "frame_", {".png", ".exr"});
    remove_frames(root / "layered", "frame_", {".exr"});
    write_manifest((root / "composite" / kManifest).string(), frames_.want);
    frames_.current = true;
  }
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
    for (int y = 0; y < passes.height; ++y)
      for (int x = 0; x < passes.width; ++x) {
        float* d = all.at(x, y);
        for (int c = 0; c < passes.channels; ++c) *d++ = passes(x, y, c);
        for (const auto& l : layers)
          for (int c = 0; c < l.channels; ++c) *d++ = l(x, y, c);
        for (int c = 0; c < 3; ++c) *d++ = rgb(x, y, c);
      }
    WriteOptions wo;
    wo.format = SampleFormat::kHalf;
    wo.channel_names = names;
    write_image(paths_.layered_exr(frame), all.cview(), wo);
  }
  if (o.composite_exr) {
    WriteOptions wo;
    wo.format = SampleFormat::kHalf;
    write_image(paths_.composite_exr(frame), rgb.cview(), wo);
  }
  // The PNG last: with the default outputs it is what has_frame looks for first.
  if (o.composite_png) {
    WriteOptions wo;
    wo.format = SampleFormat::kU16;
    write_image(paths_.composite_png(frame), rgb.cview(), wo);
  }
}

}  // namespace emaki::io
