// `emaki synth`'s argument parser (see synth_args.h); EbSynth's channel rules are
// synth/ebsynth_rules.
#include "apps/emaki/synth_args.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/check.h"
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

int parse_patch_size(const std::string& opt, const std::string& v) {
  const int n = parse_int(opt, v);
  if (n < 3) throw Error(opt, fmt::format("must be >= 3 (got {})", n));
  if (n > kMaxPatchSize) throw Error(opt, fmt::format("must be <= {} (got {})", kMaxPatchSize, n));
  if (n % 2 == 0) throw Error(opt, fmt::format("must be odd (got {})", n));
  return n;
}

uint64_t parse_seed(const std::string& opt, const std::string& v) {
  try {
    std::size_t pos = 0;
    const uint64_t seed = std::stoull(v, &pos);
    if (pos != v.size()) throw std::invalid_argument(v);
    return seed;
  } catch (const std::exception&) {
    throw Error(opt, "expects a non-negative integer, got '" + echo(v) + "'");
  }
}

// Walks the argument list; args[i] is the option being read.
struct ArgCursor {
  const std::vector<std::string>& args;
  std::size_t i = 0;
  // -weight applies to this: the -style or -guide just before it.
  float* last_weight = nullptr;
  // --guide-weight-map's (guide number, file), assigned once every -guide is known.
  std::vector<std::pair<int, std::string>> weight_maps = {};

  const std::string& option() const { return args[i]; }
  // The value after the option.
  const std::string& value() {
    if (i + 1 >= args.size()) throw Error(args[i], "is missing its value");
    return args[++i];
  }
};

void parse_guide(ArgCursor& in, SynthArgs& r) {
  const std::vector<std::string>& a = in.args;
  const std::size_t i = in.i;
  if (i + 2 >= a.size() || a[i + 1].rfind("-", 0) == 0 || a[i + 2].rfind("-", 0) == 0)
    throw Error("-guide", "needs two paths: the source guide and the target guide");
  if (r.guides.size() >= kMaxGuides)
    throw Error("-guide", fmt::format("at most {} guide pairs", kMaxGuides));
  // guides is reserved (parse_synth_args), so last_weight stays valid as pairs are added.
  r.guides.push_back({a[i + 1], a[i + 2]});
  in.i += 2;
  in.last_weight = &r.guides.back().weight;
}

void parse_weight(ArgCursor& in) {
  const float w = parse_float("-weight", in.value());
  if (!in.last_weight) throw Error("-weight", "must follow a -style or -guide option");
  if (w > 1e6f) throw Error("-weight", "must be <= 1e6");
  if (w < 0.0f) throw Error("-weight", "must be >= 0");
  *in.last_weight = w;
}

// EbSynth's options (single dash); false when the current argument is not one of them.
bool parse_ebsynth_option(ArgCursor& in, SynthArgs& r) {
  const std::string& a = in.option();
  synth::Params& params = r.params;
  if (a == "-style") {
    r.style_path = in.value();
    in.last_weight = &r.style_weight;
  } else if (a == "-guide") {
    parse_guide(in, r);
  } else if (a == "-weight") {
    parse_weight(in);
  } else if (a == "-output") {
    r.output = in.value();
  } else if (a == "-uniformity") {
    params.uniformity = parse_float(a, in.value());
    if (params.uniformity < 0.0f) throw Error(a, "must be >= 0");
  } else if (a == "-patchsize") {
    params.patch_size = parse_patch_size(a, in.value());
  } else if (a == "-pyramidlevels") {
    params.pyramid_levels = parse_int_in(a, in.value(), 1, kMaxPyramidLevels);
  } else if (a == "-searchvoteiters") {
    params.search_vote_iters = parse_int_in(a, in.value(), 0, kMaxIterations);
  } else if (a == "-patchmatchiters") {
    params.patch_match_iters = parse_int_in(a, in.value(), 0, kMaxIterations);
  } else if (a == "-stopthreshold") {
    if (parse_int(a, in.value()) < 0) throw Error(a, "must be >= 0");
  } else if (a == "-extrapass3x3") {
    params.extra_pass_3x3 = true;
  } else if (a == "-backend") {
    const std::string& b = in.value();
    if (b != "cpu" && b != "cuda" && b != "auto")
      throw Error(a, "must be cpu, cuda or auto (got '" + echo(b) + "')");
  } else {
    return false;
  }
  return true;
}

