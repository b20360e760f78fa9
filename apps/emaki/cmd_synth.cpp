// `emaki synth`: guided synthesis from files. Accepts EbSynth's command line unchanged (single-
// dash options, `-weight` applying to the -style or -guide before it), so scripts that call
// `ebsynth` switch by changing the program name; adds long options of its own.
#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <exception>
#include <filesystem>
#include <optional>
#include <string>

#include "apps/emaki/commands.h"
#include "apps/emaki/index_cache.h"
#include "apps/emaki/synth_args.h"
#include "core/error.h"
#include "core/parallel.h"
#include "io/image_io.h"
#include "synth/ebsynth_rules.h"
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
                        (6 at coarse levels; 2, 2 at the two finest)
  -patchmatchiters N    PatchMatch iterations per search-vote iteration, >= 0. Default: emaki's
                        schedule (4 at coarse levels; 3, 2 at the two finest)
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
  --vote plain|weighted voting mode of the search (weighted: by patch error); the output's
                        own vote is plain either way. Default: weighted
  --nnf-out FILE        write the nearest-neighbour field (EXR: float x, y of the source patch
                        centre; -1 outside the mask)
  --error-out FILE      write the per-pixel patch error (EXR, EbSynth units)
  --output-depth 8|16|float  output sample format. Default: that of the style image
  --index K             also try each propagated candidate's K most similar exemplar patches
                        (k-coherence sets of a per-painting index; 0..16). Default: 0 (off)
  --index-cache DIR     keep the index in DIR, one file per painting, guides, patch size and K,
                        and reuse it (with --index)
  --quiet               no summary line
  --help                this text
)";

synth::Plane plane_of(const io::AnyImage& im) {
  return std::visit([](const auto& i) -> synth::Plane { return i.view(); }, im.image);
}

void check_output_path(const std::string& opt, const std::string& path) {
  try {
    io::check_writable(path);
  } catch (const Error& e) {
    throw Error(opt, e.what());  // "-output: PATH: why"
  }
}

// The decoded files: style, then each guide's source and target, then the mask if any, then
// each guide's weight map (--guide-weight-map) in -guide order.
// PNG decoding is serial per file, so the files are decoded at once; the first failure is
// reported in command-line order so that the error does not depend on timing.
std::vector<io::AnyImage> read_files(const SynthArgs& args) {
  std::vector<std::string> paths{args.style_path};
  for (const auto& g : args.guides) paths.insert(paths.end(), {g.source, g.target});
  if (!args.mask_path.empty()) paths.push_back(args.mask_path);
  for (const auto& g : args.guides)
    if (!g.weight_map.empty()) paths.push_back(g.weight_map);
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

// EbSynth's rules (synth/ebsynth_rules.h) over the decoded files, named by their paths.
synth::RuledInputs ruled_inputs(const SynthArgs& args, const std::vector<io::AnyImage>& files) {
  std::vector<synth::NamedGuide> guides;
  for (std::size_t k = 0; k < args.guides.size(); ++k) {
    const SynthGuideArg& g = args.guides[k];
    guides.push_back(
        {{plane_of(files[1 + 2 * k]), g.source}, {plane_of(files[2 + 2 * k]), g.target}, g.weight});
  }
  std::size_t next = 1 + 2 * args.guides.size();
  std::optional<synth::NamedPlane> mask;
  if (!args.mask_path.empty()) mask = synth::NamedPlane{plane_of(files[next++]), args.mask_path};
  synth::RuledInputs ruled =
      synth::apply_ebsynth_rules({plane_of(files[0]), args.style_path}, guides, mask);
  // Weight maps are read as they are (first channel), after the rules.
  for (std::size_t k = 0; k < args.guides.size(); ++k) {
    if (args.guides[k].weight_map.empty()) continue;
    ruled.inputs.guides[k].weight_map = plane_of(files[next++]);
    ruled.inputs.guides[k].weight_map_name = args.guides[k].weight_map;
  }
  return ruled;
}

io::SampleFormat output_format(const std::string& depth, io::PixelType style_type) {
  if (depth == "8") return io::SampleFormat::kU8;
  if (depth == "16") return io::SampleFormat::kU16;
  if (depth == "float") return io::SampleFormat::kFloat;
  if (style_type == io::PixelType::kU8) return io::SampleFormat::kU8;
  if (style_type == io::PixelType::kU16) return io::SampleFormat::kU16;
  return io::SampleFormat::kFloat;
}

void write_field_and_error(const SynthArgs& args, const synth::Result& res) {
  if (!args.nnf_out.empty()) {
    Image<float> f(res.nnf.width(), res.nnf.height(), 2);
    for (int y = 0; y < f.height(); ++y)
      for (int x = 0; x < f.width(); ++x)
        for (int c = 0; c < 2; ++c) f(x, y, c) = float(res.nnf(x, y, c));
    io::WriteOptions o;
    o.format = io::SampleFormat::kFloat;
    o.channel_names = {"nnf.X", "nnf.Y"};
    io::write_image(args.nnf_out, f.cview(), o);
  }
  if (!args.error_out.empty()) {
    io::WriteOptions o;
    o.format = io::SampleFormat::kFloat;
    o.channel_names = {"error.Y"};
    io::write_image(args.error_out, res.error.cview(), o);
  }
}

}  // namespace

