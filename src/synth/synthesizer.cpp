#include "synth/synthesizer.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <type_traits>

#include "core/check.h"
#include "core/error.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "synth/exemplar_index.h"
#include "synth/patch_match.h"
#include "synth/planes.h"
#include "synth/pyramid.h"
#include "synth/voting.h"
#include "synth/weight_maps.h"

namespace emaki::synth {

namespace {

struct Level {
  int sw = 0, sh = 0, tw = 0, th = 0;
  Image<int16_t> src;            // sw x sh features
  Image<int16_t> tgt;            // padded target features
  Image<float> src_style;        // sw x sh style values for voting (coarse levels; the finest
                                 // votes from the input itself)
  Image<uint8_t> active;         // tw x th, or empty
  Image<float> weight_maps;      // tw x th x (groups - 1), with weight maps
  Image<int64_t> group_weights;  // tw x th x groups, made from them when the level starts
  Image<float> uniformity_map;   // tw x th (Params::uniformity_map), or empty
};

FeatureLayout make_layout(const Inputs& in, const Params& p) {
  FeatureLayout L;
  L.style_channels = plane_channels(in.style);
  for (const auto& g : in.guides) L.guide_channels += plane_channels(g.source);
  const int n = L.style_channels + L.guide_channels;
  L.channels = padded_channels(n);
  std::vector<float> w;
  std::vector<std::pair<float, float>> range;
  // Each channel's range, [0, 1] unless the values leave it: every plane's channels in one pass.
  auto add_ranges = [&](const Plane& a, const Plane* b) {
    const int nc = plane_channels(a);
    if (!is_float(a) && (b == nullptr || !is_float(*b))) {
      range.insert(range.end(), std::size_t(nc), {0.0f, 1.0f});
      return;
    }
    std::vector<float> mn(std::size_t(nc), INFINITY), mx(std::size_t(nc), -INFINITY);
    plane_ranges(a, mn, mx);
    if (b) plane_ranges(*b, mn, mx);
    for (int c = 0; c < nc; ++c) {
      const float lo = mn[std::size_t(c)], hi = mx[std::size_t(c)];
      if (lo < 0.0f || hi > 1.0f)
        range.push_back({lo, std::max(hi, lo + 1e-12f)});
      else
        range.push_back({0.0f, 1.0f});
    }
  };
  const float style_w = p.style_weight < 0.0f ? 1.0f : p.style_weight;
  for (int c = 0; c < L.style_channels; ++c) w.push_back(style_w / float(L.style_channels));
  add_ranges(in.style, nullptr);
  for (const auto& g : in.guides) {
    const int nc = plane_channels(g.source);
    for (int c = 0; c < nc; ++c) w.push_back(guide_weight(g, in.guides.size()) / float(nc));
    add_ranges(g.source, &g.target);
  }
  float w_max = 0.0f;
  for (float x : w) w_max = std::max(w_max, x);
  if (w_max <= 0.0f) w_max = 1.0f;
  for (int c = 0; c < n; ++c) {
    ChannelMap m;
    m.lo = range[c].first;
    m.mult =
        float(kQuantMax * std::sqrt(double(w[c]) / w_max) / (range[c].second - range[c].first));
    L.map.push_back(m);
  }
  L.err_scale = 65025.0 * w_max / (double(kQuantMax) * kQuantMax);
  assign_channel_groups(in, p.patch_size, L);
  return L;
}

// Writes channels [c0, c0 + channels(plane)) of features at (x + off, y + off).
void quantize_plane(const Plane& plane, const FeatureLayout& L, int c0, Image<int16_t>& feat,
                    int off) {
  const int nc = plane_channels(plane), w = plane_width(plane);
  const ChannelMap* map = L.map.data() + c0;
  const std::ptrdiff_t step = feat.channels();
  // The channel count fixed at compile time, so the maps stay in registers.
  const auto rows = [&]<int NC>(std::integral_constant<int, NC>) {
    parallel_rows(plane_height(plane), 32, [&](int y0, int y1) {
      ChannelMap m[NC];
      std::copy(map, map + NC, m);
      for_each_row(plane, y0, y1, [&](int y, const float* row) {
        int16_t* f = feat.at(off, y + off) + c0;
        for (int x = 0; x < w; ++x, f += step, row += NC)
          for (int c = 0; c < NC; ++c) f[c] = m[c].quantize(row[c]);
      });
    });
  };
  switch (nc) {  // 1 to 4, as validate() allows
    case 1:
      return rows(std::integral_constant<int, 1>{});
    case 2:
      return rows(std::integral_constant<int, 2>{});
    case 3:
      return rows(std::integral_constant<int, 3>{});
    default:
      CHECK_EQ(nc, 4);
      return rows(std::integral_constant<int, 4>{});
  }
}

void write_style(const Image<float>& style, const FeatureLayout& L, Image<int16_t>& tgt,
                 int border) {
  const int ns = L.style_channels;
  parallel_rows(style.height(), 32, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < style.width(); ++x) {
        const float* s = style.at(x, y);
        int16_t* f = tgt.at(x + border, y + border);
        for (int c = 0; c < ns; ++c) f[c] = L.map[c].quantize(s[c]);
      }
  });
  pad_replicate(tgt, border, 0, ns);
}

