// HID report descriptors and dial decoding: the parser, the PowerMate, Shuttle and generic
// profiles, Basalt's virtual dial box, and every recording in ../shared/testdata/hid (one test
// case each), including damaged descriptors.
// Example failures: the Surface Dial's rotation read from the wrong bits or at the wrong scale;
// a Shuttle jog wrap from 255 to 0 read as -255 counts; a truncated descriptor that crashes the
// parser instead of naming the byte; a Consumer Play/Pause key never reaching a button.

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <vector>

#include "devices/hid/dial_decoder.h"
#include "devices/hid/report_descriptor.h"
#include "sim/hid_recording.h"
#include "support/test_paths.h"

namespace basalt::devices {
namespace {

using hid::parseReportDescriptor;

std::filesystem::path hidData(const std::string& name) {
  const auto dir = test::testdataDir();
  return dir.empty() ? std::filesystem::path{} : dir / "hid" / "udev-hid-bpf" / name;
}

sim::HidRecording loadOrSkip(const std::string& name) {
  const auto path = hidData(name);
  if (path.empty() || !std::filesystem::exists(path)) return {};
  auto rec = sim::readHidRecording(path);
  EXPECT_TRUE(rec) << (rec ? "" : rec.error().describe());
  return rec ? *rec : sim::HidRecording{};
}

std::vector<Event> decodeAll(DialDecoder& d, std::span<const std::uint8_t> report) {
  std::array<Event, DialDecoder::kMaxEventsPerReport> out;
  const std::size_t n = d.decode(report, out);
  return {out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n)};
}

// Every prefix of a real descriptor either parses or fails with a message; none crashes.
void expectPrefixesSafe(const std::vector<std::uint8_t>& bytes) {
  for (std::size_t n = 0; n < bytes.size(); ++n) {
    auto r = parseReportDescriptor(std::span(bytes).first(n), "prefix");
    if (!r) {
      EXPECT_FALSE(r.error().message().empty());
    }
  }
}

#define SKIP_WITHOUT(rec, name)                                                                      \
  if ((rec).devices.empty()) {                                                                       \
    GTEST_SKIP() << "../shared/testdata/hid/udev-hid-bpf/" name " is missing (set BASALT_TESTDATA)"; \
  }

TEST(HidTestdata, MicrosoftSurfaceDialMapsToOneDialAndAButton) {
  const auto rec = loadOrSkip("microsoft_surface_dial_rdesc.hid");
  SKIP_WITHOUT(rec, "microsoft_surface_dial_rdesc.hid");
  ASSERT_EQ(rec.devices.size(), 1u);
  const auto& dev = rec.devices[0];
  EXPECT_EQ(dev.descriptor.size(), 488u);
  EXPECT_EQ(dev.vendor, 0x045e);
  EXPECT_EQ(dev.product, 0x091b);
  auto d = DialDecoder::create(dev.vendor, dev.product, dev.descriptor, "surface dial");
  ASSERT_TRUE(d) << d.error().describe();
  EXPECT_EQ(d->profile(), DialProfile::kGenericHid);
  ASSERT_GE(d->dialCount(), 1);
  EXPECT_EQ(d->channels()[0].usage, hid::usages::kDial);
  EXPECT_EQ(d->channels()[0].kind, EventKind::kDialDelta);
  EXPECT_DOUBLE_EQ(d->channels()[0].countsPerTurn, 3600) << "the Resolution Multiplier's 3600 steps per turn";
  EXPECT_GE(d->buttonCount(), 1);
  // Report 1: button bit, touch bit, 6 pad bits, 16-bit dial, X, Y, width.
  const std::vector<std::uint8_t> turn = {0x01, 0x01, 0x84, 0x03, 0, 0, 0, 0, 0};  // +900 = a quarter turn
  auto events = decodeAll(*d, turn);
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0].kind, EventKind::kDialDelta);
  EXPECT_DOUBLE_EQ(events[0].value, 0.25);
  EXPECT_EQ(events[1].kind, EventKind::kButton);
  EXPECT_EQ(events[1].value, 1);
  const std::vector<std::uint8_t> back = {0x01, 0x00, 0x7c, 0xfc, 0, 0, 0, 0, 0};  // -900
  events = decodeAll(*d, back);
  ASSERT_EQ(events.size(), 2u);
  EXPECT_DOUBLE_EQ(events[0].value, -0.25);
  EXPECT_EQ(events[1].value, 0) << "button released";
  expectPrefixesSafe(dev.descriptor);
}

