#include "farm/farm_state.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstring>

#include "core/error.h"
#include "core/limits.h"

namespace emaki::farm {

namespace {

struct Fd {
  int fd = -1;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

// Opens `path` for reading without blocking (a FIFO with no writer would block a plain open) and
// checks that it is a regular file. nullopt when there is nothing at `path`.
std::optional<off_t> open_regular(const std::string& path, Fd& f) {
  f.fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (f.fd < 0) {
    if (errno == ENOENT) return std::nullopt;
    throw Error(path, fmt::format("cannot be read: {}", std::strerror(errno)));
  }
  struct stat st {};
  if (::fstat(f.fd, &st) != 0)
    throw Error(path, fmt::format("cannot be read: {}", std::strerror(errno)));
  if (!S_ISREG(st.st_mode))
    throw Error(path, "is not a regular file (a FIFO, device or folder); remove it");
  return st.st_size;
}

// Reads at most `cap` + 1 bytes from the current offset: one more than allowed tells a file that
// grew past the cap while it was read.
std::string read_up_to(const std::string& path, int fd, std::size_t cap) {
  std::string out;
  char buf[1 << 16];
  while (out.size() <= cap) {
    const ssize_t got = ::read(fd, buf, std::min(sizeof buf, cap + 1 - out.size()));
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) throw Error(path, fmt::format("cannot be read: {}", std::strerror(errno)));
    if (got == 0) break;
    out.append(buf, std::size_t(got));
  }
  return out;
}

bool decimal(std::string_view s) {
  return !s.empty() && s.size() <= 18 && s.find_first_not_of("0123456789") == std::string::npos;
}

}  // namespace

std::optional<std::string> read_state_file(const std::string& path, std::size_t cap) {
  Fd f;
  const std::optional<off_t> size = open_regular(path, f);
  if (!size) return std::nullopt;
  const auto too_big = [&](std::size_t n) {
    return Error(
        path, fmt::format("holds {} bytes, more than the {} a farm record may; remove it", n, cap));
  };
  if (std::size_t(*size) > cap) throw too_big(std::size_t(*size));
  std::string text = read_up_to(path, f.fd, cap);
  if (text.size() > cap) throw too_big(text.size());
  return text;
}

std::optional<std::string> read_file_tail(const std::string& path, std::size_t tail) {
  Fd f;
  const std::optional<off_t> size = open_regular(path, f);
  if (!size) return std::nullopt;
  if (std::size_t(*size) > tail && ::lseek(f.fd, *size - off_t(tail), SEEK_SET) < 0)
    throw Error(path, fmt::format("cannot be read: {}", std::strerror(errno)));
  std::string text = read_up_to(path, f.fd, tail);
  if (text.size() > tail) text.resize(tail);
  return text;
}

std::map<std::string, std::string> parse_jobs(std::string_view text, const std::string& subject) {
  std::map<std::string, std::string> jobs;
  std::size_t line_no = 0;
  while (!text.empty()) {
    ++line_no;
    const std::size_t end = text.find('\n');
    const std::string_view line = text.substr(0, end);
    text = end == std::string_view::npos ? std::string_view() : text.substr(end + 1);
    if (line.empty()) continue;
    const std::size_t a = line.find('\t'), b = line.find('\t', a + 1);
    const auto bad = [&]() {
      return Error(subject, fmt::format("line {} is not a record 'TASK<tab>JOB<tab>INDEX': '{}'; "
                                        "remove the file if no job of the shot is queued",
                                        line_no, echo(line, 60)));
    };
    if (a == 0 || a == std::string_view::npos || b == std::string_view::npos) throw bad();
    const std::string_view task = line.substr(0, a), job = line.substr(a + 1, b - a - 1),
                           index = line.substr(b + 1);
    for (const char c : task)
      if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) throw bad();
    if (!decimal(job) || !decimal(index)) throw bad();
    jobs[std::string(task)] = fmt::format("{}_{}", job, index);
  }
  return jobs;
}

std::string job_record(const std::string& task, const std::string& job, std::size_t index) {
  return fmt::format("{}\t{}\t{}\n", task, job, index);
}

int parse_chunk(std::string_view text, const std::string& subject) {
  if (!text.empty() && text.back() == '\n') text.remove_suffix(1);
  int chunk = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), chunk);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size() || chunk < 1 ||
      chunk > kMaxFrameCount)
    throw Error(subject, fmt::format("is not a chunk of frames in [1, {}]: '{}'; submit the shot "
                                     "again or pass --chunk",
                                     kMaxFrameCount, echo(text, 40)));
  return chunk;
}

int parse_threads(std::string_view text, const std::string& subject) {
  if (!text.empty() && text.back() == '\n') text.remove_suffix(1);
  int threads = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), threads);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size() || threads < 1 ||
      threads > 1024)
    throw Error(subject, fmt::format("is not a number of threads in [1, 1024]: '{}'; submit the "
                                     "shot again or pass --threads",
                                     echo(text, 40)));
  return threads;
}

std::optional<int> parse_exit_code(std::string_view text) {
  if (!text.empty() && text.back() == '\n') text.remove_suffix(1);
  if (!decimal(text) || text.size() > 3) return std::nullopt;
  const int code = std::stoi(std::string(text));
  if (code > 255) return std::nullopt;
  return code;
}

std::map<std::string, QueuedJob> parse_queue(std::string_view text) {
  std::map<std::string, QueuedJob> q;
  while (!text.empty()) {
    const std::size_t end = text.find('\n');
    const std::string_view line = text.substr(0, end);
    text = end == std::string_view::npos ? std::string_view() : text.substr(end + 1);
    // The job name comes last: it is the one field a user chooses, and may hold '|'.
    const std::size_t a = line.find('|'), b = line.find('|', a + 1), c = line.find('|', b + 1);
    if (a == std::string_view::npos || b == std::string_view::npos || c == std::string_view::npos)
      continue;
    std::string id(line.substr(0, a));
    const std::size_t underscore = id.find('_');
    if (underscore == std::string::npos) id += "_0";
    if (!decimal(std::string_view(id).substr(0, id.find('_')))) continue;
    q[id] = {std::string(line.substr(a + 1, b - a - 1)), std::string(line.substr(b + 1, c - b - 1)),
             std::string(line.substr(c + 1))};
  }
  return q;
}

}  // namespace emaki::farm
