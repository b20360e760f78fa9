// The `emaki` Python module: the engine over numpy arrays, image files, the guide-pass
// renderer and the reference sphere. Everything runs the same C++ code as the command line.
#include <pybind11/pybind11.h>

#include "core/performance.h"
#include "core/version.h"
#include "python/bindings.h"
#include "python/errors.h"

PYBIND11_MODULE(emaki, m) {
  using namespace emaki::python;
  m.doc() =
      "emaki: stylize 3D animation by example.\n\n"
      "synthesize()  guided patch-based synthesis over numpy arrays (as `emaki synth`)\n"
      "read_image(), write_image(), image_channels()  image files (PNG, EXR by channel "
      "name, TIFF, JPEG)\n"
      "render()  guide passes of a glTF scene at one frame (as `emaki render`)\n"
      "template()  the reference sphere's passes and paint template (as `emaki template`)\n"
      "Shot  a shot file: run(), composite(), flicker(), plan() (as `emaki run`, ...)\n"
      "view()  the page of output folders (as `emaki view`)\n"
      "Error, InputError, FileError  the exceptions; `subject` names the argument or file\n\n"
      "Images are numpy arrays: HxW for one channel, HxWxC otherwise, in and out.";
  m.attr("__version__") = emaki::version();
  // The one performance switch (core/performance.h), as the command line applies it: huge-page
  // advice on large images, SIMD kernels unless EMAKI_SIMD=scalar.
  emaki::set_performance(emaki::performance_from_environment());
  // Each docstring starts with its own signature instead of pybind11's (which would show C++
  // handle types), in CPython's text-signature form, `name(args)\n--\n\n`: `__text_signature__`
  // then gives inspect.signature() the parameters and defaults, and help() shows them
  // (python/tests/test_docs.py checks them against emaki.pyi).
  py::options options;
  options.disable_function_signatures();
  bind_errors(m);
  bind_synth(m);
  bind_images(m);
  bind_render(m);
  bind_shot(m);
  bind_view(m);
}
