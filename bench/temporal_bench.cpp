// Temporal noise reduction on a bundled example (examples/fox/shot.toml, or --shot): one layer
// run frame by frame and with advection by `position` (the paper's) or `rest_position`, each with
// or without the advection's confidence as the temporal guide's weight map, compared on flicker
// (`emaki qa flicker`'s measure, split into the scene's objects and the static ground, then per
// object id), on ghosts (`emaki qa ghost`'s measure, against the frame-by-frame variant) and, with
// --judge, on the independent judge's `style` energy of sampled frames and coverage, and on drift
// (the layer's mean value, white outside its mask, 0-255, against frame by frame over the last
// quarter of the frames). Frames stay in memory; only the judge's inputs and --save's PNGs go out.
//
//   temporal_bench [--shot SHOT.toml] [--size WxH (the shot's)] [--frames 48] [--layer base]
//                  [--variants frame,rest_position_noconf_uniform@1,rest_position,...]
//                  [--error-full X] [--error-none Y] [--foreign-none Z] [--erode N]
//                  [--temporal-weight W] [--temporal-uniformity U]
//                  [--judge PATH/TO/judge] [--judge-every 8] [--judge-dir DIR] [--save DIR]
//                  [--threads N] [--painting-scale S] [--touch-sigma 1]
//
// Variants: `frame` (temporal = false; the reference of the ghost figures, so list it first),
// `position`, `rest_position` (with confidence, the default), `position_noconf`,
// `rest_position_noconf` (temporal_confidence = false); a `_cold` suffix runs the whole pyramid at
// every frame (temporal_warm_start = false); a `_uniform` suffix keeps the layer's uniformity at
// temporal frames (temporal_uniformity = uniformity, or --temporal-uniformity U), @W gives the
// variant the temporal weight W (`rest_position_noconf_uniform@1`: before the confidence).
// --error-*, --foreign-none, --erode: temporal::ConfidenceParams; --temporal-weight: every
// temporal variant's without @W. The judge (../shared/tools/judge, its build.sh) takes the
// layer's guides and weights; outside the layer's mask every variant's output is white.
// --touch-sigma: the flicker is also measured on values low-passed by a Gaussian of this many
// pixels (bench::low_passed_value), where a picture stuck to its surfaces scores far less (the
// `stuck` figure printed beside it) and a touch that changes still counts.
#include <fmt/format.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "composite/composite.h"
#include "core/error.h"
#include "core/parallel.h"
#include "core/performance.h"
#include "io/image_io.h"
#include "judge_run.h"
#include "memory_store.h"
#include "pipeline/flicker.h"
#include "pipeline/frames.h"
#include "pipeline/ghost.h"
#include "pipeline/run.h"
#include "render/passes.h"
#include "shot/api.h"
#include "shot/inputs.h"
#include "temporal_modifiers.h"
#include "texture_measures.h"

