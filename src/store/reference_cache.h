// The reference passes of MatCap-like exemplars (the sphere rendered at the painting's size),
// kept under a shot's output folder so that its run and each of its farm tasks need not render
// them again: OUTPUT/references/KEY.passes (float, every pass, rows as Image<float> holds them:
// read by mapping the file, without a copy; store/mapped_passes.h), KEY a digest of everything
// the render depends on (store/settings_manifests.h reference_manifest). Written through a
// temporary and renamed (io/temp_file.h): a killed write or a full disk leaves no file that is
// read as a reference; a file of another size (cut short, grown, another header) is rendered
// again. The file is checked by its header and size, as the pass cache is, not by a digest of
// its pixels: hashing them cost every layer task 0.07 s on a 1200x912 painting.
#pragma once

#include <optional>
#include <string>

#include "core/image.h"
#include "pipeline/shot_description.h"

namespace emaki::io {

// The file name stem of an exemplar's reference passes at width x height: 16 hex digits.
std::string reference_key(const pipeline::Exemplar& exemplar, int width, int height);

// The cached passes `key` in `output_folder`, or nullopt when they are missing, cut short or
// grown, or of another size or channel count.
std::optional<Image<float>> read_reference(const std::string& output_folder, const std::string& key,
                                           int width, int height);

// Records `passes` as `key` in `output_folder` (creating references/). Throws emaki::Error naming
// the file when it cannot be written.
void write_reference(const std::string& output_folder, const std::string& key,
                     ImageView<const float> passes);

}  // namespace emaki::io
