#include "io/shot_inputs.h"

#include <fmt/format.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <initializer_list>

#include "core/error.h"
#include "core/limits.h"
#include "io/gltf_loader.h"
#include "io/image_io.h"
#include "io/shot_manifest.h"
#include "io/studio_passes.h"

extern char** environ;

namespace emaki::io {

namespace fs = std::filesystem;
using pipeline::Shot;

std::string frame_file(const std::string& pattern, int frame) {
  std::string out;
  for (std::size_t i = 0; i < pattern.size(); ++i) {
    if (pattern[i] != '%') {
      out += pattern[i];
      continue;
    }
    std::size_t j = i + 1;
    int width = 0;
    while (j < pattern.size() && std::isdigit(static_cast<unsigned char>(pattern[j]))) {
      width = width * 10 + (pattern[j++] - '0');
      // Checked per digit, so the width never overflows an int either.
      if (width > kMaxFrameWidth)
        throw Error("source.sequence",
                    fmt::format("'{}': the frame number's width must be at most {}", echo(pattern),
                                kMaxFrameWidth));
    }
    out += fmt::format("{:0{}d}", frame, width);
    i = j;  // at the 'd'
  }
  return out;
}

std::vector<std::string> source_channels(const pipeline::Source& source,
                                         const render::PassInfo& pass) {
  for (const auto& m : source.channels)
    if (m.pass == pass.name) return m.channels;
  std::vector<std::string> names;
  for (int c = 0; c < pass.count; ++c)
    names.push_back(fmt::format("{}.{}", pass.name, pass.suffixes[c]));
  return names;
}

Image<float> read_pass_file(const std::string& file, const std::string& preset,
                            const std::string& view_layer) {
  if (preset == "blender") {
    const Image<float> raw = read_image_float(file, ReadOptions{blender_channels(view_layer)});
    glm::vec3 lo(INFINITY), hi(-INFINITY);
    add_blender_bounds(raw.cview(), lo, hi);
    return blender_to_emaki(raw.cview(), cube_around(lo, hi), file);
  }
  const std::vector<std::string> have = list_channels(file);
  std::vector<std::string> names;
  for (const render::PassInfo& p : render::pass_table())
    for (int c = 0; c < p.count; ++c) {
      const std::string name = fmt::format("{}.{}", p.name, p.suffixes[c]);
      const bool found = std::find(have.begin(), have.end(), name) != have.end();
      names.push_back(found || p.count > 1 ? name : std::string(p.name) + ".V");
    }
  return read_image_float(file, ReadOptions{names});
}

namespace {

// The shot file's spelling of each neutral field (Error::Field) the loaders below can meet: the
// one place a field becomes a key. `section` is the table the field sits in; an exemplar's key
// takes its name ("exemplars.NAME.sphere").
struct ShotKey {
  const char* field;
  const char* section;
  const char* key;
};
constexpr ShotKey kShotKeys[] = {
    {"frames", "source", "frames"},
    {"fps", "source", "fps"},
    {"clip", "source", "clip"},
    {"start", "source", "start"},
    {"aa", "source", "aa"},
    {"gltf_node", "source", "camera.gltf_node"},
    {"sphere", "exemplars", "sphere"},
    {"horizon", "exemplars", "horizon"},
};

// Rethrows `e` named by its shot file key under `table` ("source" or "exemplars.NAME"). An error
// that names no field (a file path) is rethrown as it is; a field with no key here keeps its
// neutral name, which is true, rather than a guessed key, and is marked as spelled so that the
// command line does not re-spell it as one of its options.
[[noreturn]] void rethrow_as_key(const Error& e, const std::string& table) {
  if (e.field().empty()) throw e;
  const std::string section = table.substr(0, table.find('.'));
  for (const ShotKey& k : kShotKeys)
    if (e.field() == k.field && section == k.section) throw e.respelled(table + "." + k.key);
  throw e.respelled(e.subject());
}

class SequenceFrames : public pipeline::FrameSource {
 public:
  explicit SequenceFrames(const pipeline::Source& s) : source_(s) {
    if (s.preset == "blender") {
      raw_ = blender_channels(s.view_layer);
      for (const auto& m : s.channels)
        for (const std::string& c : m.channels) channels_.push_back(c);
      // position_norm's cube: every frame's covered positions, so it is fixed for the shot.
      glm::vec3 lo(INFINITY), hi(-INFINITY);
      for (int f = s.first_frame; f <= s.last_frame; ++f) {
        const Image<float> raw = read_raw(frame_file(s.pattern, f));
        add_blender_bounds(raw.cview(), lo, hi);
      }
      cube_ = cube_around(lo, hi);
      return;
    }
    for (const render::PassInfo& p : render::pass_table())
      for (const std::string& c : source_channels(s, p)) channels_.push_back(c);
  }
  Image<float> passes(int frame) const override {
    const std::string file = frame_file(source_.pattern, frame);
    if (source_.preset != "blender") {
      Image<float> frame = read_checked(file, channels_);
      apply_conventions(frame, {source_.world_normals, source_.z_up, source_.premultiplied}, file);
      return frame;
    }
    Image<float> out = blender_to_emaki(read_raw(file).cview(), cube_, file);
    // Passes mapped in source.channels are read as they are, over the converted ones.
    if (!channels_.empty()) {
      const Image<float> mapped = read_checked(file, channels_);
      int k = 0;
      for (const auto& m : source_.channels) {
        const render::PassInfo* p = render::find_pass(m.pass);
        for (int c = 0; c < p->count; ++c, ++k)
          for (int y = 0; y < out.height(); ++y)
            for (int x = 0; x < out.width(); ++x) out(x, y, p->first + c) = mapped(x, y, k);
      }
    }
    return out;
  }

