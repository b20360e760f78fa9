// Validation of the synthesizer's inputs and parameters, and the search-vote schedule.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "synth/exemplar_index.h"
#include "synth/planes.h"
#include "synth/pyramid.h"
#include "synth/synthesizer.h"
#include "synth/weight_maps.h"

namespace emaki::synth {

int max_pyramid_levels(int sw, int sh, int tw, int th, int patch_size) {
  int levels = 1;
  int a = sw, b = sh, c = tw, d = th;
  for (;;) {
    a = half_size(a), b = half_size(b), c = half_size(c), d = half_size(d);
    if (std::min({a, b, c, d}) < 2 * patch_size + 1) break;
    ++levels;
  }
  return levels;
}

void validate(const Inputs& in, const Params& p) {
  using F = Error::Field;
  if (p.patch_size < 3 || p.patch_size % 2 == 0)
    throw Error(F{"patch_size"}, fmt::format("must be odd and >= 3 (got {})", p.patch_size));
  if (!(p.uniformity >= 0.0f) || !std::isfinite(p.uniformity))
    throw Error(F{"uniformity"}, "must be a finite number >= 0");
  if (p.pyramid_levels == 0 || p.pyramid_levels < -1)
    throw Error(F{"pyramid_levels"}, fmt::format("must be >= 1 (got {})", p.pyramid_levels));
  if (p.search_vote_iters < -1) throw Error(F{"search_vote_iters"}, "must be >= 0");
  if (p.patch_match_iters < -1) throw Error(F{"patch_match_iters"}, "must be >= 0");
  if (p.search_radius < 0) throw Error(F{"search_radius"}, "must be >= 0 (0: the whole exemplar)");
  if (!std::isfinite(p.style_weight)) throw Error(F{"style_weight"}, "must be finite");
  if (!(p.warm_sharp_estimate >= 0.0f && p.warm_sharp_estimate <= 1.0f))
    throw Error(F{"warm_sharp_estimate"}, "must be between 0 and 1");
  if (p.finest_search_vote_iters < -1) throw Error(F{"finest_search_vote_iters"}, "must be >= 0");
  if (p.index_k < 0 || p.index_k > kMaxIndexK)
    throw Error(F{"index_k"}, fmt::format("must be in [0, {}] (got {})", kMaxIndexK, p.index_k));

  const int sw = plane_width(in.style), sh = plane_height(in.style);
  const int ns = plane_channels(in.style);
  if (sw <= 0 || sh <= 0) throw Error(in.style_name, "style image is empty");
  if (ns < 1 || ns > 4)
    throw Error(in.style_name, fmt::format("style must have 1 to 4 channels (has {})", ns));
  check_finite(in.style, in.style_name);
  if (in.guides.empty()) throw Error("guides", "at least one guide pair is needed");
  int tw = -1, th = -1;
  std::string first_target;
  for (const auto& g : in.guides) {
    if (plane_width(g.source) != sw || plane_height(g.source) != sh)
      throw Error(
          g.source_name.empty() ? g.name : g.source_name,
          fmt::format("source guide is {}x{} but the style '{}' is {}x{}", plane_width(g.source),
                      plane_height(g.source), in.style_name, sw, sh));
    if (tw < 0) {
      tw = plane_width(g.target), th = plane_height(g.target);
      first_target = g.name;
    } else if (plane_width(g.target) != tw || plane_height(g.target) != th) {
      throw Error(g.name,
                  fmt::format("target guide is {}x{} but '{}' is {}x{}", plane_width(g.target),
                              plane_height(g.target), first_target, tw, th));
    }
    const int cs = plane_channels(g.source), ct = plane_channels(g.target);
    if (cs != ct)
      throw Error(g.name, fmt::format("source guide has {} channels, target guide {}", cs, ct));
    if (cs < 1 || cs > 4)
      throw Error(g.name, fmt::format("a guide must have 1 to 4 channels (has {})", cs));
    if (!(g.weight < 0.0f || std::isfinite(g.weight)))
      throw Error(g.name, "weight must be a finite number >= 0");
    check_finite(g.source, g.source_name.empty() ? g.name : g.source_name);
    check_finite(g.target, g.name);
  }
  if (sw < p.patch_size || sh < p.patch_size)
    throw Error(in.style_name, fmt::format("style image {}x{} is smaller than the {}x{} patch", sw,
                                           sh, p.patch_size, p.patch_size));
  if (tw < p.patch_size || th < p.patch_size)
    throw Error(first_target, fmt::format("target {}x{} is smaller than the {}x{} patch", tw, th,
                                          p.patch_size, p.patch_size));
  check_weight_maps(in, p, tw, th);
  if (p.uniformity_map) check_unit_map(*p.uniformity_map, "uniformity map", tw, th);
  const ImageView<const int32_t>& init = p.initial_nnf;
  if (!init.empty() && (init.width != tw || init.height != th || init.channels != 2))
    throw Error(F{"initial_nnf"}, fmt::format("is {}x{}x{}, the target {}x{}x2", init.width,
                                              init.height, init.channels, tw, th));
  if (in.target_mask) {
    if (plane_width(*in.target_mask) != tw || plane_height(*in.target_mask) != th)
      throw Error(in.target_mask_name,
                  fmt::format("mask is {}x{} but the target is {}x{}", plane_width(*in.target_mask),
                              plane_height(*in.target_mask), tw, th));
    check_finite(*in.target_mask, in.target_mask_name);
  }
}

std::vector<LevelSchedule> make_schedule(const Params& p, int levels) {
  std::vector<LevelSchedule> s(levels);
  if (p.search_vote_iters >= 0 || p.patch_match_iters >= 0) {
    for (auto& l : s) {
      l.search_vote_iters = p.search_vote_iters >= 0 ? p.search_vote_iters : 6;
      l.patch_match_iters = p.patch_match_iters >= 0 ? p.patch_match_iters : 4;
      l.max_search_radius = p.search_radius;
    }
    return s;
  }
  // emaki's schedule. The coarse levels are cheap and decide the layout: they search the whole
  // exemplar with EbSynth's counts, the third-finest level included. The two finest levels cost
  // 15/16 of the time and start from a field that is already good, so they refine it with fewer
  // iterations and a bounded search radius. Measured with the judge at full size on StyLit and
  // FaceStyle (docs/design/engine-schedule.md): style, joint and coverage hold against
  // EbSynth's 6 x 4 at every level. (One search-vote iteration at the finest level was enough for
  // StyLit but not for FaceStyle's joint energy.) The third-finest level ran 3 x 3 until the
  // evaluation set (bench/eval_set.py) showed 6 x 4 there worth it: worst joint 1.119x -> 1.098x
  // EbSynth's, mean style 1.037x -> 1.022x.
  // With the exemplar index (index_k > 0) every level sweeps half as often per search-vote
  // iteration (the finest once, the second-finest and the coarse levels twice): the sets'
  // candidates stand in for the other sweeps (StyLit, seeds 1-5, k = 2: judge style 0.00112
  // against 0.00117 without the index, docs/design/exemplar-index.md).
  const bool indexed = p.index_k > 0;
  for (int l = 0; l < levels; ++l) {
    const int from_finest = levels - 1 - l;
    if (from_finest == 0)
      s[l] = {p.finest_search_vote_iters >= 0 ? p.finest_search_vote_iters : 2, indexed ? 1 : 2,
              32};
    else if (from_finest == 1)
      s[l] = {2, indexed ? 2 : 3, 32};
    else
      s[l] = {6, indexed ? 2 : 4, 0};
  }
  return s;
}

}  // namespace emaki::synth
