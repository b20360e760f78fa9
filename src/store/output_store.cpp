#include "store/output_store.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>

#include "core/error.h"
#include "core/fnv.h"
#include "core/limits.h"

namespace emaki::io {

namespace fs = std::filesystem;

// ---- the folder lock ----

FolderLock::FolderLock(const std::string& folder, Kind kind) {
  const std::string path = (fs::path(folder) / ".emaki.lock").string();
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_NOFOLLOW | O_CLOEXEC, 0644);
  if (fd_ < 0)
    throw Error(
        path, fmt::format("cannot open the output folder's lock file ({})", std::strerror(errno)));
  const int op = kind == Kind::kShared ? LOCK_SH : LOCK_EX;
  if (::flock(fd_, op | LOCK_NB) != 0) {
    const int err = errno;
    std::string holder;
    if (err == EWOULDBLOCK) {
      char buf[256] = {};
      const ssize_t n = ::pread(fd_, buf, sizeof buf - 1, 0);
      for (ssize_t i = 0; i < n; ++i) holder += (buf[i] >= 0x20 && buf[i] < 0x7f) ? buf[i] : ' ';
      while (!holder.empty() && holder.back() == ' ') holder.pop_back();
    }
    ::close(fd_);
    fd_ = -1;
    if (err != EWOULDBLOCK)
      throw Error(path, fmt::format("cannot lock the output folder ({})", std::strerror(err)));
    throw Error(path, fmt::format("the output folder is in use by another emaki ({}); wait for "
                                  "it to finish or stop it",
                                  holder.empty() ? "holder unknown" : echo(holder)));
  }
  // Shared holders all write the same words, so their writes cannot interleave into nonsense.
  if (kind == Kind::kShared) {
    const std::string text = "farm tasks of this shot\n";
    if (::ftruncate(fd_, 0) == 0) {
      const ssize_t ignored = ::pwrite(fd_, text.data(), text.size(), 0);
      (void)ignored;  // the content is informational only
    }
    return;
  }
  char host[256] = {};
  ::gethostname(host, sizeof host - 1);
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  ::gmtime_r(&now, &tm);
  char since[32] = {};
  std::strftime(since, sizeof since, "%Y-%m-%d %H:%M:%S UTC", &tm);
  const std::string text = fmt::format("pid {} on {} since {}\n", ::getpid(), host, since);
  if (::ftruncate(fd_, 0) == 0) {
    const ssize_t ignored = ::pwrite(fd_, text.data(), text.size(), 0);
    (void)ignored;  // the content is informational only
  }
}

FolderLock::~FolderLock() {
  // The file stays: removing it would let a third process lock a new file while a second one
  // still waits on the old, unlinked one.
  if (fd_ >= 0) {
    const int ignored = ::ftruncate(fd_, 0);
    (void)ignored;
    ::close(fd_);
  }
}

// ---- manifests ----

std::optional<Manifest> read_manifest(const std::string& path) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return std::nullopt;
  // A manifest is a few hundred bytes; a large file is not one of ours.
  if (st.st_size > (1 << 20)) return Manifest{"<not an emaki manifest>"};
  std::ifstream f(path);
  Manifest m;
  std::string line;
  while (std::getline(f, line)) m.push_back(line);
  return m;
}

void write_manifest(const std::string& path, const Manifest& m) {
  TempFile tmp(path, path);
  std::string text;
  for (const std::string& line : m) text += line + '\n';
  tmp.write(text.data(), text.size());
  tmp.commit();
}

std::string manifest_difference(const Manifest& have, const Manifest& want) {
  auto key_of = [](const std::string& line) { return line.substr(0, line.find(" = ")); };
  auto value_of = [](const std::string& line) {
    const std::size_t p = line.find(" = ");
    return p == std::string::npos ? std::string() : line.substr(p + 3);
  };
  for (const std::string& w : want) {
    const std::string key = key_of(w);
    const std::string* found = nullptr;
    for (const std::string& h : have)
      if (key_of(h) == key) found = &h;
    if (!found) return fmt::format("{} is new", echo(key));
    if (*found != w)
      return fmt::format("{} was {}, now {}", echo(key), echo(value_of(*found), 40),
                         echo(value_of(w), 40));
  }
  if (have.size() != want.size()) return "the settings changed";
  return {};
}

namespace {

// FNV-1a (core/fnv.h) and the length. Its start is not FNV's offset basis (14695981039346656037):
// one digit short. Kept, since manifests in existing output folders record these digests and a
// change would make every finished shot run again.
struct Digest {
  uint64_t h = 1469598103934665603ull;
  uint64_t total = 0;
  void add(const char* p, std::size_t n) {
    h = fnv1a(std::string_view(p, n), h);
    total += n;
  }
  std::string text() const { return fmt::format("{:016x}-{}", h, total); }
};

// A file's identity: what changes when its bytes do.
struct FileId {
  std::string path;
  dev_t dev;
  ino_t ino;
  off_t size;
  int64_t mtime_ns;
  auto operator<=>(const FileId&) const = default;
};

FileId id_of(const std::string& path, const struct stat& st) {
  return {path, st.st_dev, st.st_ino, st.st_size,
          int64_t(st.st_mtim.tv_sec) * 1000000000 + st.st_mtim.tv_nsec};
}

std::mutex& digests_mutex() {
  static std::mutex m;
  return m;
}
std::map<FileId, std::string>& digests() {
  static std::map<FileId, std::string> d;
  return d;
}

struct Fd {
  int fd;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

// Reads the whole of `fd` (at most `cap` bytes; nullopt past it or on an error).
std::optional<std::string> read_all(int fd, std::size_t cap) {
  std::string out;
  char buf[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return std::nullopt;
    if (n == 0) return out;
    if (out.size() + std::size_t(n) > cap) return std::nullopt;
    out.append(buf, std::size_t(n));
  }
}

}  // namespace

std::string file_digest(const std::string& path) {
  struct stat st {};
  // A file already digested is not opened again: its identity is looked up first.
  if (::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode)) {
    const std::lock_guard lock(digests_mutex());
    if (const auto it = digests().find(id_of(path, st)); it != digests().end()) return it->second;
  }
  const Fd f{::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY)};
  if (f.fd < 0 || ::fstat(f.fd, &st) != 0) return "missing";
  const FileId id = id_of(path, st);
  Digest d;
  std::vector<char> buf(1 << 20);
  for (;;) {
    const ssize_t n = ::read(f.fd, buf.data(), buf.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    d.add(buf.data(), std::size_t(n));
  }
  const std::string text = d.text();
  // Only a regular file's digest is kept: a FIFO or device has no identity to tell a change by.
  if (S_ISREG(st.st_mode)) {
    const std::lock_guard lock(digests_mutex());
    digests()[id] = text;
  }
  return text;
}

std::string bytes_digest(std::string_view bytes) {
  Digest d;
  d.add(bytes.data(), bytes.size());
  return d.text();
}

std::optional<std::string> read_input_file(const std::string& path, std::size_t cap) {
  struct stat st {};
  const Fd f{::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY)};
  if (f.fd < 0 || ::fstat(f.fd, &st) != 0 || !S_ISREG(st.st_mode) || uint64_t(st.st_size) > cap)
    return std::nullopt;
  std::optional<std::string> bytes = read_all(f.fd, cap);
  // A file that changed size while it was read is read again the ordinary way.
  if (!bytes || bytes->size() != std::size_t(st.st_size)) return std::nullopt;
  const std::string digest = bytes_digest(*bytes);
  const std::lock_guard lock(digests_mutex());
  digests()[id_of(path, st)] = digest;
  return bytes;
}

}  // namespace emaki::io
