// PatchMatch with EbSynth's occupancy-based uniformity term, made deterministic.
//
// The target is swept in bands whose height depends only on its size, in parallel. Inside a band
// the sweep propagates as usual; across a band edge it reads the field as it was when the sweep
// began. Occupancy — how many target patches already cover a source patch — is kept as a
// snapshot taken at the start of each sweep plus a band-private delta. Nothing a band reads is
// written by another band, so the field is the same for any thread count and schedule.
//
// Occupancy is stored pre-summed over the patch window (a triangle filter of the patch-centre
// histogram), so a candidate's occupancy costs one lookup instead of patch_size^2.
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <vector>

#include "core/image.h"
#include "synth/patch_distance.h"

namespace emaki::synth {

// The target is swept in at most kBands bands (of at least kMinBandRows rows). Fewer, taller
// bands keep occupancy fresher (each band sees its own updates at once, the others' only at the
// next sweep); measured on StyLit, 8 bands score as well as one sequential sweep.
inline constexpr int kBands = 8;
inline constexpr int kMinBandRows = 16;
inline int band_rows(int height) {
  return std::max(kMinBandRows, (height + kBands - 1) / kBands);
}

struct PatchMatchLevel {
  int sw = 0, sh = 0, tw = 0, th = 0;
  int border = 0;                          // padding of tgt
  const Image<int16_t>* src = nullptr;     // sw x sh features
  const Image<int16_t>* tgt = nullptr;     // (tw + 2 border) x (th + 2 border) features
  const Image<uint8_t>* active = nullptr;  // tw x th, or empty: all active
  Image<int32_t>* nnf = nullptr;           // tw x th x 2
  Image<float>* err = nullptr;             // tw x th
};

struct PatchMatchConfig {
  int patch_size = 5;
  float uniformity = 3500.0f;
  int iterations = 4;
  int max_search_radius = 0;  // 0: the whole source
  double err_scale = 1.0;
  uint64_t seed = 1;  // already mixed with the level and search-vote iteration
  PatchSsdFn ssd = nullptr;
  // Called on the calling thread before each sweep, when set; it may throw to stop the run
  // (cancellation), and otherwise changes nothing.
  const std::function<void()>* before_sweep = nullptr;
};

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
