#include "apps/emaki/shot_command.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "apps/emaki/frame_range.h"
#include "core/error.h"
#include "core/limits.h"

namespace emaki::app {

std::vector<std::string> split_commas(const std::string& text) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (start < text.size()) {
    const std::size_t end = std::min(text.find(',', start), text.size());
    if (end > start) out.push_back(text.substr(start, end - start));
    start = end + 1;
  }
  return out;
}

int64_t parse_memory_mb(const std::string& option, const std::string& text) {
  std::size_t used = 0;
  long long n = -1;
  try {
    n = std::stoll(text, &used);
  } catch (const std::exception&) {
  }
  const std::string unit = text.substr(std::min(used, text.size()));
  const int shift = unit.empty() || unit == "M" ? 0 : unit == "G" ? 10 : unit == "T" ? 20 : -1;
  // At most 2^40 MB: the figure in bytes must fit an int64.
  if (n < 1 || shift < 0 || text[0] == '+' || n > (int64_t(1) << (40 - std::max(shift, 0))))
    throw Error(option, fmt::format("expected a size in MB, or with M, G or T (e.g. 8G), got '{}'",
                                    echo(text)));
  return int64_t(n) << shift;
}

namespace {

std::string duration(double s) {
  if (!std::isfinite(s) || s < 0) return "?";
  const int t = int(std::lround(s));
  return t >= 3600 ? fmt::format("{}h{:02d}m", t / 3600, t / 60 % 60)
                   : fmt::format("{}m{:02d}s", t / 60, t % 60);
}

}  // namespace

std::function<void(const pipeline::Progress&)> progress_printer(const char* command) {
  const bool tty = ::isatty(2);
  return [tty, command](const pipeline::Progress& p) {
    std::string line;
    if (p.layer.empty()) {
      line = fmt::format("emaki {}: frame {} compositing", command, p.frame);
    } else {
      const double eta = p.done > 0 ? p.elapsed_s / p.done * (p.total - p.done) : NAN;
      line =
          fmt::format("emaki {}: frame {} layer {} ({}/{}, {} elapsed, ETA {})", command, p.frame,
                      p.layer, p.done + 1, p.total, duration(p.elapsed_s), duration(eta));
    }
    if (tty)
      std::fprintf(stderr, "\r\033[K%s", line.c_str());
    else
      std::fprintf(stderr, "%s\n", line.c_str());
    std::fflush(stderr);
  };
}

void end_progress_line() {
  if (::isatty(2)) std::fprintf(stderr, "\n");
}

void ShotCommand::bind(CLI::App& app, const char* frames_help) {
  app.add_option("shot", shot_path, "the shot file (TOML; see docs/shot_file.md)")->required();
  app.add_option("--frames", frames, frames_help);
  app.add_option("--threads", threads, "worker threads, >= 0; 0 = all cores (default: the shot's)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--max-memory", max_memory,
                 "refuse to start when the estimated peak memory exceeds this: MB, or a number "
                 "with M, G or T (e.g. 8G); what the machine has available is always checked");
}

void ShotCommand::bind_previews(CLI::App& app) {
  app.add_flag("--no-previews", no_previews, "do not write the contact sheet and the MP4");
}

shot::Request ShotCommand::request(const char* command) const {
  shot::Request r;
  if (!frames.empty()) {
    const FrameRange range = parse_frame_range("--frames", frames);
    r.first_frame = range.first;
    r.last_frame = range.last;
  }
  r.layers = split_commas(layers);
  r.previews = !no_previews;
  r.qa_maps = request_maps;
  r.threads = threads;
  if (!max_memory.empty()) r.max_memory_mb = parse_memory_mb("--max-memory", max_memory);
  r.progress = progress_printer(command);
  return r;
}

}  // namespace emaki::app
