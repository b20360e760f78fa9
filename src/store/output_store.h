// A shot's output folder kept safe: a lock that keeps two emaki processes out of one output
// folder, and small manifests (the settings that made an output) so that resuming never trusts
// stale files. Files are written through temporaries (io/temp_file.h).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "io/temp_file.h"

namespace emaki::io {

// An exclusive flock on "<folder>/.emaki.lock", held until destruction. The file holds the
// holder's pid, host and start time (informational only: the kernel drops the lock when the
// process dies, so a killed run never blocks the next one).
class FolderLock {
 public:
  // kShared: the tasks of one shot on a render farm, which write disjoint files and may run at
  // once; an exclusive holder (emaki run) and shared holders exclude each other.
  enum class Kind { kExclusive, kShared };
  // Throws emaki::Error(lock file) naming the holder when another process holds it.
  explicit FolderLock(const std::string& folder, Kind kind = Kind::kExclusive);
  ~FolderLock();
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;

 private:
  int fd_ = -1;
};

// A manifest: "key = value" lines, compared line by line.
using Manifest = std::vector<std::string>;

// nullopt when the file does not exist (or is not a regular file).
std::optional<Manifest> read_manifest(const std::string& path);
// Atomic (TempFile + rename).
void write_manifest(const std::string& path, const Manifest& m);
// The first line of `want` that `have` lacks or changes, as "key: was X, now Y"; empty when equal.
std::string manifest_difference(const Manifest& have, const Manifest& want);

// A 64-bit digest of a file's bytes as 16 hex digits and its size; "missing" when it cannot be
// read. A process reads each file for it once: the digest is remembered under the file's
// identity (device, inode, size, modification time), so the manifests of a shot's layers, which
// all name its paintings, cost one read of each.
std::string file_digest(const std::string& path);
// The digest file_digest gives a file holding `bytes`.
std::string bytes_digest(std::string_view bytes);

// The bytes of the regular file `path` (at most `cap`) in one open, their digest remembered for
// file_digest: an input read to be decoded is not read again for the manifests. nullopt when it
// is not a regular file, cannot be read or holds more than `cap` bytes (the caller then reads it
// the ordinary way, which words the error).
std::optional<std::string> read_input_file(const std::string& path, std::size_t cap);

}  // namespace emaki::io