TEST(HidTestdata, HuionDial2PadDialMapsToDialZero) {
  const auto rec = loadOrSkip("huion_dial2_q630m_rdescs.hid");
  SKIP_WITHOUT(rec, "huion_dial2_q630m_rdescs.hid");
  ASSERT_EQ(rec.devices.size(), 3u);
  EXPECT_EQ(rec.devices[0].index, 0);
  EXPECT_EQ(rec.devices[2].index, 2);
  // D:0 is a vendor node with no controls: a clear refusal, not a crash.
  auto vendorNode = DialDecoder::create(0x256c, 0x0060, rec.devices[0].descriptor, "huion D:0");
  ASSERT_FALSE(vendorNode);
  EXPECT_NE(vendorNode.error().message().find("no dial"), std::string::npos) << vendorNode.error().describe();
  // D:1 is the pen: its X/Y are absolute axes, so they map to absolute dials.
  auto pen = DialDecoder::create(0x256c, 0x0060, rec.devices[1].descriptor, "huion D:1");
  ASSERT_TRUE(pen) << pen.error().describe();
  EXPECT_EQ(pen->channels()[0].kind, EventKind::kDialAbsolute);
  // D:2 is the pad: the dial of the puck pattern.
  auto pad = DialDecoder::create(0x256c, 0x0060, rec.devices[2].descriptor, "huion D:2");
  ASSERT_TRUE(pad) << pad.error().describe();
  EXPECT_EQ(pad->channels()[0].usage, hid::usages::kDial);
  EXPECT_DOUBLE_EQ(pad->channels()[0].countsPerTurn, 3600);
  // Report 0x11: button bit, touch bit, 6 pad bits, dial (16 bit), 5 padding bytes.
  std::vector<std::uint8_t> report = {0x11, 0x00, 0x0a, 0x00, 0, 0, 0, 0, 0};
  auto events = decodeAll(*pad, report);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].index, 0);
  EXPECT_DOUBLE_EQ(events[0].value, 10.0 / 3600);
  for (const auto& d : rec.devices) expectPrefixesSafe(d.descriptor);
}

