// emaki.view(): emaki view's server (src/view/) from Python, e.g. a notebook: it runs on its own
// threads, never holding the GIL, until stop() or the Viewer's end.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "python/bindings.h"
#include "python/errors.h"
#include "view/server.h"

namespace emaki::python {

namespace {

namespace fs = std::filesystem;

struct Viewer {
  std::unique_ptr<view::Server> server;
  std::string url;
  int port = 0;
  void stop() {
    py::gil_scoped_release release;
    if (server) server->stop();
  }
};

Viewer view_folders(const fs::path& folder, const std::optional<fs::path>& folder_b, int port,
                    const std::string& bind) {
  std::vector<fs::path> folders{folder};
  if (folder_b) folders.push_back(*folder_b);
  view::ServerOptions o;
  o.port = port;
  o.bind = bind;
  Viewer v;
  try {
    v.server = std::make_unique<view::Server>(folders, o);
    v.port = v.server->start();
  } catch (const Error& e) {
    // A folder is named by its path (FileError); a port by the argument (InputError).
    raise_error(e, e.field().empty() ? ErrorKind::kFile : ErrorKind::kInput);
  }
  v.url = v.server->url();
  return v;
}

constexpr const char* kDoc =
    R"(view(folder, folder_b=None, *, port=0, bind='127.0.0.1')
--

The page of `emaki view` (docs/view.md) over a shot's output folder, and a second one to
compare: frames, layers, an A/B wipe, the contact sheet and the manifests. The server runs on
threads of its own; open Viewer.url in a browser. It stops with Viewer.stop(), at the end of a
`with` block, or when the Viewer is collected.

Args:
    folder: a shot's output folder (path).
    folder_b: a second output folder, shown as B. Default None.
    port: the port; 0 (default) lets the system pick one.
    bind: the address to listen on. Default '127.0.0.1' (this machine only).

Returns:
    a Viewer: url, port, stop().

Raises:
    emaki.FileError: a folder that is not one.
    emaki.InputError: a port that cannot be bound.)";

}  // namespace

void bind_view(py::module_& m) {
  py::class_<Viewer>(m, "Viewer", "A running emaki view server (emaki.view()).")
      .def_readonly("url", &Viewer::url)
      .def_readonly("port", &Viewer::port)
      .def("stop", &Viewer::stop, "stop(self)\n--\n\nStops the server; safe to call twice.")
      .def(
          "__enter__", [](Viewer& v) -> Viewer& { return v; }, "__enter__(self)\n--\n\n")
      .def(
          "__exit__", [](Viewer& v, py::args) { v.stop(); },
          "__exit__(self, *args)\n--\n\nStops the server.")
      .def("__repr__", [](const Viewer& v) { return "<emaki.Viewer " + v.url + ">"; });
  m.def("view", &view_folders, kDoc, py::arg("folder"), py::arg("folder_b") = py::none(),
        py::kw_only(), py::arg("port") = 0, py::arg("bind") = "127.0.0.1");
}

}  // namespace emaki::python
