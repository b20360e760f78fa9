// emaki.synthesize: the engine (synth/) over numpy arrays, through the same rules as
// `emaki synth` (synth/ebsynth_rules.h), with the GIL released while it runs.
#include <fmt/format.h>
#include <pybind11/stl.h>

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "core/limits.h"
#include "core/parallel.h"
#include "python/arrays.h"
#include "python/bindings.h"
#include "python/errors.h"
#include "synth/ebsynth_rules.h"
#include "synth/synthesizer.h"

namespace emaki::python {
namespace {

constexpr const char* kDoc =
    R"(synthesize(style, guides, mask=None, *, style_weight=None, uniformity=3500.0, patch_size=5, pyramid_levels=None, search_vote_iters=None, patch_match_iters=None, extra_pass_3x3=False, vote='weighted', seed=1, threads=0, nnf=False, error=False, dtype=None, progress=None)
--

Guided patch-based synthesis (A : A' :: B : B'), as `emaki synth`.

Stylizes the target so that it relates to its guides as the style exemplar relates to its
own. Same defaults and, on the same data, the same result bit for bit as `emaki synth`
(EbSynth's command line); the result does not depend on `threads`.

Arrays are uint8, uint16 (both meaning [0, 1]) or float32 (taken as they are), HxW or HxWxC,
read in place when their layout allows (C-contiguous, or rows at any stride): no copy. The
GIL is released while the engine runs; Ctrl-C stops it within one PatchMatch sweep
(KeyboardInterrupt). As in EbSynth, an RGB image whose channels are equal counts as one
channel, and an alpha channel that is opaque everywhere is dropped.

Args:
    style: A', the style exemplar, 1-4 channels that count.
    guides: a list of (source, target) or (source, target, weight): A_k with the style's
        size, B_k with the output's, 1-4 channels each (a gray one is spread over RGB when
        its partner is in colour). weight >= 0 (at most 1e6), spread over the guide's
        channels; None (default): 1 / number of guides. 1 to 64 pairs.
    mask: optional target mask, HxW(xC), the target's size; first channel > 0 is inside.
        Outside pixels are not synthesized and come out transparent: the result gets an
        alpha channel.
    style_weight: weight of the style channels, [0, 1e6]; None (default): 1.
    uniformity: EbSynth's uniformity weight, >= 0 (500-15000 sensible; 0 disables it).
        Default 3500.
    patch_size: odd, [3, 65]. Default 5.
    pyramid_levels: [1, 32]; None (default): as many as fit.
    search_vote_iters: search-vote iterations at every level, [0, 1000]; None (default):
        emaki's schedule (6 at coarse levels; 2, 2 at the two finest).
    patch_match_iters: PatchMatch iterations per search-vote iteration, [0, 1000]; None
        (default): emaki's schedule (4 at coarse levels; 3, 2 at the two finest).
    extra_pass_3x3: a final polishing pass with 3x3 patches. Default False.
    vote: 'weighted' (default) or 'plain'.
    seed: random seed, [0, 2**64 - 1]. Default 1.
    threads: worker threads, [0, 1024]; 0 (default): all cores.
    nnf: also return the nearest-neighbour field, int32 HxWx2 (x, y of the source patch
        centre; -1 outside the mask). Default False.
    error: also return the per-pixel patch error, float32 HxW (EbSynth units). Default False.
    dtype: the result's dtype, uint8, uint16 or float32 (integers: clamped to [0, 1] and
        rounded, as `emaki synth` writes PNG files); None (default): the style's dtype.
    progress: optional callable(p), called with the GIL held as each pyramid level starts,
        p = {'level': 0.., 'levels': n} (one dict, as Shot.run's progress gets); an exception
        it raises stops the synthesis and propagates.

Returns:
    B', HxWxC (HxW for an HxW style without a mask): the style's channels that count, given
    back as RGB when the style was an RGB(A) image whose channels are equal (as `emaki
    synth` writes it), plus alpha with a mask. With nnf and/or error: a tuple (B', nnf),
    (B', error) or (B', nnf, error).

Raises:
    emaki.InputError: (also a ValueError) a wrong dtype, shape or size, a non-finite value, a
        parameter out of range; `subject` names the argument ('style', 'guides[1][0]',
        'mask', 'patch_size', ...).
)";

struct GuideArrays {
  ArrayPlane source, target;
  float weight = -1.0f;
};

float checked_weight(std::optional<float> w, const std::string& name) {
  if (!w) return -1.0f;
  if (!(std::isfinite(*w) && *w >= 0.0f && *w <= synth::kMaxWeight))
    raise_input_error(name, fmt::format("must be a number in [0, 1e6], got {}", *w));
  return *w;
}

int checked_int(std::optional<int> v, const std::string& name, int lo, int hi) {
  if (!v) return -1;
  if (*v < lo || *v > hi)
    raise_input_error(name, fmt::format("must be in [{}, {}], got {}", lo, hi, *v));
  return *v;
}

std::vector<GuideArrays> guide_arrays(const py::sequence& guides) {
  if (py::len(guides) == 0) raise_input_error("guides", "at least one guide pair is needed");
  if (py::len(guides) > std::size_t(synth::kMaxGuides))
    raise_input_error("guides", fmt::format("at most {} guide pairs", synth::kMaxGuides));
  std::vector<GuideArrays> out;
  for (std::size_t k = 0; k < py::len(guides); ++k) {
    const std::string name = fmt::format("guides[{}]", k);
    const py::object g = guides[k];
    if (!py::isinstance<py::sequence>(g) || py::isinstance<py::str>(g) ||
        (py::len(g) != 2 && py::len(g) != 3))
      raise_input_error(name, "expects (source, target) or (source, target, weight)");
    const py::sequence pair = g;
    std::optional<float> w;
    if (py::len(pair) == 3 && !pair[2].is_none()) {
      try {
        w = pair[2].cast<float>();  // any real number, numpy scalars included
      } catch (const py::cast_error&) {
        raise_input_error(name + "[2]", "the weight must be a number or None");
      }
    }
    out.push_back({inspect_array(pair[0], name + "[0]"), inspect_array(pair[1], name + "[1]"),
                   checked_weight(w, name + "[2]")});
  }
  return out;
}

// Sizes first, then the memory any layout copy needs, then the copies: a bad argument is refused
// before a large copy (a zero-stride view of gigabytes is a few bytes in Python).
void copy_layouts_after_checks(ArrayPlane& style, std::vector<GuideArrays>& guides,
                               std::optional<ArrayPlane>& mask) {
  auto size = [](const ArrayPlane& a) { return synth::NamedSize{a.name, a.width, a.height}; };
  std::vector<std::pair<synth::NamedSize, synth::NamedSize>> sizes;
  std::vector<const ArrayPlane*> all{&style};
  for (const GuideArrays& g : guides) {
    sizes.emplace_back(size(g.source), size(g.target));
    all.insert(all.end(), {&g.source, &g.target});
  }
  if (mask) all.push_back(&*mask);
  translating(ErrorKind::kInput, {}, [&] { synth::check_guide_sizes(size(style), sizes); });
  check_copy_memory(all);
  copy_layout(style);
  for (GuideArrays& g : guides) copy_layout(g.source), copy_layout(g.target);
  if (mask) copy_layout(*mask);
}

uint64_t checked_seed(const py::object& seed) {
  // Any integer, numpy's included (__index__); not a float.
  const py::object index = py::reinterpret_steal<py::object>(PyNumber_Index(seed.ptr()));
  const unsigned long long v = index ? PyLong_AsUnsignedLongLong(index.ptr()) : 0;
  if (PyErr_Occurred()) {
    PyErr_Clear();
    raise_input_error("seed", "must be an integer in [0, 2**64 - 1]");
  }
  return v;
}

// Runs the rules and the engine with the GIL released; Ctrl-C and `progress` come in through
// the engine's hooks with the GIL taken back for a moment.
synth::Result run_engine(const ArrayPlane& style, const std::vector<GuideArrays>& guides,
                         const std::optional<ArrayPlane>& mask, synth::Params params,
                         const synth::OutputRequest& request, int threads,
                         const py::object& progress, int& style_channels) {
  PendingError pending;
  params.cancel = [&pending] {
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() == 0) return false;
    pending.fetch();
    return true;
  };
  if (!progress.is_none())
    params.progress = [&pending, &progress](int level, int levels) {
      py::gil_scoped_acquire gil;
      py::dict p;
      p["level"] = level;
      p["levels"] = levels;
      PyObject* returned = PyObject_CallFunctionObjArgs(progress.ptr(), p.ptr(), nullptr);
      if (returned == nullptr) {
        pending.fetch();
        throw synth::Cancelled();
      }
      Py_DECREF(returned);
    };
  std::vector<synth::NamedGuide> named;
  for (std::size_t k = 0; k < guides.size(); ++k)
    named.push_back({{guides[k].source.plane, fmt::format("guides[{}][0]", k)},
                     {guides[k].target.plane, fmt::format("guides[{}][1]", k)},
                     guides[k].weight});
  std::optional<synth::NamedPlane> named_mask;
  if (mask) named_mask = synth::NamedPlane{mask->plane, "mask"};

  std::optional<py::gil_scoped_release> released(std::in_place);
  try {
    const ScopedThreadCount thread_count(threads);
    synth::RuledInputs ruled =
        synth::apply_ebsynth_rules({style.plane, "style"}, named, named_mask);
    style_channels = synth::plane_channels(ruled.inputs.style);
    synth::Synthesizer synthesizer(ruled.inputs, params);
    ruled.release_guides();
    return synthesizer.run(request);
  } catch (const synth::Cancelled&) {
    released.reset();
    pending.raise();
  } catch (const Error& e) {
    released.reset();
    raise_error(e, ErrorKind::kInput);
  }
}

py::object synthesize(const py::handle& style_obj, const py::sequence& guides_obj,
                      const py::handle& mask_obj, std::optional<float> style_weight,
                      float uniformity, int patch_size, std::optional<int> pyramid_levels,
                      std::optional<int> search_vote_iters, std::optional<int> patch_match_iters,
                      bool extra_pass_3x3, const std::string& vote, const py::object& seed,
                      int threads, bool nnf, bool error, const py::handle& dtype,
                      const py::object& progress) {
  synth::Params params;
  params.style_weight = checked_weight(style_weight, "style_weight");
  params.uniformity = uniformity;
  if (patch_size > synth::kMaxPatchSize)
    raise_input_error("patch_size",
                      fmt::format("must be <= {} (got {})", synth::kMaxPatchSize, patch_size));
  params.patch_size = patch_size;
  params.pyramid_levels =
      checked_int(pyramid_levels, "pyramid_levels", 1, synth::kMaxPyramidLevels);
  params.search_vote_iters =
      checked_int(search_vote_iters, "search_vote_iters", 0, synth::kMaxIterations);
  params.patch_match_iters =
      checked_int(patch_match_iters, "patch_match_iters", 0, synth::kMaxIterations);
  params.extra_pass_3x3 = extra_pass_3x3;
  if (vote != "weighted" && vote != "plain")
    raise_input_error("vote", fmt::format("must be 'weighted' or 'plain', got '{}'", echo(vote)));
  params.vote_mode = vote == "plain" ? synth::VoteMode::kPlain : synth::VoteMode::kWeighted;
  params.seed = checked_seed(seed);
  checked_int(threads, "threads", 0, synth::kMaxThreads);
  if (!progress.is_none() && !PyCallable_Check(progress.ptr()))
    raise_input_error("progress", "must be callable({'level', 'levels'}) or None");

  ArrayPlane style = inspect_array(style_obj, "style");
  std::vector<GuideArrays> guides = guide_arrays(guides_obj);
  std::optional<ArrayPlane> mask;
  if (!mask_obj.is_none()) mask = inspect_array(mask_obj, "mask");
  copy_layouts_after_checks(style, guides, mask);
  const SampleType out_type = sample_type(dtype, "dtype", style.type);
  synth::OutputRequest request;
  request.nnf = nnf;
  request.error = error;

  int ns = 0;
  synth::Result res = run_engine(style, guides, mask, params, request, threads, progress, ns);
  // As `emaki synth` writes it: a one-channel style that came as RGB(A) goes back as RGB.
  if (ns == 1 && style.channels() >= 3) res.image = synth::gray_to_rgb(res.image);
  py::array image = to_array(res.image, out_type, style.ndim == 2);
  if (!nnf && !error) return image;
  py::list out;
  out.append(image);
  if (nnf) out.append(to_array(res.nnf));
  if (error) out.append(to_array(res.error, SampleType::kF32, true));
  return py::tuple(out);
}

}  // namespace

void bind_synth(py::module_& m) {
  m.def("synthesize", &synthesize, kDoc, py::arg("style"), py::arg("guides"),
        py::arg("mask") = py::none(), py::kw_only(), py::arg("style_weight") = py::none(),
        py::arg("uniformity") = synth::Params().uniformity,
        py::arg("patch_size") = synth::Params().patch_size, py::arg("pyramid_levels") = py::none(),
        py::arg("search_vote_iters") = py::none(), py::arg("patch_match_iters") = py::none(),
        py::arg("extra_pass_3x3") = false, py::arg("vote") = "weighted", py::arg("seed") = 1,
        py::arg("threads") = 0, py::arg("nnf") = false, py::arg("error") = false,
        py::arg("dtype") = py::none(), py::arg("progress") = py::none());
}

}  // namespace emaki::python