// The warm start's field: `given` where its patch lies inside the source, random_nnf's draw
// elsewhere (drawn only there).
Image<int32_t> warm_nnf(ImageView<const int32_t> given, int sw, int sh, int r, uint64_t seed) {
  Image<int32_t> out(given.width, given.height, 2);
  parallel_rows(given.height, 32, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < given.width; ++x) {
        const int32_t sx = given(x, y, 0), sy = given(x, y, 1);
        if (sx >= r && sx < sw - r && sy >= r && sy < sh - r)
          out(x, y, 0) = sx, out(x, y, 1) = sy;
        else
          random_entry(x, y, sw, sh, r, seed, out.at(x, y));
      }
  });
  return out;
}

}  // namespace

struct Synthesizer::State {
  Params params;
  Image<int32_t> initial_nnf;  // the warm start's field (Params::initial_nnf), or empty
  Plane style;
  std::optional<Plane> mask;
  int sw = 0, sh = 0, tw = 0, th = 0, levels = 0, border = 0;
  FeatureLayout layout;
  std::vector<LevelSchedule> schedule;
  std::vector<Level> pyr;
  bool ran = false;
};

Synthesizer::~Synthesizer() = default;

Synthesizer::Synthesizer(const Inputs& in, const Params& params)
    : state_(std::make_unique<State>()) {
  validate(in, params);
  State& st = *state_;
  st.params = params;
  st.style = in.style;
  st.mask = in.target_mask;
  const int p = params.patch_size, r = p / 2;
  const int border = st.border = r;
  const int sw = st.sw = plane_width(in.style), sh = st.sh = plane_height(in.style);
  const int tw = st.tw = plane_width(in.guides[0].target);
  const int th = st.th = plane_height(in.guides[0].target);
  st.layout = make_layout(in, params);
  const FeatureLayout& layout = st.layout;
  const int ns = layout.style_channels;

  int levels = max_pyramid_levels(sw, sh, tw, th, p);
  if (params.pyramid_levels > 0) levels = std::min(levels, params.pyramid_levels);
  if (!params.initial_nnf.empty()) {
    levels = 1;  // a warm start refines the given field at the finest level only
    st.initial_nnf = warm_nnf(params.initial_nnf, sw, sh, r, params.seed);
  }
  st.levels = levels;
  st.schedule = make_schedule(params, levels);

  // Finest level (index 0) from the inputs; coarser ones by halving.
  std::vector<Level>& pyr = st.pyr;
  pyr.resize(levels);
  {
    Level& f = pyr[0];
    f.sw = sw, f.sh = sh, f.tw = tw, f.th = th;
    f.src.reset(sw, sh, layout.channels);
    f.tgt.reset(tw + 2 * border, th + 2 * border, layout.channels);
    quantize_plane(in.style, layout, 0, f.src, 0);
    int c = ns;
    for (const auto& g : in.guides) {
      quantize_plane(g.source, layout, c, f.src, 0);
      quantize_plane(g.target, layout, c, f.tgt, border);
      c += plane_channels(g.source);
    }
    pad_replicate(f.tgt, border, ns, layout.channels);
    if (layout.groups > 1) f.weight_maps = gather_weight_maps(in, tw, th);
    if (params.uniformity_map) f.uniformity_map = gather_map(*params.uniformity_map, tw, th);
    if (in.target_mask) {
      // Synthesize the mask dilated by the patch radius, so pixels at its edge get whole patches.
      Image<uint8_t> inside(tw, th, 1);
      const int mc = plane_channels(*in.target_mask);
      parallel_rows(th, 32, [&](int y0, int y1) {
        for_each_row(*in.target_mask, y0, y1, [&](int y, const float* row) {
          for (int x = 0; x < tw; ++x) inside(x, y) = row[x * mc] > 0.0f ? 1 : 0;
        });
      });
      f.active = dilate_mask(inside, r);
    }
  }
}

