// Where a run's time goes: wall and CPU seconds (the process's, every thread's, and its finished
// child processes') charged to the stage of the work that is current, for `emaki run --timings`
// and bench/farm_bench.sh, which sets a run's stages beside the farm's tasks of the same kinds.
// Measuring never changes a result. Stages follow one another on one thread (the work inside
// one may use many threads).
#pragma once

#include <array>
#include <chrono>

namespace emaki {

class StageClock {
 public:
  // The farm's task kinds (shot/plan.h), which a run's work falls into: prepare (inputs read and
  // checked, the exemplars' reference passes), passes (the frames' guide passes rendered or read
  // and their advection fields), layers (synthesis and the layer files), composite (compositing
  // and the frame's outputs), previews (contact sheet and MP4).
  enum Stage { kPrepare, kPasses, kLayers, kComposite, kPreviews, kStageCount };
  static const char* name(Stage s);

  struct Seconds {
    double wall = 0.0, cpu = 0.0;
  };

  // Starts now, in kPrepare.
  StageClock();
  // Charges the time since the last switch to the current stage, then makes `s` current;
  // returns the stage that was.
  Stage enter(Stage s);
  // What `s` was charged, with the current stage's time up to now.
  Seconds seconds(Stage s) const;

 private:
  struct Stamp {
    std::chrono::steady_clock::time_point wall;
    double cpu = 0.0;
  };
  static Stamp now();

  Stage current_ = kPrepare;
  Stamp since_;
  std::array<Seconds, kStageCount> charged_{};
};

// While it lives, `clock` (null: nothing is measured) charges stage `s`; then the stage before.
class StageScope {
 public:
  StageScope(StageClock* clock, StageClock::Stage s)
      : clock_(clock), previous_(clock ? clock->enter(s) : s) {}
  ~StageScope() {
    if (clock_) clock_->enter(previous_);
  }
  StageScope(const StageScope&) = delete;
  StageScope& operator=(const StageScope&) = delete;

 private:
  StageClock* clock_;
  StageClock::Stage previous_;
};

}  // namespace emaki