TEST(HidTestdata, HuionKeydialMiniReplaysWheelAndPlayPause) {
  const auto rec = loadOrSkip("huion_keydial_mini050_bluetooth.hid");
  SKIP_WITHOUT(rec, "huion_keydial_mini050_bluetooth.hid");
  ASSERT_EQ(rec.devices.size(), 2u);
  EXPECT_TRUE(rec.devices[0].reports.empty());
  const auto& dev = rec.devices[1];
  EXPECT_EQ(dev.bus, 5);
  ASSERT_EQ(dev.reports.size(), 5u);
  auto d = DialDecoder::create(dev.vendor, dev.product, dev.descriptor, "keydial D:1");
  ASSERT_TRUE(d) << d.error().describe();
  EXPECT_EQ(d->channels()[0].usage, hid::usages::kWheel) << "the knob arrives as the mouse wheel";
  std::vector<Event> all;
  for (const auto& r : dev.reports) {
    for (Event e : decodeAll(*d, r.bytes)) {
      e.time = r.time;
      all.push_back(e);
    }
  }
  ASSERT_EQ(all.size(), 3u);
  EXPECT_EQ(all[0].kind, EventKind::kDialDelta);
  EXPECT_EQ(all[0].index, 0);
  EXPECT_DOUBLE_EQ(all[0].value, -1.0 / kWheelCountsPerTurn);
  EXPECT_EQ(all[0].time, Nanos{64'859'915'000});
  EXPECT_EQ(all[1].kind, EventKind::kButton);
  EXPECT_EQ(all[1].value, 1) << "Consumer Play/Pause pressed";
  EXPECT_EQ(all[2].index, all[1].index);
  EXPECT_EQ(all[2].value, 0);
  // D:0, the puck pattern that never sends, still maps to a dial.
  auto puck = DialDecoder::create(dev.vendor, dev.product, rec.devices[0].descriptor, "keydial D:0");
  ASSERT_TRUE(puck) << puck.error().describe();
  EXPECT_EQ(puck->channels()[0].usage, hid::usages::kDial);
  for (const auto& dv : rec.devices) expectPrefixesSafe(dv.descriptor);
}

TEST(HidDescriptor, MalformedDescriptorsNameTheByte) {
  struct Case {
    std::vector<std::uint8_t> bytes;
    const char* expect;
  };
  const std::vector<Case> cases = {
      {{}, "empty"},
      {{0x05, 0x01, 0x26, 0xff}, "byte 2"},                       // item cut short
      {{0xb4}, "Pop without Push"},                               // pop on an empty stack
      {{0xc0}, "End Collection without"},                         // stray end
      {{0x05, 0x01, 0x09, 0x02, 0xa1, 0x01}, "open collection"},  // never closed
      {{0x85, 0x00}, "Report ID 0"},
      {{0x75, 0xff, 0x95, 0x10, 0x81, 0x02}, "Report Size"},  // 255-bit... fine size, but see next
      {{0x76, 0x00, 0x10, 0x95, 0x01, 0x81, 0x02}, "Report Size 4096"},
      {{0x29, 0x05}, "Usage Maximum without"},
      {{0xc4}, "unknown global item 0xc4"},  // global tag 0xc is reserved; Linux refuses it too
      {{0xfe, 0x10}, "long item"},
  };
  for (const auto& c : cases) {
    auto r = parseReportDescriptor(c.bytes, "test");
    if (std::string(c.expect) == "Report Size") {
      EXPECT_TRUE(r) << "255-bit fields are legal";
      continue;
    }
    ASSERT_FALSE(r) << c.expect;
    EXPECT_NE(r.error().describe().find(c.expect), std::string::npos) << r.error().describe();
    EXPECT_EQ(r.error().where(), "test");
  }
}

// Descriptors Linux's parser (drivers/hid/hid-core.c) accepts. Built by HID 1.11 §6.2.2: an
// item's prefix is tag << 4 | type << 2 | size code, types main 0, global 1, local 2, reserved 3.
// A wheel: Generic Desktop, Application collection, Usage Wheel, -127..127, 8 bits x 1, Input
// (Data, Variable, Relative), End Collection: 19 bytes.
const std::vector<std::uint8_t> kWheel = {0x05, 0x01, 0x09, 0x02, 0xa1, 0x01, 0x09, 0x38, 0x15, 0x81,
                                          0x25, 0x7f, 0x75, 0x08, 0x95, 0x01, 0x81, 0x06, 0xc0};

void expectOneWheel(const hid::ReportDescriptor& d) {
  ASSERT_EQ(d.fields.size(), 1u);
  const hid::ReportField& f = d.fields[0];
  EXPECT_EQ(f.bitSize, 8u);
  EXPECT_EQ(f.count, 1u);
  EXPECT_EQ(f.logicalMin, -127);
  EXPECT_EQ(f.logicalMax, 127);
  ASSERT_EQ(f.usages.size(), 1u);
  EXPECT_EQ(f.usages[0], hid::usage(0x01, 0x38));
  ASSERT_EQ(d.collections.size(), 1u);
  EXPECT_EQ(d.reportBytes(hid::ReportType::kInput, 0), 1u);
}

TEST(HidDescriptor, TrailingZeroPaddingIsSkippedAsLinuxDoes) {
  // 0x00 is a main item with tag 0 (reserved) and no data; Linux skips it. Game controllers
  // report their descriptor padded with zeros to a fixed length.
  for (const std::size_t pads : {1u, 3u}) {
    std::vector<std::uint8_t> desc = kWheel;
    desc.insert(desc.end(), pads, 0x00);
    auto r = parseReportDescriptor(desc, "padded");
    ASSERT_TRUE(r) << r.error().describe();
    expectOneWheel(*r);
    ASSERT_EQ(r->ignored.size(), pads);
    EXPECT_NE(r->ignored[0].find("byte 19"), std::string::npos) << r->ignored[0];
    EXPECT_NE(r->ignored[0].find("0x00"), std::string::npos) << r->ignored[0];
  }
}

TEST(HidDescriptor, ReservedMainItemEndsTheLocalState) {
  // Like any main item, a reserved one clears the usages before it (Linux resets the local
  // state after every main item): the wheel's usage is gone, the field stays.
  std::vector<std::uint8_t> desc = kWheel;
  desc.insert(desc.begin() + 8, 0x00);  // right after Usage Wheel
  auto r = parseReportDescriptor(desc);
  ASSERT_TRUE(r) << r.error().describe();
  ASSERT_EQ(r->fields.size(), 1u);
  ASSERT_EQ(r->fields[0].usages.size(), 1u);
  EXPECT_EQ(r->fields[0].usages[0], 0u);
  ASSERT_EQ(r->ignored.size(), 1u);
  EXPECT_NE(r->ignored[0].find("byte 8"), std::string::npos) << r->ignored[0];
}

TEST(HidDescriptor, LongItemsAreSkippedByTheirLength) {
  // 0xfe, data size 3, long tag 0x42, three data bytes; its data bytes would be items if the
  // parser did not skip them (0xc0 is End Collection, 0xb4 is Pop).
  std::vector<std::uint8_t> desc = kWheel;
  const std::vector<std::uint8_t> longItem = {0xfe, 0x03, 0x42, 0xc0, 0xb4, 0xc0};
  desc.insert(desc.begin() + 6, longItem.begin(), longItem.end());
  auto r = parseReportDescriptor(desc);
  ASSERT_TRUE(r) << r.error().describe();
  expectOneWheel(*r);
  ASSERT_EQ(r->ignored.size(), 1u);
  EXPECT_NE(r->ignored[0].find("byte 6: long item with tag 0x42 and 3 data byte(s)"), std::string::npos)
      << r->ignored[0];
  // A long item whose data runs past the end is still an error.
  std::vector<std::uint8_t> cut = kWheel;
  cut.insert(cut.end(), {0xfe, 0x05, 0x01, 0x00});
  EXPECT_FALSE(parseReportDescriptor(cut));
}

TEST(HidDescriptor, ReservedTagsAndTypeAreSkipped) {
  // Before the wheel's Usage: local tag 0xb (reserved; 0xb0 | 2 << 2 | 1 = 0xb9), local tag 6
  // (reserved; 0x69), an item of the reserved type (tag 1, type 3, one byte: 0x1d) and main
  // tag 0xd (reserved; 0xd1, one byte). All four are skipped, as Linux skips them.
  std::vector<std::uint8_t> desc = kWheel;
  const std::vector<std::uint8_t> reserved = {0xb9, 0x07, 0x69, 0x01, 0x1d, 0x55, 0xd1, 0x00};
  desc.insert(desc.begin() + 6, reserved.begin(), reserved.end());
  auto r = parseReportDescriptor(desc);
  ASSERT_TRUE(r) << r.error().describe();
  expectOneWheel(*r);
  ASSERT_EQ(r->ignored.size(), 4u);
  EXPECT_NE(r->ignored[0].find("byte 6: local item 0xb9"), std::string::npos) << r->ignored[0];
  EXPECT_NE(r->ignored[1].find("byte 8: local item 0x69"), std::string::npos) << r->ignored[1];
  EXPECT_NE(r->ignored[2].find("byte 10: item 0x1d of the reserved type"), std::string::npos) << r->ignored[2];
  EXPECT_NE(r->ignored[3].find("byte 12: main item 0xd1"), std::string::npos) << r->ignored[3];
}

TEST(HidDescriptor, UsageMaximumBelowItsMinimumAddsNoUsage) {
  // Buttons 5..2: Linux adds no usage and keeps the field; so three buttons without usages.
  const std::vector<std::uint8_t> desc = {0x05, 0x09, 0x19, 0x05, 0x29, 0x02, 0x15, 0x00,
                                          0x25, 0x01, 0x75, 0x01, 0x95, 0x03, 0x81, 0x02};
  auto r = parseReportDescriptor(desc);
  ASSERT_TRUE(r) << r.error().describe();
  ASSERT_EQ(r->fields.size(), 1u);
  EXPECT_EQ(r->fields[0].usages, std::vector<std::uint32_t>(3, 0u));
  ASSERT_EQ(r->ignored.size(), 1u);
  EXPECT_NE(r->ignored[0].find("byte 4"), std::string::npos) << r->ignored[0];
}

TEST(HidDescriptor, ManySkippedItemsAreCountedNotListed) {
  std::vector<std::uint8_t> desc = kWheel;
  desc.insert(desc.end(), 40, 0x00);
  auto r = parseReportDescriptor(desc);
  ASSERT_TRUE(r) << r.error().describe();
  ASSERT_EQ(r->ignored.size(), 17u);
  EXPECT_EQ(r->ignored.back(), "24 more skipped item(s)");
}

TEST(HidDescriptor, FieldsGetOffsetsPerReportIdAndSignedValues) {
  // Report 2: 8-bit signed wheel then 3 buttons; report 3: 16-bit unsigned X.
  const std::vector<std::uint8_t> desc = {
      0x05, 0x01, 0x09, 0x02, 0xa1, 0x01, 0x85, 0x02, 0x09, 0x38, 0x15, 0x81, 0x25, 0x7f, 0x75, 0x08, 0x95, 0x01,
      0x81, 0x06, 0x05, 0x09, 0x19, 0x01, 0x29, 0x03, 0x15, 0x00, 0x25, 0x01, 0x75, 0x01, 0x95, 0x03, 0x81, 0x02,
      0x85, 0x03, 0x05, 0x01, 0x09, 0x30, 0x15, 0x00, 0x26, 0xff, 0xff, 0x75, 0x10, 0x95, 0x01, 0x81, 0x02, 0xc0};
  auto r = parseReportDescriptor(desc);
  ASSERT_TRUE(r) << r.error().describe();
  ASSERT_EQ(r->fields.size(), 3u);
  EXPECT_TRUE(r->usesReportIds);
  EXPECT_EQ(r->fields[1].bitOffset, 8u);
  EXPECT_EQ(r->fields[1].usages[2], hid::usage(9, 3));
  EXPECT_EQ(r->fields[2].reportId, 3);
  EXPECT_EQ(r->fields[2].bitOffset, 0u) << "offsets restart for each report id";
  EXPECT_EQ(r->fields[2].logicalMax, 65535) << "an unsigned maximum when the minimum is not negative";
  const std::uint8_t data[] = {0xfe, 0x05};
  EXPECT_EQ(hid::extractElement(r->fields[0], 0, data), -2);
  EXPECT_EQ(hid::extractElement(r->fields[1], 0, data), 1) << "0x05: buttons 1 and 3";
  EXPECT_EQ(hid::extractElement(r->fields[1], 1, data), 0);
  EXPECT_EQ(hid::extractElement(r->fields[1], 2, data), 1);
  bool ok = true;
  (void)hid::extractElement(r->fields[1], 0, std::span(data).first(1), &ok);
  EXPECT_FALSE(ok) << "bits past the end of a short report are not read";
  EXPECT_EQ(r->reportBytes(hid::ReportType::kInput, 2), 2u);
}

TEST(DialProfiles, PowerMateButtonAndSignedDelta) {
  auto d = DialDecoder::create(kGriffinVendor, kPowerMateProduct, {});
  ASSERT_TRUE(d);
  EXPECT_EQ(d->profile(), DialProfile::kPowerMate);
  const std::uint8_t press[] = {0x01, 0xfd, 0, 0x50, 0, 0};
  auto events = decodeAll(*d, press);
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0].kind, EventKind::kButton);
  EXPECT_EQ(events[0].value, 1);
  EXPECT_DOUBLE_EQ(events[1].value, -3 / kPowerMateCountsPerTurn);
  const std::uint8_t idle[] = {0x01, 0x00};
  EXPECT_TRUE(decodeAll(*d, idle).empty()) << "a held button and no turn: nothing new";
  const std::uint8_t tooShort[] = {0x01};
  EXPECT_TRUE(decodeAll(*d, tooShort).empty());
}

