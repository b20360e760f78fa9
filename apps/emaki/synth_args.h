// `emaki synth`'s command line, parsed without touching a file (so it can be fuzzed and
// tested alone), and EbSynth's channel rules over loaded images.
#pragma once

#include <string>
#include <vector>

#include "io/image_io.h"
#include "synth/synthesizer.h"

namespace emaki::app {

struct SynthGuideArg {
  std::string source, target;
  float weight = -1.0f;  // -1: EbSynth's default (1 / number of guides)
};

struct SynthArgs {
  bool help = false;
  std::string style_path, output = "output.png", mask_path, nnf_out, error_out;
  std::string depth;           // "", "8", "16" or "float"
  float style_weight = -1.0f;  // -1: EbSynth's default (1)
  std::vector<SynthGuideArg> guides;
  synth::Params params;
  int threads = 0;
  bool quiet = false;
};

// Bounds on counts a command line may ask for: a typo or a hostile script must not start a
// run that never ends. Far above anything useful (EbSynth's own defaults are 6 and 4).
inline constexpr int kMaxPatchSize = 65;
inline constexpr int kMaxPyramidLevels = 32;
inline constexpr int kMaxIterations = 1000;
inline constexpr int kMaxThreads = 1024;
inline constexpr int kMaxGuides = 64;

// Parses EbSynth's command line plus emaki's options. Throws Error naming the option; checks
// values and required options, never files.
SynthArgs parse_synth_args(const std::vector<std::string>& args);

// EbSynth counts an RGB image whose three channels are equal everywhere as one channel, and
// drops an alpha channel that is opaque everywhere.
int effective_channels(const io::AnyImage& im);

// Gives an image `channels` channels: keeps the first ones (effective_channels only drops
// trailing ones), or spreads a gray image over RGB when its partner guide is in colour.
io::AnyImage with_channels(io::AnyImage im, int channels);

}  // namespace emaki::app