namespace {

using namespace emaki;

const std::vector<std::string> kVariants = {"frame", "position", "rest_position", "position_noconf",
                                            "rest_position_noconf"};

struct Options {
  int width = 0, height = 0, frames = 48, threads = 0, judge_every = 8;  // size 0: the shot's
  std::string shot = std::string(EMAKI_SOURCE_DIR) + "/examples/fox/shot.toml";
  std::string layer = "base", judge, judge_dir = "/tmp/emaki_temporal_judge", save;
  std::vector<std::string> variants = {"frame", "rest_position_noconf_uniform@1",
                                       "rest_position_uniform", "position", "rest_position"};
  temporal::ConfidenceParams confidence;
  bool confidence_set = false;        // any of --error-*, --foreign-none, --erode given
  float temporal_weight = -1.0f;      // -1: the example's
  double painting_scale = 1.0;        // the paintings resampled by this (Exemplar::scale)
  float touch_sigma = 1.0f;           // the flicker measured again on values low-passed by this
  float temporal_uniformity = -1.0f;  // for `_uniform` variants; -1: the layer's uniformity
};

[[noreturn]] void usage(const std::string& why) {
  std::fprintf(
      stderr,
      "temporal_bench: %s\nusage: temporal_bench [--shot SHOT] [--size WxH] [--frames N] [--layer "
      "NAME] "
      "[--variants a,b,...] [--error-full X] [--error-none Y] [--foreign-none Z] [--erode N] "
      "[--temporal-weight W] [--temporal-uniformity U] [--judge PATH] "
      "[--judge-every K] [--judge-dir DIR] [--save DIR] [--threads N] [--painting-scale S] "
      "[--touch-sigma S]\n",
      why.c_str());
  std::exit(2);
}

// A variant's base name: without @WEIGHT and _uniform.
std::string base_name(const std::string& variant) {
  std::string name = variant.substr(0, std::min(variant.find('@'), variant.find(':')));
  // The modifiers, in any order.
  for (bool stripped = true; stripped;) {
    stripped = false;
    for (const std::string_view suffix : {"_uniform", "_cold"})
      if (name.size() > suffix.size() && name.ends_with(suffix))
        name.resize(name.size() - suffix.size()), stripped = true;
  }
  return name;
}

// NAME[_uniform][@WEIGHT].
std::vector<std::string> parse_variants(const std::string& v) {
  std::vector<std::string> out;
  std::stringstream ss(v);
  for (std::string s; std::getline(ss, s, ',');) {
    const std::string name = base_name(s);
    if (std::find(kVariants.begin(), kVariants.end(), name) == kVariants.end())
      usage("bad variant " + s);
    out.push_back(s);
  }
  return out;
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (i + 1 >= argc) usage("missing value after " + a);
    const std::string v = argv[++i];
    if (a == "--shot") {
      o.shot = v;
    } else if (a == "--size") {
      if (std::sscanf(v.c_str(), "%dx%d", &o.width, &o.height) != 2) usage("bad --size " + v);
    } else if (a == "--frames") {
      o.frames = std::max(2, std::atoi(v.c_str()));
    } else if (a == "--layer") {
      o.layer = v;
    } else if (a == "--variants") {
      o.variants = parse_variants(v);
    } else if (a == "--error-full") {
      o.confidence.error_full = std::strtof(v.c_str(), nullptr);
      o.confidence_set = true;
    } else if (a == "--error-none") {
      o.confidence.error_none = std::strtof(v.c_str(), nullptr);
      o.confidence_set = true;
    } else if (a == "--foreign-none") {
      o.confidence.foreign_none = std::strtof(v.c_str(), nullptr);
      o.confidence_set = true;
    } else if (a == "--erode") {
      o.confidence.erode = std::atoi(v.c_str());
      o.confidence_set = true;
    } else if (a == "--temporal-weight") {
      o.temporal_weight = std::strtof(v.c_str(), nullptr);
    } else if (a == "--temporal-uniformity") {
      o.temporal_uniformity = std::strtof(v.c_str(), nullptr);
    } else if (a == "--judge") {
      o.judge = v;
    } else if (a == "--judge-every") {
      o.judge_every = std::max(1, std::atoi(v.c_str()));
    } else if (a == "--judge-dir") {
      o.judge_dir = v;
    } else if (a == "--save") {
      o.save = v;
    } else if (a == "--threads") {
      o.threads = std::atoi(v.c_str());
    } else if (a == "--touch-sigma") {
      o.touch_sigma = std::max(0.1f, std::strtof(v.c_str(), nullptr));
    } else if (a == "--painting-scale") {
      o.painting_scale = std::strtod(v.c_str(), nullptr);
    } else {
      usage("unknown option " + a);
    }
  }
  return o;
}

// A one-channel or RGB image written as 8-bit PNG (what the judge reads).
void write_png(const std::string& path, const Image<float>& img) {
  io::WriteOptions w;
  w.format = io::SampleFormat::kU8;
  io::write_image(path, img.cview(), w);
}

