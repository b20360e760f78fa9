// numpy arrays <-> emaki images. An input array is seen in place through the buffer protocol
// whenever its layout is one an ImageView can describe (rows at any positive stride, pixels and
// channels packed, aligned): no copy. Any other layout (a transposed or channel-sliced view, a
// negative stride) is copied once into an Image of the same dtype. Results are new C-contiguous
// arrays.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "core/image.h"
#include "synth/synthesizer.h"

namespace emaki::python {

namespace py = pybind11;

enum class SampleType { kU8, kU16, kF32 };

// An array seen as an image plane. Holds the buffer (and so the array) until destroyed, which
// must happen with the GIL held.
struct ArrayPlane {
  synth::Plane plane;    // the array's memory, or `copy`'s
  py::buffer_info info;  // the exported buffer
  std::variant<std::monostate, Image<uint8_t>, Image<uint16_t>, Image<float>> copy;
  SampleType type = SampleType::kF32;
  int ndim = 3;                          // 2: an HxW array; 3: HxWxC
  std::string name;                      // the argument, for errors
  int width = 0, height = 0, depth = 0;  // from the shape (depth: channels)
  // The layout is not one a view can describe: copy_layout() makes the copy (`plane` is empty
  // until then).
  bool needs_copy = false;
  int channels() const { return synth::plane_channels(plane); }
  const void* data() const;  // where the engine reads the samples
};

// Checks `obj` (uint8, uint16 or float32; HxW or HxWxC; any object with the buffer protocol)
// and views it in place when its layout allows. Raises emaki.InputError naming `name` for
// another dtype or shape, an empty array or one over the pixel budget. An array of another
// layout is not copied yet (needs_copy): a caller with several arrays checks them all, and
// their sizes against one another, before any copy, so a bad argument never waits on one.
ArrayPlane inspect_array(const py::handle& obj, const std::string& name);

// Raises emaki.InputError when the copies these arrays need exceed the memory the machine has
// available (checked before copying: a zero-stride view of gigabytes is a few bytes in Python).
void check_copy_memory(const std::vector<const ArrayPlane*>& arrays);

// Makes the copy inspect_array left for later (nothing when none is needed).
void copy_layout(ArrayPlane& a);

// inspect_array, check_copy_memory and copy_layout for one array.
ArrayPlane array_plane(const py::handle& obj, const std::string& name);

// The dtype an argument names (None: `fallback`); raises emaki.InputError naming `name` unless
// it is uint8, uint16 or float32.
SampleType sample_type(const py::handle& dtype, const std::string& name, SampleType fallback);

// A float image as a new C-contiguous array of `type` (integer types: clamped to [0, 1] and
// rounded, as PNG files are written). `squeeze`: a one-channel image becomes HxW.
py::array to_array(const Image<float>& image, SampleType type, bool squeeze);
py::array to_array(const Image<int32_t>& image);

// An array of any supported dtype as float (integers normalised to [0, 1]), for writing.
Image<float> to_float_image(const ArrayPlane& a);

}  // namespace emaki::python
