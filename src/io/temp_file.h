// Safe writes into folders other people can see: temporaries with unpredictable names created
// exclusively (never through a planted symlink), renamed over their target when finished, and a
// clean-up that removes only emaki's own temporaries.
#pragma once

#include <cstddef>
#include <functional>
#include <string>

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

}  // namespace emaki::io
