// emaki.Shot: the shot API (src/shot/api.h, src/shot/plan.h) from Python — the same calls the
// command line and the farm submitter make, not a copy of them.
#include <fmt/format.h>
#include <pybind11/eval.h>
#include <pybind11/functional.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"
#include "python/bindings.h"
#include "python/errors.h"
#include "shot/api.h"
#include "shot/plan.h"

namespace emaki::python {
namespace {

// Shot errors name shot-file keys (their own spelling); a Request's neutral fields become the
// keyword arguments of the call.
constexpr std::initializer_list<FieldName> kShotArgs = {
    {"frames", "frames"}, {"layers", "layers"},   {"layer", "layer"},
    {"chunk", "chunk"},   {"threads", "threads"}, {"max_memory", "max_memory_mb"}};

// Thrown out of the pipeline's progress hook to stop a run: Ctrl-C, or the callback raised.
struct Stop {};

class PyShot {
 public:
  explicit PyShot(pipeline::Shot shot) : shot_(std::move(shot)) {}

  static PyShot load(const std::filesystem::path& path) {
    return PyShot(translating(ErrorKind::kFile, {}, [&] { return shot::open(path.string()); }));
  }
  static PyShot from_toml(const std::string& text, const std::string& path) {
    return PyShot(translating(ErrorKind::kInput, {}, [&] { return shot::open_text(text, path); }));
  }

  const pipeline::Shot& shot() const { return shot_; }

  std::string repr() const {
    std::string layers;
    for (const auto& l : shot_.layers) layers += (layers.empty() ? "" : ", ") + l.name;
    return fmt::format("<emaki.Shot {} frames {}-{} {}x{} layers [{}]>",
                       std::string(py::repr(py::str(shot_.path))), shot_.source.first_frame,
                       shot_.source.last_frame, shot_.source.width, shot_.source.height, layers);
  }

  py::dict run(const py::object& frames, const py::object& layers, bool force, bool previews,
               const py::object& threads, const py::object& progress,
               const py::object& max_memory_mb, bool one_layer_at_a_time) {
    shot::Request r = request(frames, threads, max_memory_mb);
    r.layers = layer_names(layers);
    r.force = force;
    r.previews = previews;
    r.concurrent_layers = !one_layer_at_a_time;  // as `emaki run` does
    PendingError pending;
    bool stopped = false;
    // The GIL is taken back for a moment at each layer-frame: Ctrl-C and the callback.
    r.progress = [&](const pipeline::Progress& p) {
      py::gil_scoped_acquire gil;
      if (PyErr_CheckSignals() != 0) {
        pending.fetch();
        stopped = true;
        throw Stop();
      }
      if (progress.is_none()) return;
      py::dict d;
      d["frame"] = p.frame;
      d["layer"] = p.layer.empty() ? py::none() : py::object(py::str(p.layer));
      d["done"] = p.done;
      d["total"] = p.total;
      d["elapsed"] = p.elapsed_s;
      if (PyObject_CallFunctionObjArgs(progress.ptr(), d.ptr(), nullptr) == nullptr) {
        pending.fetch();
        stopped = true;
        throw Stop();
      }
    };
    std::optional<shot::RunResult> res;
    try {
      res = without_gil(ErrorKind::kInput, kShotArgs, [&] { return shot::run(shot_, r); });
    } catch (const Stop&) {
    }
    if (stopped) pending.raise();
    py::dict out;
    out["synthesized"] = res->report.synthesized;
    out["reused"] = res->report.reused;
    out["composited"] = res->report.composited;
    out["frames"] = py::make_tuple(res->report.first_frame, res->report.last_frame);
    out["previews"] =
        std::vector<std::filesystem::path>(res->previews.begin(), res->previews.end());
    return out;
  }

