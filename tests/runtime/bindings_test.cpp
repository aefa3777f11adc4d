// Bindings beyond LAVA's table: the show's gain, acceleration (a fast turn goes further than the
// same turn made slowly), per-dial overrides and inversion, absolute dials turned into motion,
// shuttle rings that keep turning while held and stop when their device is lost, and the action
// names a manifest uses.
// Example failures: acceleration applied to slow turns; an absolute dial's first reading jumping
// the object; a shuttle ring that keeps the object spinning after the Shuttle is unplugged.

#include <gtest/gtest.h>

#include <cmath>

#include "runtime/bindings.h"

namespace basalt::runtime {
namespace {

float angleY(const Show& show) {
  // rotationY(a): m[8] = sin(a) (column-major third column, first row).
  return std::atan2(show.position().global.m[8], show.position().global.m[0]) * 180.0f / 3.14159265f;
}

Event dial(std::uint16_t index, double turns, Nanos t = Nanos{0}, EventKind kind = EventKind::kDialDelta) {
  return Event{t, 1, kind, index, turns};
}

TEST(BindingsExtended, GainScalesEveryDialAndInvertFlips) {
  Bindings b = Bindings::lavaDefaults();
  b.setGain(0.5);
  Show show;
  ASSERT_TRUE(b.apply(dial(1, 0.25), show));
  EXPECT_NEAR(angleY(show), 45, 1e-3);
  DialBinding d = b.dial(1);
  d.invert = true;
  b.setDial(1, d);
  ASSERT_TRUE(b.apply(dial(1, 0.25), show));
  EXPECT_NEAR(angleY(show), 0, 1e-3);
}

TEST(BindingsExtended, AccelerationRewardsSpeedOnly) {
  Bindings b = Bindings::lavaDefaults();
  b.setAcceleration(1.0);
  Show slow;
  // Ten slow steps of 1/100 turn, a second apart: speed 0.04 turns/s (one step per 0.25 s cap).
  for (int i = 0; i < 10; ++i) b.apply(dial(1, 0.01, std::chrono::seconds(i)), slow);
  b.reset();
  Show fast;
  // The same ten steps 5 ms apart: 2 turns per second.
  for (int i = 0; i < 10; ++i) b.apply(dial(1, 0.01, std::chrono::milliseconds(5 * i)), fast);
  EXPECT_NEAR(angleY(slow), 36 * 1.04, 0.05);
  EXPECT_GT(angleY(fast), angleY(slow) * 2) << "a fast turn must go further";
}

TEST(BindingsExtended, PerDialOverrideAndNames) {
  Bindings b = Bindings::lavaDefaults();
  b.setDial(7, {Action::kRotateY, 180});  // LAVA's idle dial 7 now turns Y, half as fast
  Show show;
  ASSERT_TRUE(b.apply(dial(7, 0.5), show));
  EXPECT_NEAR(angleY(show), 90, 1e-3);
  EXPECT_EQ(actionByName("translate_z"), Action::kTranslateZ);
  EXPECT_EQ(actionName(Action::kScale), "scale");
  EXPECT_FALSE(actionByName("spin"));
  EXPECT_FALSE(b.apply(dial(40, 1.0), show)) << "dials past the table do nothing";
}

TEST(BindingsExtended, AbsoluteDialsMoveByTheirChange) {
  Bindings b = Bindings::lavaDefaults();
  Show show;
  EXPECT_FALSE(b.apply(dial(1, 0.6, Nanos{0}, EventKind::kDialAbsolute), show))
      << "the first reading only sets the origin";
  EXPECT_NEAR(angleY(show), 0, 1e-3);
  ASSERT_TRUE(b.apply(dial(1, 0.85, Nanos{0}, EventKind::kDialAbsolute), show));
  EXPECT_NEAR(angleY(show), 90, 1e-3);
}

TEST(BindingsExtended, ShuttleTurnsWhileHeldAndStopsWhenItsDeviceIsLost) {
  Bindings b = Bindings::lavaDefaults();
  b.setShuttleTurnsPerSecond(0.5);
  Show show;
  b.apply(Event{Nanos{0}, 9, EventKind::kShuttle, 1, 0.5}, show);  // ring half right on dial 1 (Y)
  ASSERT_TRUE(b.advance(std::chrono::milliseconds(500), show));    // 0.5 * 0.5 * 0.5 s = 1/8 turn
  EXPECT_NEAR(angleY(show), 45, 1e-3);
  b.apply(Event{Nanos{0}, 3, EventKind::kDeviceState, 0, 0}, show);  // another device lost: no effect
  EXPECT_TRUE(b.advance(std::chrono::milliseconds(100), show));
  b.apply(Event{Nanos{0}, 9, EventKind::kDeviceState, 0, 0}, show);  // the Shuttle is unplugged
  EXPECT_FALSE(b.advance(std::chrono::seconds(1), show)) << "nothing keeps spinning";
}

}  // namespace
}  // namespace basalt::runtime

