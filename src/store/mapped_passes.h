// A frame's guide passes on disk in the layout Image<float> holds them in memory, read by
// mapping the file: no decoding, no copy, no fresh pages to fault in. The exemplars' reference
// passes (store/reference_cache.h) and the farm's pass cache (store/file_store.h) are such
// files, read by every layer task.
//
// The file: a 64-byte header (magic "emkpass1", width, height, channels, the row stride in
// floats), then every row padded to kRowAlign bytes. Written through a temporary and renamed
// (io/temp_file.h): a killed write or a full disk leaves no file that maps.
#pragma once

#include <optional>
#include <string>

#include "core/image.h"

namespace emaki::io {

// Writes `passes` (render::kChannelCount channels) to `path`. Throws emaki::Error naming `path`
// when it cannot be written.
void write_mapped_passes(const std::string& path, ImageView<const float> passes);

// The passes of `path` mapped copy-on-write (writing to the image never reaches the file), or
// nullopt when the file is missing, not such a file, cut short or longer, or not width x height
// x render::kChannelCount.
std::optional<Image<float>> map_passes(const std::string& path, int width, int height);

// Whether `path` is such a file of width x height, by its header and size (nothing mapped).
bool mapped_passes_complete(const std::string& path, int width, int height);

}  // namespace emaki::io
