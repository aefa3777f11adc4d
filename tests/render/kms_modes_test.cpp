// Choosing the KMS connector and mode as plain logic: the connector the manifest names or the
// first connected one; the mode the manifest names or the preferred one, progressive before
// interlaced. Example failures: a show opening on a disconnected port; 1080i chosen over 1080p;
// a typo'd connector name failing without saying which connectors exist.

#include <gtest/gtest.h>

#include "render/kms_modes.h"

namespace basalt::render {
namespace {

std::vector<KmsConnector> card() {
  return {
      {31, "DP-1", false, {}},
      {33,
       "HDMI-A-1",
       true,
       {{1920, 1080, 60.0, false, true},
        {1920, 1080, 50.0, false, false},
        {1920, 1080, 60.0, true, false},
        {1280, 720, 60.0, false, false},
        {3840, 2160, 30.0, false, false}}},
      {35, "HDMI-A-2", true, {{1024, 768, 60.0, false, false}, {1280, 1024, 75.0, false, false}}},
  };
}

TEST(KmsModes, TheFirstConnectedConnectorAndItsPreferredMode) {
  const auto c = card();
  auto s = selectConnectorAndMode(c, "", std::nullopt);
  ASSERT_TRUE(s) << s.error().describe();
  EXPECT_EQ(c[s->connector].name, "HDMI-A-1");
  const KmsMode& m = c[s->connector].modes[s->mode];
  EXPECT_TRUE(m.preferred);
  EXPECT_FALSE(m.interlaced);
}

TEST(KmsModes, WithoutAPreferredModeTheLargestProgressiveOne) {
  const auto c = card();
  auto s = selectConnectorAndMode(c, "hdmi-a-2", std::nullopt);
  ASSERT_TRUE(s);
  EXPECT_EQ(c[s->connector].name, "HDMI-A-2") << "names match without regard to case";
  EXPECT_EQ(c[s->connector].modes[s->mode].width, 1280u);
}

TEST(KmsModes, TheModeAsked) {
  const auto c = card();
  auto any = selectConnectorAndMode(c, "HDMI-A-1", ModeWish{1920, 1080, 0});
  ASSERT_TRUE(any);
  EXPECT_TRUE(c[1].modes[any->mode].preferred) << "among equal sizes the preferred mode";
  auto fifty = selectConnectorAndMode(c, "HDMI-A-1", ModeWish{1920, 1080, 50});
  ASSERT_TRUE(fifty);
  EXPECT_DOUBLE_EQ(c[1].modes[fifty->mode].refresh, 50.0);
  auto slow = selectConnectorAndMode(c, "", ModeWish{3840, 2160, 30.2});
  ASSERT_TRUE(slow) << "refresh within half a hertz";
  EXPECT_EQ(c[1].modes[slow->mode].width, 3840u);
}

TEST(KmsModes, MistakesListWhatThereIs) {
  const auto c = card();
  const auto noSuch = selectConnectorAndMode(c, "VGA-1", std::nullopt);
  ASSERT_FALSE(noSuch);
  EXPECT_NE(noSuch.error().message().find("there is no connector 'VGA-1'"), std::string::npos);
  EXPECT_NE(noSuch.error().message().find("HDMI-A-1 (connected)"), std::string::npos) << noSuch.error().message();
  const auto unplugged = selectConnectorAndMode(c, "DP-1", std::nullopt);
  ASSERT_FALSE(unplugged);
  EXPECT_NE(unplugged.error().message().find("nothing is connected to DP-1"), std::string::npos);
  const auto mode = selectConnectorAndMode(c, "", ModeWish{800, 600, 0});
  ASSERT_FALSE(mode);
  EXPECT_NE(mode.error().message().find("has no mode 800x600"), std::string::npos);
  EXPECT_NE(mode.error().message().find("1920x1080@60.00 (preferred)"), std::string::npos) << mode.error().message();
  const std::vector<KmsConnector> dark{{1, "HDMI-A-1", false, {}}};
  const auto none = selectConnectorAndMode(dark, "", std::nullopt);
  ASSERT_FALSE(none);
  EXPECT_NE(none.error().message().find("no display is connected"), std::string::npos);
  const std::vector<KmsConnector> noEdid{{1, "HDMI-A-1", true, {}}};
  EXPECT_FALSE(selectConnectorAndMode(noEdid, "", std::nullopt));
}

}  // namespace
}  // namespace basalt::render
