// EbSynth's rules for images as a caller holds them (decoded files, numpy arrays), shared by
// `emaki synth` and the Python module so that both hand the engine the same inputs:
//  - an RGB image whose three channels are equal everywhere counts as one channel, and an alpha
//    channel that is opaque everywhere is dropped (effective_channels);
//  - the two images of a guide pair get the same channel count, the larger of their two: a gray
//    image is spread over RGB;
//  - a one-channel style's result is given back as RGB (gray_to_rgb).
// The default weights (style 1, each guide 1 / number of guides, spread over its channels) are
// the engine's own (Params::style_weight, GuidePair::weight). No file I/O.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "core/image.h"
#include "synth/synthesizer.h"

namespace emaki::synth {

// Bounds on counts a caller may ask for: a typo or a hostile script must not start a run that
// never ends. Far above anything useful (EbSynth's own defaults are 6 and 4).
inline constexpr int kMaxPatchSize = 65;
inline constexpr int kMaxPyramidLevels = 32;
inline constexpr int kMaxIterations = 1000;
inline constexpr int kMaxThreads = 1024;
inline constexpr int kMaxGuides = 64;
inline constexpr float kMaxWeight = 1e6f;

// An image as the caller holds it (any channel count) and the name errors give it: a file path
// for the command line, an argument ("style", "guides[0][1]") for Python.
struct NamedPlane {
  Plane plane;
  std::string name;
};

struct NamedGuide {
  NamedPlane source, target;
  float weight = -1.0f;  // >= 0; negative: 1 / number of guides
};

// Channels that count: 4 -> 3 when alpha is opaque everywhere, 3 -> 1 when R = G = B everywhere,
// 2 -> 1 when the second channel is opaque everywhere.
int effective_channels(const Plane& p);

// The engine's inputs made by the rules, with the images the rules had to make (when a channel
// count changed): the planes in `inputs` point into those or into the caller's images, which
// must outlive them.
class RuledInputs {
 public:
  Inputs inputs;
  // How many images the rules made (0 when every input went to the engine as it was).
  int images_made() const { return int(made_.size()); }
  // Drops the guide planes and the images made for them: once a Synthesizer is constructed,
  // only the style and the mask are read again.
  void release_guides();

 private:
  friend RuledInputs apply_ebsynth_rules(const NamedPlane&, const std::vector<NamedGuide>&,
                                         const std::optional<NamedPlane>&);
  using Made = std::variant<Image<uint8_t>, Image<uint16_t>, Image<float>>;
  // An image with `channels` channels (see the header comment), made only when needed.
  Plane with_channels(const Plane& p, int channels, bool is_guide);
  std::vector<Made> made_;
  std::vector<bool> made_for_guide_;
};

// An image's name and size: what the size checks need, before any pixel is read or copied.
struct NamedSize {
  std::string name;
  int width = 0, height = 0;
};

// Throws emaki::Error naming the image for a source guide whose size is not the style's, or
// target guides of different sizes. apply_ebsynth_rules checks this first; a caller that must
// copy its inputs (an array of another layout) calls it before copying.
void check_guide_sizes(const NamedSize& style,
                       const std::vector<std::pair<NamedSize, NamedSize>>& guides);

// Applies the rules; throws emaki::Error naming the image (NamedPlane::name) for a style or
// guide with more than 4 channels that count, a source guide whose size is not the style's, or
// target guides of different sizes. The engine checks the rest (Synthesizer's constructor).
RuledInputs apply_ebsynth_rules(const NamedPlane& style, const std::vector<NamedGuide>& guides,
                                const std::optional<NamedPlane>& mask);

// A gray result (1 channel, or 2: gray and alpha) as RGB (or RGBA), as EbSynth gives back a
// one-channel style.
Image<float> gray_to_rgb(const Image<float>& gray);

}  // namespace emaki::synth