// --guide-weight-map N FILE: the N-th -guide (counting from 1, in command-line order, wherever
// the option stands) gets a per-pixel weight map. Kept until every -guide is known.
void parse_guide_weight_map(ArgCursor& in) {
  const std::string opt = in.option();
  const std::size_t i = in.i;
  const std::vector<std::string>& a = in.args;
  if (i + 2 >= a.size() || a[i + 2].rfind("-", 0) == 0)
    throw Error(opt, "needs a guide number and a file: --guide-weight-map N FILE");
  const int n = parse_int_in(opt, a[i + 1], 1, kMaxGuides);
  in.weight_maps.push_back({n, a[i + 2]});
  in.i += 2;
}

// emaki's own options (double dash); false when the current argument is not one of them.
bool parse_emaki_option(ArgCursor& in, SynthArgs& r) {
  const std::string& a = in.option();
  if (a == "--seed") {
    r.params.seed = parse_seed(a, in.value());
  } else if (a == "--threads") {
    r.threads = parse_int_in(a, in.value(), 0, kMaxThreads);
  } else if (a == "--mask") {
    r.mask_path = in.value();
  } else if (a == "--vote") {
    const std::string& v = in.value();
    if (v == "plain")
      r.params.vote_mode = synth::VoteMode::kPlain;
    else if (v == "weighted")
      r.params.vote_mode = synth::VoteMode::kWeighted;
    else
      throw Error(a, "must be plain or weighted (got '" + echo(v) + "')");
  } else if (a == "--nnf-out") {
    r.nnf_out = in.value();
  } else if (a == "--error-out") {
    r.error_out = in.value();
  } else if (a == "--output-depth") {
    r.depth = in.value();
    if (r.depth != "8" && r.depth != "16" && r.depth != "float")
      throw Error(a, "must be 8, 16 or float (got '" + echo(r.depth) + "')");
  } else if (a == "--guide-weight-map") {
    parse_guide_weight_map(in);
  } else if (a == "--index") {
    r.params.index_k = parse_int_in(a, in.value(), 0, 16);
  } else if (a == "--index-cache") {
    r.index_cache = in.value();
  } else if (a == "--quiet") {
    r.quiet = true;
  } else {
    return false;
  }
  return true;
}

}  // namespace

SynthArgs parse_synth_args(const std::vector<std::string>& args) {
  SynthArgs r;
  r.guides.reserve(kMaxGuides);
  ArgCursor in{args};
  for (; in.i < args.size(); ++in.i) {
    const std::string& a = in.option();
    if (a == "--help" || a == "-help" || a == "-h") {
      r.help = true;
      return r;
    }
    if (!parse_ebsynth_option(in, r) && !parse_emaki_option(in, r))
      throw Error(echo(a), "unknown option (see 'emaki synth --help')");
  }
  if (r.style_path.empty()) throw Error("-style", "is required (the style exemplar)");
  if (r.guides.empty()) throw Error("-guide", "at least one guide pair is required");
  if (!r.index_cache.empty() && r.params.index_k == 0)
    throw Error("--index-cache", "needs --index K (K > 0)");
  for (const auto& [n, file] : in.weight_maps) {
    if (n > int(r.guides.size()))
      throw Error("--guide-weight-map",
                  fmt::format("guide {} does not exist (there {} {})", n,
                              r.guides.size() == 1 ? "is" : "are", r.guides.size()));
    std::string& map = r.guides[n - 1].weight_map;
    if (!map.empty())
      throw Error("--guide-weight-map", fmt::format("guide {} has two weight maps", n));
    map = file;
  }
  return r;
}

}  // namespace emaki::app