namespace basalt::runtime {
namespace {

// The Zoom picture on dials: move_zoom_x/y turns are collected in output pixels for the movie
// streams and leave the object where it is. Failure caught: a zoom dial that also turns the
// object, a move counted twice (not cleared when taken), the wrong direction when inverted.
TEST(BindingsExtended, ZoomDialsMoveThePictureNotTheObject) {
  Bindings b = Bindings::lavaDefaults();
  b.setDial(6, {Action::kMoveZoomX, 320});
  b.setDial(7, {Action::kMoveZoomY, 240, 0, true});
  Show show = Show::makeDefault();
  const Mat4 before = show.position().global;
  EXPECT_TRUE(b.apply(Event{Nanos{0}, 1, EventKind::kDialDelta, 6, 0.25}, show));
  EXPECT_TRUE(b.apply(Event{Nanos{0}, 1, EventKind::kDialDelta, 7, 0.5}, show));
  EXPECT_TRUE(b.apply(Event{Nanos{0}, 1, EventKind::kDialDelta, 6, 0.25}, show));
  EXPECT_EQ(show.position().global.m, before.m) << "the object does not move";
  const Bindings::ZoomMove m = b.takeZoomMove();
  EXPECT_FLOAT_EQ(m.dx, 160.0f);
  EXPECT_FLOAT_EQ(m.dy, -120.0f) << "inverted";
  const Bindings::ZoomMove none = b.takeZoomMove();
  EXPECT_EQ(none.dx, 0.0f);
  EXPECT_EQ(none.dy, 0.0f);
  EXPECT_EQ(actionByName("move_zoom_x"), Action::kMoveZoomX);
  EXPECT_EQ(actionName(Action::kMoveZoomY), "move_zoom_y");
}

TEST(BindingsExtended, ViewerDialsWalkAndTurnTheViewer) {
  // A dial box bound to the walk-through viewer (thesis §4.6): walking goes along the heading,
  // turning right turns the heading, the map bounds hold, and the object itself stays put.
  // Example failure: a walk dial that moves the object instead of the viewer, or walks north
  // whatever the heading.
  Bindings b = Bindings::lavaDefaults();
  b.setDial(0, {Action::kWalk, 2});
  b.setDial(1, {Action::kTurn, 90});
  b.setDial(2, {Action::kTilt, 90});
  b.setDial(3, {Action::kRise, 2});
  b.setDial(4, {Action::kStrafe, 2});
  Show show = Show::makeDefault();
  show.viewer().mapMin = {-10, -10, -10};
  show.viewer().mapMax = {10, 10, 10};
  const Mat4 object = show.position().global;
  ASSERT_TRUE(b.apply(dial(0, 0.5), show));  // one unit ahead: -Z at heading 0
  EXPECT_NEAR(show.viewer().position.z, -1.0f, 1e-5f);
  EXPECT_NEAR(show.viewer().position.x, 0.0f, 1e-5f);
  EXPECT_TRUE(show.viewer().fromScene);
  ASSERT_TRUE(b.apply(dial(1, 1.0), show));  // a quarter turn to the right: facing +X
  EXPECT_NEAR(show.viewer().rotation.y, -90.0f, 1e-4f);
  ASSERT_TRUE(b.apply(dial(0, 0.5), show));
  EXPECT_NEAR(show.viewer().position.x, 1.0f, 1e-5f);
  EXPECT_NEAR(show.viewer().position.z, -1.0f, 1e-5f);
  ASSERT_TRUE(b.apply(dial(4, 0.5), show));  // sideways to the right of +X is +Z
  EXPECT_NEAR(show.viewer().position.z, 0.0f, 1e-5f);
  ASSERT_TRUE(b.apply(dial(3, 0.25), show));
  EXPECT_NEAR(show.viewer().position.y, 0.5f, 1e-5f);
  ASSERT_TRUE(b.apply(dial(2, 5.0), show));  // tilting stops short of straight down
  EXPECT_NEAR(show.viewer().rotation.x, 89.0f, 1e-4f);
  ASSERT_TRUE(b.apply(dial(0, 100.0), show));  // the map's edge holds
  EXPECT_NEAR(show.viewer().position.x, 10.0f, 1e-5f);
  EXPECT_EQ(show.position().global.m, object.m) << "the object does not move";
  for (const char* name : {"walk", "strafe", "rise", "turn", "tilt"}) {
    ASSERT_TRUE(actionByName(name)) << name;
    EXPECT_EQ(actionName(*actionByName(name)), name);
  }
}

}  // namespace
}  // namespace basalt::runtime
