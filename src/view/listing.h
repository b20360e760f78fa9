// What an output folder holds, as the viewer's page reads it: the image sequences (the
// composite, each layer, any other folder of numbered PNG/JPEG frames such as pass previews or
// QA maps), the contact sheet and the settings manifests. Read afresh on every request, so a run
// in progress shows its new frames.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace emaki::view {

struct Sequence {
  std::string name;                // its folder, relative to the output folder: "layers/base"
  std::vector<int> frames;         // ascending
  std::vector<std::string> files;  // the file of each frame, relative to the output folder
  std::vector<long long> stamps;   // each file's modification time (ns), for the page's caches
};

struct Listing {
  std::string folder;               // as given on the command line
  std::vector<Sequence> sequences;  // composite first, then layers/*, then the others by name
  std::string contact_sheet;        // "contact_sheet.png" or empty
  long long contact_sheet_stamp = 0;
  std::vector<std::pair<std::string, std::string>> manifests;  // (folder, text)
};

// Bounds of one scan: folders this deep below the output folder, this many entries in all,
// manifests up to this size (longer ones are cut, marked).
inline constexpr int kMaxScanDepth = 3;
inline constexpr int kMaxScanEntries = 200000;
inline constexpr std::size_t kMaxManifestBytes = 64 * 1024;

// Scans `folder`; hidden entries (a leading '.') other than the manifests, and symlinks to
// folders, are skipped. A folder that cannot be read yields an empty listing.
Listing scan_output(const std::filesystem::path& folder);

// The listings as the JSON of GET /api/outputs (docs/view.md).
std::string listing_json(const std::vector<Listing>& listings);

}  // namespace emaki::view