// The layer's value over white outside its mask: what the judge and --save see.
Image<float> on_white(const Image<float>& v, int value_channels) {
  Image<float> out(v.width(), v.height(), value_channels);
  for (int y = 0; y < v.height(); ++y)
    for (int x = 0; x < v.width(); ++x) {
      const float a = v.channels() > value_channels ? v(x, y, value_channels) : 1.0f;
      for (int c = 0; c < value_channels; ++c) out(x, y, c) = a * v(x, y, c) + (1.0f - a);
    }
  return out;
}

// One variant: the layer's settings for it, its frames and what was measured on them.
struct Variant {
  std::string name;
  pipeline::Layer layer;
  bench::MemoryStore store;
  double seconds = 0.0;
  pipeline::SequenceFlicker flicker;
  pipeline::SequenceFlicker held_flicker;  // where the light held (bench::light_held)
  pipeline::SequenceFlicker stuck;  // t-1 carried in whole pixels (bench::carried_whole_pixels)
  // flicker, stuck and held_flicker at the touches' scale (bench::low_passed_value, --touch-sigma).
  pipeline::SequenceFlicker touch_flicker, touch_stuck, touch_held;
  Image<float> last_low;  // the last measured frame's value low-passed: t-1's at the next frame
  int last_low_frame = -1;
  pipeline::GhostStats ghost;
  double style_sum = 0.0, coverage_sum = 0.0;
  double drift_sum = 0.0;  // mean value against frame by frame, summed over the last quarter
  int drift_frames = 0;
  bench::ToneTexture tone;  // inside the mask, over the last quarter
  bench::ToneTexture wash;  // in recently disoccluded pixels inside the mask, every frame
  std::map<int, bench::ToneTexture> tone_by_id;  // `tone` per object id
};

constexpr float kLightTolerance = 0.02f;  // a guide moving no more between frames: same light

std::string object_name(const pipeline::Shot& shot, int id) {
  std::string name = id == 1 ? "ground" : "object";
  for (std::size_t i = 0; i < shot.source.objects.size(); ++i)
    if (shot.source.objects[i].id == id)
      name = fmt::format("objects[{}] {}", i,
                         std::filesystem::path(shot.source.objects[i].scene).stem().string());
  return name;
}

// Flicker per object id (rows) and variant (columns), and each variant against the first; then
// each temporal variant's tone drift and texture kept per object (as print_tone_table's).
void print_objects(const pipeline::Shot& shot, const std::vector<Variant>& variants) {
  std::printf("\n%-4s %-24s", "id", "object");
  for (const Variant& v : variants) std::printf(" %14s", v.name.c_str());
  std::printf("\n");
  for (const auto& [id, first] : variants[0].flicker.by_id) {
    std::printf("%-4d %-24s", id, object_name(shot, id).c_str());
    for (const Variant& v : variants) {
      const auto it = v.flicker.by_id.find(id);
      const double m = it == v.flicker.by_id.end() ? 0.0 : it->second.mean();
      std::printf(" %7.5f %5.2fx", m, first.mean() > 0 ? m / first.mean() : 0.0);
    }
    std::printf("\n");
  }
  // Pixels: the object's share of the layer's pixels in the last quarter (each variant counts
  // the same ones).
  std::printf("\n%-4s %-24s %7s", "id", "tone, texture", "pixels");
  for (const Variant& v : variants)
    if (!v.tone_by_id.empty()) std::printf(" %16s", v.name.c_str());
  std::printf("\n");
  std::map<int, long> ids;
  long all = 0;
  for (const Variant& v : variants)
    if (!v.tone_by_id.empty()) {
      for (const auto& [id, t] : v.tone_by_id) ids[id] = t.pixels, all += t.pixels;
      break;
    }
  for (const auto& [id, pixels] : ids) {
    std::printf("%-4d %-24s %6.1f%%", id, object_name(shot, id).c_str(),
                all ? 100.0 * double(pixels) / double(all) : 0.0);
    for (const Variant& v : variants) {
      if (v.tone_by_id.empty()) continue;
      const auto it = v.tone_by_id.find(id);
      if (it == v.tone_by_id.end())
        std::printf(" %16s", "-");
      else
        std::printf(" %+7.2f %7.3fx", it->second.drift_levels(), it->second.texture_kept());
    }
    std::printf("\n");
  }
}

