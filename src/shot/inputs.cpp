#include "shot/inputs.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <mutex>
#include <optional>

#include "colour/colour.h"
#include "core/error.h"
#include "core/limits.h"
#include "core/resample.h"
#include "core/shot_keys.h"
#include "io/gltf_loader.h"
#include "io/image_io.h"
#include "shot/objects.h"
#include "store/file_store.h"
#include "store/frame_sequence.h"
#include "store/output_store.h"
#include "store/reference_cache.h"
#include "store/settings_manifests.h"

namespace emaki::shot {

using io::ReadOptions;
using pipeline::Shot;

namespace {

// Rethrows `e` named by its shot file key under `table` ("source" or "exemplars.NAME"). An error
// that names no field (a file path) is rethrown as it is; a field with no key here keeps its
// neutral name, which is true, rather than a guessed key, and is marked as spelled so that the
// command line does not re-spell it as one of its options.
[[noreturn]] void rethrow_as_key(const Error& e, const std::string& table) {
  if (e.field().empty()) throw e;
  const std::string section = table.substr(0, table.find('.'));
  for (const shot_keys::FieldKey& k : shot_keys::kFieldKeys)
    if (e.field() == k.field && section == k.section) throw e.respelled(table + "." + k.key);
  throw e.respelled(e.subject());
}

// The largest input file read whole into memory to be decoded (and digested) in one read; a
// larger one is read the ordinary way.
constexpr std::size_t kMaxInputBytes = std::size_t(1) << 30;

// An input file's bytes, read once for its decoding and its digest (file_digest); empty when it
// is left to the readers that take a path (which word the errors).
std::optional<std::string> input_bytes(const std::string& path) {
  return io::read_input_file(path, kMaxInputBytes);
}

Image<float> read_input_image(const std::string& path, const std::optional<std::string>& bytes,
                              const ReadOptions& options = {}) {
  if (bytes) return io::read_image_memory(bytes->data(), bytes->size(), path, options).to_float();
  return io::read_image_float(path, options);
}

// What `decode` makes of the file at `path` (given its bytes, or nullopt when they are left to a
// reader that takes the path), taken from `cache` when the file holds the bytes of one decoded
// before. `kind` tells apart what different decoders make of one file.
Image<float> decoded(InputCache* cache, const std::string& kind, const std::string& path,
                     const std::function<Image<float>(const std::optional<std::string>&)>& decode) {
  if (!cache) return decode(input_bytes(path));
  const std::string prefix = kind + "|" + path + "|";
  if (const auto kept = cache->find(prefix + io::file_digest(path))) return kept->clone();
  // The key is the digest of the very bytes decoded: a file saved again meanwhile misses next
  // time instead of finding this image under its new digest.
  const std::optional<std::string> bytes = input_bytes(path);
  Image<float> image = decode(bytes);
  if (bytes) cache->keep(prefix + io::bytes_digest(*bytes), image.clone());
  return image;
}

Image<float> rgb_of(const std::string& key, const std::string& path, InputCache* cache) {
  Image<float> img = decoded(cache, "image", path, [&](const std::optional<std::string>& bytes) {
    return read_input_image(path, bytes);
  });
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

// The albedo of a studio render's passes (all of render's channels) converted from `space` to
// the config's scene_linear (what emaki's renderer writes); the data passes are left as they are.
void albedo_to_scene_linear(const colour::Config& colour, const std::string& space,
                            Image<float>& passes) {
  ImageView<float> albedo = passes.view();
  albedo.data += render::kAlbedo;
  albedo.channels = passes.channels();  // the pixel step; convert() touches the first three
  colour.convert(albedo, space, "scene_linear");
}

// A studio render's frames, their albedo from source.passes_colorspace to scene_linear.
class ColourConvertedFrames : public pipeline::FrameSource {
 public:
  ColourConvertedFrames(const Shot& shot, std::unique_ptr<pipeline::FrameSource> inner)
      : colour_(shot.colour), space_(shot.source.passes_colorspace), inner_(std::move(inner)) {}
  Image<float> passes(int frame) const override {
    Image<float> p = inner_->passes(frame);
    albedo_to_scene_linear(colour_.get(), space_, p);
    return p;
  }

 private:
  const pipeline::Colour colour_;
  const std::string space_;
  std::unique_ptr<pipeline::FrameSource> inner_;
};

// A scene's frames, the scene loaded when a frame is first rendered.
class LazySceneFrames final : public pipeline::FrameSource {
 public:
  explicit LazySceneFrames(const pipeline::Source& source) : source_(source) {}
  void load() const {
    std::call_once(loaded_, [this] {
      try {
        frames_ = pipeline::scene_frames(load_scene(source_), source_);
      } catch (const Error& e) {
        rethrow_as_key(e, "source");
      }
    });
  }
  Image<float> passes(int frame) const override {
    load();
    return frames_->passes(frame);
  }

 private:
  const pipeline::Source source_;
  mutable std::once_flag loaded_;
  mutable std::unique_ptr<pipeline::FrameSource> frames_;
};

}  // namespace

std::unique_ptr<pipeline::FrameSource> open_frames(const Shot& shot, InputCache* cache) {
  const pipeline::Source& s = shot.source;
  try {
    if (s.kind == pipeline::SourceKind::kSequence) {
      std::unique_ptr<pipeline::FrameSource> frames = io::open_sequence(s);
      if (shot.colour.get().is_identity(s.passes_colorspace, "scene_linear")) return frames;
      return std::make_unique<ColourConvertedFrames>(shot, std::move(frames));
    }
    const auto open = [&]() -> std::unique_ptr<pipeline::FrameSource> {
      auto lazy = std::make_unique<LazySceneFrames>(s);
      const LazySceneFrames* scene = lazy.get();
      std::unique_ptr<pipeline::FrameSource> frames = io::with_pass_cache(shot, std::move(lazy));
      // Without a current pass cache every frame is rendered: the scene is loaded now, so that
      // a bad one fails before any output is written. With one, its passes were rendered from
      // this very scene file (the cache's manifest holds its digest), and a farm task that only
      // reads them (a layer or composite task) never parses the scene nor decodes its textures.
      if (frames.get() == scene) scene->load();
      return frames;
    };
    if (!cache) return open();
    // Everything that decides a frame's passes, the scene file's digest included.
    std::string settings;
    for (const std::string& line : io::passes_manifest(shot)) settings += line + "\n";
    return cache->frames(settings, open);
  } catch (const Error& e) {
    rethrow_as_key(e, "source");
  }
}

namespace {

// A MatCap-like exemplar's reference passes at w x h: from the shot's output folder when a task
// or run kept them there (with `rendered`), else rendered (and then noted in `rendered`).
Image<float> reference_passes(const Shot& shot, const pipeline::Exemplar& e, int w, int h,
                              std::vector<std::string>* rendered) {
  // Rendered once per shot: later tasks and runs read what the first one kept.
  std::optional<Image<float>> kept;
  if (rendered) kept = io::read_reference(shot.outputs.folder, io::reference_key(e, w, h), w, h);
  if (!kept) {
    try {
      kept = pipeline::matcap_passes(e, w, h);
    } catch (const Error& err) {
      rethrow_as_key(err, "exemplars." + e.name);
    }
    if (rendered) rendered->push_back(e.name);
  }
  return std::move(*kept);
}

// A studio exemplar's pass file (`bytes`, or nullopt: read it by path) as kChannelCount channels
// of w x h: the passes its layers use as guides, the rest zero.
Image<float> studio_passes(const Shot& shot, const pipeline::Exemplar& e, int w, int h,
                           const std::optional<std::string>& bytes) {
  const std::string key = "exemplars." + e.name;
  Image<float> passes(w, h, render::kChannelCount);
  const std::vector<std::string> have =
      bytes ? io::list_channels_memory(bytes->data(), bytes->size(), e.passes)
            : io::list_channels(e.passes);
  std::vector<std::string> names;  // the file's channels to read
  std::vector<int> into;           // parallel: the channel of `passes` each fills
  for (const pipeline::Layer& l : shot.layers) {
    if (l.exemplar != e.name) continue;
    for (const pipeline::GuideSpec& g : l.guides) {
      const render::PassInfo* p = render::find_pass(g.pass);
      std::vector<std::string> pass_names;
      for (int c = 0; c < p->count; ++c)
        pass_names.push_back(fmt::format("{}.{}", p->name, p->suffixes[c]));
      // tools/blender/emaki_passes.py writes a single-channel pass as NAME.V.
      const std::string value = std::string(p->name) + ".V";
      if (p->count == 1 && std::find(have.begin(), have.end(), pass_names[0]) == have.end() &&
          std::find(have.begin(), have.end(), value) != have.end())
        pass_names = {value};
      for (int c = 0; c < p->count; ++c) {
        const std::string& n = pass_names[std::size_t(c)];
        if (std::find(have.begin(), have.end(), n) == have.end())
          throw Error(key + ".passes",
                      fmt::format("channel '{}' (guide '{}' of layer '{}') is not in '{}'", n,
                                  g.pass, l.name, e.passes));
        if (std::find(into.begin(), into.end(), p->first + c) != into.end()) continue;
        names.push_back(n);
        into.push_back(p->first + c);
      }
    }
  }
  if (!names.empty()) {
    const Image<float> pass =
        bytes ? io::read_image_memory(bytes->data(), bytes->size(), e.passes, ReadOptions{names})
                    .to_float()
              : io::read_image_float(e.passes, ReadOptions{names});
    if (pass.width() != w || pass.height() != h)
      throw Error(key + ".passes",
                  fmt::format("'{}' is {}x{}, its painting '{}' is {}x{}", e.passes, pass.width(),
                              pass.height(), e.painting, w, h));
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        for (std::size_t i = 0; i < into.size(); ++i) passes(x, y, into[i]) = pass(x, y, int(i));
  }
  // Its albedo is a studio render's, in source.passes_colorspace, as the shot's frames are.
  if (std::find(into.begin(), into.end(), int(render::kAlbedo)) != into.end())
    albedo_to_scene_linear(shot.colour.get(), shot.source.passes_colorspace, passes);
  return passes;
}

// The passes the layers of exemplar `e` use as guides.
std::vector<std::string> guide_passes(const Shot& shot, const pipeline::Exemplar& e) {
  std::vector<std::string> out;
  for (const pipeline::Layer& l : shot.layers)
    if (l.exemplar == e.name)
      for (const pipeline::GuideSpec& g : l.guides)
        if (std::find(out.begin(), out.end(), g.pass) == out.end()) out.push_back(g.pass);
  return out;
}

// Fills im.guides from `cache` when it holds every guide of `e`'s layers cut from the passes
// `from` names; the passes themselves are then not needed.
bool kept_guides(const Shot& shot, const pipeline::Exemplar& e, InputCache& cache,
                 const std::string& from, pipeline::ExemplarImages& im) {
  std::map<std::string, std::shared_ptr<const Image<float>>> guides;
  for (const std::string& pass : guide_passes(shot, e)) {
    auto kept = cache.find("guide|" + from + "|" + pass);
    if (!kept) return false;
    guides.emplace(pass, std::move(kept));
  }
  im.guides = std::move(guides);
  return true;
}

// Cuts the guides of `e`'s layers out of im.passes into im.guides, and keeps them in `cache`.
void keep_guides(const Shot& shot, const pipeline::Exemplar& e, InputCache& cache,
                 const std::string& from, pipeline::ExemplarImages& im) {
  for (const std::string& pass : guide_passes(shot, e))
    im.guides[pass] =
        cache.keep("guide|" + from + "|" + pass, pipeline::extract_pass(im.passes.cview(), pass));
}

}  // namespace

std::map<std::string, pipeline::ExemplarImages> load_exemplars(const Shot& shot,
                                                               std::vector<std::string>* rendered,
                                                               InputCache* cache) {
  std::map<std::string, pipeline::ExemplarImages> out;
  for (const pipeline::Exemplar& e : shot.exemplars) {
    const std::string key = "exemplars." + e.name;
    pipeline::ExemplarImages im;
    im.painting = rgb_of(key + ".painting", e.painting, cache);
    shot.colour.get().convert(im.painting.view(), e.colorspace, "color_picking");
    if (e.scale != 1.0)
      im.painting = resample_area(im.painting.cview(),
                                  std::max(1, int(std::lround(im.painting.width() * e.scale))),
                                  std::max(1, int(std::lround(im.painting.height() * e.scale))));
    const int w = im.painting.width(), h = im.painting.height();
    const bool matcap = e.kind == pipeline::ExemplarKind::kMatcap;
    // With a cache, the guides its layers cut out of the passes, under what the passes are.
    const auto from = [&](const std::string& digest) {
      return matcap ? "reference " + io::reference_key(e, w, h)
                    : fmt::format("passes {}x{} {} {}", w, h, e.passes, digest);
    };
    if (!(cache &&
          kept_guides(shot, e, *cache, from(matcap ? "" : io::file_digest(e.passes)), im))) {
      std::optional<std::string> bytes;  // a pass file's, read once for its digest and decoding
      if (matcap) {
        im.passes = reference_passes(shot, e, w, h, rendered);
      } else {
        bytes = input_bytes(e.passes);
        im.passes = studio_passes(shot, e, w, h, bytes);
      }
      // The key names the very bytes decoded: a file saved again meanwhile misses next time.
      if (cache && (matcap || bytes))
        keep_guides(shot, e, *cache, from(bytes ? io::bytes_digest(*bytes) : ""), im);
    }
    out.emplace(e.name, std::move(im));
  }
  return out;
}

void keep_references(const Shot& shot,
                     const std::map<std::string, pipeline::ExemplarImages>& exemplars,
                     const std::vector<std::string>& rendered) {
  for (const std::string& name : rendered) {
    const pipeline::ExemplarImages& im = exemplars.at(name);
    const int w = im.painting.width(), h = im.painting.height();
    io::write_reference(shot.outputs.folder, io::reference_key(*shot.find_exemplar(name), w, h),
                        im.passes.cview());
  }
}

pipeline::WeightMapImages load_weight_maps(const Shot& shot, InputCache* cache) {
  pipeline::WeightMapImages out;
  for (const pipeline::Layer& l : shot.layers)
    for (const pipeline::GuideSpec& g : l.guides) {
      if (g.map_image.empty() || out.count(g.map_image)) continue;
      const std::string key = fmt::format("layers.{}.guides.{}.map", l.name, g.pass);
      const Image<float> img =
          decoded(cache, "image float", g.map_image, [&](const std::optional<std::string>& bytes) {
            return read_input_image(g.map_image, bytes);
          });
      const int w = shot.source.maps_width > 0 ? shot.source.maps_width : shot.source.width;
      const int h = shot.source.maps_height > 0 ? shot.source.maps_height : shot.source.height;
      if (img.width() != w || img.height() != h)
        throw Error(key, fmt::format("'{}' is {}x{}, the shot is {}x{}", g.map_image, img.width(),
                                     img.height(), w, h));
      Image<float> map = pipeline::extract(img.cview(), 0, 1);
      if (w != shot.source.width || h != shot.source.height)
        map = resample_area(map.cview(), shot.source.width, shot.source.height);
      out.emplace(g.map_image, std::move(map));
    }
  return out;
}

pipeline::CompositeInputs load_composite_inputs(const Shot& shot, InputCache* cache) {
  pipeline::CompositeInputs ci;
  if (!shot.compositing.paper.empty()) {
    ci.paper = rgb_of("compositing.paper", shot.compositing.paper, cache);
    shot.colour.get().convert(ci.paper.view(), shot.compositing.paper_colorspace, "color_picking");
  }
  return ci;
}

}  // namespace emaki::shot
