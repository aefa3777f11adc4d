// The thesis' set-up keys (Appendix B, "general runtime commands") read from key events:
// "Ctrl-c toggle control mode [...] c toggle cave mode, F toggle fog, s toggle smooth shading,
// n toggle surface normal display, Ctrl-d toggle light token display, Ctrl-l toggle lighting,
// p toggle pause, t toggle stereo mode, f draw surfaces as filled polygons (default), P draw
// surfaces as vertex points, w draw surfaces as lines(wireframe) [...] Esc exit program", and
// what each does to the Show, and that a second press brings back what the first took away.
//
// Example failures: Ctrl-l taken as the cave's small Yskew key; F and f confused; auto-repeat
// toggling back and forth while a key is held; keys acting while control mode is off; the fog
// toggle forgetting the scene's fog function.

#include <gtest/gtest.h>

#include "runtime/setup_keys.h"

namespace basalt::runtime {
namespace {

Event key(std::uint16_t code, double value = 1) {
  Event e;
  e.kind = EventKind::kKey;
  e.index = code;
  e.value = value;
  return e;
}

// Linux key codes, from linux/input-event-codes.h.
constexpr std::uint16_t kEsc = 1, kW = 17, kT = 20, kP = 25, kCtrl = 29, kS = 31, kD = 32, kF = 33, kL = 38,
                        kShift = 42, kC = 46, kN = 49;

std::optional<SetupToggle> press(SetupToggles& t, std::uint16_t code, std::uint16_t modifier = 0) {
  if (modifier) t.key(key(modifier, 1));
  const auto r = t.key(key(code, 1));
  t.key(key(code, 0));
  if (modifier) t.key(key(modifier, 0));
  return r;
}

TEST(SetupKeys, EachKeyOfAppendixBNamesItsToggle) {
  SetupToggles t;
  EXPECT_EQ(press(t, kC), SetupToggle::kCaveMode);
  EXPECT_EQ(press(t, kT), SetupToggle::kStereo);
  EXPECT_EQ(press(t, kF, kShift), SetupToggle::kFog);
  EXPECT_EQ(press(t, kF), SetupToggle::kFilled);
  EXPECT_EQ(press(t, kS), SetupToggle::kSmoothShading);
  EXPECT_EQ(press(t, kS, kShift), std::nullopt) << "S is the cave's base-side key";
  EXPECT_EQ(press(t, kN), SetupToggle::kNormals);
  EXPECT_EQ(press(t, kD, kCtrl), SetupToggle::kLightTokens);
  EXPECT_EQ(press(t, kL, kCtrl), SetupToggle::kLighting);
  EXPECT_EQ(press(t, kL), std::nullopt) << "l alone is the cave's Yskew key";
  EXPECT_EQ(press(t, kP), SetupToggle::kPause);
  EXPECT_EQ(press(t, kP, kShift), SetupToggle::kPoints);
  EXPECT_EQ(press(t, kW), SetupToggle::kWireframe);
  EXPECT_EQ(press(t, kEsc), SetupToggle::kExit);
  EXPECT_EQ(t.key(key(kT, 2)), std::nullopt) << "auto-repeat toggles nothing";
}

TEST(SetupKeys, ControlModeOffLeavesOnlyCtrlC) {
  SetupToggles t;
  Show show;
  ASSERT_EQ(press(t, kC, kCtrl), SetupToggle::kControlMode);
  t.apply(SetupToggle::kControlMode, show);
  EXPECT_FALSE(t.controlMode());
  EXPECT_EQ(press(t, kF, kShift), std::nullopt);
  EXPECT_EQ(press(t, kL, kCtrl), std::nullopt);
  EXPECT_EQ(press(t, kEsc), std::nullopt);
  ASSERT_EQ(press(t, kC, kCtrl), SetupToggle::kControlMode);
  t.apply(SetupToggle::kControlMode, show);
  EXPECT_TRUE(t.controlMode());
}

TEST(SetupKeys, EachToggleChangesTheShowAndTheSecondPressRestoresIt) {
  Show show = Show::makeDefault();
  show.fog().mode = FogMode::kExp2;
  const Show before = show;
  SetupToggles t;
  t.apply(SetupToggle::kFog, show);
  EXPECT_EQ(show.fog().mode, FogMode::kNone);
  t.apply(SetupToggle::kFog, show);
  EXPECT_EQ(show.fog().mode, FogMode::kExp2) << "the scene's fog function comes back";

  t.apply(SetupToggle::kLighting, show);
  EXPECT_EQ(show.globalStyle().front.illumination, Illumination::kNone);
  t.apply(SetupToggle::kLighting, show);
  EXPECT_EQ(show.globalStyle().front.illumination, before.globalStyle().front.illumination);

  t.apply(SetupToggle::kSmoothShading, show);
  EXPECT_EQ(show.globalStyle().front.illumination, Illumination::kPerVertex);
  t.apply(SetupToggle::kSmoothShading, show);
  EXPECT_EQ(show.globalStyle().front.illumination, Illumination::kPerFacet);

  t.apply(SetupToggle::kWireframe, show);
  EXPECT_EQ(show.globalStyle().render.primType, PrimType::kWireframe);
  t.apply(SetupToggle::kPoints, show);
  EXPECT_EQ(show.globalStyle().render.primType, PrimType::kMarkers);
  t.apply(SetupToggle::kFilled, show);
  EXPECT_EQ(show.globalStyle().render.primType, PrimType::kSolid);

  t.apply(SetupToggle::kStereo, show);
  EXPECT_TRUE(show.global().stereo);
  t.apply(SetupToggle::kStereo, show);
  EXPECT_FALSE(show.global().stereo);

  ASSERT_TRUE(show.motion().globalFreeRun) << "the default show turns";
  t.apply(SetupToggle::kPause, show);
  EXPECT_TRUE(t.paused());
  EXPECT_FALSE(show.motion().globalFreeRun);
  const Mat4 held = show.position().global;
  show.advanceFrame();
  EXPECT_EQ(show.position().global, held) << "paused: nothing turns";
  t.apply(SetupToggle::kPause, show);
  EXPECT_TRUE(show.motion().globalFreeRun);

  // Basalt draws neither aid: the toggle is kept and says so.
  EXPECT_NE(t.apply(SetupToggle::kNormals, show).find("does not draw"), std::string::npos);
  EXPECT_TRUE(t.normals());
  EXPECT_NE(t.apply(SetupToggle::kLightTokens, show).find("does not draw"), std::string::npos);
  EXPECT_TRUE(t.lightTokens());
}

TEST(SetupKeys, NamesForControlRequestsRoundTrip) {
  for (const char* name : {"control", "cave", "stereo", "fog", "smooth", "lighting", "filled", "points", "wireframe",
                           "normals", "light-tokens", "pause", "exit"}) {
    const auto t = parseSetupToggle(name);
    ASSERT_TRUE(t) << name;
    EXPECT_EQ(setupToggleName(*t), name);
  }
  EXPECT_FALSE(parseSetupToggle("fogg"));
}

}  // namespace
}  // namespace basalt::runtime
