// A small tmpfs for a test, filled to any point: what a full disk does to a writer. Mounting
// needs root (CI runs the tests as root); where it is not permitted, mounted() is false and the
// test skips itself.
#pragma once

#include <fcntl.h>
#include <sys/mount.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <string>

namespace emaki::test {

class SmallDisk {
 public:
  // A fresh folder named after `name` and the process, with `size_bytes` of tmpfs on it.
  SmallDisk(const std::string& name, int64_t size_bytes)
      : path_(std::filesystem::temp_directory_path() /
              ("emaki_disk_" + name + "_" + std::to_string(::getpid()))) {
    std::error_code ec;
    std::filesystem::create_directories(path_, ec);
    const std::string options = "size=" + std::to_string(size_bytes) + ",mode=0755";
    mounted_ = ::mount("tmpfs", path_.c_str(), "tmpfs", 0, options.c_str()) == 0;
  }
  ~SmallDisk() {
    if (mounted_) ::umount2(path_.c_str(), MNT_DETACH);
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  SmallDisk(const SmallDisk&) = delete;
  SmallDisk& operator=(const SmallDisk&) = delete;

  bool mounted() const { return mounted_; }
  const std::filesystem::path& path() const { return path_; }
  std::string operator/(const std::string& name) const { return (path_ / name).string(); }

  // Bytes the disk still takes.
  int64_t free_bytes() const {
    struct statvfs st {};
    if (::statvfs(path_.c_str(), &st) != 0) return -1;
    return int64_t(st.f_bavail) * int64_t(st.f_bsize);
  }

  // Takes all but `keep` bytes (whole pages) with a hidden filler file; true when done.
  bool leave_free(int64_t keep) {
    release();
    const int64_t take = free_bytes() - keep;
    if (take <= 0) return take == 0;
    const int fd = ::open(filler().c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
    if (fd < 0) return false;
    const bool ok = ::posix_fallocate(fd, 0, take) == 0;
    ::close(fd);
    return ok;
  }
  // Gives the filler's space back.
  void release() {
    std::error_code ec;
    std::filesystem::remove(filler(), ec);
  }

 private:
  std::string filler() const { return (path_ / ".filler").string(); }

  std::filesystem::path path_;
  bool mounted_ = false;
};

}  // namespace emaki::test
