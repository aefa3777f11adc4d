// The hid-recorder files Basalt writes: the line structure of hid-recorder's own (comments, then
// R:, N:, P:, I:, then each E: after a comment that decodes it), the P: line, comments that
// decode each report by its descriptor's fields, and Basalt reading its own file back exactly.
// Where hid-tools' hid-decode is installed, it reads Basalt's file too.
// Example failures: no P: line, so hid-replay makes a device without a physical path; a comment
// that names the wrong field or value; a comment line the reader takes for data.

#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "devices/hid/dial_decoder.h"
#include "sim/hid_comments.h"
#include "sim/hid_recording.h"
#include "sim/trace.h"
#include "support/process.h"
#include "support/test_paths.h"

namespace basalt::sim {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

std::string readText(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

/// A report of Basalt's virtual dial box (report id 1, 8 signed 16-bit dials, 32 button bits),
/// built byte by byte from its layout.
std::vector<std::uint8_t> virtualReport(int dial, std::int16_t delta, std::uint32_t buttons) {
  std::vector<std::uint8_t> r(21, 0);
  r[0] = 1;
  const auto raw = static_cast<std::uint16_t>(delta);
  r[1 + 2 * static_cast<std::size_t>(dial)] = static_cast<std::uint8_t>(raw & 0xff);
  r[2 + 2 * static_cast<std::size_t>(dial)] = static_cast<std::uint8_t>(raw >> 8);
  for (std::size_t i = 0; i < 4; ++i) r[17 + i] = static_cast<std::uint8_t>(buttons >> (8 * i));
  return r;
}

struct Written {
  fs::path file;
  std::vector<std::vector<std::uint8_t>> reports;
  std::vector<Nanos> times;
};

/// Records three reports of the virtual dial box through the TraceRecorder, as `basalt record`
/// does, and returns the .hid file it wrote.
Written recordThreeReports(const std::string& scratch) {
  Written w;
  const fs::path folder = test::scratchDir(scratch) / "knob.trace";
  ManualClock clock(Nanos{std::chrono::seconds(50)});
  auto recorder = TraceRecorder::create(folder, clock, {"test-host", "basalt-test", 60, {}});
  EXPECT_TRUE(recorder) << recorder.error().describe();
  if (!recorder) return w;
  devices::DeviceInfo info{"Test Knob", "hid", "usb", 0x077d, 0x0410, "usb:3-1", ""};
  EXPECT_TRUE((*recorder)->addDialBox(7, "knob", info, devices::virtualDialBoxDescriptor()));
  w.reports = {virtualReport(0, 180, 0), virtualReport(1, -5, 0x4), virtualReport(7, 32767, 0x80000001u)};
  w.times = {250ms, 1s + 500us, 2s};
  for (std::size_t i = 0; i < w.reports.size(); ++i) {
    (*recorder)->onReport(7, clock.now() + w.times[i], w.reports[i]);
  }
  clock.advance(3s);
  auto info2 = (*recorder)->finish();
  EXPECT_TRUE(info2) << info2.error().describe();
  w.file = folder / "knob.hid";
  return w;
}

// Makes sure the file has hid-recorder's shape: comments first, then exactly R:, N:, P:, I:, then
// each E: line after the comment that decodes it.
TEST(HidRecorderFiles, BasaltsFileHasHidRecordersLineStructure) {
  const Written w = recordThreeReports("hid-comments-structure");
  const std::string text = readText(w.file);
  std::string tags;
  for (const std::string& line : lines(text)) {
    ASSERT_GE(line.size(), 2u) << "no empty or one-character line: '" << line << "'";
    if (line[0] == '#') {
      ASSERT_EQ(line[1], ' ') << line;
      tags += '#';
    } else {
      ASSERT_EQ(line[1], ':') << line;
      ASSERT_EQ(line[2], ' ') << line;
      tags += line[0];
    }
  }
  EXPECT_TRUE(std::regex_match(tags, std::regex("#+RNPI(#E){3}"))) << tags << "\n" << text;
  EXPECT_NE(text.find("\nN: Test Knob\nP: usb:3-1\nI: 3 077d 0410\n"), std::string::npos) << text;
  EXPECT_EQ(text.rfind("# Test Knob\n", 0), 0u) << "the name first, as hid-recorder writes it: " << text;
}

// Makes sure each comment decodes its report by the virtual dial box's fields, computed here by
// hand from the layout: eight Generic Desktop Dials (16-bit, signed), then 32 buttons.
TEST(HidRecorderFiles, CommentsDecodeEachReportByItsDescriptor) {
  const Written w = recordThreeReports("hid-comments-decode");
  const std::vector<std::string> all = lines(readText(w.file));
  std::vector<std::string> before;  // the comment before each E: line
  for (std::size_t i = 1; i < all.size(); ++i) {
    if (all[i].starts_with("E: ")) before.push_back(all[i - 1]);
  }
  const std::string noButtons = "0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0";
  ASSERT_EQ(before.size(), 3u);
  EXPECT_EQ(before[0], "# ReportID: 1 / Dial: 180, 0, 0, 0, 0, 0, 0, 0 | Button: " + noButtons);
  EXPECT_EQ(before[1], "# ReportID: 1 / Dial: 0, -5, 0, 0, 0, 0, 0, 0 | Button: 0 0 1 " + noButtons.substr(6));
  EXPECT_EQ(before[2], "# ReportID: 1 / Dial: 0, 0, 0, 0, 0, 0, 0, 32767 | Button: 1 " + noButtons.substr(4) + " 1");
  // The descriptor, item by item, before R: (a few of its 33 items).
  const std::string text = readText(w.file);
  EXPECT_NE(text.find("// Usage Page (Generic Desktop)"), std::string::npos) << text;
  EXPECT_NE(text.find("//   Logical Minimum (-32767)"), std::string::npos) << text;
  EXPECT_NE(text.find("//   Input (Data,Var,Rel)"), std::string::npos) << text;
  EXPECT_NE(text.find("//   Usage Maximum (Button 32)"), std::string::npos) << text;
}

// Makes sure Basalt reads its own file back: the same device and the same reports at the same
// times (to the microsecond the format keeps), the comments skipped.
TEST(HidRecorderFiles, BasaltReadsItsOwnFileBack) {
  const Written w = recordThreeReports("hid-comments-read-back");
  auto read = readHidRecording(w.file);
  ASSERT_TRUE(read) << read.error().describe();
  ASSERT_EQ(read->devices.size(), 1u);
  const HidRecordedDevice& d = read->devices[0];
  EXPECT_EQ(d.name, "Test Knob");
  EXPECT_EQ(d.phys, "usb:3-1");
  EXPECT_EQ(d.bus, 3);
  EXPECT_EQ(d.vendor, 0x077d);
  EXPECT_EQ(d.product, 0x0410);
  EXPECT_EQ(d.descriptor, devices::virtualDialBoxDescriptor());
  ASSERT_EQ(d.reports.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(d.reports[i].bytes, w.reports[i]) << i;
    EXPECT_EQ(d.reports[i].time, w.times[i]) << i;
  }
}

// Real descriptors from other projects: the Huion Keydial's second interface (keyboard, consumer
// and mouse reports). Expected comments worked out by hand from its descriptor bytes.
TEST(HidRecorderFiles, CommentsForARealKeydial) {
  const auto dir = test::testdataDir();
  if (dir.empty()) GTEST_SKIP() << "../shared/testdata is missing (BASALT_TESTDATA)";
  auto read = readHidRecording(dir / "hid/udev-hid-bpf/huion_keydial_mini050_bluetooth.hid");
  ASSERT_TRUE(read) << read.error().describe();
  ASSERT_EQ(read->devices.size(), 2u);
  const HidComments comments = HidComments::create(read->devices[1].descriptor);
  const auto& r = read->devices[1].reports;
  ASSERT_EQ(r.size(), 5u);
  // Report 1: eight modifier bits, a padding byte, six key slots (0x0e is 'k').
  EXPECT_EQ(comments.reportLine(r[0].bytes),
            "# ReportID: 1 / LeftControl: 0 | LeftShift: 0 | LeftAlt: 0 | LeftGUI: 0 | RightControl: 0 | "
            "RightShift: 0 | RightAlt: 0 | RightGUI: 0 | Keyboard ['', 'k', '', '', '', '']\n");
  // Report 5: five buttons, padding, X and Y (16-bit, relative), the wheel (8-bit): 0xff is -1.
  EXPECT_EQ(comments.reportLine(r[1].bytes), "# ReportID: 5 / Button: 0 0 0 0 0 | X: 0 | Y: 0 | Wheel: -1\n");
  // Report 2: one 16-bit consumer usage: 0xcd is Play/Pause, 0 is none.
  EXPECT_EQ(comments.reportLine(r[3].bytes), "# ReportID: 2 / Consumer ['Play/Pause']\n");
  EXPECT_EQ(comments.reportLine(r[4].bytes), "# ReportID: 2 / Consumer ['']\n");
  // A report id the descriptor does not have says so.
  EXPECT_EQ(comments.reportLine(std::vector<std::uint8_t>{9, 1, 2}),
            "# ReportID: 9 / not an input report of the descriptor\n");
  // A descriptor that does not parse: its items are still listed, its reports get no comment.
  const std::vector<std::uint8_t> broken{0x05, 0x01, 0x09};
  const HidComments none = HidComments::create(broken);
  EXPECT_EQ(none.reportLine(std::vector<std::uint8_t>{1, 2}), "");
  EXPECT_NE(none.descriptorLines().find("Basalt cannot decode this descriptor"), std::string::npos);
}

// Makes sure a damaged descriptor or report cannot break the writer: every prefix of a real
// 488-byte descriptor, with reports of every length up to 64 bytes. Example failure: a read past
// the end of a truncated item or a short report (caught by the sanitizers).
TEST(HidRecorderFiles, TruncatedDescriptorsAndReports) {
  const auto dir = test::testdataDir();
  if (dir.empty()) GTEST_SKIP() << "../shared/testdata is missing (BASALT_TESTDATA)";
  auto read = readHidRecording(dir / "hid/udev-hid-bpf/microsoft_surface_dial_rdesc.hid");
  ASSERT_TRUE(read) << read.error().describe();
  const std::vector<std::uint8_t>& full = read->devices.at(0).descriptor;
  ASSERT_EQ(full.size(), 488u);
  std::vector<std::uint8_t> report(64);
  for (std::size_t i = 0; i < report.size(); ++i) report[i] = static_cast<std::uint8_t>(i * 37 + 1);
  for (std::size_t n = 0; n <= full.size(); ++n) {
    const HidComments c = HidComments::create(std::span(full).first(n));
    const std::string items = c.descriptorLines();
    EXPECT_FALSE(items.empty()) << n;
    for (std::size_t len = 0; len <= report.size(); len += 7) {
      const std::string line = c.reportLine(std::span(report).first(len));
      EXPECT_TRUE(line.empty() || line.back() == '\n') << n << " " << len;
    }
  }
  // The whole descriptor: report 1 is the dial (a button, a 16-bit Dial, X and Y).
  const HidComments dial = HidComments::create(full);
  EXPECT_NE(dial.reportLine(std::vector<std::uint8_t>{0x01, 0x01, 0xfe, 0xff, 0, 0, 0, 0}).find("ReportID: 1 / "),
            std::string::npos);
}

// Makes sure P: carries the kernel's physical path of a hidraw node, as hid-recorder's does, and
// the device's own path otherwise. Example failure: "/dev/hidraw3" written as the physical path.
TEST(HidRecorderFiles, ThePhysicalPath) {
  const fs::path sys = test::scratchDir("hid-comments-sysfs");
  fs::create_directories(sys / "class/hidraw/hidraw7/device");
  std::ofstream(sys / "class/hidraw/hidraw7/device/uevent")
      << "DRIVER=hid-generic\nHID_ID=0003:0000077D:00000410\nHID_NAME=Griffin PowerMate\n"
         "HID_PHYS=usb-0000:00:14.0-2/input0\nHID_UNIQ=\n";
  fs::create_directories(sys / "class/hidraw/hidraw8/device");
  std::ofstream(sys / "class/hidraw/hidraw8/device/uevent") << "HID_NAME=uhid device\nHID_PHYS=\n";
  devices::DeviceInfo info{"Griffin PowerMate", "hid", "usb", 0x077d, 0x0410, "/dev/hidraw7", ""};
  EXPECT_EQ(hidPhysicalPath(info, sys), "usb-0000:00:14.0-2/input0");
  info.path = "/dev/hidraw8";  // an empty HID_PHYS
  EXPECT_EQ(hidPhysicalPath(info, sys), "/dev/hidraw8");
  info.path = "/dev/hidraw9";  // no such node in sysfs
  EXPECT_EQ(hidPhysicalPath(info, sys), "/dev/hidraw9");
  info.path = "usb:1-2";
  EXPECT_EQ(hidPhysicalPath(info, sys), "usb:1-2");
  info.path = "";
  EXPECT_EQ(hidPhysicalPath(info, sys), "basalt");
}

// hid-tools' own reader on Basalt's file, where it is installed. hid-tools is not packaged for
// Debian 12 (`apt-cache search hid-tools` finds nothing); `pip install hid-tools` provides it.
TEST(HidRecorderFiles, HidDecodeReadsBasaltsFile) {
  const std::string decode = test::onPath("hid-decode");
  if (decode.empty()) {
    GTEST_SKIP() << "hid-decode (hid-tools) is not installed: Debian 12 has no package for it; "
                    "`pip install hid-tools` puts it on PATH";
  }
  const Written w = recordThreeReports("hid-comments-hid-decode");
  const auto r = test::run({decode, w.file.string()});
  EXPECT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("Dial"), std::string::npos) << "hid-decode names the descriptor's dials: " << r.output;
}

}  // namespace
}  // namespace basalt::sim