pipeline::Layer variant_layer(pipeline::Layer l, const std::string& variant, const Options& o) {
  const std::size_t at = variant.find('@');
  const std::string name = base_name(variant);
  l.temporal.enabled = name != "frame";
  l.temporal.guide = name.rfind("position", 0) == 0 ? pipeline::AdvectionGuide::kPosition
                                                    : pipeline::AdvectionGuide::kRestPosition;
  l.temporal.confidence = name.find("_noconf") == std::string::npos;
  if (variant.find("_cold") != std::string::npos) l.temporal.warm_start = false;
  if (o.confidence_set) l.temporal.confidence_params = o.confidence;
  if (o.temporal_weight >= 0.0f) l.temporal.weight = o.temporal_weight;
  if (at != std::string::npos && at < variant.find(':'))
    l.temporal.weight = std::strtof(variant.c_str() + at + 1, nullptr);
  if (variant.find("_uniform") != std::string::npos)
    l.temporal.uniformity =
        o.temporal_uniformity >= 0.0f ? o.temporal_uniformity : l.synth.uniformity;
  try {
    bench::apply_modifiers(l, variant);
  } catch (const std::invalid_argument& e) {
    usage(e.what());
  }
  return l;
}

// The example at the bench's size and length, with `layer` found in it.
pipeline::Shot example(const Options& opt, pipeline::Layer*& layer) {
  pipeline::Shot shot = shot::open(opt.shot);
  if (opt.width > 0) {
    shot.source.width = shot.source.render.width = opt.width;
    shot.source.height = shot.source.render.height = opt.height;
  }
  shot.source.last_frame = shot.source.first_frame + opt.frames - 1;
  shot.source.shot.last_frame = shot.source.last_frame;
  for (pipeline::Exemplar& e : shot.exemplars)
    if (e.kind == pipeline::ExemplarKind::kMatcap) e.scale = opt.painting_scale;
  layer = nullptr;
  for (pipeline::Layer& l : shot.layers)
    if (l.name == opt.layer) layer = &l;
  if (!layer) usage("no layer " + opt.layer + " in the example");
  return shot;
}

// Each variant's frames, the layer alone (the shot's other layers are left out).
void run_variants(pipeline::Shot& shot, pipeline::Layer& layer, const pipeline::FrameSource& src,
                  std::vector<Variant>& variants, const Options& opt) {
  const auto exemplars = shot::load_exemplars(shot);
  const pipeline::CompositeInputs ci = shot::load_composite_inputs(shot);
  const pipeline::Layer original = layer;
  for (Variant& v : variants) {
    layer = v.layer;
    pipeline::RunOptions o;
    o.layers = {opt.layer};
    const auto t0 = std::chrono::steady_clock::now();
    const std::clock_t c0 = std::clock();
    pipeline::run_shot(shot, src, exemplars, ci, v.store, o);
    v.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    // CPU seconds of the whole process (every thread): comparable between variants on a loaded
    // machine, where the wall time is not.
    const double cpu = double(std::clock() - c0) / CLOCKS_PER_SEC;
    std::fprintf(stderr, "temporal_bench: %s done in %.1f s, %.1f CPU s (%.3f CPU s a frame)\n",
                 v.name.c_str(), v.seconds, cpu, cpu / opt.frames);
  }
  layer = original;
}

// Judge inputs that do not change: the touch and the exemplar's guides. Returns the command's
// fixed part.
std::string judge_setup(const pipeline::Shot& shot, const pipeline::Layer& layer,
                        const Options& opt) {
  std::filesystem::create_directories(opt.judge_dir);
  const pipeline::ExemplarImages ex = std::move(shot::load_exemplars(shot).at(layer.exemplar));
  const std::string style = opt.judge_dir + "/style.png";
  write_png(style, layer.single_colour ? composite::touch(ex.painting.cview(), layer.channel)
                                       : pipeline::extract(ex.painting.cview(), 0, 3));
  for (const pipeline::GuideSpec& g : layer.guides)
    write_png(fmt::format("{}/source_{}.png", opt.judge_dir, g.pass),
              bench::judge_guide(pipeline::extract_pass(ex.passes.cview(), g.pass), g.pass));
  return fmt::format("'{}' -style '{}'", opt.judge, style);
}

