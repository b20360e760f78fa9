// Guided patch-based synthesis (Image Analogies, A : A' :: B : B'): given a style exemplar A',
// source guides A_k and target guides B_k, synthesize B' so that A : A' :: B : B'.
// Multiscale PatchMatch with an occupancy-based uniformity term (EbSynth's), voting, and an
// optional target mask. No file I/O: images come and go in memory.
//
// Units. Patch error is EbSynth's: sum over patch pixels and channels of
// weight_c * (255 * (a_c - b_c))^2 for values in [0, 1], so `uniformity` has EbSynth's meaning.
// Float guides whose values leave [0, 1] are normalised by their range over source and target.
//
// Per-pixel weights. A guide pair may carry a weight map over the target: the guide's share of
// the error of the patch centred at target pixel p is its weight times map(p) (the map at the
// patch centre, for every pixel of the patch; docs/design/temporal-confidence.md has the
// measurement behind that choice). The map's values are quantised to 1/65536 and the weighted sum
// stays an exact integer; a map of ones gives the same result, bit for bit, as no map.
//
// Precision. Each channel is quantised to 16383 * sqrt(weight_c / max_weight) levels over its
// range (14 bits for the heaviest channel; at least 12 bits for every channel whose weight is
// at least 1/16 of the heaviest; lighter channels are quantised more coarsely, in proportion to
// how little they count). Patch sums are exact 64-bit integers, so the SIMD and scalar kernels
// agree bit for bit and results never depend on the thread count.
#pragma once

#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "core/image.h"