TEST(DialProfiles, ShuttleJogWrapsRingAndButtons) {
  for (std::uint16_t product : {kShuttleProV1Product, kShuttleXpressProduct, kShuttleProV2Product}) {
    auto d = DialDecoder::create(kContourVendor, product, {});
    ASSERT_TRUE(d);
    EXPECT_EQ(d->profile(), DialProfile::kShuttle);
    const std::uint8_t first[] = {0x00, 0xfe, 0x00, 0x00, 0x00};
    EXPECT_TRUE(decodeAll(*d, first).empty()) << "the first jog value is only a reference";
    const std::uint8_t wrapped[] = {0x03, 0x01, 0x00, 0x10, 0x01};  // jog 254 -> 1 is +3; ring +3; buttons 4, 8
    auto events = decodeAll(*d, wrapped);
    ASSERT_EQ(events.size(), 4u);
    EXPECT_EQ(events[0].kind, EventKind::kShuttle);
    EXPECT_DOUBLE_EQ(events[0].value, 3.0 / 7);
    EXPECT_EQ(events[1].kind, EventKind::kDialDelta);
    EXPECT_DOUBLE_EQ(events[1].value, 3 / kShuttleJogCountsPerTurn);
    EXPECT_EQ(events[2].index, 4);
    EXPECT_EQ(events[3].index, 8);
    const std::uint8_t back[] = {0xf9, 0xfd, 0x00, 0x00, 0x00};  // ring -7, jog 1 -> 253 = -4, buttons up
    events = decodeAll(*d, back);
    ASSERT_EQ(events.size(), 4u);
    EXPECT_DOUBLE_EQ(events[0].value, -1.0);
    EXPECT_DOUBLE_EQ(events[1].value, -4 / kShuttleJogCountsPerTurn);
    EXPECT_EQ(events[2].value, 0);
  }
}

