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

#include "core/error.h"
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

std::string file_digest(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) return "missing";
  // FNV-1a: fast enough for paintings and pass files, and only compared with itself (not a
  // security boundary: a changed file is redone, a forged one is the user's own).
  uint64_t h = 1469598103934665603ull;
  std::vector<char> buf(1 << 20);
  uint64_t total = 0;
  while (f) {
    f.read(buf.data(), std::streamsize(buf.size()));
    const std::size_t n = std::size_t(f.gcount());
    for (std::size_t i = 0; i < n; ++i) {
      h ^= static_cast<unsigned char>(buf[i]);
      h *= 1099511628211ull;
    }
    total += n;
  }
  return fmt::format("{:016x}-{}", h, total);
}

}  // namespace emaki::io
