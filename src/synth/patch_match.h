// PatchMatch with EbSynth's occupancy-based uniformity term, made deterministic.
//
// The target is cut into bands whose height depends only on its size. A sweep visits them in
// rounds of bands that are never adjacent (band b in round b % kRounds); the bands of one round
// run in parallel. Inside a band the sweep propagates as usual; across a band edge it reads the
// neighbouring band, which no one writes during the round (it was swept in an earlier round of
// this sweep, or will be in a later one). Occupancy — how many target patches already cover a
// source patch — is the state at the start of the round plus a band-private delta, so each round
// sees what the rounds before it did. Nothing a band reads is written by another band during the
// round, so the field is the same for any thread count and schedule.
//
// Occupancy is stored pre-summed over the patch window (a triangle filter of the patch-centre
// histogram), so a candidate's occupancy costs one lookup instead of patch_size^2.
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <vector>

#include "core/image.h"
#include "synth/exemplar_index.h"
#include "synth/patch_distance.h"

namespace emaki::synth {

// The target is swept in at most kBands bands (of at least kMinBandRows rows), in kRounds rounds
// of kBands / kRounds bands at once. Bands of one round see each other's occupancy only from the
// next round on: on smooth exemplars over flat guides (the MatCaps of bench/eval_set.py,
// docs/design/deterministic-bands.md) bands that run blind to each other crowd onto the same
// best-fitting source region and the output is mottled. Judge style on the Cornell box MatCap pair
// (EbSynth 0.000145), with the vote of voting.cpp: 8 bands in 2 rounds 0.000227, 16 in 4 rounds
// 0.000167, 8 in 4 0.000162 (8 bands at once, with the former vote: 0.000358). 16 in 4 keeps 4
// threads busy.
inline constexpr int kBands = 16;
inline constexpr int kRounds = 4;  // >= 2: adjacent bands never run at once
inline constexpr int kMinBandRows = 16;
inline int band_rows(int height) {
  return std::max(kMinBandRows, (height + kBands - 1) / kBands);
}

struct PatchMatchLevel {
  int sw = 0, sh = 0, tw = 0, th = 0;
  int border = 0;                          // padding of tgt
  const Image<int16_t>* src = nullptr;     // sw x sh features (an even channel count)
  const Image<int16_t>* tgt = nullptr;     // (tw + 2 border) x (th + 2 border) features
  const Image<uint8_t>* active = nullptr;  // tw x th, or empty: all active
  Image<int32_t>* nnf = nullptr;           // tw x th x 2
  Image<float>* err = nullptr;             // tw x th
  // With weight maps: tw x th x groups, each target pixel's group weights (group 0, the
  // channels without a map, at kGroupWeightOne); nullptr or empty: the plain distance.
  const Image<int64_t>* group_weights = nullptr;
  // tw x th multipliers of the uniformity term's cost at each target pixel; nullptr or empty:
  // 1 everywhere.
  const Image<float>* uniformity_map = nullptr;
};

struct PatchMatchConfig {
  int patch_size = 5;
  float uniformity = 3500.0f;
  int iterations = 4;
  int max_search_radius = 0;  // 0: the whole source
  double err_scale = 1.0;
  uint64_t seed = 1;  // already mixed with the level and search-vote iteration
  PatchSsdFn ssd = nullptr;
  // With group_weights: the grouped kernel and its masks (groups rows, mask_stride apart, of at
  // least patch_size x channels elements).
  PatchSsdGroupedFn ssd_grouped = nullptr;
  const int16_t* group_masks = nullptr;
  std::ptrdiff_t group_mask_stride = 0;
  int groups = 1;
  // Called on the calling thread before each sweep, when set; it may throw to stop the run
  // (cancellation), and otherwise changes nothing.
  const std::function<void()>* before_sweep = nullptr;
  // The level's k-coherence sets (exemplar_index.h, the source's size and this patch size), or
  // nullptr: each propagated centre's set is tried after it.
  const CoherenceSets* coherence = nullptr;
};

// The distance between the target patch centred at (x, y) (top-left element t) and a source
// patch (top-left element s), in the level's integer units, stopping above `bound` like the
// kernels: the plain kernel, or the grouped one at the pixel's group weights.
inline int64_t patch_distance(const PatchMatchLevel& L, const PatchMatchConfig& C, int x, int y,
                              const int16_t* t, const int16_t* s, int row_elems, int rows,
                              int64_t bound) {
  const std::ptrdiff_t ts = L.tgt->stride(), ss = L.src->stride();
  if (L.group_weights == nullptr || L.group_weights->empty())
    return C.ssd(t, ts, s, ss, row_elems, rows, bound);
  const int64_t* w = L.group_weights->at(x, y);
  bool full = true;
  for (int g = 1; g < C.groups; ++g) full = full && w[g] == kGroupWeightOne;
  // Every group at full weight (most pixels of a typical map): the plain kernel gives the same
  // sum, scaled, at its speed. Stopping above bound / 2^16 is stopping above bound.
  if (full) return C.ssd(t, ts, s, ss, row_elems, rows, bound >> 16) << 16;
  return C.ssd_grouped(t, ts, s, ss, row_elems, rows, bound, C.group_masks, C.group_mask_stride, w,
                       C.groups);
}

// Starting fields (tw x th, 2 channels: source patch centre x, y, kept r from the source's
// border): the coarser level's field doubled, the identity scaled to the source, or uniform
// random draws keyed by `seed` and the pixel (independent of the thread count).
Image<int32_t> upscale_nnf(const Image<int32_t>& coarse, int tw, int th, int sw, int sh, int r);
Image<int32_t> identity_nnf(int tw, int th, int sw, int sh, int r);
Image<int32_t> random_nnf(int tw, int th, int sw, int sh, int r, uint64_t seed);
// random_nnf's entry at target pixel (x, y), written to out[0], out[1].
void random_entry(int x, int y, int sw, int sh, int r, uint64_t seed, int32_t* out);

// Patch error of every active target pixel against its current match, in EbSynth units.
void compute_errors(const PatchMatchLevel& level, const PatchMatchConfig& config);

// Runs `config.iterations` sweeps (errors must be current).
void run_patch_match(const PatchMatchLevel& level, const PatchMatchConfig& config);

// Occupancy summed over the patch window of each source centre, sw * sh values row by row
// (exposed for tests).
// `scratch` is a work buffer; both are resized as needed (reused across sweeps).
void occupancy_window_sums(const PatchMatchLevel& level, int patch_size, std::vector<int32_t>& sums,
                           std::vector<int32_t>& scratch);

}  // namespace emaki::synth
