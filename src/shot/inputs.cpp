#include "shot/inputs.h"

#include <fmt/format.h>

#include <algorithm>

#include "core/error.h"
#include "core/limits.h"
#include "core/shot_keys.h"
#include "io/gltf_loader.h"
#include "io/image_io.h"
#include "shot/objects.h"
#include "store/file_store.h"
#include "store/frame_sequence.h"

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

Image<float> rgb_of(const std::string& key, const std::string& path) {
  Image<float> img = io::read_image_float(path);
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
  try {
    if (s.kind == pipeline::SourceKind::kSequence) return io::open_sequence(s);
    return io::with_pass_cache(shot, pipeline::scene_frames(load_scene(s), s));
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
      const std::vector<std::string> have = io::list_channels(e.passes);
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
          const Image<float> pass = io::read_image_float(e.passes, ReadOptions{names});
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

pipeline::WeightMapImages load_weight_maps(const Shot& shot) {
  pipeline::WeightMapImages out;
  for (const pipeline::Layer& l : shot.layers)
    for (const pipeline::GuideSpec& g : l.guides) {
      if (g.map_image.empty() || out.count(g.map_image)) continue;
      const std::string key = fmt::format("layers.{}.guides.{}.map", l.name, g.pass);
      const Image<float> img = io::read_image_float(g.map_image);
      if (img.width() != shot.source.width || img.height() != shot.source.height)
        throw Error(key, fmt::format("'{}' is {}x{}, the shot is {}x{}", g.map_image, img.width(),
                                     img.height(), shot.source.width, shot.source.height));
      out.emplace(g.map_image, pipeline::extract(img.cview(), 0, 1));
    }
  return out;
}

pipeline::CompositeInputs load_composite_inputs(const Shot& shot) {
  pipeline::CompositeInputs ci;
  if (!shot.compositing.paper.empty())
    ci.paper = rgb_of("compositing.paper", shot.compositing.paper);
  return ci;
}

}  // namespace emaki::shot