namespace {

// Levels 1.. of the pyramid, each from the one finer: features by halving, the style from the
// input (level 1) or by halving, the target mask by halving.
void build_coarse_levels(std::vector<Level>& pyr, const Plane& style, int sw, int sh,
                         const FeatureLayout& layout, int border) {
  const int ns = layout.style_channels;
  for (std::size_t l = 1; l < pyr.size(); ++l) {
    Level& c = pyr[l];
    const Level& f = pyr[l - 1];
    c.src = downsample(f.src.cview());
    decimate_channels(f.src.cview(), c.src, 0, ns);
    c.src_style.reset(c.src.width(), c.src.height(), ns);
    if (l == 1) {
      for_each_row(style, 0, sh, [&](int y, const float* row) {
        if (y % 2 != 0 || y / 2 >= c.src_style.height()) return;
        for (int x = 0; x < c.src_style.width(); ++x)
          for (int k = 0; k < ns; ++k)
            c.src_style(x, y / 2, k) = row[std::min(2 * x, sw - 1) * ns + k];
      });
    } else {
      decimate_channels(f.src_style.cview(), c.src_style, 0, ns);
    }
    Image<int16_t> t = downsample(interior(f.tgt, border));
    c.sw = c.src.width(), c.sh = c.src.height(), c.tw = t.width(), c.th = t.height();
    c.tgt.reset(c.tw + 2 * border, c.th + 2 * border, layout.channels);
    for (int y = 0; y < c.th; ++y)
      std::copy(t.row(y), t.row(y) + std::size_t(c.tw) * layout.channels,
                c.tgt.at(border, y + border));
    pad_replicate(c.tgt, border, ns, layout.channels);
    if (!f.active.empty()) c.active = downsample_mask(f.active.cview());
    if (!f.weight_maps.empty()) c.weight_maps = downsample(f.weight_maps.cview());
    if (!f.uniformity_map.empty()) c.uniformity_map = downsample(f.uniformity_map.cview());
  }
}

// The coarse-to-fine solve: the nearest-neighbour field, its patch errors and the voted style,
// carried from each level to the next finer one.
struct Solve {
  const Params& params;
  const FeatureLayout& layout;
  const Plane& input_style;  // the finest level votes from the input itself
  int border;
  PatchSsdFn ssd;
  // Cancellation (Params::cancel), polled on this thread before each level and each sweep.
  std::function<void()> poll;
  const ExemplarIndex* index = nullptr;  // with Params::index_k
  Image<int32_t> nnf;  // holds the warm start's field (if any) until the level starts
  Image<float> err;
  Image<float> style;

  Plane source_style(const Level& L, int l) const {
    return l == 0 ? input_style : Plane(L.src_style.cview());
  }

  PatchMatchLevel pm_level(const Level& L) {
    return {L.sw,   L.sh,      L.tw, L.th, border,           &L.src,
            &L.tgt, &L.active, &nnf, &err, &L.group_weights, &L.uniformity_map};
  }
  PatchMatchConfig pm_config(int patch) const {
    PatchMatchConfig cfg;
    cfg.patch_size = patch;
    cfg.err_scale = layout.err_scale;
    cfg.ssd = ssd;
    cfg.ssd_grouped = best_patch_ssd_grouped();
    cfg.group_masks = layout.group_masks.data();
    cfg.group_mask_stride = std::ptrdiff_t(params.patch_size) * layout.channels;
    cfg.groups = layout.groups;
    return cfg;
  }