int run_synth(const Args& argv) {
  const SynthArgs args = parse_synth_args(argv);
  if (args.help) {
    std::fputs(kHelp, stdout);
    return 0;
  }
  // Fail on an unwritable output before any long work.
  check_output_path("-output", args.output);
  if (!args.nnf_out.empty()) check_output_path("--nnf-out", args.nnf_out);
  if (!args.error_out.empty()) check_output_path("--error-out", args.error_out);
  const ScopedThreadCount threads(args.threads);

  const auto t0 = std::chrono::steady_clock::now();
  std::vector<io::AnyImage> files = read_files(args);
  const auto t_read = std::chrono::steady_clock::now();
  const std::clock_t cpu_read = std::clock();  // CPU time of every thread of the process
  synth::RuledInputs ruled = ruled_inputs(args, files);
  synth::Params params = args.params;
  params.style_weight = args.style_weight;
  synth::OutputRequest req;
  req.nnf = !args.nnf_out.empty();
  req.error = !args.error_out.empty();
  const std::string index_path = args.index_cache.empty() ? "" : index_cache_path(args);
  if (!index_path.empty()) params.index = load_cached_index(index_path, args.quiet);
  synth::Synthesizer synthesizer(ruled.inputs, params);
  // The guides are packed into the engine's features now; free them before the long part.
  ruled.release_guides();
  for (std::size_t i = 1; i < 1 + 2 * args.guides.size(); ++i) files[i] = io::AnyImage();
  synth::Result res = synthesizer.run(req);
  const auto t1 = std::chrono::steady_clock::now();
  const double cpu_seconds = double(std::clock() - cpu_read) / CLOCKS_PER_SEC;

  io::WriteOptions wo;
  wo.format = output_format(args.depth, files[0].type());
  // A one-channel style (an RGB file whose channels are equal, say) is written back as RGB, as
  // EbSynth does.
  const int ns = synth::plane_channels(ruled.inputs.style);
  const Image<float> out_img = ns == 1 ? synth::gray_to_rgb(res.image) : std::move(res.image);
  io::write_image(args.output, out_img.cview(), wo);
  write_field_and_error(args, res);
  if (!index_path.empty() && res.index && res.index != params.index)
    store_cached_index(index_path, *res.index);
  if (!args.quiet) {
    using seconds = std::chrono::duration<double>;
    std::fprintf(stderr,
                 "emaki synth: %dx%d from %dx%d, %d channels + %zu guides, %d levels, %.2f s "
                 "(reading %.3f s, synthesis %.3f s, %.3f CPU s)\n",
                 out_img.width(), out_img.height(), files[0].width(), files[0].height(), ns,
                 args.guides.size(), res.pyramid_levels, seconds(t1 - t0).count(),
                 seconds(t_read - t0).count(), seconds(t1 - t_read).count(), cpu_seconds);
  }
  return 0;
}

}  // namespace emaki::app
