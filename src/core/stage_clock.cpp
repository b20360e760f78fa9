#include "core/stage_clock.h"

#include <sys/resource.h>

#include <ctime>

namespace emaki {

const char* StageClock::name(Stage s) {
  switch (s) {
    case kPrepare:
      return "prepare";
    case kPasses:
      return "passes";
    case kLayers:
      return "layers";
    case kComposite:
      return "composite";
    case kPreviews:
      return "previews";
    case kStageCount:
      break;
  }
  return "?";
}

// The process's CPU time, every thread's, and its finished children's (ffmpeg writing the MP4).
StageClock::Stamp StageClock::now() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  rusage children{};
  getrusage(RUSAGE_CHILDREN, &children);
  const auto seconds = [](const timeval& v) { return double(v.tv_sec) + 1e-6 * double(v.tv_usec); };
  return {std::chrono::steady_clock::now(), double(t.tv_sec) + 1e-9 * double(t.tv_nsec) +
                                                seconds(children.ru_utime) +
                                                seconds(children.ru_stime)};
}

StageClock::StageClock() : since_(now()) {}

StageClock::Stage StageClock::enter(Stage s) {
  const Stamp t = now();
  Seconds& c = charged_[current_];
  c.wall += std::chrono::duration<double>(t.wall - since_.wall).count();
  c.cpu += t.cpu - since_.cpu;
  since_ = t;
  const Stage was = current_;
  current_ = s;
  return was;
}

StageClock::Seconds StageClock::seconds(Stage s) const {
  Seconds r = charged_[s];
  if (s == current_) {
    const Stamp t = now();
    r.wall += std::chrono::duration<double>(t.wall - since_.wall).count();
    r.cpu += t.cpu - since_.cpu;
  }
  return r;
}

}  // namespace emaki