  // The level's starting field (the warm start's, identity or random at the coarsest level, the
  // coarser field upscaled below it) and a plain vote from it, so the first search sees a target
  // style.
  void start_level(Level& L, int l, bool coarsest) {
    const int p = params.patch_size, r = p / 2;
    if (!coarsest)
      nnf = upscale_nnf(nnf, L.tw, L.th, L.sw, L.sh, r);
    else if (nnf.empty())  // else it holds the warm start's field
      nnf = params.init == FieldInit::kIdentity
                ? identity_nnf(L.tw, L.th, L.sw, L.sh, r)
                : random_nnf(L.tw, L.th, L.sw, L.sh, r, params.seed);
    err.reset(L.tw, L.th, 1);
    if (!L.weight_maps.empty()) L.group_weights = quantize_group_weights(L.weight_maps);
    vote(source_style(L, l), nnf, err, L.active, p, VoteMode::kPlain, style);
    // A warm start runs the finest level alone, so this is its first estimate.
    if (!params.initial_nnf.empty() && params.warm_sharp_estimate > 0.0f)
      sharpen_estimate(source_style(L, l), L);
    write_style(style, layout, L.tgt, border);
  }

  // Mixes each pixel's own match's centre value into the voted estimate
  // (Params::warm_sharp_estimate).
  void sharpen_estimate(const Plane& source, const Level& L) {
    const int ns = layout.style_channels;
    Image<float> values(L.sw, L.sh, ns);
    parallel_rows(L.sh, 32, [&](int y0, int y1) {
      for_each_row(source, y0, y1, [&](int y, const float* row) {
        std::copy(row, row + std::size_t(L.sw) * ns, values.at(0, y));
      });
    });
    const float a = params.warm_sharp_estimate;  // in (0, 1] (validate())
    parallel_rows(L.th, 32, [&](int y0, int y1) {
      for (int y = y0; y < y1; ++y)
        for (int x = 0; x < L.tw; ++x) {
          if (!L.active.empty() && !L.active(x, y)) continue;
          const float* c = values.at(nnf(x, y, 0), nnf(x, y, 1));
          float* s = style.at(x, y);
          for (int k = 0; k < ns; ++k) s[k] += a * (c[k] - s[k]);
        }
    });
  }

  // The schedule's search-vote iterations at one level; `step` seeds them. `last`: the pass
  // whose final vote is the output.
  void search_and_vote(Level& L, int l, int step, const LevelSchedule& sch, int patch,
                       float uniformity, bool last) {
    const PatchMatchLevel pm = pm_level(L);
    if (err.width() != L.tw || err.height() != L.th) err.reset(L.tw, L.th, 1);
    PatchMatchConfig cfg = pm_config(patch);
    cfg.uniformity = uniformity;
    cfg.iterations = sch.patch_match_iters;
    cfg.max_search_radius = sch.max_search_radius;
    cfg.before_sweep = &poll;
    if (index != nullptr && patch == index->patch_size) cfg.coherence = &index->levels[l];
    for (int it = 0; it < sch.search_vote_iters; ++it) {
      cfg.seed = hash_key(params.seed, uint64_t(step), uint64_t(it), uint64_t(patch));
      compute_errors(pm, cfg);
      run_patch_match(pm, cfg);
      // The output (the last vote of the finest level, or of the 3x3 pass) is plain even in
      // weighted mode: the weights steer the search, but a plain average joins the output's
      // patches more smoothly. Measured with bench/eval_set.py (docs/design/engine-schedule.md):
      // mean judge style 1.022x -> 0.960x EbSynth's (jade MatCap 1.300x -> 0.997x), worst
      // joint 1.098x -> 1.076x; worse style only on the toon MatCap (1.046x -> 1.101x) and the
      // stippling (0.995x -> 1.013x).
      const bool output = last && it + 1 == sch.search_vote_iters;
      vote(source_style(L, l), nnf, err, L.active, patch,
           output ? VoteMode::kPlain : params.vote_mode, style);
      write_style(style, layout, L.tgt, border);
    }
  }
};

// The voted style, with the target mask as an alpha channel (and zero colour where it is 0)
// when there is one.
Image<float> output_image(const Image<float>& style, const std::optional<Plane>& mask, int ns,
                          int tw, int th) {
  Image<float> image(tw, th, ns + (mask ? 1 : 0));
  parallel_rows(th, 32, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < tw; ++x)
        for (int c = 0; c < ns; ++c) image(x, y, c) = style(x, y, c);
    if (!mask) return;
    const int mc = plane_channels(*mask);
    for_each_row(*mask, y0, y1, [&](int y, const float* row) {
      for (int x = 0; x < tw; ++x) {
        const float a = std::clamp(row[x * mc], 0.0f, 1.0f);
        image(x, y, ns) = a;
        if (a <= 0.0f)
          for (int c = 0; c < ns; ++c) image(x, y, c) = 0.0f;
      }
    });
  });
  return image;
}

