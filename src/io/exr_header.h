// A walk over an OpenEXR file's header(s) before OpenImageIO and OpenEXR see the file. OpenEXR
// 3.1 allocates from header values as it reads them: a string attribute's claimed length, a
// preview's size, a chunk table as long as the data window is tall, a tile buffer per thread as
// large as the tile size claims. A 1 KB file can so make it take gigabytes before it reports
// the file short. This walk checks every such value against the file's size, the pixel budget
// and emaki's bounds, reading nothing larger than a channel list.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

namespace emaki::io::detail {

// True when the bytes start with OpenEXR's magic number.
bool has_exr_magic(const unsigned char* bytes, std::size_t n);

// Throws emaki::Error(subject) when the header asks for more than the file, the pixel budget
// (core/limits.h) or emaki's bounds allow: attributes past the end of the file, a preview
// whose size disagrees with its attribute, a data or display window that is empty or overflows,
// a data window over the budget, more than kMaxChannels channels or kMaxParts parts, deep data,
// a chunk (tile or scanline block) much larger than the image, or more chunks than the file
// can hold offsets for.
void check_exr_header(const unsigned char* data, std::size_t size, const std::string& subject);
void check_exr_header(std::FILE* file, const std::string& subject);

// The header checks above, then the chunk offset tables: every chunk they list must start after
// them and end within the file. What a writer cut short (a full disk, a killed process) leaves:
// OpenEXR writes the table last and reports no error when its final writes fail.
void check_exr_complete(const unsigned char* data, std::size_t size, const std::string& subject);
void check_exr_complete(std::FILE* file, const std::string& subject);

}  // namespace emaki::io::detail
