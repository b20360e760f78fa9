// `emaki synth`'s command line, parsed without touching a file (so it can be fuzzed and
// tested alone). EbSynth's channel rules over the loaded images are synth/ebsynth_rules.h.
#pragma once

#include <string>
#include <vector>

#include "synth/ebsynth_rules.h"
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
  std::string index_cache;  // --index-cache DIR, or empty
};

// Bounds on counts a command line may ask for (the same as Python's, see ebsynth_rules.h).
using synth::kMaxGuides;
using synth::kMaxIterations;
using synth::kMaxPatchSize;
using synth::kMaxPyramidLevels;
using synth::kMaxThreads;
using synth::kMaxWeight;

// Parses EbSynth's command line plus emaki's options. Throws Error naming the option; checks
// values and required options, never files.
SynthArgs parse_synth_args(const std::vector<std::string>& args);

}  // namespace emaki::app
