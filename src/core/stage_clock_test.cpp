// StageClock: time goes to the stage that is current, nested scopes hand it back.
#include "core/stage_clock.h"

#include <gtest/gtest.h>

#include <ctime>

namespace emaki {
namespace {

double process_cpu() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// Spins until this process has used `seconds` more CPU time.
void burn(double seconds) {
  const double end = process_cpu() + seconds;
  volatile double sink = 0.0;
  while (process_cpu() < end)
    for (int i = 0; i < 1000; ++i) sink = sink + 1.0;
}

double cpu_sum(const StageClock& c) {
  double s = 0.0;
  for (int k = 0; k < StageClock::kStageCount; ++k) s += c.seconds(StageClock::Stage(k)).cpu;
  return s;
}

TEST(StageClock, ChargesTheInnermostStageAndRestoresTheOuter) {
  const double start = process_cpu();
  StageClock clock;
  {
    const StageScope layers(&clock, StageClock::kLayers);
    {
      const StageScope passes(&clock, StageClock::kPasses);
      burn(0.05);
    }
    EXPECT_EQ(clock.enter(StageClock::kLayers), StageClock::kLayers);  // restored
    burn(0.02);
  }
  EXPECT_EQ(clock.enter(StageClock::kPrepare), StageClock::kPrepare);
  const double sum = cpu_sum(clock);  // up to its own reading of the clock, before the next
  const double total = process_cpu() - start;
  EXPECT_GE(clock.seconds(StageClock::kPasses).cpu, 0.05);
  EXPECT_GE(clock.seconds(StageClock::kLayers).cpu, 0.02);
  EXPECT_LT(clock.seconds(StageClock::kLayers).cpu, clock.seconds(StageClock::kPasses).cpu);
  EXPECT_EQ(clock.seconds(StageClock::kComposite).cpu, 0.0);
  EXPECT_EQ(clock.seconds(StageClock::kComposite).wall, 0.0);
  // Every moment is charged to exactly one stage.
  EXPECT_LE(sum, total);
  EXPECT_GE(sum, 0.07);
  EXPECT_GE(clock.seconds(StageClock::kPasses).wall, 0.0);
}

TEST(StageClock, NamesTheFarmsTaskKinds) {
  EXPECT_STREQ(StageClock::name(StageClock::kPrepare), "prepare");
  EXPECT_STREQ(StageClock::name(StageClock::kPasses), "passes");
  EXPECT_STREQ(StageClock::name(StageClock::kLayers), "layers");
  EXPECT_STREQ(StageClock::name(StageClock::kComposite), "composite");
  EXPECT_STREQ(StageClock::name(StageClock::kPreviews), "previews");
}

}  // namespace
}  // namespace emaki