// The judge's style energy of every variant's frame f, added to its sum.
void judge_frame(const std::string& fixed, const pipeline::Layer& layer, const Image<float>& passes,
                 int f, std::vector<Variant>& variants, const Options& opt) {
  std::string guides;
  for (const pipeline::GuideSpec& g : layer.guides) {
    const std::string tgt = fmt::format("{}/target_{}_{:04d}.png", opt.judge_dir, g.pass, f);
    write_png(tgt, bench::judge_guide(pipeline::extract_pass(passes.cview(), g.pass), g.pass));
    guides += fmt::format(" -guide '{}/source_{}.png' '{}' -weight {}", opt.judge_dir, g.pass, tgt,
                          g.weight);
  }
  const int n = layer.single_colour ? 1 : 3;
  for (Variant& v : variants) {
    const std::string path = fmt::format("{}/{}_{:04d}.png", opt.judge_dir, v.name, f);
    write_png(path, on_white(v.store.read_layer(layer, f), n));
    const bench::JudgeFigures j =
        bench::run_judge(fixed + guides + fmt::format(" -output-to-judge '{}'", path));
    std::fprintf(stderr, "temporal_bench: judge frame %d %s style %.6f coverage %.4f\n", f,
                 v.name.c_str(), j.style, j.coverage);
    v.style_sum += j.style;
    v.coverage_sum += j.coverage;
  }
}

// Flicker of frame f of variant v (frame by frame: also of its t-1 carried in whole pixels), its
// ghosts against the reference variant (frame by frame, when first) and, with --save, the PNG.
void measure_frame(Variant& v, const Variant& reference, const pipeline::Layer& layer,
                   const Image<float>& passes, const Image<float>& prev_passes, int f,
                   bool drift_frame, const Image<uint8_t>& disoccluded, const Image<uint8_t>& held,
                   const Options& opt) {
  const int n = layer.single_colour ? 1 : 3;
  const Image<float> cur = v.store.read_layer(layer, f), prev = v.store.read_layer(layer, f - 1);
  const int mask_channel = cur.channels() > n ? n : -1;
  v.flicker.add(pipeline::frame_flicker(cur.cview(), prev.cview(), passes.cview(),
                                        prev_passes.cview(), mask_channel));
  Image<float> cur_low = bench::low_passed_value(cur, n, opt.touch_sigma);
  const Image<float> prev_low = v.last_low_frame == f - 1
                                    ? std::move(v.last_low)
                                    : bench::low_passed_value(prev, n, opt.touch_sigma);
  v.touch_flicker.add(pipeline::frame_flicker(cur_low.cview(), prev_low.cview(), passes.cview(),
                                              prev_passes.cview(), mask_channel));
  if (!v.layer.temporal.enabled) {
    const Image<float> carried = bench::carried_whole_pixels(prev, passes.cview());
    v.stuck.add(pipeline::frame_flicker(carried.cview(), prev.cview(), passes.cview(),
                                        prev_passes.cview(), mask_channel));
    v.touch_stuck.add(pipeline::frame_flicker(
        bench::low_passed_value(carried, n, opt.touch_sigma).cview(), prev_low.cview(),
        passes.cview(), prev_passes.cview(), mask_channel));
  }
  if (!held.empty()) {
    v.held_flicker.add(pipeline::frame_flicker(cur.cview(), prev.cview(), passes.cview(),
                                               prev_passes.cview(), mask_channel, nullptr, &held));
    v.touch_held.add(pipeline::frame_flicker(cur_low.cview(), prev_low.cview(), passes.cview(),
                                             prev_passes.cview(), mask_channel, nullptr, &held));
  }
  if (reference.name == "frame" && v.layer.temporal.enabled) {
    const Image<float> ref = reference.store.read_layer(layer, f);
    v.ghost.add(pipeline::frame_ghost(v.layer, cur.cview(), prev.cview(), ref.cview(),
                                      passes.cview(), prev_passes.cview(), f)
                    .stats);
    const Image<float> cur_white = on_white(cur, n), ref_white = on_white(ref, n);
    bench::add_tone_texture(v.wash, cur_white, ref_white, cur, mask_channel, disoccluded);
    if (drift_frame) {
      v.drift_sum += bench::mean_value(cur_white) - bench::mean_value(ref_white);
      ++v.drift_frames;
      bench::add_tone_texture(v.tone, cur_white, ref_white, cur, mask_channel, {});
      bench::add_tone_texture_by_object(v.tone_by_id, cur_white, ref_white, cur, mask_channel,
                                        passes.cview());
    }
  }
  if (!opt.save.empty())
    write_png(fmt::format("{}/{}_{:04d}.png", opt.save, v.name, f), on_white(cur, n));
  v.last_low = std::move(cur_low);
  v.last_low_frame = f;
}

