// emaki's own reader and writer for the EXR files it writes: one scanline part, uncompressed or
// ZIP (zlib), channels of 32-bit float or half sampled at every pixel. Every EXR emaki writes
// (layers, the layered and composite frames, renders) is such a file, and reading them back (the
// layers in a composite task, the previous layer frame in a layer task) needs neither a decoder
// library nor a full-size staging buffer.
// OpenImageIO, with the ~260 libraries it loads (0.25-0.45 CPU-s a process), is then needed
// only for other files: a studio's renders, TIFF, JPEG. Through it, a 1200x912 frame of 24
// float passes cost 1.3 CPU-s to read, against 0.16 here.
#pragma once

#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "core/image.h"
#include "io/image_io.h"

namespace emaki::io::detail {

// The channels named (in that order; float, with their names) of the open EXR file `f` when it is
// plain: one scanline part, compression none, ZIPS or ZIP, every channel FLOAT or HALF and sampled
// at every pixel, every chunk present once. No names: every channel, for the channel sets of
// emaki's layer files (Y, Y A, R G B, R G B A) in the order OpenImageIO gives them. nullopt for any
// other file, one without a named channel, one with a NaN or Inf, or an image outside the pixel
// budget: the general reader then reads it and words what is wrong.
// The header must have been walked (exr_header.h) first; `f`'s position is left anywhere.
std::optional<AnyImage> read_plain_exr(std::FILE* f, const std::string& path,
                                       const std::vector<std::string>& channels);

// The bytes of `image` as such a file (half or float samples; compression "none", "zips" or
// "zip" as WriteOptions names it; channels as named, stored sorted by name as OpenEXR does,
// each channel's samples as OpenImageIO would convert them), or nullopt when `options` ask for
// something else (another compression, no channel names), which OpenImageIO then writes.
std::optional<std::string> encode_plain_exr(ImageView<const float> image,
                                            const WriteOptions& options, bool half);

}  // namespace emaki::io::detail