namespace emaki::synth {

struct ExemplarIndex;  // exemplar_index.h

// A read-only input plane: 8-bit and 16-bit samples mean [0, 1]; float samples are taken as-is.
using Plane =
    std::variant<ImageView<const uint8_t>, ImageView<const uint16_t>, ImageView<const float>>;

int plane_width(const Plane& p);
int plane_height(const Plane& p);
int plane_channels(const Plane& p);

struct GuidePair {
  std::string name;      // shown in error messages (a file name, a pass name)
  Plane source;          // A_k, the size of the style exemplar
  Plane target;          // B_k, the size of the output
  float weight = -1.0f;  // >= 0; negative: 1 / number of guides (EbSynth's default)
  // Names the source in errors about it alone (its size), when it has a name of its own (a
  // file); empty: `name`.
  std::string source_name = {};
  // Optional per-target-pixel multiplier of `weight`: first channel, the target's size, values
  // in [0, 1] (0: the guide does not count at that pixel). At most kMaxWeightMaps guides.
  std::optional<Plane> weight_map = {};
  std::string weight_map_name = {};  // names the map in errors; empty: `name`
};

inline constexpr int kMaxWeightMaps = 7;

enum class VoteMode {
  kPlain,     // every overlapping patch counts the same
  kWeighted,  // patches count 1 / (1 + e / 100), e their error per pixel and channel: sharper;
              // the output itself (the run's last vote) is plain
};

// How the field starts at the coarsest level.
enum class FieldInit {
  kRandom,    // each target patch at a random source patch
  kIdentity,  // target pixel (x, y) at source pixel (x, y) scaled by the size ratio: for a source
              // and target that are nearly aligned, such as two consecutive frames (advection)
};

// Iterations at one pyramid level.
struct LevelSchedule {
  int search_vote_iters = 6;
  int patch_match_iters = 4;
  // Random search starts at this radius in pixels (0: the whole exemplar) and halves down to 1.
  int max_search_radius = 0;
};

struct Params {
  float style_weight = -1.0f;  // >= 0, spread over the style channels; negative: 1
  float uniformity = 3500.0f;  // >= 0; 500..15000 sensible; 0 disables the uniformity term
  // Optional per-target-pixel multiplier of `uniformity`: first channel, the target's size,
  // values in [0, 1] (0: the pixel's matches pay no occupancy cost); halved with the pyramid at
  // coarser levels. Read only by the constructor.
  std::optional<Plane> uniformity_map = {};
  int patch_size = 5;       // odd, >= 3
  int pyramid_levels = -1;  // >= 1; -1: as many as fit (coarsest side >= 2 * patch_size + 1)
  // -1: emaki's schedule (full search at coarse levels, leaner at the fine ones);
  // >= 0: that many at every level (EbSynth's behaviour; its defaults are 6 and 4).
  int search_vote_iters = -1;
  int patch_match_iters = -1;
  // With explicit iteration counts: the random search radius in pixels at every level (0: the
  // whole exemplar). With emaki's schedule it is chosen per level.
  int search_radius = 0;
  FieldInit init = FieldInit::kRandom;
  // emaki's schedule only: search-vote iterations at the finest level (-1: the schedule's 2).
  int finest_search_vote_iters = -1;
  // Optional warm start: the finest level's starting field, the target's size, 2 channels (the
  // source patch centre x, y, as Result::nnf gives it; the caller's, read only by the
  // constructor). With it the run is the finest level alone (pyramid_levels is taken as 1, so
  // the schedule is that of the finest level) and `init` does not count. An entry whose patch
  // leaves the source (such as Result::nnf's (-1, -1) outside a mask) starts at a random draw
  // keyed by `seed` and the pixel, as FieldInit::kRandom would.
  ImageView<const int32_t> initial_nnf = {};
  // A warm start's first estimate of the target style, which the first search compares the
  // exemplar's patches with: 0 votes the given field (as every level does); 1 takes each pixel's
  // own match's centre value, sharp where the vote of a carried field that has come apart
  // blurs; between, that mix. Without a warm start it does nothing.
  float warm_sharp_estimate = 0.0f;
  bool extra_pass_3x3 = false;  // a final polishing pass with 3x3 patches, no uniformity
  // 0..16: PatchMatch also tries the k-coherence sets of its propagated candidates, from a
  // per-painting index (exemplar_index.h) of this many sets per source patch; 0: no index.
  int index_k = 0;
  // Optional prebuilt index (Result::index of an earlier run on the same painting, guides and
  // patch size): used when it was built from the same source features with the same k, else
  // built anew.
  std::shared_ptr<const ExemplarIndex> index = {};
  VoteMode vote_mode = VoteMode::kWeighted;
  uint64_t seed = 1;
  // Optional progress callback: (level, levels).
  std::function<void(int, int)> progress;
  // Optional cancellation hook, polled on the calling thread before each level and each
  // PatchMatch sweep. Returning true stops the run with synth::Cancelled; returning false
  // changes nothing (results are those of a run without the hook).
  std::function<bool()> cancel;
};

// Thrown by Synthesizer::run when Params::cancel asked to stop.
struct Cancelled : std::exception {
  const char* what() const noexcept override { return "synthesis cancelled"; }
};

struct Inputs {
  Plane style;  // A', 1 to 4 channels
  std::string style_name = "style";
  std::vector<GuidePair> guides;  // at least one
  // Optional target mask (first channel, > 0.5 is inside). Pixels outside are not synthesized
  // and come out transparent: B' then gets one more channel, alpha.
  std::optional<Plane> target_mask;
  std::string target_mask_name = "mask";
};

struct OutputRequest {
  bool nnf = false;    // nearest-neighbour field: 2 channels (x, y) of the source patch centre
  bool error = false;  // per-pixel patch error (EbSynth units)
};

struct Result {
  Image<float> image;  // B': style channels, plus alpha when a mask was given
  Image<int32_t> nnf;  // when requested; (-1, -1) outside the mask
  Image<float> error;  // when requested; 0 outside the mask
  int pyramid_levels = 0;
  std::vector<LevelSchedule> schedule;
  std::shared_ptr<const ExemplarIndex> index;  // the index used (Params::index_k > 0)
};

// Checks the inputs (sizes, channel counts, finite values, parameter ranges) and throws
// emaki::Error naming the offending guide or parameter.
void validate(const Inputs& inputs, const Params& params);

// The schedule the synthesizer will run for these sizes and parameters.
std::vector<LevelSchedule> make_schedule(const Params& params, int levels);
int max_pyramid_levels(int sw, int sh, int tw, int th, int patch_size);

// Two phases, so a caller can free the guide images once they are packed into the engine's own
// features: the constructor validates and builds the pyramid (it reads every input); run()
// reads only inputs.style and inputs.target_mask again, which must outlive it.
class Synthesizer {
 public:
  Synthesizer(const Inputs& inputs, const Params& params);
  ~Synthesizer();
  Synthesizer(const Synthesizer&) = delete;
  Synthesizer& operator=(const Synthesizer&) = delete;
  Result run(const OutputRequest& request = {});

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// Both phases at once.
Result synthesize(const Inputs& inputs, const Params& params, const OutputRequest& request = {});

}  // namespace emaki::synth
