// `emaki synth`: guided synthesis from files. Accepts EbSynth's command line unchanged (single-
// dash options, `-weight` applying to the -style or -guide before it), so scripts that call
// `ebsynth` switch by changing the program name; adds long options of its own.
#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <optional>
#include <string>

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

void check_output_path(const std::string& opt, const std::string& path) {
  try {
    io::check_writable(path);
  } catch (const Error& e) {
    throw Error(opt, e.what());  // "-output: PATH: why"
  }
}

}  // namespace

int run_synth(const Args& argv) {
  const SynthArgs args = parse_synth_args(argv);
  if (args.help) {
    std::fputs(kHelp, stdout);
    return 0;
  }
  const std::string& style_path = args.style_path;
  const std::string& output = args.output;
  const std::string& mask_path = args.mask_path;
  const std::string& nnf_out = args.nnf_out;
  const std::string& error_out = args.error_out;
  const std::string& depth = args.depth;
  const std::vector<SynthGuideArg>& guides = args.guides;
  synth::Params params = args.params;
  const bool quiet = args.quiet;

  // Fail on an unwritable output before any long work.
  check_output_path("-output", output);
  if (!nnf_out.empty()) check_output_path("--nnf-out", nnf_out);
  if (!error_out.empty()) check_output_path("--error-out", error_out);
  set_thread_count(args.threads);

  const auto t0 = std::chrono::steady_clock::now();
  // Decode every file at once (PNG decoding is serial per file); report the first failure in
  // command-line order so the error does not depend on timing.
  std::vector<std::string> paths{style_path};
  for (const auto& g : guides) paths.insert(paths.end(), {g.source, g.target});
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
  io::AnyImage style = std::move(files[0]);
  style = with_channels(std::move(style), effective_channels(style));
  if (style.channels() > 4) throw Error(style_path, "style must have 1 to 4 channels");

  std::vector<io::AnyImage> loaded;
  loaded.reserve(guides.size() * 2);
  synth::Inputs in;
  in.style = plane_of(style);
  in.style_name = style_path;
  for (std::size_t k = 0; k < guides.size(); ++k) {
    const SynthGuideArg& g = guides[k];
    io::AnyImage s = std::move(files[1 + 2 * k]);
    io::AnyImage t = std::move(files[2 + 2 * k]);
    if (s.width() != style.width() || s.height() != style.height())
      throw Error(g.source,
                  fmt::format("source guide is {}x{} but the style '{}' is {}x{}", s.width(),
                              s.height(), style_path, style.width(), style.height()));
    const int nc = std::max(effective_channels(s), effective_channels(t));
    if (nc > 4) throw Error(g.source, "a guide must have 1 to 4 channels");
    loaded.push_back(with_channels(std::move(s), std::min(nc, 4)));
    loaded.push_back(with_channels(std::move(t), std::min(nc, 4)));
    const io::AnyImage& ls = loaded[loaded.size() - 2];
    const io::AnyImage& lt = loaded.back();
    if (ls.channels() != lt.channels())
      throw Error(g.target, fmt::format("has {} channels but its source guide '{}' has {}",
                                        lt.channels(), g.source, ls.channels()));
    synth::GuidePair gp;
    gp.name = g.target;
    gp.source = plane_of(ls);
    gp.target = plane_of(lt);
    gp.weight = g.weight;
    in.guides.push_back(gp);
  }
  // Name the right file when sizes disagree.
  for (std::size_t k = 1; k < in.guides.size(); ++k)
    if (synth::plane_width(in.guides[k].target) != synth::plane_width(in.guides[0].target) ||
        synth::plane_height(in.guides[k].target) != synth::plane_height(in.guides[0].target))
      throw Error(guides[k].target,
                  fmt::format("target guide is {}x{} but '{}' is {}x{}",
                              synth::plane_width(in.guides[k].target),
                              synth::plane_height(in.guides[k].target), guides[0].target,
                              synth::plane_width(in.guides[0].target),
                              synth::plane_height(in.guides[0].target)));
  io::AnyImage mask;
  if (!mask_path.empty()) {
    mask = io::read_image(mask_path);
    in.target_mask = plane_of(mask);
    in.target_mask_name = mask_path;
  }
  params.style_weight = args.style_weight;

  synth::OutputRequest req;
  req.nnf = !nnf_out.empty();
  req.error = !error_out.empty();
  synth::Synthesizer synthesizer(in, params);
  // The guides are packed into the engine's features now; free them before the long part.
  in.guides.clear();
  loaded.clear();
  loaded.shrink_to_fit();
  synth::Result res = synthesizer.run(req);
  const auto t1 = std::chrono::steady_clock::now();

  io::WriteOptions wo;
  if (depth == "8")
    wo.format = io::SampleFormat::kU8;
  else if (depth == "16")
    wo.format = io::SampleFormat::kU16;
  else if (depth == "float")
    wo.format = io::SampleFormat::kFloat;
  else if (style.type() == io::PixelType::kU8)
    wo.format = io::SampleFormat::kU8;
  else if (style.type() == io::PixelType::kU16)
    wo.format = io::SampleFormat::kU16;
  else
    wo.format = io::SampleFormat::kFloat;
  // A one-channel style whose file was RGB is written back as RGB, as EbSynth does.
  Image<float> out_img;
  const int ns = synth::plane_channels(in.style);
  if (ns == 1 && res.image.channels() <= 2) {
    const bool alpha = res.image.channels() == 2;
    out_img.reset(res.image.width(), res.image.height(), alpha ? 4 : 3);
    for (int y = 0; y < res.image.height(); ++y)
      for (int x = 0; x < res.image.width(); ++x) {
        for (int c = 0; c < 3; ++c) out_img(x, y, c) = res.image(x, y, 0);
        if (alpha) out_img(x, y, 3) = res.image(x, y, 1);
      }
  } else {
    out_img = std::move(res.image);
  }
  io::write_image(output, out_img.cview(), wo);
  if (req.nnf) {
    Image<float> f(res.nnf.width(), res.nnf.height(), 2);
    for (int y = 0; y < f.height(); ++y)
      for (int x = 0; x < f.width(); ++x)
        for (int c = 0; c < 2; ++c) f(x, y, c) = float(res.nnf(x, y, c));
    io::WriteOptions o;
    o.format = io::SampleFormat::kFloat;
    o.channel_names = {"nnf.X", "nnf.Y"};
    io::write_image(nnf_out, f.cview(), o);
  }
  if (req.error) {
    io::WriteOptions o;
    o.format = io::SampleFormat::kFloat;
    o.channel_names = {"error.Y"};
    io::write_image(error_out, res.error.cview(), o);
  }
  if (!quiet)
    std::fprintf(stderr,
                 "emaki synth: %dx%d from %dx%d, %d channels + %zu guides, %d levels, %.2f s\n",
                 out_img.width(), out_img.height(), style.width(), style.height(), ns,
                 guides.size(), res.pyramid_levels, std::chrono::duration<double>(t1 - t0).count());
  return 0;
}

}  // namespace emaki::app
