// Temporal noise reduction on a bundled example (examples/fox/shot.toml, or --shot): one layer
// run frame by frame, with advection by `position` (the paper's) and by `rest_position`,
// compared on flicker (`emaki qa flicker`'s measure, split into the scene's objects and the
// static ground, then per object id) and, with --judge, on the independent judge's `style`
// energy of sampled frames (is the output still made of exemplar texture?). Frames stay in
// memory; nothing is written except the judge's inputs.
//
//   temporal_bench [--shot SHOT.toml] [--size WxH (the shot's)] [--frames 48] [--layer base]
//                  [--variants frame,position,rest_position]
//                  [--judge PATH/TO/judge] [--judge-every 8] [--judge-dir DIR] [--threads N]
//
// The judge is ../shared/tools/judge (build it with its build.sh). Its guides are the layer's
// guides (normal mapped to [0,1], diffuse) with the layer's weights; outside the layer's mask
// the output is taken as white on every variant alike.
#include <fmt/format.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "composite/composite.h"
#include "core/error.h"
#include "core/parallel.h"
#include "io/image_io.h"
#include "memory_store.h"
#include "pipeline/flicker.h"
#include "pipeline/frames.h"
#include "pipeline/run.h"
#include "render/passes.h"
#include "shot/inputs.h"
#include "shot/shot.h"

namespace {

using namespace emaki;

struct Options {
  int width = 0, height = 0, frames = 48, threads = 0, judge_every = 8;  // size 0: the shot's
  std::string shot = std::string(EMAKI_SOURCE_DIR) + "/examples/fox/shot.toml";
  std::string layer = "base", judge, judge_dir = "/tmp/emaki_temporal_judge";
  std::vector<std::string> variants = {"frame", "position", "rest_position"};
};

[[noreturn]] void usage(const std::string& why) {
  std::fprintf(stderr,
               "temporal_bench: %s\nusage: temporal_bench [--shot SHOT] [--size WxH] [--frames N] "
               "[--layer NAME] "
               "[--variants a,b,...] [--judge PATH] [--judge-every K] [--judge-dir DIR] "
               "[--threads N]\n",
               why.c_str());
  std::exit(2);
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
      o.variants.clear();
      std::stringstream ss(v);
      for (std::string s; std::getline(ss, s, ',');) {
        if (s != "frame" && s != "position" && s != "rest_position") usage("bad variant " + s);
        o.variants.push_back(s);
      }
    } else if (a == "--judge") {
      o.judge = v;
    } else if (a == "--judge-every") {
      o.judge_every = std::max(1, std::atoi(v.c_str()));
    } else if (a == "--judge-dir") {
      o.judge_dir = v;
    } else if (a == "--threads") {
      o.threads = std::atoi(v.c_str());
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

// The judge's view of a guide pass: normals mapped from [-1, 1] to [0, 1], others as they are.
Image<float> judge_guide(const Image<float>& pass, const std::string& name) {
  Image<float> out = pass.clone();
  if (name == "normal")
    for (int y = 0; y < out.height(); ++y)
      for (int x = 0; x < out.width(); ++x)
        for (int c = 0; c < out.channels(); ++c) out(x, y, c) = 0.5f * (out(x, y, c) + 1.0f);
  return out;
}

double run_judge(const std::string& cmd) {
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) throw std::runtime_error("cannot run " + cmd);
  std::string out;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, p)) out += buf;
  if (pclose(p) != 0) throw std::runtime_error("judge failed: " + cmd + "\n" + out);
  std::smatch m;
  if (!std::regex_search(out, m, std::regex("\"style\"\\s*:\\s*([0-9.eE+-]+)")))
    throw std::runtime_error("no style energy in the judge's output: " + out);
  return std::stod(m[1]);
}