// The final field with -1 where the target is outside its (dilated) mask.
Image<int32_t> active_nnf(const Image<int32_t>& nnf, const Image<uint8_t>& active, int tw, int th) {
  Image<int32_t> out(tw, th, 2);
  parallel_rows(th, 32, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < tw; ++x) {
        const bool act = active.empty() || active(x, y);
        out(x, y, 0) = act ? nnf(x, y, 0) : -1;
        out(x, y, 1) = act ? nnf(x, y, 1) : -1;
      }
  });
  return out;
}

// The index of the levels' source features: `given` when it was built from the same ones with
// the same patch size and k, else built coarse to fine (each level started from the coarser one's
// sets). Its seed is fixed, so one painting has one index whatever the run's seed.
std::shared_ptr<const ExemplarIndex> level_index(
    const std::vector<Level>& pyr, const Params& params,
    const std::shared_ptr<const ExemplarIndex>& given) {
  std::vector<const Image<int16_t>*> features;
  for (const Level& L : pyr) features.push_back(&L.src);
  const uint64_t digest = features_digest(features);
  if (given && given->features_digest == digest && given->patch_size == params.patch_size &&
      given->k == params.index_k && given->levels.size() == pyr.size())
    return given;
  auto index = std::make_shared<ExemplarIndex>();
  index->patch_size = params.patch_size, index->k = params.index_k;
  index->features_digest = digest;
  index->levels.resize(pyr.size());
  for (std::size_t l = pyr.size(); l-- > 0;)
    index->levels[l] = build_coherence_sets(pyr[l].src, params.patch_size, params.index_k,
                                            l + 1 < pyr.size() ? &index->levels[l + 1] : nullptr,
                                            best_patch_ssd(), hash_key(0x1de, l));
  return index;
}

}  // namespace

Result Synthesizer::run(const OutputRequest& request) {
  State& st = *state_;
  CHECK(!st.ran);  // the pyramid is consumed by a run
  st.ran = true;
  const Params& params = st.params;
  const int p = params.patch_size, levels = st.levels;
  std::vector<Level>& pyr = st.pyr;
  const std::vector<LevelSchedule>& schedule = st.schedule;

  // The coarse levels come from the finest features, built here rather than in the constructor
  // so that the caller has already freed the guide images.
  build_coarse_levels(pyr, st.style, st.sw, st.sh, st.layout, st.border);

  Solve solve{params, st.layout, st.style, st.border, best_patch_ssd(), {}, nullptr, {}, {}, {}};
  std::shared_ptr<const ExemplarIndex> index;
  if (params.index_k > 0) index = level_index(pyr, params, params.index);
  solve.index = index.get();
  solve.nnf = std::move(st.initial_nnf);
  solve.poll = [&params] {
    if (params.cancel && params.cancel()) throw Cancelled();
  };
  for (int l = levels - 1; l >= 0; --l) {
    Level& L = pyr[l];
    solve.poll();
    if (params.progress) params.progress(levels - 1 - l, levels);
    solve.start_level(L, l, l == levels - 1);
    solve.search_and_vote(L, l, levels - 1 - l, schedule[levels - 1 - l], p, params.uniformity,
                          l == 0 && !params.extra_pass_3x3);
    if (l > 0) pyr[l] = Level();  // free the coarse level
  }
  if (params.extra_pass_3x3)
    solve.search_and_vote(pyr[0], 0, levels, schedule.back(), 3, 0.0f, true);

  Result res;
  res.pyramid_levels = levels;
  res.schedule = schedule;
  res.index = std::move(index);
  const Level& F = pyr[0];
  if (request.nnf) res.nnf = active_nnf(solve.nnf, F.active, st.tw, st.th);
  if (request.error) {
    compute_errors(solve.pm_level(F), solve.pm_config(params.extra_pass_3x3 ? 3 : p));
    res.error = std::move(solve.err);
  }
  // The finest level's features go before the output is made: the run is over.
  pyr = std::vector<Level>();
  // Without a mask the voted style is the output as it is (no copy of it alongside).
  res.image = st.mask ? output_image(solve.style, st.mask, st.layout.style_channels, st.tw, st.th)
                      : std::move(solve.style);
  return res;
}

Result synthesize(const Inputs& inputs, const Params& params, const OutputRequest& request) {
  Synthesizer s(inputs, params);
  return s.run(request);
}

}  // namespace emaki::synth
