#include "view/listing.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <map>
#include <optional>

#include "core/utf8.h"
#include "shot/plan.h"

namespace emaki::view {

namespace fs = std::filesystem;

namespace {

// "frame_0012.png" -> 12 with the prefix "frame_" (the group key); nothing for other names.
std::optional<std::pair<std::string, int>> frame_file(const std::string& name) {
  const std::size_t dot = name.rfind('.');
  if (dot == std::string::npos) return std::nullopt;
  const std::string ext = name.substr(dot + 1);
  if (ext != "png" && ext != "jpg" && ext != "jpeg") return std::nullopt;
  std::size_t start = dot;
  while (start > 0 && std::isdigit(static_cast<unsigned char>(name[start - 1]))) --start;
  if (start == dot || dot - start > 7) return std::nullopt;
  return std::make_pair(name.substr(0, start) + "#." + ext, std::stoi(name.substr(start, dot)));
}

long long stamp(const fs::path& p) {
  std::error_code ec;
  const auto t = fs::last_write_time(p, ec);
  return ec ? 0 : static_cast<long long>(t.time_since_epoch().count());
}

std::string read_manifest(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::string text(kMaxManifestBytes + 1, '\0');
  in.read(text.data(), std::streamsize(text.size()));
  text.resize(std::size_t(in.gcount()));
  if (text.size() > kMaxManifestBytes) text = text.substr(0, kMaxManifestBytes) + "\n...";
  return valid_utf8_or_marks(text);
}

int sequence_rank(const std::string& name) {
  if (name == "composite") return 0;
  if (name.rfind("layers/", 0) == 0) return 1;
  return 2;
}

struct Scan {
  fs::path root;
  int entries = 0;
  std::map<std::pair<std::string, std::string>, std::map<int, std::pair<std::string, long long>>>
      groups;  // (folder, pattern) -> frame -> (file, stamp)
  Listing listing;
};

void scan_folder(Scan& s, const fs::path& folder, const std::string& rel, int depth) {
  std::error_code ec;
  for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    if (++s.entries > kMaxScanEntries) return;
    const std::string name = it->path().filename().string();
    if (first_invalid_utf8(name) != std::string::npos) continue;
    const std::string path = rel.empty() ? name : rel + "/" + name;
    if (name == ".emaki-manifest" && !rel.empty()) {
      s.listing.manifests.emplace_back(rel, read_manifest(it->path()));
      continue;
    }
    if (name.front() == '.' || it->is_symlink(ec)) continue;
    if (it->is_directory(ec)) {
      if (depth < kMaxScanDepth && name != "references")
        scan_folder(s, it->path(), path, depth + 1);
      continue;
    }
    if (!it->is_regular_file(ec)) continue;
    if (rel.empty() && name == "contact_sheet.png") {
      s.listing.contact_sheet = name;
      s.listing.contact_sheet_stamp = stamp(it->path());
    } else if (const auto f = frame_file(name); f && !rel.empty()) {
      s.groups[{rel, f->first}][f->second] = {path, stamp(it->path())};
    }
  }
}

}  // namespace

Listing scan_output(const fs::path& folder) {
  Scan s;
  s.listing.folder = folder.string();
  scan_folder(s, folder, "", 0);
  std::map<std::string, int> per_folder;
  for (const auto& [key, frames] : s.groups) ++per_folder[key.first];
  for (const auto& [key, frames] : s.groups) {
    Sequence q;
    // Two sequences in one folder (rare) are told apart by their file pattern.
    q.name = per_folder[key.first] > 1 ? key.first + "/" + key.second : key.first;
    for (const auto& [frame, file] : frames) {
      q.frames.push_back(frame);
      q.files.push_back(file.first);
      q.stamps.push_back(file.second);
    }
    s.listing.sequences.push_back(std::move(q));
  }
  std::stable_sort(s.listing.sequences.begin(), s.listing.sequences.end(),
                   [](const Sequence& a, const Sequence& b) {
                     return std::make_pair(sequence_rank(a.name), a.name) <
                            std::make_pair(sequence_rank(b.name), b.name);
                   });
  std::sort(s.listing.manifests.begin(), s.listing.manifests.end());
  return s.listing;
}

namespace {

std::string json(const std::string& s) {
  return shot::json_string(valid_utf8_or_marks(s), "view");
}

template <typename T, typename F>
std::string json_array(const std::vector<T>& v, F each) {
  std::string out = "[";
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (i) out += ',';
    out += each(v[i]);
  }
  return out + "]";
}

std::string sequence_json(const Sequence& q) {
  return fmt::format("{{\"name\":{},\"frames\":{},\"files\":{},\"stamps\":{}}}", json(q.name),
                     json_array(q.frames, [](int f) { return std::to_string(f); }),
                     json_array(q.files, json),
                     json_array(q.stamps, [](long long t) { return std::to_string(t); }));
}

}  // namespace

std::string listing_json(const std::vector<Listing>& listings) {
  return "{\"outputs\":" +
         json_array(listings,
                    [](const Listing& l) {
                      return fmt::format(
                          "{{\"folder\":{},\"sequences\":{},\"contact_sheet\":{},\"contact_sheet_"
                          "stamp\":{},"
                          "\"manifests\":{}}}",
                          json(l.folder), json_array(l.sequences, sequence_json),
                          json(l.contact_sheet), l.contact_sheet_stamp,
                          json_array(l.manifests, [](const auto& m) {
                            return fmt::format("{{\"folder\":{},\"text\":{}}}", json(m.first),
                                               json(m.second));
                          }));
                    }) +
         "}";
}

}  // namespace emaki::view