void print_table(const std::vector<Variant>& variants, const Options& opt, int first, int last,
                 int judged) {
  std::printf("temporal_bench: layer '%s', %dx%d, frames %d-%d, %d threads%s\n", opt.layer.c_str(),
              opt.width, opt.height, first, last, thread_count(),
              judged ? fmt::format(", judge on {} frames", judged).c_str() : "");
  std::printf("%-24s %8s %9s %9s %9s %9s %12s %9s %9s %9s %9s %7s\n", "variant", "s/frame",
              "flicker", "fox", "ground", "vs frame", "judge style", "coverage", "ghost",
              "diff hid", "diff vis", "drift");
  const Variant& base = variants[0];
  const bool ref = base.name == "frame";
  const double base_style = ref && judged ? base.style_sum / judged : 0.0;
  for (const Variant& v : variants) {
    const double style = judged ? v.style_sum / judged : 0.0;
    const std::string style_text =
        judged ? fmt::format("{:.6f}{}", style,
                             base_style > 0
                                 ? fmt::format(" ({:+.1f} %)", 100.0 * (style / base_style - 1))
                                 : "")
               : "-";
    const bool ghosted = ref && v.layer.temporal.enabled;
    const std::string coverage_text =
        judged ? fmt::format("{:.4f}", v.coverage_sum / judged) : std::string("-");
    const std::string drift_text =
        v.drift_frames ? fmt::format("{:+.2f}", 255.0 * v.drift_sum / v.drift_frames) : "-";
    std::printf("%-24s %8.2f %9.5f %9.5f %9.5f %8.2fx %12s %9s %9s %9s %9s %7s\n", v.name.c_str(),
                v.seconds / opt.frames, v.flicker.all.mean(), v.flicker.objects.mean(),
                v.flicker.ground.mean(), ref ? v.flicker.all.mean() / base.flicker.all.mean() : 0.0,
                style_text.c_str(), coverage_text.c_str(),
                ghosted ? fmt::format("{:.4f}", v.ghost.ghost_share()).c_str() : "-",
                ghosted ? fmt::format("{:.5f}", v.ghost.diff()).c_str() : "-",
                ghosted ? fmt::format("{:.5f}", v.ghost.visible_diff()).c_str() : "-",
                drift_text.c_str());
  }
  if (ref && base.stuck.all.pixels)
    std::printf("stuck (frame by frame's t-1 carried to t in whole pixels) %8.2fx\n",
                base.stuck.all.mean() / base.flicker.all.mean());
  if (ref && base.touch_stuck.all.pixels && base.touch_flicker.all.mean() > 0.0) {
    std::printf("flicker at the touches' scale (values low-passed, sigma %.1f):", opt.touch_sigma);
    for (const Variant& v : variants)
      std::printf(" %s %.2fx", v.name.c_str(),
                  v.touch_flicker.all.mean() / base.touch_flicker.all.mean());
    std::printf("; stuck %.2fx\n", base.touch_stuck.all.mean() / base.touch_flicker.all.mean());
    if (base.touch_held.all.mean() > 0.0) {
      std::printf("the same where the light held:");
      for (const Variant& v : variants)
        std::printf(" %s %.2fx", v.name.c_str(),
                    v.touch_held.all.mean() / base.touch_held.all.mean());
      std::printf("\n");
    }
  }
}