  int composite(const py::object& frames, bool previews, const py::object& threads,
                const py::object& max_memory_mb) {
    shot::Request r = request(frames, threads, max_memory_mb);
    r.previews = previews;
    return without_gil(ErrorKind::kInput, kShotArgs,
                       [&] { return shot::composite(shot_, r).composited; });
  }

  py::dict flicker(const std::string& layer, const py::object& frames, bool maps) {
    shot::Request r = request(frames, py::none());
    r.qa_maps = maps;
    const shot::FlickerResult f =
        without_gil(ErrorKind::kInput, kShotArgs, [&] { return shot::flicker(shot_, layer, r); });
    py::list per_frame;
    for (const pipeline::FrameFlicker& ff : f.frames)
      per_frame.append(py::dict(py::arg("frame") = ff.frame, py::arg("all") = ff.all.mean(),
                                py::arg("objects") = ff.objects.mean(),
                                py::arg("ground") = ff.ground.mean()));
    return py::dict(py::arg("layer") = layer,
                    py::arg("frames") = py::make_tuple(f.first_frame, f.last_frame),
                    py::arg("mean") = f.mean.all.mean(), py::arg("objects") = f.mean.objects.mean(),
                    py::arg("ground") = f.mean.ground.mean(), py::arg("per_frame") = per_frame);
  }

  py::object plan(int chunk, int threads, const std::string& emaki) {
    shot::PlanOptions o;
    o.chunk = chunk;
    o.threads = threads;
    o.emaki = emaki;
    const std::string json = translating(ErrorKind::kInput, kShotArgs, [&] {
      return shot::plan_json(shot::plan({{"", shot_.path, shot_}}, o));
    });
    return py::module_::import("json").attr("loads")(json);
  }

 private:
  // `value` as T, or emaki.InputError naming `argument` and what it expected (never pybind11's
  // "Unable to cast" RuntimeError). A bool is not taken for a number, nor a str for a list.
  template <typename T>
  static T cast_argument(const py::object& value, const char* argument, const char* expected) {
    const bool refused = py::isinstance<py::bool_>(value) || py::isinstance<py::str>(value);
    if (!refused) {
      try {
        return value.cast<T>();
      } catch (const py::cast_error&) {
      }
    }
    raise_input_error(argument, fmt::format("expected {}, got {} {}", expected,
                                            std::string(py::str(value.get_type().attr("__name__"))),
                                            std::string(py::repr(value))));
  }

  static std::vector<std::string> layer_names(const py::object& layers) {
    if (layers.is_none()) return {};
    return cast_argument<std::vector<std::string>>(layers, "layers",
                                                   "a list of layer names (layers=['base'])");
  }

  shot::Request request(const py::object& frames, const py::object& threads,
                        const py::object& max_memory_mb = py::none()) const {
    shot::Request r;
    constexpr const char* kFrames = "a frame or (first, last), e.g. frames=(0, 3)";
    if (py::isinstance<py::int_>(frames) && !py::isinstance<py::bool_>(frames)) {
      r.first_frame = r.last_frame = frames.cast<int>();
    } else if (!frames.is_none()) {
      const auto ab = cast_argument<std::vector<int>>(frames, "frames", kFrames);
      if (ab.size() != 2) raise_input_error("frames", "expected a frame or (first, last)");
      r.first_frame = ab[0], r.last_frame = ab[1];
    }
    if (r.first_frame < -1 || r.last_frame < -1) raise_input_error("frames", "frames must be >= 0");
    if (!threads.is_none()) {
      r.threads = cast_argument<int>(threads, "threads", "an int or None");
      if (r.threads < 0 || r.threads > 1024) raise_input_error("threads", "must be in [0, 1024]");
    }
    if (!max_memory_mb.is_none()) {
      r.max_memory_mb = cast_argument<int64_t>(max_memory_mb, "max_memory_mb", "an int or None");
      if (r.max_memory_mb < 1 || r.max_memory_mb > (int64_t(1) << 40))
        raise_input_error("max_memory_mb", "must be in [1, 2**40] (MB) or None");
    }
    return r;
  }

