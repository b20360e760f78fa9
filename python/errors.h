// emaki's Python exceptions and the one place an emaki::Error becomes one. Errors name the
// thing (a file, an argument); code below the module names settings by a neutral field
// (Error::Field), which each call re-spells as its own Python argument.
#pragma once

#include <pybind11/pybind11.h>

#include <initializer_list>
#include <optional>
#include <string>

#include "core/error.h"

namespace emaki::python {

namespace py = pybind11;

// Creates emaki.Error (base), emaki.InputError (also a ValueError: a bad argument or array) and
// emaki.FileError (also an OSError: a file that cannot be read or written) in `m`.
void bind_errors(py::module_& m);

enum class ErrorKind {
  kInput,  // emaki.InputError
  kFile,   // emaki.FileError (an Error::Field still makes an InputError: it names an argument)
};

// The Python spelling of a neutral field a call can meet ("gltf_node" -> "gltf_camera").
struct FieldName {
  const char* field;
  const char* argument;
};

// Sets the Python exception for `e` and throws py::error_already_set. The exception's `subject`
// is the argument, file or key the message is about, its `message` the text without it.
[[noreturn]] void raise_error(const Error& e, ErrorKind kind,
                              std::initializer_list<FieldName> fields = {});

// Raises emaki.InputError naming `argument` (for checks the binding makes itself).
[[noreturn]] void raise_input_error(const std::string& argument, const std::string& message);

// A Python exception raised inside a callback (or a pending Ctrl-C) while C++ ran, kept until
// the C++ call has unwound and the GIL is back.
struct PendingError {
  PyObject *type = nullptr, *value = nullptr, *trace = nullptr;
  void fetch() { PyErr_Fetch(&type, &value, &trace); }
  [[noreturn]] void raise() {
    PyErr_Restore(type, value, trace);
    throw py::error_already_set();
  }
};

// Runs fn(), turning an emaki::Error it throws into the Python exception.
template <typename Fn>
auto translating(ErrorKind kind, std::initializer_list<FieldName> fields, Fn&& fn) {
  try {
    return fn();
  } catch (const Error& e) {
    raise_error(e, kind, fields);
  }
}

// Runs fn() with the GIL released (it must not touch Python objects), turning an emaki::Error
// it throws into the Python exception once the GIL is back.
template <typename Fn>
auto without_gil(ErrorKind kind, std::initializer_list<FieldName> fields, Fn&& fn) {
  std::optional<Error> failure;
  {
    py::gil_scoped_release released;
    try {
      return fn();
    } catch (const Error& e) {
      failure = e;
    }
  }
  raise_error(*failure, kind, fields);
}

}  // namespace emaki::python
