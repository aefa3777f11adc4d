// Clocks: the manual clock moves only when told and never backwards; the system clock is
// monotonic. Example failure: a ManualClock that drifts per frame makes replays inexact.

#include <gtest/gtest.h>

#include "runtime/clock.h"

namespace basalt {
namespace {

TEST(ManualClock, MovesOnlyWhenAdvanced) {
  ManualClock clock(Nanos{100});
  EXPECT_EQ(clock.now(), Nanos{100});
  clock.advance(Nanos{50});
  EXPECT_EQ(clock.now(), Nanos{150});
  EXPECT_TRUE(clock.isManual());
}

TEST(ManualClock, NeverGoesBackwards) {
  ManualClock clock(Nanos{1000});
  clock.set(Nanos{10});
  EXPECT_EQ(clock.now(), Nanos{1000});
  clock.advance(Nanos{-5});
  EXPECT_EQ(clock.now(), Nanos{1000});
  clock.set(Nanos{2000});
  EXPECT_EQ(clock.now(), Nanos{2000});
}

TEST(ManualClock, WallTimeFollowsMonotonicTime) {
  const WallTime origin = WallTime{} + std::chrono::hours(24 * 365 * 50);
  ManualClock clock(Nanos{0}, origin);
  clock.advance(std::chrono::seconds(90));
  EXPECT_EQ(clock.wallNow() - origin, std::chrono::seconds(90));
}

TEST(FrameTime, IsExactWithoutDrift) {
  // Frame 3600 at 60 fps is exactly 60 s; accumulating 1/60 in floating point would drift.
  EXPECT_EQ(frameTime(3600, 60.0), std::chrono::seconds(60));
  EXPECT_EQ(frameTime(1, 30.0), Nanos{33'333'333});
  EXPECT_EQ(frameTime(30000, 30000.0 / 1001.0), std::chrono::seconds(1001));  // NTSC rate
}

TEST(SystemClock, IsMonotonic) {
  SystemClock clock;
  const Nanos a = clock.now();
  const Nanos b = clock.now();
  EXPECT_LE(a, b);
  EXPECT_FALSE(clock.isManual());
}

}  // namespace
}  // namespace basalt
