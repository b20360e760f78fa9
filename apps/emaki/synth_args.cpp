// `emaki synth`'s argument parser (see synth_args.h).
#include "apps/emaki/synth_args.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/error.h"
#include "core/limits.h"

namespace emaki::app {
namespace {

int parse_int(const std::string& opt, const std::string& v) {
  try {
    std::size_t pos = 0;
    const int n = std::stoi(v, &pos);
    if (pos != v.size()) throw std::invalid_argument(v);
    return n;
  } catch (const std::exception&) {
    throw Error(opt, "expects an integer, got '" + echo(v) + "'");
  }
}

float parse_float(const std::string& opt, const std::string& v) {
  try {
    std::size_t pos = 0;
    const float f = std::stof(v, &pos);
    if (pos != v.size() || !std::isfinite(f)) throw std::invalid_argument(v);
    return f;
  } catch (const std::exception&) {
    throw Error(opt, "expects a number, got '" + echo(v) + "'");
  }
}

// An integer option within [lo, hi], named in the error.
int parse_int_in(const std::string& opt, const std::string& v, int lo, int hi) {
  const int n = parse_int(opt, v);
  if (n < lo || n > hi) throw Error(opt, fmt::format("must be in [{}, {}] (got {})", lo, hi, n));
  return n;
}

}  // namespace

SynthArgs parse_synth_args(const std::vector<std::string>& args) {
  SynthArgs r;
  std::string& style_path = r.style_path;
  std::string& output = r.output;
  std::string& mask_path = r.mask_path;
  std::string& nnf_out = r.nnf_out;
  std::string& error_out = r.error_out;
  std::string& depth = r.depth;
  float& style_weight = r.style_weight;
  std::vector<SynthGuideArg>& guides = r.guides;
  synth::Params& params = r.params;
  int& threads = r.threads;
  bool& quiet = r.quiet;
  float* last_weight = nullptr;
  // guides is reserved so that last_weight stays valid as pairs are added.
  guides.reserve(kMaxGuides);

  auto need = [&](std::size_t& i, const std::string& opt) -> const std::string& {
    if (i + 1 >= args.size()) throw Error(opt, "is missing its value");
    return args[++i];
  };
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--help" || a == "-help" || a == "-h") {
      r.help = true;
      return r;
    } else if (a == "-style") {
      style_path = need(i, a);
      last_weight = &style_weight;
    } else if (a == "-guide") {
      SynthGuideArg g;
      if (i + 2 >= args.size() || args[i + 1].rfind("-", 0) == 0 || args[i + 2].rfind("-", 0) == 0)
        throw Error("-guide", "needs two paths: the source guide and the target guide");
      g.source = args[++i];
      g.target = args[++i];
      if (guides.size() >= kMaxGuides)
        throw Error("-guide", fmt::format("at most {} guide pairs", kMaxGuides));
      guides.push_back(g);
      last_weight = &guides.back().weight;
    } else if (a == "-weight") {
      const float w = parse_float(a, need(i, a));
      if (!last_weight) throw Error("-weight", "must follow a -style or -guide option");
      if (w > kMaxWeight) throw Error("-weight", "must be <= 1e6");
      if (w < 0.0f) throw Error("-weight", "must be >= 0");
      *last_weight = w;
    } else if (a == "-output") {
      output = need(i, a);
    } else if (a == "-uniformity") {
      params.uniformity = parse_float(a, need(i, a));
      if (params.uniformity < 0.0f) throw Error(a, "must be >= 0");
    } else if (a == "-patchsize") {
      params.patch_size = parse_int(a, need(i, a));
      if (params.patch_size < 3)
        throw Error(a, fmt::format("must be >= 3 (got {})", params.patch_size));
      if (params.patch_size > kMaxPatchSize)
        throw Error(a, fmt::format("must be <= {} (got {})", kMaxPatchSize, params.patch_size));
      if (params.patch_size % 2 == 0)
        throw Error(a, fmt::format("must be odd (got {})", params.patch_size));
    } else if (a == "-pyramidlevels") {
      params.pyramid_levels = parse_int_in(a, need(i, a), 1, kMaxPyramidLevels);
    } else if (a == "-searchvoteiters") {
      params.search_vote_iters = parse_int_in(a, need(i, a), 0, kMaxIterations);
    } else if (a == "-patchmatchiters") {
      params.patch_match_iters = parse_int_in(a, need(i, a), 0, kMaxIterations);
    } else if (a == "-stopthreshold") {
      if (parse_int(a, need(i, a)) < 0) throw Error(a, "must be >= 0");
    } else if (a == "-extrapass3x3") {
      params.extra_pass_3x3 = true;
    } else if (a == "-backend") {
      const std::string b = need(i, a);
      if (b != "cpu" && b != "cuda" && b != "auto")
        throw Error(a, "must be cpu, cuda or auto (got '" + echo(b) + "')");
    } else if (a == "--seed") {
      const std::string v = need(i, a);
      try {
        std::size_t pos = 0;
        params.seed = std::stoull(v, &pos);
        if (pos != v.size()) throw std::invalid_argument(v);
      } catch (const std::exception&) {
        throw Error(a, "expects a non-negative integer, got '" + echo(v) + "'");
      }
    } else if (a == "--threads") {
      threads = parse_int_in(a, need(i, a), 0, kMaxThreads);
    } else if (a == "--mask") {
      mask_path = need(i, a);
    } else if (a == "--vote") {
      const std::string v = need(i, a);
      if (v == "plain")
        params.vote_mode = synth::VoteMode::kPlain;
      else if (v == "weighted")
        params.vote_mode = synth::VoteMode::kWeighted;
      else
        throw Error(a, "must be plain or weighted (got '" + echo(v) + "')");
    } else if (a == "--nnf-out") {
      nnf_out = need(i, a);
    } else if (a == "--error-out") {
      error_out = need(i, a);
    } else if (a == "--output-depth") {
      depth = need(i, a);
      if (depth != "8" && depth != "16" && depth != "float")
        throw Error(a, "must be 8, 16 or float (got '" + echo(depth) + "')");
    } else if (a == "--quiet") {
      quiet = true;
    } else {
      throw Error(echo(a), "unknown option (see 'emaki synth --help')");
    }
  }
  if (style_path.empty()) throw Error("-style", "is required (the style exemplar)");
  if (guides.empty()) throw Error("-guide", "at least one guide pair is required");

  return r;
}

}  // namespace emaki::app
