#include "python/errors.h"

#include <pybind11/eval.h>

namespace emaki::python {
namespace {

// Created once at import, alive as long as the module (held by it, too).
PyObject* g_input_error = nullptr;
PyObject* g_file_error = nullptr;

// In Python, so that FileError can be an OSError whose str() is the message (OSError's own
// str() shows errno and filename instead).
constexpr const char* kClasses = R"(
class Error(Exception):
    """Base of emaki's errors. `subject` names the argument, file or key the error is about;
    `message` is the text without it; str() is "subject: message"."""
    subject = ""
    message = ""


class InputError(Error, ValueError):
    """A bad argument: a value out of range, an array of the wrong dtype, shape or size, a
    non-finite value. Also a ValueError."""


class FileError(Error, OSError):
    """A file that cannot be read, decoded or written. Also an OSError; `filename` is the
    file (as `subject`)."""
    def __str__(self):
        return self.args[0] if self.args else ""


for _cls in (Error, InputError, FileError):
    _cls.__module__ = "emaki"
)";

// A message, subject or path as a Python str: bytes that are not UTF-8 (a path from a Latin-1
// file system, a value cut by echo) become U+FFFD rather than a UnicodeDecodeError that would
// hide the error itself.
py::str text(const std::string& s) {
  PyObject* o = PyUnicode_DecodeUTF8(s.data(), Py_ssize_t(s.size()), "replace");
  if (!o) throw py::error_already_set();
  return py::reinterpret_steal<py::str>(o);
}

}  // namespace

void bind_errors(py::module_& m) {
  py::dict scope;
  scope["__builtins__"] = py::module_::import("builtins");
  py::exec(kClasses, scope);
  for (const char* name : {"Error", "InputError", "FileError"}) m.attr(name) = scope[name];
  g_input_error = py::object(scope["InputError"]).release().ptr();
  g_file_error = py::object(scope["FileError"]).release().ptr();
}

void raise_error(const Error& e, ErrorKind kind, std::initializer_list<FieldName> fields) {
  std::string subject = e.subject();
  bool is_field = !e.field().empty();
  for (const FieldName& f : fields)
    if (e.field() == f.field) subject = f.argument;
  const Error named = is_field ? e.respelled(subject) : e;
  PyObject* cls = kind == ErrorKind::kFile && !is_field ? g_file_error : g_input_error;
  py::object instance = py::reinterpret_steal<py::object>(
      PyObject_CallFunctionObjArgs(cls, text(named.what()).ptr(), nullptr));
  if (!instance) throw py::error_already_set();
  instance.attr("subject") = text(subject);
  instance.attr("message") = text(e.message());
  if (cls == g_file_error) instance.attr("filename") = text(subject);
  PyErr_SetObject(cls, instance.ptr());
  throw py::error_already_set();
}

void raise_input_error(const std::string& argument, const std::string& message) {
  raise_error(Error(argument, message), ErrorKind::kInput);
}

}  // namespace emaki::python