// Flicker per object id (rows) and variant (columns), and each variant against the first.
void print_objects(const pipeline::Shot& shot, const std::vector<std::string>& variants,
                   const std::vector<pipeline::SequenceFlicker>& flicker) {
  std::printf("\n%-4s %-24s", "id", "object");
  for (const std::string& v : variants) std::printf(" %14s", v.c_str());
  std::printf("\n");
  for (const auto& [id, first] : flicker[0].by_id) {
    std::string name = id == 1 ? "ground" : "object";
    for (std::size_t i = 0; i < shot.source.objects.size(); ++i)
      if (shot.source.objects[i].id == id)
        name = fmt::format("objects[{}] {}", i,
                           std::filesystem::path(shot.source.objects[i].scene).stem().string());
    std::printf("%-4d %-24s", id, name.c_str());
    for (const pipeline::SequenceFlicker& f : flicker) {
      const auto it = f.by_id.find(id);
      const double m = it == f.by_id.end() ? 0.0 : it->second.mean();
      std::printf(" %7.5f %5.2fx", m, first.mean() > 0 ? m / first.mean() : 0.0);
    }
    std::printf("\n");
  }
}

// The judge's style energy of every variant's frame f, added to style_sum.
void judge_frame(const Options& opt, const pipeline::Layer& l, int f, const Image<float>& passes,
                 const std::vector<bench::MemoryStore>& stores, const std::string& judge_fixed,
                 std::vector<double>& style_sum) {
  const int value_channels = l.single_colour ? 1 : 3;
  std::string guides;
  for (const pipeline::GuideSpec& g : l.guides) {
    const std::string tgt = fmt::format("{}/target_{}_{:04d}.png", opt.judge_dir, g.pass, f);
    write_png(tgt, judge_guide(pipeline::extract_pass(passes.cview(), g.pass), g.pass));
    guides += fmt::format(" -guide '{}/source_{}.png' '{}' -weight {}", opt.judge_dir, g.pass, tgt,
                          g.weight);
  }
  for (std::size_t v = 0; v < opt.variants.size(); ++v) {
    const Image<float> cur = stores[v].read_layer(l, f);
    Image<float> out(cur.width(), cur.height(), value_channels);
    for (int y = 0; y < cur.height(); ++y)
      for (int x = 0; x < cur.width(); ++x) {
        const float a = cur.channels() > value_channels ? cur(x, y, value_channels) : 1.0f;
        for (int c = 0; c < value_channels; ++c) out(x, y, c) = a * cur(x, y, c) + (1.0f - a);
      }
    const std::string path = fmt::format("{}/{}_{:04d}.png", opt.judge_dir, opt.variants[v], f);
    write_png(path, out);
    const double s = run_judge(judge_fixed + guides + fmt::format(" -output-to-judge '{}'", path));
    std::fprintf(stderr, "temporal_bench: judge frame %d %s style %.6f\n", f,
                 opt.variants[v].c_str(), s);
    style_sum[v] += s;
  }
}

// The judge's inputs that do not change (the touch and the exemplar's guides), written once;
// returns the start of its command line.
std::string judge_inputs(const Options& opt, const pipeline::Layer& layer,
                         const pipeline::ExemplarImages& ex) {
  std::filesystem::create_directories(opt.judge_dir);
  const std::string style = opt.judge_dir + "/style.png";
  write_png(style, layer.single_colour ? composite::touch(ex.painting.cview(), layer.channel)
                                       : pipeline::extract(ex.painting.cview(), 0, 3));
  for (const pipeline::GuideSpec& g : layer.guides)
    write_png(fmt::format("{}/source_{}.png", opt.judge_dir, g.pass),
              judge_guide(pipeline::extract_pass(ex.passes.cview(), g.pass), g.pass));
  return fmt::format("'{}' -style '{}'", opt.judge, style);
}

// Each variant of the layer run into its own store (frame by frame, position, rest_position).
std::vector<bench::MemoryStore> run_variants(
    std::vector<double>& seconds, const Options& opt, const pipeline::Shot& shot,
    pipeline::Layer& layer, const pipeline::FrameSource& source,
    const std::map<std::string, pipeline::ExemplarImages>& exemplars,
    const pipeline::CompositeInputs& ci) {
  std::vector<bench::MemoryStore> stores(opt.variants.size());
  seconds.assign(opt.variants.size(), 0.0);
  for (std::size_t v = 0; v < opt.variants.size(); ++v) {
    const std::string& name = opt.variants[v];
    layer.temporal.enabled = name != "frame";
    layer.temporal.guide = name == "position" ? pipeline::AdvectionGuide::kPosition
                                              : pipeline::AdvectionGuide::kRestPosition;
    pipeline::RunOptions o;
    o.layers = {opt.layer};
    const auto t0 = std::chrono::steady_clock::now();
    pipeline::run_shot(shot, source, exemplars, ci, stores[v], o);
    seconds[v] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::fprintf(stderr, "temporal_bench: %s done in %.1f s\n", name.c_str(), seconds[v]);
  }
  return stores;
}

}  // namespace

