// Image files through OpenImageIO: PNG 8/16-bit, EXR half/float (channels picked by name from
// multilayer files), TIFF, JPEG. Images come back in their file's precision (8-bit, 16-bit or
// float), so an 8-bit guide costs one byte per sample in memory and a float guide keeps all of
// its precision. Every write is atomic: a temporary file in the same folder, then a rename.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "core/image.h"

namespace emaki::io {

enum class PixelType { kU8, kU16, kF32 };

// An image as stored in its file: 8-bit, 16-bit or float samples (half is read as float).
struct AnyImage {
  std::variant<Image<uint8_t>, Image<uint16_t>, Image<float>> image;
  std::vector<std::string> channel_names;

  int width() const;
  int height() const;
  int channels() const;
  PixelType type() const;
  // Sample (x, y, c) normalised to [0, 1] for integer types, as-is for float.
  float value(int x, int y, int c) const;
  // Converts to float (integer types normalised to [0, 1]).
  Image<float> to_float() const&;
  // The same, moving a float image out instead of copying it.
  Image<float> to_float() &&;
  // Keeps only channels [first, first + count).
  AnyImage select_channels(int first, int count) const;
};

struct ReadOptions {
  // Channel names to pick, in order (e.g. {"position.X","position.Y","position.Z"}); empty reads
  // all channels. Names are searched in every part (subimage) of a multilayer file.
  std::vector<std::string> channels;
};

// Throws emaki::Error naming the file on a missing, unreadable or corrupt file, a header whose
// size is over the pixel budget (core/limits.h, `--max-pixels`) or otherwise implausible
// (checked before any pixel memory is allocated), or a channel that is not in it (the message
// lists the channels the file has).
AnyImage read_image(const std::string& path, const ReadOptions& options = {});
Image<float> read_image_float(const std::string& path, const ReadOptions& options = {});
// The image at `path` when it is whole to its end (image_file_complete's rule), read in the same
// single open of the file; nullopt when it is missing, empty or cut short. A whole file that
// does not read throws as read_image does.
std::optional<AnyImage> read_image_if_complete(const std::string& path,
                                               const ReadOptions& options = {});
// The same from `size` bytes in memory (the fuzz targets, and callers that hold a file's
// bytes). `name` names the bytes in errors, and its extension picks the format when the bytes
// are not PNG (".exr", ".tif", ...).
AnyImage read_image_memory(const void* data, std::size_t size, const std::string& name,
                           const ReadOptions& options = {});

// Lists the channel names of every part of a file.
std::vector<std::string> list_channels(const std::string& path);
// The same from `size` bytes in memory; `name` as read_image_memory takes it.
std::vector<std::string> list_channels_memory(const void* data, std::size_t size,
                                              const std::string& name);

enum class SampleFormat { kAuto, kU8, kU16, kHalf, kFloat };

struct WriteOptions {
  // kAuto: 16-bit for PNG/TIFF, half for EXR, 8-bit for JPEG.
  SampleFormat format = SampleFormat::kAuto;
  std::vector<std::string> channel_names;  // EXR channel names; default R,G,B,A / Y
  // An EXR's compression, as OpenImageIO names it: "zip" for what users keep; an intermediate
  // file read back by emaki alone may take a cheaper one.
  std::string compression = "zip";
  // An EXR's header (other formats leave them out): string attributes (name, value), e.g. the
  // colour space's name, and the chromaticities attribute (red, green, blue, white x y), when
  // given.
  std::vector<std::pair<std::string, std::string>> attributes;
  std::vector<float> chromaticities;  // 8 values, or empty
};

// Writes a float image (values in [0,1] for integer formats, clamped and rounded). Atomic, and
// verified before the rename: a write the disk took only part of (a full disk) is an error naming
// `path` that leaves any file already there as it was (io/output_store.h TempFile::commit).
void write_image(const std::string& path, ImageView<const float> image,
                 const WriteOptions& options = {});

// True when `path` is a non-empty regular file and, for PNG and EXR, whole to its end: a PNG
// that ends with its end chunk, an EXR whose chunk table lies in the file and points at chunks
// that do. Cheap (no pixel is decoded): what the output store asks before it counts a frame as
// finished, so that a file cut short by a full disk or a killed copy is made again.
bool image_file_complete(const std::string& path);

// True when the file extension names a format we can write.
bool is_writable_extension(const std::string& path);

// Checks early (before any long computation) that `path` can be written: its folder exists and
// is writable and its extension names an image format. Throws emaki::Error naming the path.
void check_writable(const std::string& path);

}  // namespace emaki::io