  pipeline::Shot shot_;
};

constexpr const char* kShotDoc = R"(A shot: its file's settings, checked (docs/shot_file.md).

Shot.load(path)            the shot file (TOML); relative paths are the file's folder's
Shot.from_dict(d, path)    the same settings as nested dicts (keys as in the file)
shot.run(...)              synthesize, composite and write (as `emaki run`)
shot.composite(...)        re-colour finished layers (as `emaki composite`)
shot.flicker(layer, ...)   temporal error of a finished layer (as `emaki qa flicker`)
shot.plan(...)             the render-farm task graph (as `emaki plan --json`)

Errors: emaki.InputError whose `subject` is the shot file's key ("layers.base.opacity") or the
argument ("frames", "layers", "layer"); emaki.FileError for a file that cannot be read.)";

// Shot.from_dict: the dict written as the TOML the shot file would hold, then parsed by the same
// parser (so a bad key is named by its key path exactly as in a file).
constexpr const char* kFromDict = R"(
import json as _json
import os as _os
import re as _re


def _toml_key(k):
    if not isinstance(k, str):
        raise TypeError(f"shot keys must be strings, got {k!r}")
    return k if _re.fullmatch(r"[A-Za-z0-9_-]+", k) else _json.dumps(k)


def _toml_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return repr(v)  # inf and nan are TOML too (the parser refuses them with the key)
    if isinstance(v, str):
        return _json.dumps(v)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{_toml_key(k)} = {_toml_value(x)}" for k, x in v.items()) + "}"
    if hasattr(v, "item"):  # a numpy scalar
        return _toml_value(v.item())
    raise TypeError(f"a shot value must be a bool, number, string, list or dict, got {type(v).__name__}")


def _toml_table(d, prefix, lines):
    scalars = [(k, v) for k, v in d.items() if not isinstance(v, dict)]
    tables = [(k, v) for k, v in d.items() if isinstance(v, dict)]
    if prefix and (scalars or not tables):
        lines.append(f"[{prefix}]")
    for k, v in scalars:
        lines.append(f"{_toml_key(k)} = {_toml_value(v)}")
    for k, v in tables:
        _toml_table(v, f"{prefix}.{_toml_key(k)}" if prefix else _toml_key(k), lines)


def from_dict(d, path="shot.toml"):
    """from_dict(d: dict, path: str | os.PathLike = "shot.toml") -> Shot

    A shot from nested dicts with the shot file's keys (docs/shot_file.md), e.g.
    {"source": {"scene": "Fox.glb", "frames": [0, 47], "size": [960, 540]}, ...}. Relative
    paths are resolved against path's folder (the current folder by default); errors name the
    key path as for a file."""
    if not isinstance(d, dict):
        raise TypeError("from_dict expects a dict")
    lines = []
    _toml_table(d, "", lines)
    return Shot._from_toml("\n".join(lines) + "\n", _os.fspath(path))
)";

}  // namespace