 private:
  Image<float> read_checked(const std::string& file, const std::vector<std::string>& ch) const {
    Image<float> img = read_image_float(file, ReadOptions{ch});
    if (img.width() != source_.width || img.height() != source_.height)
      throw Error(file, fmt::format("is {}x{}, the sequence's first frame is {}x{}", img.width(),
                                    img.height(), source_.width, source_.height));
    return img;
  }
  Image<float> read_raw(const std::string& file) const { return read_checked(file, raw_); }

  pipeline::Source source_;
  std::vector<std::string> channels_;  // emaki: every pass; blender: the mapped passes only
  std::vector<std::string> raw_;       // blender: blender_channels()
  Cube cube_;
};

Image<float> rgb_of(const std::string& key, const std::string& path) {
  Image<float> img = read_image_float(path);
  if (img.channels() >= 3 && img.channels() <= 4) {
    if (img.channels() == 3) return img;
    Image<float> out(img.width(), img.height(), 3);
    for (int y = 0; y < img.height(); ++y)
      for (int x = 0; x < img.width(); ++x)
        for (int c = 0; c < 3; ++c) out(x, y, c) = img(x, y, c);
    return out;
  }
  if (img.channels() <= 2) {
    Image<float> out(img.width(), img.height(), 3);
    for (int y = 0; y < img.height(); ++y)
      for (int x = 0; x < img.width(); ++x)
        for (int c = 0; c < 3; ++c) out(x, y, c) = img(x, y, 0);
    return out;
  }
  throw Error(
      key, fmt::format("'{}' has {} channels; expected grey, RGB or RGBA", path, img.channels()));
}

}  // namespace

std::unique_ptr<pipeline::FrameSource> open_frames(const Shot& shot) {
  const pipeline::Source& s = shot.source;
  if (s.kind == pipeline::SourceKind::kSequence) return std::make_unique<SequenceFrames>(s);
  scene::Scene scene = load_gltf(s.scene_path);
  try {
    return pipeline::scene_frames(std::move(scene), s);
  } catch (const Error& e) {
    rethrow_as_key(e, "source");
  }
}

std::map<std::string, pipeline::ExemplarImages> load_exemplars(const Shot& shot) {
  std::map<std::string, pipeline::ExemplarImages> out;
  for (const pipeline::Exemplar& e : shot.exemplars) {
    const std::string key = "exemplars." + e.name;
    pipeline::ExemplarImages im;
    im.painting = rgb_of(key + ".painting", e.painting);
    const int w = im.painting.width(), h = im.painting.height();
    if (e.kind == pipeline::ExemplarKind::kMatcap) {
      try {
        im.passes = pipeline::matcap_passes(e, w, h);
      } catch (const Error& err) {
        rethrow_as_key(err, key);
      }
    } else {
      // Read the passes the layers use as guides; the rest stay zero.
      im.passes = Image<float>(w, h, render::kChannelCount);
      const std::vector<std::string> have = list_channels(e.passes);
      for (const pipeline::Layer& l : shot.layers) {
        if (l.exemplar != e.name) continue;
        for (const pipeline::GuideSpec& g : l.guides) {
          const render::PassInfo* p = render::find_pass(g.pass);
          std::vector<std::string> names;
          for (int c = 0; c < p->count; ++c)
            names.push_back(fmt::format("{}.{}", p->name, p->suffixes[c]));
          // tools/blender/emaki_passes.py writes a single-channel pass as NAME.V.
          const std::string value = std::string(p->name) + ".V";
          if (p->count == 1 && std::find(have.begin(), have.end(), names[0]) == have.end() &&
              std::find(have.begin(), have.end(), value) != have.end())
            names = {value};
          for (const std::string& n : names)
            if (std::find(have.begin(), have.end(), n) == have.end())
              throw Error(key + ".passes",
                          fmt::format("channel '{}' (guide '{}' of layer '{}') is not in '{}'", n,
                                      g.pass, l.name, e.passes));
          const Image<float> pass = read_image_float(e.passes, ReadOptions{names});
          if (pass.width() != w || pass.height() != h)
            throw Error(key + ".passes",
                        fmt::format("'{}' is {}x{}, its painting '{}' is {}x{}", e.passes,
                                    pass.width(), pass.height(), e.painting, w, h));
          for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
              for (int c = 0; c < p->count; ++c) im.passes(x, y, p->first + c) = pass(x, y, c);
        }
      }
    }
    out.emplace(e.name, std::move(im));
  }
  return out;
}

pipeline::CompositeInputs load_composite_inputs(const Shot& shot) {
  pipeline::CompositeInputs ci;
  if (!shot.compositing.paper.empty())
    ci.paper = rgb_of("compositing.paper", shot.compositing.paper);
  return ci;
}

// ---- the output folder ----

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

constexpr const char* kManifest = ".emaki-manifest";

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

const char* kRedo = "run `emaki run` to redo it (`emaki run --force` redoes everything)";

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
                  fmt::format("was made with other settings ({}); {}", m.stale, kRedo));
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
                            img.width(), img.height(), img.channels(), w, h, n, n + 1, kRedo));
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

