// `emaki synth`'s command line, parsed without touching a file (so it can be fuzzed and
// tested alone), and EbSynth's channel rules over loaded images.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "io/image_io.h"
#include "synth/synthesizer.h"

namespace emaki::app {

struct SynthGuideArg {
  std::string source, target;
  float weight = -1.0f;         // -1: EbSynth's default (1 / number of guides)
  std::string weight_map = {};  // --guide-weight-map: per-pixel weight over the target, or empty
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

// What EbSynth's command line gives the engine for each input: its channel count and weight.
// The engine spreads a weight evenly over the input's channels.
struct SynthChannels {
  struct Guide {
    int channels = 0;  // source and target alike: the larger of their effective counts
    float weight = 0;  // -weight after the -guide, else 1 / number of guides
  };
  int style_channels = 0;     // the style's effective count (the engine checks it is 1 to 4)
  float style_weight = 1.0f;  // -weight after the -style, else 1
  std::vector<Guide> guides;
};

// EbSynth's channel rules. `style_channels` and `guide_channels` ({source, target} per -guide,
// in order) are effective_channels() of the files. A guide pair whose files disagree gets the
// larger count (a gray side is spread over RGB); a guide file with more than 4 effective
// channels is an Error naming it.
SynthChannels resolve_channels(const SynthArgs& args, int style_channels,
                               const std::vector<std::array<int, 2>>& guide_channels);

}  // namespace emaki::app
