// QA maps on disk (pipeline/qa_maps.h): OUTPUT/qa/KIND/LAYER/frame_NNNN.png, 8-bit RGB, for emaki
// view's overlay (drawn over the frame with a screen blend, so black shows nothing). A measured
// pixel goes from dark blue (nothing wrong) through red and yellow to white (the map's scale or
// more); a pixel not measured is black. Written through a temporary file and renamed, as every
// output is.
#pragma once

#include <string>

#include "core/image.h"

namespace emaki::io {

std::string qa_map_png(const std::string& output_folder, const std::string& kind,
                       const std::string& layer, int frame);

// The RGB picture of a 2-channel map (value in [0, 1], measured).
Image<float> qa_map_colours(ImageView<const float> map);

// Writes `map` as qa_map_png(...) (creating its folder); returns the file. Throws emaki::Error
// naming the file when it cannot be written.
std::string write_qa_map(const std::string& output_folder, const std::string& kind,
                         const std::string& layer, int frame, ImageView<const float> map);

}  // namespace emaki::io