// ---- previews ----

void encode_mp4(const std::string& pattern, int first, float fps, int crf, const std::string& out) {
  // Created exclusively beside the target; ffmpeg then writes the file we made (commit checks
  // that it still is).
  TempFile tmp_file(out, "outputs.mp4");
  const std::string tmp = tmp_file.path();
  std::vector<std::string> args = {"ffmpeg", "-nostdin", "-y", "-loglevel", "error", "-framerate",
                                   fmt::format("{}", fps), "-start_number", std::to_string(first),
                                   "-i", pattern, "-c:v", "libx264", "-pix_fmt", "yuv420p", "-crf",
                                   std::to_string(crf),
                                   // yuv420p needs even sizes.
                                   "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", tmp};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  if (posix_spawnp(&pid, "ffmpeg", nullptr, nullptr, argv.data(), environ) != 0)
    throw Error("outputs.mp4", "cannot run 'ffmpeg' (is it installed and on PATH?)");
  int status = 0;
  waitpid(pid, &status, 0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw Error("outputs.mp4", fmt::format("ffmpeg failed encoding '{}'", pattern));
  tmp_file.commit();
}

std::vector<std::string> write_previews(const Shot& shot, int first, int last) {
  std::vector<std::string> written;
  const OutputPaths paths{shot.outputs.folder};
  std::error_code ec;
  // Frames composited under other settings (a killed run after a resize) are not previewed.
  const auto made =
      read_manifest((fs::path(shot.outputs.folder) / "composite" / kManifest).string());
  if (!made || *made != frames_manifest(shot)) return written;
  for (int f = first; f <= last; ++f)
    if (!fs::is_regular_file(paths.composite_png(f), ec)) return written;  // not all composited
  if (shot.outputs.contact_sheet && shot.outputs.composite_png) {
    // At most 12 frames, spread over the shot.
    const int count = std::min(12, last - first + 1);
    std::vector<Image<float>> thumbs;
    for (int i = 0; i < count; ++i) {
      const int f = count == 1 ? first : first + int((long(last - first) * i) / (count - 1));
      const std::string file = paths.composite_png(f);
      thumbs.push_back(read_image_float(file));
      const Image<float>& t = thumbs.back();
      if (t.width() != shot.source.width || t.height() != shot.source.height)
        throw Error(file, fmt::format("is {}x{}, the shot makes {}x{}; {}", t.width(), t.height(),
                                      shot.source.width, shot.source.height, kRedo));
    }
    const Image<float> sheet = pipeline::contact_sheet(thumbs, 4, 320);
    WriteOptions wo;
    wo.format = SampleFormat::kU8;
    write_image(paths.contact_sheet(), sheet.cview(), wo);
    written.push_back(paths.contact_sheet());
  }
  if (shot.outputs.mp4) {
    encode_mp4(shot.outputs.folder + "/composite/frame_%04d.png", first, shot.source.fps,
               shot.outputs.crf, paths.mp4());
    written.push_back(paths.mp4());
  }
  return written;
}

}  // namespace emaki::io