int main(int argc, char** argv) {
  const Options opt = parse(argc, argv);
  set_thread_count(opt.threads);
  try {
    pipeline::Shot shot = shot::open(opt.shot);
    if (opt.width > 0) {
      shot.source.width = shot.source.render.width = opt.width;
      shot.source.height = shot.source.render.height = opt.height;
    }
    shot.source.last_frame = shot.source.first_frame + opt.frames - 1;
    shot.source.shot.last_frame = shot.source.last_frame;
    pipeline::Layer* layer = nullptr;
    for (pipeline::Layer& l : shot.layers)
      if (l.name == opt.layer) layer = &l;
    if (!layer) usage("no layer " + opt.layer + " in " + opt.shot);
    const auto source = shot::open_frames(shot);
    const auto exemplars = shot::load_exemplars(shot);
    const pipeline::CompositeInputs ci = shot::load_composite_inputs(shot);
    const int first = shot.source.first_frame, last = shot.source.last_frame;
    const int value_channels = layer->single_colour ? 1 : 3;

    std::vector<double> seconds;
    std::vector<bench::MemoryStore> stores =
        run_variants(seconds, opt, shot, *layer, *source, exemplars, ci);

    const bool judging = !opt.judge.empty();
    const std::string judge_fixed =
        judging ? judge_inputs(opt, *layer, exemplars.at(layer->exemplar)) : std::string();

    std::vector<pipeline::SequenceFlicker> flicker(opt.variants.size());
    std::vector<double> style_sum(opt.variants.size(), 0.0);
    int judged = 0;
    Image<float> prev_passes = source->passes(first);
    for (int f = first + 1; f <= last; ++f) {
      Image<float> passes = source->passes(f);
      const pipeline::Layer& l = *layer;
      for (std::size_t v = 0; v < opt.variants.size(); ++v) {
        const Image<float> cur = stores[v].read_layer(l, f), prev = stores[v].read_layer(l, f - 1);
        const int mask_channel = cur.channels() > value_channels ? value_channels : -1;
        flicker[v].add(pipeline::frame_flicker(cur.cview(), prev.cview(), passes.cview(),
                                               prev_passes.cview(), mask_channel));
      }
      if (judging && (f - first) % opt.judge_every == opt.judge_every / 2) {
        judge_frame(opt, *layer, f, passes, stores, judge_fixed, style_sum);
        ++judged;
      }
      prev_passes = std::move(passes);
    }

    std::printf("temporal_bench: layer '%s', %dx%d, frames %d-%d, %d threads%s\n",
                opt.layer.c_str(), shot.source.width, shot.source.height, first, last,
                thread_count(), judging ? fmt::format(", judge on {} frames", judged).c_str() : "");
    std::printf("%-14s %9s %10s %10s %10s %12s %12s\n", "variant", "s/frame", "flicker", "objects",
                "ground", "vs frame", "judge style");
    const double base = opt.variants[0] == "frame" ? flicker[0].all.mean() : 0.0;
    const double base_style = opt.variants[0] == "frame" && judged ? style_sum[0] / judged : 0.0;
    for (std::size_t v = 0; v < opt.variants.size(); ++v) {
      const double style = judged ? style_sum[v] / judged : 0.0;
      std::printf(
          "%-14s %9.2f %10.5f %10.5f %10.5f %11.2fx %12s\n", opt.variants[v].c_str(),
          seconds[v] / opt.frames, flicker[v].all.mean(), flicker[v].objects.mean(),
          flicker[v].ground.mean(), base > 0 ? flicker[v].all.mean() / base : 0.0,
          judged ? fmt::format("{:.6f}{}", style,
                               base_style > 0
                                   ? fmt::format(" ({:+.1f} %)", 100.0 * (style / base_style - 1))
                                   : "")
                       .c_str()
                 : "-");
    }
    print_objects(shot, opt.variants, flicker);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "temporal_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
