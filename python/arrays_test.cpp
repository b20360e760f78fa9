// The binding's zero-copy rule (python/arrays.h), checked in an embedded interpreter against
// the addresses numpy gives (__array_interface__): an array whose layout an ImageView can
// describe is read where it lies, any other is copied once. python/tests/test_zero_copy.py
// checks the same from Python, through what synthesize() returns.
#include "python/arrays.h"

#include <gtest/gtest.h>
#include <pybind11/embed.h>

#include <cstdint>
#include <string>

namespace emaki::python {
namespace {

// The interpreter lives as long as the process; every Python object of a test is gone at its
// end.
py::module_ numpy() {
  static py::scoped_interpreter interpreter;
  return py::module_::import("numpy");
}

// `expression` evaluated with numpy as np.
py::object array(const std::string& expression) {
  py::module_ np = numpy();  // first: it starts the interpreter
  py::dict scope;
  scope["np"] = np;
  return py::eval(expression, scope);
}

std::uintptr_t numpy_address(const py::object& a) {
  return a.attr("__array_interface__")["data"].cast<py::tuple>()[0].cast<std::uintptr_t>();
}

std::uintptr_t engine_address(const ArrayPlane& p) {
  return reinterpret_cast<std::uintptr_t>(p.data());
}

TEST(ArrayPlane, CContiguousArraysOfEveryDtypeAreReadInPlace) {
  for (const std::string dtype : {"uint8", "uint16", "float32"}) {
    for (const std::string shape : {"(48, 64, 3)", "(48, 64)", "(1, 64, 4)"}) {
      const py::object a = array("np.zeros(" + shape + ", np." + dtype + ")");
      const ArrayPlane p = array_plane(a, "style");
      EXPECT_EQ(engine_address(p), numpy_address(a)) << dtype << " " << shape;
      EXPECT_EQ(p.copy.index(), 0u) << dtype << " " << shape;
    }
  }
}

TEST(ArrayPlane, RowsAtAnyStrideAreReadInPlace) {
  const py::object wide = array("np.zeros((48, 100, 3), np.float32)");
  py::dict scope;
  scope["wide"] = wide;
  const py::object crop = py::eval("wide[:, 10:74]", scope);  // rows 100 pixels apart
  const ArrayPlane p = array_plane(crop, "style");
  EXPECT_EQ(engine_address(p), numpy_address(crop));
  EXPECT_EQ(engine_address(p), numpy_address(wide) + 10 * 3 * sizeof(float));
  EXPECT_EQ(p.copy.index(), 0u);
  EXPECT_EQ(std::get<ImageView<const float>>(p.plane).stride, 100 * 3);
}

TEST(ArrayPlane, OtherLayoutsAreCopiedOnceWithTheirValues) {
  for (const std::string expression :
       {"np.arange(48 * 64 * 4, dtype=np.float32).reshape(48, 64, 4)[:, :, :3]",
        "np.arange(48 * 64 * 3, dtype=np.float32).reshape(48, 64, 3)[::-1]",
        "np.asfortranarray(np.arange(48 * 64 * 3, dtype=np.float32).reshape(48, 64, 3))"}) {
    const py::object a = array(expression);
    const ArrayPlane p = array_plane(a, "style");
    EXPECT_NE(p.copy.index(), 0u) << expression;
    EXPECT_NE(engine_address(p), numpy_address(a)) << expression;
    const auto& v = std::get<ImageView<const float>>(p.plane);
    py::dict scope;
    scope["a"] = a;
    for (const auto& [x, y, c] : {std::tuple{0, 0, 0}, std::tuple{63, 47, 2}, std::tuple{5, 7, 1}})
      EXPECT_EQ(v(x, y, c), py::eval("float(a[" + std::to_string(y) + ", " + std::to_string(x) +
                                         ", " + std::to_string(c) + "])",
                                     scope)
                                .cast<float>())
          << expression << " at " << x << ", " << y << ", " << c;
  }
}

}  // namespace
}  // namespace emaki::python
