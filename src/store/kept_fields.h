// The advection fields of one frame, made ahead by the farm's passes task for the shot's temporal
// layers (pipeline::advection_fields) and kept beside the frame's passes,
// OUTPUT/passes/advection_NNNN.field: a 40-byte header (magic, version, frame, size, how many
// fields, the digest of what follows), then per field its key (guide, patch size, seed), its
// entries and errors and, when it was made with surfaces, the visible_before() map and the id
// shares (temporal::AdvectionField), as the machine holds them, uncompressed. The layer tasks
// read it instead of each computing the fields again. The reader takes the bytes as hostile
// input: anything but the exact header the caller expects, the exact size, the digest, entries
// inside the frame and finite errors and shares gives no field (the layers then compute theirs),
// never a crash.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "pipeline/frames.h"

namespace emaki::io {

// The whole file for frame `frame` of a width x height shot. Each field's nnf is that size.
std::string encode_kept_fields(int frame, int width, int height,
                               const std::vector<pipeline::KeptField>& fields);

// The fields in `bytes`, or none when they are not exactly such a file for `frame` at width x
// height.
std::vector<pipeline::KeptField> decode_kept_fields(const void* bytes, std::size_t size, int frame,
                                                    int width, int height);

// Sets the digest in the header of `bytes` (size >= the 40-byte header) to that of the bytes
// after it, as encode_kept_fields does: for files made by hand (the fuzz target's mutations,
// which then reach the fields' own checks).
void seal_kept_fields(void* bytes, std::size_t size);

}  // namespace emaki::io
