// The HID recording reader (sim/hid_recording.h) that the replay backend and the virtual lab's
// uhid replay share: hid-recorder's text format, the shared recordings, and malformed input.

#include "sim/hid_recording.h"

#include <gtest/gtest.h>

#include "support/test_paths.h"

namespace basalt::sim {
namespace {

using namespace std::chrono_literals;

std::filesystem::path recording(const char* name) {
  const auto dir = test::testdataDir();
  return dir.empty() ? std::filesystem::path{} : dir / "hid" / "udev-hid-bpf" / name;
}

// Makes sure the Huion Dial 2 recording gives its three devices with their descriptors and ids.
// Example failure: D: lines are ignored, so the three descriptors overwrite one another.
TEST(HidRecordingFile, HuionDial2HasThreeDescriptorOnlyDevices) {
  const auto path = recording("huion_dial2_q630m_rdescs.hid");
  if (path.empty()) GTEST_SKIP() << "../shared/testdata is missing (BASALT_TESTDATA)";
  auto read = readHidRecording(path);
  ASSERT_TRUE(read) << read.error().describe();
  const std::vector<HidRecordedDevice>* devices = &read->devices;
  ASSERT_EQ(devices->size(), 3U);
  EXPECT_EQ((*devices)[0].descriptor.size(), 18U);
  EXPECT_EQ((*devices)[1].descriptor.size(), 93U);
  EXPECT_EQ((*devices)[2].descriptor.size(), 148U);
  for (const auto& d : *devices) {
    EXPECT_EQ(d.name, "HUION Huion Tablet_Q630M");
    EXPECT_EQ(d.bus, 3);
    EXPECT_EQ(d.vendor, 0x256c);
    EXPECT_EQ(d.product, 0x0060);
    EXPECT_TRUE(d.reports.empty());
  }
}

// Makes sure the Keydial recording's reports belong to device 1, in order, with their times.
// Example failure: events are given to the first device, which never sends any.
TEST(HidRecordingFile, KeydialReportsBelongToTheSecondDevice) {
  const auto path = recording("huion_keydial_mini050_bluetooth.hid");
  if (path.empty()) GTEST_SKIP() << "../shared/testdata is missing (BASALT_TESTDATA)";
  auto read = readHidRecording(path);
  ASSERT_TRUE(read) << read.error().describe();
  const std::vector<HidRecordedDevice>* devices = &read->devices;
  ASSERT_EQ(devices->size(), 2U);
  EXPECT_EQ((*devices)[0].descriptor.size(), 114U);
  EXPECT_TRUE((*devices)[0].reports.empty());
  const auto& d = (*devices)[1];
  EXPECT_EQ(d.bus, 5);
  EXPECT_EQ(d.vendor, 0x256c);
  EXPECT_EQ(d.product, 0x8251);
  ASSERT_EQ(d.reports.size(), 5U);
  EXPECT_EQ(d.reports[0].time, 292us);
  EXPECT_EQ(d.reports[1].time, 64s + 859915us);
  EXPECT_EQ(d.reports[1].bytes, (std::vector<std::uint8_t>{0x05, 0, 0, 0, 0, 0, 0xff}));
  EXPECT_EQ(d.reports[3].bytes, (std::vector<std::uint8_t>{0x02, 0xcd, 0x00}));
}

// Makes sure the Surface Dial's single-device recording (no D: line) is read whole.
// Example failure: a file without D: lines reads as no device at all.
TEST(HidRecordingFile, SurfaceDialIsOneDevice) {
  const auto path = recording("microsoft_surface_dial_rdesc.hid");
  if (path.empty()) GTEST_SKIP() << "../shared/testdata is missing (BASALT_TESTDATA)";
  auto read = readHidRecording(path);
  ASSERT_TRUE(read) << read.error().describe();
  const std::vector<HidRecordedDevice>* devices = &read->devices;
  ASSERT_EQ(devices->size(), 1U);
  EXPECT_EQ((*devices)[0].name, "Surface Dial");
  EXPECT_EQ((*devices)[0].descriptor.size(), 488U);
  EXPECT_EQ((*devices)[0].vendor, 0x045e);
  EXPECT_EQ((*devices)[0].product, 0x091b);
}

// Makes sure malformed recordings are rejected with the file and line and what is wrong, never
// read half. Example failure: a byte count that disagrees with the bytes is accepted, and the
// replayed descriptor is cut short.
TEST(HidRecordingParse, MalformedLinesNameTheLine) {
  struct Case {
    const char* text;
    const char* where;
    const char* what;
  };
  const Case cases[] = {
      {"R: 3 05 01\n", "t.hid:1", "says 3 bytes but has 2"},
      {"R: 2 05 zz\n", "t.hid:1", "'zz' is not a hexadecimal byte"},
      {"R: 1 05\nE: 1,5 1 00\n", "t.hid:2", "seconds.microseconds"},
      {"R: 1 05\nI: 3 256c\n", "t.hid:2", "bus vendor product"},
      {"R: 1 05\nI: 3 1ffff 1\n", "t.hid:2", "bus vendor product"},
      {"R: 1 05\nE: 000001.000000 0\n", "t.hid:2", "empty input report"},
      {"# nothing\n", "t.hid", "no R: report descriptor"},
      {"N: named\nE: 000001.000000 1 00\n", "t.hid:2", "before any R: report descriptor"},
      {"R: x\n", "t.hid:1", "'x' is not a byte count"},
      {"R: 1 05\nnot a record\n", "t.hid:2", "unknown line"},
  };
  for (const auto& c : cases) {
    auto parsed = parseHidRecording(c.text, "t.hid");
    ASSERT_FALSE(parsed) << c.text;
    EXPECT_EQ(parsed.error().where(), c.where) << c.text;
    EXPECT_NE(parsed.error().message().find(c.what), std::string::npos)
        << c.text << " -> " << parsed.error().describe();
  }
}

// Makes sure comments, blank lines, CRLF endings and unknown line types (newer recorders) are
// passed over. Example failure: a P: or an unknown line stops the reader.
TEST(HidRecordingParse, ToleratesCommentsUnknownLinesAndCrlf) {
  auto parsed = parseHidRecording(
      "# a comment\r\n\r\nR: 2 05 01\r\nN: Knob\r\nP: usb-1/input0\r\nX: future\r\n"
      "I: 3 1209 0001\r\nE: 000000.500000 2 01 ff\r\n",
      "t.hid");
  ASSERT_TRUE(parsed) << parsed.error().describe();
  ASSERT_EQ(parsed->devices.size(), 1U);
  const HidRecordedDevice& d = parsed->devices[0];
  EXPECT_EQ(d.name, "Knob");
  EXPECT_EQ(d.phys, "usb-1/input0");
  ASSERT_EQ(d.reports.size(), 1U);
  EXPECT_EQ(d.reports[0].time, 500ms);
}

// Makes sure a missing file is a clear error. Example failure: an empty recording is returned.
TEST(HidRecordingFile, MissingFileIsNotFound) {
  auto parsed = readHidRecording("/nonexistent/basalt.hid");
  ASSERT_FALSE(parsed);
  EXPECT_EQ(parsed.error().code(), Errc::kNotFound);
  EXPECT_EQ(parsed.error().where(), "/nonexistent/basalt.hid");
}

}  // namespace
}  // namespace basalt::sim
