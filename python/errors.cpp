#include "python/errors.h"

namespace emaki::python {
namespace {

// Created once at import, alive as long as the module (held by it, too).
PyObject* g_error = nullptr;
PyObject* g_input_error = nullptr;
PyObject* g_file_error = nullptr;

PyObject* new_class(py::module_& m, const char* name, const char* doc, py::tuple bases) {
  const std::string full = std::string("emaki.") + name;
  PyObject* cls = PyErr_NewExceptionWithDoc(full.c_str(), doc, bases.ptr(), nullptr);
  if (!cls) throw py::error_already_set();
  m.add_object(name, py::handle(cls));
  return cls;
}

}  // namespace

void bind_errors(py::module_& m) {
  g_error = new_class(m, "Error",
                      "Base of emaki's errors. `subject` names the argument, file or key the "
                      "error is about; `message` is the text without it.",
                      py::make_tuple(py::handle(PyExc_Exception)));
  g_input_error = new_class(m, "InputError",
                            "A bad argument: a value out of range, an array of the wrong dtype, "
                            "shape or size, a non-finite value. Also a ValueError.",
                            py::make_tuple(py::handle(g_error), py::handle(PyExc_ValueError)));
  g_file_error = new_class(m, "FileError",
                           "A file that cannot be read, decoded or written. Also an OSError; "
                           "`filename` is the file.",
                           py::make_tuple(py::handle(g_error), py::handle(PyExc_OSError)));
}

void raise_error(const Error& e, ErrorKind kind, std::initializer_list<FieldName> fields) {
  std::string subject = e.subject();
  bool is_field = !e.field().empty();
  for (const FieldName& f : fields)
    if (e.field() == f.field) subject = f.argument;
  const Error named = is_field ? e.respelled(subject) : e;
  PyObject* cls = kind == ErrorKind::kFile && !is_field ? g_file_error : g_input_error;
  py::object instance =
      py::reinterpret_steal<py::object>(PyObject_CallFunction(cls, "s", named.what()));
  if (!instance) throw py::error_already_set();
  instance.attr("subject") = subject;
  instance.attr("message") = e.message();
  if (cls == g_file_error) instance.attr("filename") = subject;
  PyErr_SetObject(cls, instance.ptr());
  throw py::error_already_set();
}

void raise_input_error(const std::string& argument, const std::string& message) {
  raise_error(Error(argument, message), ErrorKind::kInput);
}

}  // namespace emaki::python