TEST(DialProfiles, AbsoluteWrappingAxisGivesDeltas) {
  // One 8-bit absolute Dial with the Wrap flag, 0..255.
  const std::vector<std::uint8_t> desc = {0x05, 0x01, 0x09, 0x08, 0xa1, 0x01, 0x09, 0x37, 0x15, 0x00,
                                          0x26, 0xff, 0x00, 0x75, 0x08, 0x95, 0x01, 0x81, 0x0a, 0xc0};
  auto d = DialDecoder::create(0x1234, 0x5678, desc);
  ASSERT_TRUE(d) << d.error().describe();
  EXPECT_DOUBLE_EQ(d->channels()[0].countsPerTurn, 256);
  const std::uint8_t a[] = {250}, b[] = {4};
  EXPECT_TRUE(decodeAll(*d, a).empty());
  auto events = decodeAll(*d, b);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_DOUBLE_EQ(events[0].value, 10.0 / 256);
}

// A 6-axis puck laid out like 3Dconnexion's SpaceNavigator: translations X/Y/Z in report 1,
// rotations Rx/Ry/Rz in report 2 (16-bit relative, -350..350, a length unit that is no
// rotation), two buttons in report 3. The application usage is a parameter: the SpaceMouse
// declares Multi-axis Controller, the puck pattern of the Surface Dial System Multi-Axis Controller.
std::vector<std::uint8_t> sixAxisPuckDescriptor(std::uint8_t application) {
  std::vector<std::uint8_t> desc = {
      0x05, 0x01,        // Usage Page (Generic Desktop)
      0x09, 0x08,        // Usage (Multi-axis Controller; replaced by `application`)
      0xa1, 0x01,        // Collection (Application)
      0xa1, 0x00,        //   Collection (Physical)
      0x85, 0x01,        //     Report ID (1)
      0x16, 0xa2, 0xfe,  //     Logical Minimum (-350)
      0x26, 0x5e, 0x01,  //     Logical Maximum (350)
      0x36, 0x88, 0xfa,  //     Physical Minimum (-1400)
      0x46, 0x78, 0x05,  //     Physical Maximum (1400)
      0x55, 0x0c,        //     Unit Exponent (-4)
      0x65, 0x11,        //     Unit (SI Linear: cm)
      0x09, 0x30,        //     Usage (X)
      0x09, 0x31,        //     Usage (Y)
      0x09, 0x32,        //     Usage (Z)
      0x75, 0x10,        //     Report Size (16)
      0x95, 0x03,        //     Report Count (3)
      0x81, 0x06,        //     Input (Data, Variable, Relative)
      0xc0,              //   End Collection
      0xa1, 0x00,        //   Collection (Physical)
      0x85, 0x02,        //     Report ID (2)
      0x09, 0x33,        //     Usage (Rx)
      0x09, 0x34,        //     Usage (Ry)
      0x09, 0x35,        //     Usage (Rz)
      0x75, 0x10,        //     Report Size (16)
      0x95, 0x03,        //     Report Count (3)
      0x81, 0x06,        //     Input (Data, Variable, Relative)
      0xc0,              //   End Collection
      0xa1, 0x02,        //   Collection (Logical)
      0x85, 0x03,        //     Report ID (3)
      0x05, 0x09,        //     Usage Page (Button)
      0x19, 0x01,        //     Usage Minimum (1)
      0x29, 0x02,        //     Usage Maximum (2)
      0x15, 0x00,        //     Logical Minimum (0)
      0x25, 0x01,        //     Logical Maximum (1)
      0x35, 0x00,        //     Physical Minimum (0)
      0x45, 0x01,        //     Physical Maximum (1)
      0x75, 0x01,        //     Report Size (1)
      0x95, 0x02,        //     Report Count (2)
      0x81, 0x02,        //     Input (Data, Variable, Absolute)
      0x95, 0x0e,        //     Report Count (14)
      0x81, 0x03,        //     Input (Constant): padding
      0xc0,              //   End Collection
      0xc0,              // End Collection
  };
  desc[3] = application;
  return desc;
}

