#include "io/temp_file.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>

#include "core/error.h"
#include "core/limits.h"

namespace emaki::io {

namespace fs = std::filesystem;

namespace {

constexpr const char* kTempMark = ".emaki-tmp-";
constexpr std::size_t kTempMarkSize = 11;
constexpr std::size_t kRandomDigits = 16;

bool is_hex(const std::string& s) {
  for (char c : s)
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  return true;
}

}  // namespace

unsigned long long random_u64() {
  unsigned long long v = 0;
  std::size_t got = 0;
  auto* bytes = reinterpret_cast<unsigned char*>(&v);
  while (got < sizeof v) {
    const ssize_t n = ::getrandom(bytes + got, sizeof v - got, 0);
    if (n < 0) {
      if (errno == EINTR) continue;
      // No getrandom (very old kernel): time and address entropy still make the name hard to
      // guess, and O_EXCL keeps a guessed name harmless.
      v ^= static_cast<unsigned long long>(
               std::chrono::high_resolution_clock::now().time_since_epoch().count()) ^
           reinterpret_cast<uintptr_t>(&v) ^ (static_cast<unsigned long long>(::getpid()) << 32);
      break;
    }
    got += std::size_t(n);
  }
  return v;
}

TempFile::TempFile(const std::string& target, const std::string& subject)
    : target_(target), subject_(subject) {
  const fs::path t(target);
  const std::string stem = t.stem().string(), ext = t.extension().string();
  // A few tries: a collision of 64 random bits only happens when someone planted the name.
  for (int attempt = 0; attempt < 8 && fd_ < 0; ++attempt) {
    path_ = (t.parent_path() / fmt::format(".{}{}{:016x}{}", stem, kTempMark, random_u64(), ext))
                .string();
    fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (fd_ < 0 && errno != EEXIST)
      throw Error(subject_, fmt::format("cannot create a temporary file beside it ({})",
                                        std::strerror(errno)));
  }
  if (fd_ < 0) throw Error(subject_, "cannot create a temporary file beside it (names taken)");
  struct stat st {};
  ::fstat(fd_, &st);
  dev_ = st.st_dev;
  ino_ = st.st_ino;
}

void TempFile::write(const void* data, std::size_t size) {
  const auto* p = static_cast<const char*>(data);
  std::size_t done = 0;
  while (done < size) {
    const ssize_t n = ::write(fd_, p + done, size - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0)
      fail_unsaved(n < 0 ? std::strerror(errno) : "the disk took no more bytes (disk full?)");
    done += std::size_t(n);
  }
  written_ += size;
}

void TempFile::fail_unsaved(const std::string& why) const {
  throw Error(subject_, fmt::format("could not be written ({}); nothing was replaced", why));
}

TempFile::~TempFile() {
  if (fd_ >= 0) ::close(fd_);
  if (!committed_) {
    // Only our own file: if the name now points elsewhere, leave it for the user to see.
    struct stat st {};
    if (::lstat(path_.c_str(), &st) == 0 && S_ISREG(st.st_mode) && st.st_dev == dev_ &&
        st.st_ino == ino_)
      ::unlink(path_.c_str());
  }
}

int TempFile::release_fd() {
  const int fd = fd_;
  fd_ = -1;
  return fd;
}

void TempFile::commit(const std::function<void(const std::string& path)>& verify) {
  // Writers that take a path (OpenImageIO, ffmpeg) reopen the name: check it still names the
  // file we created, not a symlink or file swapped in meanwhile.
  struct stat st {};
  auto ours = [&] { return S_ISREG(st.st_mode) && st.st_dev == dev_ && st.st_ino == ino_; };
  if (::lstat(path_.c_str(), &st) != 0 || !ours())
    throw Error(subject_,
                fmt::format("its temporary file '{}' was replaced while writing", echo(path_)));
  // A writer that was given the descriptor has closed it: the file is opened again to sync it.
  if (fd_ < 0) {
    fd_ = ::open(path_.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
    if (fd_ < 0 || ::fstat(fd_, &st) != 0 || !ours())
      throw Error(subject_,
                  fmt::format("its temporary file '{}' was replaced while writing", echo(path_)));
  }
  // Delayed allocation and network file systems report a full disk here, not at write().
  if (::fsync(fd_) != 0) fail_unsaved(fmt::format("fsync: {}", std::strerror(errno)));
  if (::fstat(fd_, &st) != 0) fail_unsaved(fmt::format("fstat: {}", std::strerror(errno)));
  if (st.st_size == 0) fail_unsaved("the file is empty (disk full?)");
  if (written_ > 0 && (unsigned long long)st.st_size != written_)
    fail_unsaved(fmt::format("{} of {} bytes reached the disk", st.st_size, written_));
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0) fail_unsaved(fmt::format("close: {}", std::strerror(errno)));
  if (verify) {
    verify(path_);
    if (::lstat(path_.c_str(), &st) != 0 || !ours())
      throw Error(subject_,
                  fmt::format("its temporary file '{}' was replaced while writing", echo(path_)));
  }
  if (::rename(path_.c_str(), target_.c_str()) != 0)
    throw Error(subject_,
                fmt::format("cannot move the finished file into place ({})", std::strerror(errno)));
  committed_ = true;
}

bool is_temporary_name(const std::string& name, std::string* target_name) {
  if (name.size() < 2 || name[0] != '.') return false;
  const std::size_t mark = name.rfind(kTempMark);
  if (mark == std::string::npos || mark < 1) return false;
  const std::size_t digits = mark + kTempMarkSize;
  if (name.size() < digits + kRandomDigits) return false;
  if (!is_hex(name.substr(digits, kRandomDigits))) return false;
  const std::string ext = name.substr(digits + kRandomDigits);
  if (!ext.empty() && (ext[0] != '.' || ext.find('/') != std::string::npos)) return false;
  if (target_name) *target_name = name.substr(1, mark - 1) + ext;
  return true;
}

void remove_temporaries(const std::string& dir,
                        const std::function<bool(const std::string&)>& ours) {
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    std::string target;
    if (!is_temporary_name(name, &target) || !ours(target)) continue;
    struct stat st {};
    if (::lstat(entry.path().c_str(), &st) != 0 || !S_ISREG(st.st_mode) || st.st_uid != ::geteuid())
      continue;
    fs::remove(entry.path(), ec);
  }
}
}  // namespace emaki::io
