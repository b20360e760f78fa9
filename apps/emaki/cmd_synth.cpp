// `emaki synth`: guided synthesis from files. Accepts EbSynth's command line unchanged (single-
// dash options, `-weight` applying to the -style or -guide before it), so scripts that call
// `ebsynth` switch by changing the program name; adds long options of its own.
#include <array>
#include <chrono>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "apps/emaki/commands.h"
#include "apps/emaki/synth_args.h"
#include "core/error.h"
#include "core/parallel.h"
#include "io/image_io.h"
#include "synth/synthesizer.h"

namespace emaki::app {
namespace {

constexpr const char* kHelp =
    R"(usage: emaki synth -style A'.png -guide A1.png B1.png [-weight W] [-guide ...] -output B'.png [options]

Guided patch-based synthesis (A : A' :: B : B'). Accepts EbSynth's command line unchanged.

EbSynth options (single dash)
  -style FILE           style exemplar A' (1-4 channels; an RGB image whose channels are all
                        equal counts as one channel, as in EbSynth). Required.
  -guide SRC TGT        a guide pair: SRC has the style's size, TGT the output's. Repeatable,
                        at least one. 1-4 channels each (equal-channel RGB counts as one).
  -weight W             weight (>= 0) of the -style or -guide just before it.
                        Default: style 1; each guide 1 / number of guides.
  -output FILE          output B' (.png, .exr, .tif, .jpg). Default: output.png
  -uniformity U         uniformity weight, >= 0 (500-15000 sensible). Default: 3500
  -patchsize N          patch size, odd, >= 3. Default: 5
  -pyramidlevels N      pyramid levels, >= 1. Default: as many as fit
  -searchvoteiters N    search-vote iterations per level, >= 0. Default: emaki's schedule
                        (6 at coarse levels; 3, 2, 2 at the three finest)
  -patchmatchiters N    PatchMatch iterations per search-vote iteration, >= 0. Default: emaki's
                        schedule (4 at coarse levels; 3, 3, 2 at the three finest)
  -stopthreshold N      accepted for compatibility; no effect (as in EbSynth's CPU backend)
  -extrapass3x3         a final polishing pass with 3x3 patches. Default: off
  -backend cpu|cuda|auto  accepted for compatibility; emaki always runs on the CPU

emaki options
  --seed N              random seed (same inputs and seed: bit-identical output). Default: 1
  --threads N           worker threads, >= 0 (0: all cores). Default: 0
  --mask FILE           target mask (first channel > 0 is inside): outside pixels are not
                        synthesized and come out transparent (B' gets an alpha channel)
  --guide-weight-map N FILE  per-pixel weight of the N-th -guide (from 1): FILE's first
                        channel, the output's size, values in [0, 1], multiplies the guide's
                        weight at each output pixel (0: the guide does not count there)
  --vote plain|weighted voting mode. Default: weighted
  --nnf-out FILE        write the nearest-neighbour field (EXR: float x, y of the source patch
                        centre; -1 outside the mask)
  --error-out FILE      write the per-pixel patch error (EXR, EbSynth units)
  --output-depth 8|16|float  output sample format. Default: that of the style image
  --quiet               no summary line
  --help                this text
)";

synth::Plane plane_of(const io::AnyImage& im) {
  return std::visit([](const auto& i) -> synth::Plane { return i.view(); }, im.image);
}

// ---------------------------------------------------------------------------------------------
// Parse: the command line (synth_args.cpp), then every output path, so that an unwritable one
// fails before any long work.

void check_output_path(const std::string& opt, const std::string& path) {
  try {
    io::check_writable(path);
  } catch (const Error& e) {
    throw Error(opt, e.what());  // "-output: PATH: why"
  }
}

void check_output_paths(const SynthArgs& args) {
  check_output_path("-output", args.output);
  if (!args.nnf_out.empty()) check_output_path("--nnf-out", args.nnf_out);
  if (!args.error_out.empty()) check_output_path("--error-out", args.error_out);
}

// ---------------------------------------------------------------------------------------------
// Load: the files, with the channels EbSynth's rules give them. Sizes, channel counts and
// values are the engine's to check (synth::validate), naming the file each came from.

struct SynthFiles {
  SynthChannels channels;  // what EbSynth's rules made of the files
  io::AnyImage style;
  std::vector<io::AnyImage> guides;       // source, target, source, target, ... in -guide order
  std::vector<io::AnyImage> weight_maps;  // per -guide; empty without --guide-weight-map
  io::AnyImage mask;                      // empty without --mask
};

// Decodes every file at once (PNG decoding is serial per file); reports the first failure in
// command-line order so the error does not depend on timing.
std::vector<io::AnyImage> read_images(const std::vector<std::string>& paths) {
  std::vector<io::AnyImage> files(paths.size());
  std::vector<std::exception_ptr> failures(paths.size());
  parallel_for(int64_t(paths.size()), 1, [&](int64_t a, int64_t b) {
    for (int64_t i = a; i < b; ++i) {
      try {
        files[i] = io::read_image(paths[i]);
      } catch (...) {
        failures[i] = std::current_exception();
      }
    }
  });
  for (const auto& f : failures)
    if (f) std::rethrow_exception(f);
  return files;
}

SynthFiles load_files(const SynthArgs& args) {
  std::vector<std::string> paths{args.style_path}, map_paths;
  for (const SynthGuideArg& g : args.guides) {
    paths.insert(paths.end(), {g.source, g.target});
    if (!g.weight_map.empty()) map_paths.push_back(g.weight_map);
  }
  const std::size_t guide_files = paths.size();
  paths.insert(paths.end(), map_paths.begin(), map_paths.end());
  std::vector<io::AnyImage> files = read_images(paths);
  std::vector<io::AnyImage> maps(std::make_move_iterator(files.begin() + guide_files),
                                 std::make_move_iterator(files.end()));
  files.resize(guide_files);
  std::vector<std::array<int, 2>> guide_channels;
  for (std::size_t k = 1; k < files.size(); k += 2)
    guide_channels.push_back({effective_channels(files[k]), effective_channels(files[k + 1])});

  SynthFiles r;
  r.channels = resolve_channels(args, effective_channels(files[0]), guide_channels);
  r.style = with_channels(std::move(files[0]), r.channels.style_channels);
  for (std::size_t k = 1; k < files.size(); ++k)
    r.guides.push_back(with_channels(std::move(files[k]), r.channels.guides[(k - 1) / 2].channels));
  for (std::size_t k = 0, m = 0; k < args.guides.size(); ++k)
    r.weight_maps.push_back(args.guides[k].weight_map.empty() ? io::AnyImage()
                                                              : std::move(maps[m++]));
  if (!args.mask_path.empty()) r.mask = io::read_image(args.mask_path);
  return r;
}

// The engine's view of the files, with the names its errors give.
synth::Inputs engine_inputs(const SynthArgs& args, const SynthFiles& files) {
  synth::Inputs in;
  in.style = plane_of(files.style);
  in.style_name = args.style_path;
  for (std::size_t k = 0; k < args.guides.size(); ++k) {
    synth::GuidePair gp;
    gp.name = args.guides[k].target;
    gp.source_name = args.guides[k].source;
    gp.source = plane_of(files.guides[2 * k]);
    gp.target = plane_of(files.guides[2 * k + 1]);
    gp.weight = files.channels.guides[k].weight;
    if (!args.guides[k].weight_map.empty()) {
      gp.weight_map = plane_of(files.weight_maps[k]);
      gp.weight_map_name = args.guides[k].weight_map;
    }
    in.guides.push_back(gp);
  }
  if (!args.mask_path.empty()) {
    in.target_mask = plane_of(files.mask);
    in.target_mask_name = args.mask_path;
  }
  return in;
}

// ---------------------------------------------------------------------------------------------
// Run

synth::Result run_engine(const SynthArgs& args, SynthFiles& files) {
  synth::Inputs in = engine_inputs(args, files);
  synth::Params params = args.params;
  params.style_weight = files.channels.style_weight;
  synth::OutputRequest req;
  req.nnf = !args.nnf_out.empty();
  req.error = !args.error_out.empty();
  synth::Synthesizer synthesizer(in, params);
  // The guides are packed into the engine's features now; free them before the long part.
  in.guides.clear();
  files.guides.clear();
  files.guides.shrink_to_fit();
  return synthesizer.run(req);
}

// ---------------------------------------------------------------------------------------------
// Write

// --output-depth, else the style file's sample type.
io::SampleFormat output_format(const std::string& depth, io::PixelType style_type) {
  if (depth == "8") return io::SampleFormat::kU8;
  if (depth == "16") return io::SampleFormat::kU16;
  if (depth == "float") return io::SampleFormat::kFloat;
  if (style_type == io::PixelType::kU8) return io::SampleFormat::kU8;
  if (style_type == io::PixelType::kU16) return io::SampleFormat::kU16;
  return io::SampleFormat::kFloat;
}

// A one-channel style comes out as RGB (plus alpha with a mask), as EbSynth writes it.
Image<float> as_written(Image<float> image, int style_channels) {
  if (style_channels != 1 || image.channels() > 2) return image;
  const bool alpha = image.channels() == 2;
  Image<float> rgb(image.width(), image.height(), alpha ? 4 : 3);
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x) {
      for (int c = 0; c < 3; ++c) rgb(x, y, c) = image(x, y, 0);
      if (alpha) rgb(x, y, 3) = image(x, y, 1);
    }
  return rgb;
}

void write_nnf(const std::string& path, const Image<int32_t>& nnf) {
  Image<float> f(nnf.width(), nnf.height(), 2);
  for (int y = 0; y < f.height(); ++y)
    for (int x = 0; x < f.width(); ++x)
      for (int c = 0; c < 2; ++c) f(x, y, c) = float(nnf(x, y, c));
  io::WriteOptions o;
  o.format = io::SampleFormat::kFloat;
  o.channel_names = {"nnf.X", "nnf.Y"};
  io::write_image(path, f.cview(), o);
}

void write_error(const std::string& path, const Image<float>& error) {
  io::WriteOptions o;
  o.format = io::SampleFormat::kFloat;
  o.channel_names = {"error.Y"};
  io::write_image(path, error.cview(), o);
}

// B' as EbSynth writes it, and the extras asked for.
void write_outputs(const SynthArgs& args, const SynthFiles& files, synth::Result& res) {
  io::WriteOptions wo;
  wo.format = output_format(args.depth, files.style.type());
  const Image<float> out = as_written(std::move(res.image), files.channels.style_channels);
  io::write_image(args.output, out.cview(), wo);
  if (!args.nnf_out.empty()) write_nnf(args.nnf_out, res.nnf);
  if (!args.error_out.empty()) write_error(args.error_out, res.error);
}

}  // namespace

int run_synth(const Args& argv) {
  const SynthArgs args = parse_synth_args(argv);
  if (args.help) {
    std::fputs(kHelp, stdout);
    return 0;
  }
  check_output_paths(args);
  set_thread_count(args.threads);

  const auto t0 = std::chrono::steady_clock::now();
  SynthFiles files = load_files(args);
  synth::Result res = run_engine(args, files);
  const auto t1 = std::chrono::steady_clock::now();
  const int width = res.image.width(), height = res.image.height();
  write_outputs(args, files, res);
  if (!args.quiet)
    std::fprintf(
        stderr, "emaki synth: %dx%d from %dx%d, %d channels + %zu guides, %d levels, %.2f s\n",
        width, height, files.style.width(), files.style.height(), files.channels.style_channels,
        args.guides.size(), res.pyramid_levels, std::chrono::duration<double>(t1 - t0).count());
  return 0;
}

}  // namespace emaki::app