// Makes sure a SpaceMouse-like puck gives six relative dials, rotations before translations
// (dials 0-2 rotate in LAVA's table), each read from its own report id, and its two buttons.
// Example failures: the rotations of report 2 read from report 1's bytes; the cm unit taken for
// a rotation unit (a wrong scale); a negative 16-bit value read as 65 000 counts.
TEST(DialProfiles, SixAxisPuckMapsRotationsThenTranslations) {
  for (const std::uint8_t application : {std::uint8_t{0x08}, std::uint8_t{0x0e}}) {
    SCOPED_TRACE(application == 0x08 ? "Multi-axis Controller" : "System Multi-Axis Controller");
    auto d = DialDecoder::create(0x046d, 0xc626, sixAxisPuckDescriptor(application), "puck");
    ASSERT_TRUE(d) << d.error().describe();
    EXPECT_EQ(d->profile(), DialProfile::kGenericHid);
    ASSERT_EQ(d->dialCount(), 6);
    EXPECT_EQ(d->buttonCount(), 2);
    const std::uint32_t order[] = {hid::usages::kRx, hid::usages::kRy, hid::usages::kRz,
                                   hid::usages::kX,  hid::usages::kY,  hid::usages::kZ};
    for (std::size_t i = 0; i < 6; ++i) {
      EXPECT_EQ(d->channels()[i].usage, order[i]) << "dial " << i;
      EXPECT_EQ(d->channels()[i].kind, EventKind::kDialDelta) << "dial " << i;
      EXPECT_DOUBLE_EQ(d->channels()[i].countsPerTurn, kAxisCountsPerTurn) << "dial " << i;
    }
    // Report 1: X +10, Y -5, Z 0 (no event for an axis at rest).
    const std::uint8_t push[] = {0x01, 0x0a, 0x00, 0xfb, 0xff, 0x00, 0x00};
    auto events = decodeAll(*d, push);
    ASSERT_EQ(events.size(), 2u);
    EXPECT_EQ(events[0].index, 3);
    EXPECT_DOUBLE_EQ(events[0].value, 10 / kAxisCountsPerTurn);
    EXPECT_EQ(events[1].index, 4);
    EXPECT_DOUBLE_EQ(events[1].value, -5 / kAxisCountsPerTurn);
    // Report 2: Rx 0, Ry -350 (its minimum), Rz +350 (its maximum).
    const std::uint8_t twist[] = {0x02, 0x00, 0x00, 0xa2, 0xfe, 0x5e, 0x01};
    events = decodeAll(*d, twist);
    ASSERT_EQ(events.size(), 2u);
    EXPECT_EQ(events[0].index, 1);
    EXPECT_DOUBLE_EQ(events[0].value, -350 / kAxisCountsPerTurn);
    EXPECT_EQ(events[1].index, 2);
    EXPECT_DOUBLE_EQ(events[1].value, 350 / kAxisCountsPerTurn);
    // The same report again turns again: relative axes have no memory.
    EXPECT_EQ(decodeAll(*d, twist).size(), 2u);
    // Report 3: the right button (bit 1) down, then both up.
    const std::uint8_t right[] = {0x03, 0x02, 0x00};
    events = decodeAll(*d, right);
    ASSERT_EQ(events.size(), 1u);
    EXPECT_EQ(events[0].kind, EventKind::kButton);
    EXPECT_EQ(events[0].index, 1);
    EXPECT_EQ(events[0].value, 1);
    const std::uint8_t none[] = {0x03, 0x00, 0x00};
    events = decodeAll(*d, none);
    ASSERT_EQ(events.size(), 1u);
    EXPECT_EQ(events[0].value, 0);
    // A short report 1 (one axis cut off) gives what it holds and nothing past its end.
    const std::uint8_t cut[] = {0x01, 0x01, 0x00, 0x02};
    events = decodeAll(*d, cut);
    ASSERT_EQ(events.size(), 1u);
    EXPECT_EQ(events[0].index, 3);
    expectPrefixesSafe(sixAxisPuckDescriptor(application));
  }
}