// Against frame by frame, same pixels: tone drift and texture kept inside the mask over the last
// quarter, and both again over the pixels disoccluded within the last few frames (the wash).
void print_tone_table(const std::vector<Variant>& variants) {
  // flicker held: where the light held within a patch's reach (bench::light_held), against frame
  // by frame's there: the chain's own, without what a moving light, shadow or silhouette changes.
  const double held_ref = variants[0].held_flicker.all.mean();
  std::printf("\n%-24s %9s %9s %11s %11s %12s %13s\n", "variant", "tone", "texture", "wash tone",
              "wash tex", "wash pixels", "flicker held");
  for (const Variant& v : variants) {
    if (!v.tone.pixels) continue;
    std::printf("%-24s %+9.2f %8.3fx %+11.2f %10.3fx %12ld %12.2fx\n", v.name.c_str(),
                v.tone.drift_levels(), v.tone.texture_kept(), v.wash.drift_levels(),
                v.wash.texture_kept(), v.wash.pixels,
                held_ref > 0 ? v.held_flicker.all.mean() / held_ref : 0.0);
  }
}

}  // namespace

int main(int argc, char** argv) {
  emaki::set_performance(emaki::performance_from_environment());  // as `emaki` does
  const Options opt = parse(argc, argv);
  const ScopedThreadCount count(opt.threads);
  try {
    pipeline::Layer* layer = nullptr;
    pipeline::Shot shot = example(opt, layer);
    const auto source = shot::open_frames(shot);
    const int first = shot.source.first_frame, last = shot.source.last_frame;
    std::vector<Variant> variants(opt.variants.size());
    for (std::size_t i = 0; i < variants.size(); ++i)
      variants[i].name = opt.variants[i],
      variants[i].layer = variant_layer(*layer, opt.variants[i], opt);
    run_variants(shot, *layer, *source, variants, opt);
    if (std::getenv("EMAKI_INK_DUMP"))  // each frame's ink and guides (bench::print_inks)
      bench::print_inks(*source, *layer, first, last, opt.variants, [&](std::size_t i, int f) {
        return variants[i].store.read_layer(*layer, f);
      });
    const bool judging = !opt.judge.empty();
    const std::string judge_fixed = judging ? judge_setup(shot, *layer, opt) : std::string();
    if (!opt.save.empty()) std::filesystem::create_directories(opt.save);
    int judged = 0;
    Image<float> prev_passes = source->passes(first);
    Image<uint8_t> age;  // frames since each pixel's surface was last hidden
    for (int f = first + 1; f <= last; ++f) {
      Image<float> passes = source->passes(f);
      bench::update_disocclusion_age(age, passes.cview(), prev_passes.cview());
      const Image<uint8_t> disoccluded = bench::recently_disoccluded(age, passes.cview());
      const Image<float> light = pipeline::change_guides(*layer, passes.cview()),
                         prev_light = pipeline::change_guides(*layer, prev_passes.cview());
      const Image<uint8_t> held =
          light.empty() ? Image<uint8_t>{}
                        : bench::light_held(light, prev_light, passes.cview(), kLightTolerance,
                                            layer->synth.patch_size - 1);
      // Drift: the last quarter of the frames (at least one), where a chain has had time to.
      const bool drift_frame = 4 * (last - f) < last - first + 1;
      for (Variant& v : variants)
        measure_frame(v, variants[0], *layer, passes, prev_passes, f, drift_frame, disoccluded,
                      held, opt);
      if (judging && (f - first) % opt.judge_every == opt.judge_every / 2) {
        judge_frame(judge_fixed, *layer, passes, f, variants, opt);
        ++judged;
      }
      prev_passes = std::move(passes);
    }
    print_table(variants, opt, first, last, judged);
    print_tone_table(variants);
    print_objects(shot, variants);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "temporal_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