void bind_shot(py::module_& m) {
  py::class_<PyShot>(m, "Shot", kShotDoc)
      .def(py::init(&PyShot::load), py::arg("path"),
           "__init__(self, path)\n--\n\nShot(path), path a str or os.PathLike: the same as "
           "Shot.load(path).")
      .def_static(
          "load", &PyShot::load, py::arg("path"),
          "load(path)\n--\n\nReads and checks a shot file (a str or os.PathLike) and returns "
          "its Shot; writes nothing.")
      .def("__repr__", &PyShot::repr)
      .def_static("_from_toml", &PyShot::from_toml, py::arg("text"), py::arg("path"))
      .def_property_readonly("path",
                             [](const PyShot& s) { return std::filesystem::path(s.shot().path); })
      .def_property_readonly("frames",
                             [](const PyShot& s) {
                               return py::make_tuple(s.shot().source.first_frame,
                                                     s.shot().source.last_frame);
                             })
      .def_property_readonly("size",
                             [](const PyShot& s) {
                               return py::make_tuple(s.shot().source.width, s.shot().source.height);
                             })
      .def_property_readonly("layers",
                             [](const PyShot& s) {
                               std::vector<std::string> names;
                               for (const auto& l : s.shot().layers) names.push_back(l.name);
                               return names;
                             })
      .def_property_readonly(
          "output_folder",
          [](const PyShot& s) { return std::filesystem::path(s.shot().outputs.folder); })
      .def("run", &PyShot::run, py::kw_only(), py::arg("frames") = py::none(),
           py::arg("layers") = py::none(), py::arg("force") = false, py::arg("previews") = true,
           py::arg("threads") = py::none(), py::arg("progress") = py::none(),
           py::arg("max_memory_mb") = py::none(), py::arg("one_layer_at_a_time") = false,
           "run(self, *, frames=None, layers=None, force=False, previews=True, threads=None, "
           "progress=None, max_memory_mb=None, one_layer_at_a_time=False)\n--\n\n"
           "Synthesizes every layer of the requested frames (with the temporal chain), composites "
           "them and writes the shot's outputs; resumes after the last finished frame.\n"
           "frames: None (all), a frame, or (first, last) inclusive, within the shot's frames.\n"
           "layers: None (all) or a list of layer names.  force: redo finished frames.\n"
           "previews: write the contact sheet and MP4.  threads: None (the shot's), 0 = all "
           "cores, [0, 1024].\nprogress: called with {frame, layer, done, total, elapsed} before "
           "each layer-frame (layer None: compositing); raising from it stops the run.\n"
           "max_memory_mb: refuse to start when the estimated peak memory exceeds it (what the "
           "machine has available is always checked).\n"
           "one_layer_at_a_time: synthesize a frame's layers one after another (less memory at "
           "once, more time) instead of at once; the results are the same.\n"
           "The GIL is released while it runs; Ctrl-C stops it before the next layer-frame starts "
           "(a frame's layers start together unless one_layer_at_a_time).\n"
           "Returns {synthesized, reused, composited, frames, previews (a list of "
           "pathlib.Path)}.")
      .def(
          "composite", &PyShot::composite, py::kw_only(), py::arg("frames") = py::none(),
          py::arg("previews") = true, py::arg("threads") = py::none(),
          py::arg("max_memory_mb") = py::none(),
          "composite(self, *, frames=None, previews=True, threads=None, max_memory_mb=None)\n--\n\n"
          "Re-composites finished layers with the shot's colours, blends and paper; returns the "
          "frames written.")
      .def("flicker", &PyShot::flicker, py::arg("layer"), py::kw_only(),
           py::arg("frames") = py::none(), py::arg("maps") = false,
           "flicker(self, layer, *, frames=None, maps=False)\n--\n\nTemporal error of a finished "
           "layer over at least two frames: {layer, frames, mean, objects, ground, per_frame}. "
           "With maps=True also writes each frame's flicker map into the output folder "
           "(qa/flicker/LAYER/, as `emaki qa flicker --maps`).")
      .def("plan", &PyShot::plan, py::kw_only(), py::arg("chunk") = 8, py::arg("threads") = 1,
           py::arg("emaki") = "emaki",
           "plan(self, *, chunk=8, threads=1, emaki='emaki')\n--\n\nThe render-farm task graph "
           "as a dict (docs/farm.md): chunk frames per chunked task, [1, 1000000]; threads per "
           "task; emaki "
           "the binary the tasks run.");
  py::dict scope;
  scope["__builtins__"] = py::module_::import("builtins");
  scope["Shot"] = m.attr("Shot");
  py::exec(kFromDict, scope);
  m.attr("Shot").attr("from_dict") =
      py::module_::import("builtins").attr("staticmethod")(scope["from_dict"]);
}

}  // namespace emaki::python