// Makes sure a mouse-like X/Y relative pair maps to two dials after its wheel, signed 8-bit,
// with the buttons before them in the report. Example failure: X read from the button byte.
TEST(DialProfiles, RelativeXYPairMapsToDialsAfterTheWheel) {
  const std::vector<std::uint8_t> desc = {
      0x05, 0x01,              // Usage Page (Generic Desktop)
      0x09, 0x02,              // Usage (Mouse)
      0xa1, 0x01,              // Collection (Application)
      0x09, 0x01,              //   Usage (Pointer)
      0xa1, 0x00,              //   Collection (Physical)
      0x05, 0x09,              //     Usage Page (Button)
      0x19, 0x01,              //     Usage Minimum (1)
      0x29, 0x03,              //     Usage Maximum (3)
      0x15, 0x00,              //     Logical Minimum (0)
      0x25, 0x01,              //     Logical Maximum (1)
      0x75, 0x01, 0x95, 0x03,  //     Report Size (1), Report Count (3)
      0x81, 0x02,              //     Input (Data, Variable, Absolute)
      0x75, 0x05, 0x95, 0x01,  //     Report Size (5), Report Count (1)
      0x81, 0x03,              //     Input (Constant): padding
      0x05, 0x01,              //     Usage Page (Generic Desktop)
      0x09, 0x30,              //     Usage (X)
      0x09, 0x31,              //     Usage (Y)
      0x09, 0x38,              //     Usage (Wheel)
      0x15, 0x81,              //     Logical Minimum (-127)
      0x25, 0x7f,              //     Logical Maximum (127)
      0x75, 0x08, 0x95, 0x03,  //     Report Size (8), Report Count (3)
      0x81, 0x06,              //     Input (Data, Variable, Relative)
      0xc0,                    //   End Collection
      0xc0,                    // End Collection
  };
  auto d = DialDecoder::create(0x1234, 0x0001, desc, "mouse");
  ASSERT_TRUE(d) << d.error().describe();
  ASSERT_EQ(d->dialCount(), 3);
  EXPECT_EQ(d->buttonCount(), 3);
  EXPECT_EQ(d->channels()[0].usage, hid::usages::kWheel);
  EXPECT_DOUBLE_EQ(d->channels()[0].countsPerTurn, kWheelCountsPerTurn);
  EXPECT_EQ(d->channels()[1].usage, hid::usages::kX);
  EXPECT_EQ(d->channels()[2].usage, hid::usages::kY);
  for (int i = 1; i < 3; ++i) {
    EXPECT_EQ(d->channels()[static_cast<std::size_t>(i)].kind, EventKind::kDialDelta);
    EXPECT_DOUBLE_EQ(d->channels()[static_cast<std::size_t>(i)].countsPerTurn, kAxisCountsPerTurn);
  }
  // Left button, X +3, Y -128 is outside -127..127 (no reading), wheel 0.
  const std::uint8_t moved[] = {0x01, 0x03, 0x80, 0x00};
  auto events = decodeAll(*d, moved);
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0].kind, EventKind::kDialDelta);
  EXPECT_EQ(events[0].index, 1);
  EXPECT_DOUBLE_EQ(events[0].value, 3 / kAxisCountsPerTurn);
  EXPECT_EQ(events[1].kind, EventKind::kButton);
  EXPECT_EQ(events[1].index, 0);
  // X -2, Y +7, wheel -1, left still down.
  const std::uint8_t again[] = {0x01, 0xfe, 0x07, 0xff};
  events = decodeAll(*d, again);
  ASSERT_EQ(events.size(), 3u);
  EXPECT_EQ(events[0].index, 0);
  EXPECT_DOUBLE_EQ(events[0].value, -1 / kWheelCountsPerTurn);
  EXPECT_EQ(events[1].index, 1);
  EXPECT_DOUBLE_EQ(events[1].value, -2 / kAxisCountsPerTurn);
  EXPECT_EQ(events[2].index, 2);
  EXPECT_DOUBLE_EQ(events[2].value, 7 / kAxisCountsPerTurn);
}

// Makes sure an absolute Rz with the Wrap flag, 10 bits packed after 6 button bits, gives
// deltas across the wrap both ways, and that an absolute Z without Wrap stays an absolute dial.
// Example failures: 1020 -> 3 read as -1017 counts; the 10 bits read from a byte boundary.
TEST(DialProfiles, AbsoluteWrappingRzAndAbsoluteZ) {
  const std::vector<std::uint8_t> desc = {
      0x05, 0x01,              // Usage Page (Generic Desktop)
      0x09, 0x08,              // Usage (Multi-axis Controller)
      0xa1, 0x01,              // Collection (Application)
      0x05, 0x09,              //   Usage Page (Button)
      0x19, 0x01,              //   Usage Minimum (1)
      0x29, 0x06,              //   Usage Maximum (6)
      0x15, 0x00,              //   Logical Minimum (0)
      0x25, 0x01,              //   Logical Maximum (1)
      0x75, 0x01, 0x95, 0x06,  //   Report Size (1), Report Count (6)
      0x81, 0x02,              //   Input (Data, Variable, Absolute)
      0x05, 0x01,              //   Usage Page (Generic Desktop)
      0x09, 0x35,              //   Usage (Rz)
      0x15, 0x00,              //   Logical Minimum (0)
      0x26, 0xff, 0x03,        //   Logical Maximum (1023)
      0x75, 0x0a, 0x95, 0x01,  //   Report Size (10), Report Count (1)
      0x81, 0x0a,              //   Input (Data, Variable, Absolute, Wrap)
      0x09, 0x32,              //   Usage (Z)
      0x26, 0xff, 0x00,        //   Logical Maximum (255)
      0x75, 0x08,              //   Report Size (8)
      0x81, 0x02,              //   Input (Data, Variable, Absolute)
      0xc0,                    // End Collection
  };
  auto d = DialDecoder::create(0x1234, 0x0002, desc, "knob");
  ASSERT_TRUE(d) << d.error().describe();
  ASSERT_EQ(d->dialCount(), 2);
  EXPECT_EQ(d->channels()[0].usage, hid::usages::kRz);
  EXPECT_EQ(d->channels()[0].kind, EventKind::kDialDelta);
  EXPECT_DOUBLE_EQ(d->channels()[0].countsPerTurn, 1024) << "a wrapping axis turns once per logical range";
  EXPECT_EQ(d->channels()[1].usage, hid::usages::kZ);
  EXPECT_EQ(d->channels()[1].kind, EventKind::kDialAbsolute);
  // Rz occupies bits 6..15: value v is bytes {(v & 3) << 6 | buttons, v >> 2}; Z is byte 2.
  auto report = [](unsigned rz, std::uint8_t buttons, std::uint8_t z) {
    return std::vector<std::uint8_t>{static_cast<std::uint8_t>(((rz & 3u) << 6) | buttons),
                                     static_cast<std::uint8_t>(rz >> 2), z};
  };
  auto events = decodeAll(*d, report(1020, 0, 0));
  ASSERT_EQ(events.size(), 1u) << "the first Rz is only a reference; Z reports where it is";
  EXPECT_EQ(events[0].kind, EventKind::kDialAbsolute);
  EXPECT_EQ(events[0].index, 1);
  EXPECT_DOUBLE_EQ(events[0].value, 0);
  events = decodeAll(*d, report(3, 0, 0));  // 1020 -> 1023 -> 0 -> 3: +7
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].index, 0);
  EXPECT_DOUBLE_EQ(events[0].value, 7.0 / 1024);
  events = decodeAll(*d, report(1021, 0x20, 255));  // 3 -> 1021: -6; button 6; Z at its maximum
  ASSERT_EQ(events.size(), 3u);
  EXPECT_EQ(events[0].index, 0);
  EXPECT_DOUBLE_EQ(events[0].value, -6.0 / 1024);
  EXPECT_EQ(events[1].kind, EventKind::kDialAbsolute);
  EXPECT_DOUBLE_EQ(events[1].value, 1.0);
  EXPECT_EQ(events[2].kind, EventKind::kButton);
  EXPECT_EQ(events[2].index, 5);
  events = decodeAll(*d, report(1021, 0x20, 255));
  EXPECT_TRUE(events.empty()) << "nothing moved, nothing changed";
  events = decodeAll(*d, report(509, 0x20, 255));  // 1021 -> 509: -512, half a turn, either way
  ASSERT_EQ(events.size(), 1u);
  EXPECT_DOUBLE_EQ(std::abs(events[0].value), 0.5);
}

