// Safe writes into folders other people can see: temporaries with unpredictable names created
// exclusively (never through a planted symlink), a clean-up that removes only emaki's own
// temporaries, a lock that keeps two emaki processes out of one output folder, and small
// manifests (the settings that made an output) so that resuming never trusts stale files.
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace emaki::io {

// A file created with O_CREAT | O_EXCL | O_NOFOLLOW beside `target`, named
// ".<stem>.emaki-tmp-<16 hex digits><ext>" (the extension kept last: writers pick the format from
// it). The descriptor stays open until commit() or destruction so that commit() can check that
// the path still names the file we created. Destruction without commit() removes the file.
class TempFile {
 public:
  // Throws emaki::Error(subject) when the file cannot be created.
  TempFile(const std::string& target, const std::string& subject);
  ~TempFile();
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;

  const std::string& path() const { return path_; }
  int fd() const { return fd_; }
  // Writes all of `data` (short and interrupted writes retried); throws emaki::Error(subject)
  // when the file takes no more (a full disk).
  void write(const void* data, std::size_t size);
  // Gives the descriptor away (e.g. to fdopen); the file is still removed unless committed.
  int release_fd();
  // Checks what reached the disk, then renames the finished temporary over the target (a symlink
  // at the target is replaced, not followed). Before the rename: fsync and close must succeed,
  // the file must not be empty, it must hold every byte write() took, and `verify` (given the
  // temporary's path; a format's reader) must accept it. A writer that reports success while the
  // disk took only part of the file (OpenEXR's last writes on a full disk) so never replaces the
  // target. Throws emaki::Error(subject) when any check fails (the temporary is then removed) or
  // when the temporary was swapped for another file.
  void commit(const std::function<void(const std::string& path)>& verify = {});

 private:
  [[noreturn]] void fail_unsaved(const std::string& why) const;

  std::string target_, subject_, path_;
  int fd_ = -1;
  unsigned long long dev_ = 0, ino_ = 0;
  unsigned long long written_ = 0;  // bytes taken by write()
  bool committed_ = false;
};

// The name a temporary of `target_name` (a file name, no folder) would have, for tests.
bool is_temporary_name(const std::string& name, std::string* target_name = nullptr);

// Removes, in `dir` only, the regular files (never symlinks or folders) owned by this user whose
// name is emaki's temporary pattern for a target that `ours(target_name)` accepts: what a killed
// run left behind, and nothing a user made.
void remove_temporaries(const std::string& dir,
                        const std::function<bool(const std::string&)>& ours);

// 64 random bits from getrandom(2).
unsigned long long random_u64();

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

// A 64-bit digest of a file's bytes as 16 hex digits; "missing" when it cannot be read.
std::string file_digest(const std::string& path);

}  // namespace emaki::io
