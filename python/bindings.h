// The parts of the `emaki` module, one function per file; module.cpp calls each once. A new
// part (the shot API, `emaki.Shot`) is one more bind_* function and file.
#pragma once

#include <pybind11/pybind11.h>

namespace emaki::python {

namespace py = pybind11;

void bind_synth(py::module_& m);   // synthesize (bind_synth.cpp)
void bind_images(py::module_& m);  // read_image, write_image, image_channels (bind_images.cpp)
void bind_render(py::module_& m);  // render, template, pass_names (bind_render.cpp)
void bind_shot(py::module_& m);    // Shot: the shot API (bind_shot.cpp)
void bind_view(py::module_& m);    // view, Viewer: emaki view's server (bind_view.cpp)

}  // namespace emaki::python