TEST(VirtualDialBox, EncodedEventsDecodeBackExactly) {
  VirtualReportEncoder enc;
  auto d = DialDecoder::create(0, 0, virtualDialBoxDescriptor());
  ASSERT_TRUE(d) << d.error().describe();
  EXPECT_EQ(d->dialCount(), 8);
  EXPECT_EQ(d->buttonCount(), 32);
  std::vector<Event> decoded;
  auto sink = [&](std::span<const std::uint8_t> report) {
    for (const Event& e : decodeAll(*d, report)) decoded.push_back(e);
  };
  enc.encode(Event{Nanos{0}, 0, EventKind::kDialDelta, 3, 0.25}, sink);
  enc.encode(Event{Nanos{0}, 0, EventKind::kButton, 31, 1}, sink);
  enc.encode(Event{Nanos{0}, 0, EventKind::kDialDelta, 7, -20.0}, sink);  // needs several reports
  enc.encode(Event{Nanos{0}, 0, EventKind::kButton, 31, 0}, sink);
  ASSERT_GE(decoded.size(), 4u);
  EXPECT_EQ(decoded[0].index, 3);
  EXPECT_DOUBLE_EQ(decoded[0].value, 0.25);
  EXPECT_EQ(decoded[1].kind, EventKind::kButton);
  EXPECT_EQ(decoded[1].index, 31);
  double turned = 0;
  for (std::size_t i = 2; i + 1 < decoded.size(); ++i) turned += decoded[i].value;
  EXPECT_NEAR(turned, -20.0, 1e-9);
  EXPECT_EQ(decoded.back().value, 0);
}

TEST(HidRecordingFormat, ParsesWritesAndRejectsWithLineNumbers) {
  const std::string text =
      "# a comment\r\n"
      "R: 3 05 01 c0\n"
      "N: Test Dial\n"
      "I: 3 077d 0410\n"
      "E: 000001.500000 2 01 fd\n"
      "E: 2.25 2 00 00\n";
  auto rec = sim::parseHidRecording(text, "t.hid");
  ASSERT_TRUE(rec) << rec.error().describe();
  ASSERT_EQ(rec->devices.size(), 1u);
  const auto& d = rec->devices[0];
  EXPECT_EQ(d.name, "Test Dial");
  EXPECT_EQ(d.vendor, 0x077d);
  ASSERT_EQ(d.reports.size(), 2u);
  EXPECT_EQ(d.reports[0].time, Nanos{1'500'000'000});
  EXPECT_EQ(d.reports[1].time, Nanos{2'250'000'000});
  EXPECT_EQ(sim::HidRecordingWriter::reportLine(Nanos{1'500'000'000}, d.reports[0].bytes),
            "E: 000001.500000 2 01 fd\n");
  const std::string header = sim::HidRecordingWriter::header(d, false);
  auto again = sim::parseHidRecording(header + "E: 000001.500000 2 01 fd\n", "again");
  ASSERT_TRUE(again);
  EXPECT_EQ(again->devices[0].descriptor, d.descriptor);

  const std::vector<std::pair<std::string, std::string>> bad = {
      {"E: 0.1 1 00\n", "t.hid:1"},    {"R: 2 05\n", "t.hid:1"},
      {"R: 1 zz\n", "t.hid:1"},        {"R: 1 05\nE: x 1 00\n", "t.hid:2"},
      {"R: 1 05\nwhat\n", "t.hid:2"},  {"R: 1 05\nE: 000001.000000 0\n", "t.hid:2"},
      {"# only a comment\n", "t.hid"}, {"R: 1 05\nI: 3 nothex 1\n", "t.hid:2"},
  };
  for (const auto& [input, where] : bad) {
    auto r = sim::parseHidRecording(input, "t.hid");
    ASSERT_FALSE(r) << input;
    EXPECT_EQ(r.error().where(), where) << input << " -> " << r.error().describe();
  }
}

}  // namespace
}  // namespace basalt::devices
