// A per-painting exemplar index: k-coherence candidate sets (Tong et al. 2002) for each pyramid
// level of the source features (style and source guides). For each source patch centre s, the
// set holds the k source centres, outside a small neighbourhood of s, whose patches are closest
// to s's. PatchMatch (patch_match.h) tries, for a target pixel p whose swept neighbour q matches
// s(q), the sets of s(q) + (p - q) besides that propagated centre itself.
//
// The sets depend only on the source features and the patch size (never on the target), so one
// index serves every frame made from the same painting and guides. The sets are found by a
// PatchMatch of each level onto itself that keeps the k best, started from the coarser level's
// sets; it is deterministic and the same for any thread count (bands of rows whose height
// depends only on the size, each reading the other bands as they were when the sweep began).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/image.h"
#include "synth/patch_distance.h"

namespace emaki::synth {

inline constexpr int kMaxIndexK = 16;

struct CoherenceSets {
  int width = 0, height = 0, k = 0;
  // width x height x k source centres (y * width + x), nearest first; -1 ends a short set (and
  // fills the sets of centres whose patch leaves the source).
  std::vector<int32_t> entries;
  const int32_t* at(int x, int y) const {
    return entries.data() + (std::size_t(y) * width + x) * std::size_t(k);
  }
};

struct ExemplarIndex {
  int patch_size = 0, k = 0;
  uint64_t features_digest = 0;       // features_digest() of the levels it was built from
  std::vector<CoherenceSets> levels;  // finest first
};

// Centres within this many pixels of s (in x and in y) are left out of s's set: propagation
// already tries them.
inline int index_exclusion(int patch_size) {
  return patch_size / 2;
}

// One level's sets over the level's features (an even channel count, as FeatureLayout pads
// them). `coarser`: the next coarser level's sets (its half size), or nullptr.
CoherenceSets build_coherence_sets(const Image<int16_t>& src, int patch_size, int k,
                                   const CoherenceSets* coarser, PatchSsdFn ssd, uint64_t seed);

// A digest of feature images (sizes, channels and every value), finest first.
uint64_t features_digest(const std::vector<const Image<int16_t>*>& levels);

// Bytes: a header (magic, version, patch size, k, level count, features digest), each level's
// size and entries (little-endian int32), then the FNV-1a digest of everything before it.
std::vector<uint8_t> serialize_index(const ExemplarIndex& index);
// The index in `bytes`; throws emaki::Error naming `subject` for anything that is not exactly
// what serialize_index writes (wrong magic or version, bad digest, sizes, entries out of range,
// bytes left over). Nothing is allocated beyond what the byte count can hold.
ExemplarIndex deserialize_index(const uint8_t* bytes, std::size_t size,
                                const std::string& subject = "exemplar index");

}  // namespace emaki::synth
