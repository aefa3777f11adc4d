// The tracker kind: HID tracker reports decoded against descriptors written here by hand (the
// values worked out from HID 1.11's unit and range rules in the comments), Basalt's virtual
// tracker encoding, the state machine of a fed tracker, unplug and replug of a synthetic tracker
// through the DeviceManager, and replay of a recorded tracker, the same samples every time.
// Example failures: a unit exponent read as unsigned (millimetres taken as kilometres); a
// physical range ignored (an angle in counts); a tracker whose samples buffer is replaced on
// replug (the viewer stops following after the cable was pulled once); a replay whose samples
// differ between two runs under the same manual clock.

#include <gtest/gtest.h>

#include <chrono>
#include <vector>

#include "devices/device_manager.h"
#include "devices/hid/report_descriptor.h"
#include "devices/hid/tracker_decoder.h"
#include "devices/tracker.h"
#include "sim/providers.h"
#include "sim/replay_tracker.h"
#include "sim/synthetic_tracker.h"

namespace basalt::devices {
namespace {

using namespace std::chrono_literals;

// A head tracker with report id 2: X, Y, Z as 16-bit signed millimetres (unit SI linear =
// centimetres, exponent -1), Rx, Ry, Rz as 16-bit counts -18000..18000 meaning -180..180
// degrees (physical range, English rotation), then a constant padding byte.
const std::vector<std::uint8_t> kHeadTracker{
    0x05, 0x01, 0x09, 0x08, 0xa1, 0x01,  // Generic Desktop, Multi-axis Controller, Application
    0x85, 0x02,                          // Report ID 2
    0x09, 0x30, 0x09, 0x31, 0x09, 0x32,  // X, Y, Z
    0x16, 0x01, 0x80,                    // Logical Minimum -32767
    0x26, 0xff, 0x7f,                    // Logical Maximum 32767
    0x65, 0x11,                          // Unit: SI linear, length (centimetres)
    0x55, 0x0f,                          // Unit Exponent -1: millimetres
    0x75, 0x10, 0x95, 0x03, 0x81, 0x02,  // 3 x 16 bits, Input (Data, Variable, Absolute)
    0x09, 0x33, 0x09, 0x34, 0x09, 0x35,  // Rx, Ry, Rz
    0x16, 0xb0, 0xb9,                    // Logical Minimum -18000
    0x26, 0x50, 0x46,                    // Logical Maximum 18000
    0x36, 0x4c, 0xff,                    // Physical Minimum -180
    0x46, 0xb4, 0x00,                    // Physical Maximum 180
    0x65, 0x14,                          // Unit: English rotation (degrees)
    0x55, 0x00,                          // Unit Exponent 0
    0x75, 0x10, 0x95, 0x03, 0x81, 0x02,  // 3 x 16 bits, Input (Data, Variable, Absolute)
    0x75, 0x08, 0x95, 0x01, 0x81, 0x03,  // 1 x 8 bits, Input (Constant)
    0xc0,
};

std::vector<std::uint8_t> le16(std::initializer_list<int> values) {
  std::vector<std::uint8_t> out;
  for (int v : values) {
    const auto u = static_cast<std::uint16_t>(static_cast<std::int16_t>(v));
    out.push_back(static_cast<std::uint8_t>(u & 0xff));
    out.push_back(static_cast<std::uint8_t>(u >> 8));
  }
  return out;
}

TEST(TrackerDecoder, AHandWrittenHeadTrackerDecodesToMetresAndDegrees) {
  auto parsed = hid::parseReportDescriptor(kHeadTracker, "head tracker");
  ASSERT_TRUE(parsed) << parsed.error().describe();
  auto decoder = TrackerDecoder::create(*parsed, "head tracker");
  ASSERT_TRUE(decoder) << decoder.error().describe();
  EXPECT_EQ(decoder->reportId(), 2);
  EXPECT_TRUE(decoder->hasRotation());

  std::vector<std::uint8_t> report{0x02};
  for (std::uint8_t b : le16({1234, -500, 32767, 9000, -4500, 0})) report.push_back(b);
  report.push_back(0xaa);  // padding: ignored
  const auto s = decoder->decode(report, 5ms);
  ASSERT_TRUE(s);
  EXPECT_EQ(s->time, 5ms);
  // 1234 mm, -500 mm, 32767 mm.
  EXPECT_NEAR(s->position.x, 1.234f, 1e-6f);
  EXPECT_NEAR(s->position.y, -0.5f, 1e-6f);
  EXPECT_NEAR(s->position.z, 32.767f, 1e-5f);
  // -180 + (9000 + 18000) * 360 / 36000 = 90; -180 + 13500 * 0.01 = -45; 0 -> 0.
  EXPECT_NEAR(s->rotation.x, 90.0f, 1e-4f);
  EXPECT_NEAR(s->rotation.y, -45.0f, 1e-4f);
  EXPECT_NEAR(s->rotation.z, 0.0f, 1e-4f);

  // Another report id, or a short report, is not a sample.
  std::vector<std::uint8_t> other = report;
  other[0] = 0x01;
  EXPECT_FALSE(decoder->decode(other, 0ns));
  EXPECT_FALSE(decoder->decode(std::span(report).first(5), 0ns));
}

TEST(TrackerDecoder, RelativeAxesAreADialBoxNotATracker) {
  // A SpaceMouse-like puck: X, Y, Z, Rx, Ry, Rz relative.
  const std::vector<std::uint8_t> puck{0x05, 0x01, 0x09, 0x08, 0xa1, 0x01, 0x09, 0x30, 0x09, 0x31, 0x09,
                                       0x32, 0x09, 0x33, 0x09, 0x34, 0x09, 0x35, 0x16, 0x01, 0x80, 0x26,
                                       0xff, 0x7f, 0x75, 0x10, 0x95, 0x06, 0x81, 0x06, 0xc0};
  auto parsed = hid::parseReportDescriptor(puck);
  ASSERT_TRUE(parsed);
  auto decoder = TrackerDecoder::create(*parsed, "puck");
  ASSERT_FALSE(decoder);
  EXPECT_NE(decoder.error().message().find("dial box"), std::string::npos) << decoder.error().message();
}

TEST(TrackerDecoder, TheVirtualTrackerRoundsToMicrometresAndTenThousandthsOfADegree) {
  auto parsed = hid::parseReportDescriptor(virtualTrackerDescriptor(), "virtual tracker");
  ASSERT_TRUE(parsed) << parsed.error().describe();
  auto decoder = TrackerDecoder::create(*parsed);
  ASSERT_TRUE(decoder) << decoder.error().describe();
  runtime::TrackerSample in;
  in.position = {0.1234567f, -1.5f, 2.0000004f};
  in.rotation = {12.34567f, -170.0f, 0.00004f};
  const auto report = encodeVirtualTrackerReport(in);
  // X = round(123456.7) = 123457 um, little-endian.
  EXPECT_EQ(report[0] | report[1] << 8 | report[2] << 16, 123457);
  const auto out = decoder->decode(report, 0ns);
  ASSERT_TRUE(out);
  EXPECT_NEAR(out->position.x, 0.123457f, 1e-7f);
  EXPECT_NEAR(out->position.y, -1.5f, 1e-7f);
  EXPECT_NEAR(out->position.z, 2.0f, 1e-7f);
  EXPECT_NEAR(out->rotation.x, 12.3457f, 1e-5f);
  EXPECT_NEAR(out->rotation.y, -170.0f, 1e-5f);
  EXPECT_NEAR(out->rotation.z, 0.0f, 1e-6f);
}

TEST(FedTracker, ThePushSeamFollowsTheStateMachine) {
  TrackerSamples samples(4);
  FedTracker t({"OSC head", "osc", "network", 0, 0, "osc:/tracker/head", ""});
  runtime::TrackerSample s;
  s.time = 1ms;
  EXPECT_FALSE(t.push(s)) << "a closed tracker takes nothing";
  ASSERT_TRUE(t.open(7, samples));
  EXPECT_EQ(t.state(), DeviceState::kLive);
  for (int i = 0; i < 6; ++i) {
    s.time = Nanos{i * 1'000'000LL};
    EXPECT_TRUE(t.push(s));
  }
  // Bounded: the two oldest went.
  EXPECT_EQ(samples.size(), 4U);
  EXPECT_EQ(samples.dropped(), 2U);
  std::vector<Nanos> taken;
  samples.takeDue(3ms, [&](const runtime::TrackerSample& x) { taken.push_back(x.time); });
  EXPECT_EQ(taken, (std::vector<Nanos>{2ms, 3ms}));
  // The feed goes away: the next service() loses the tracker; it cannot open until it is back.
  t.setPresent(false);
  t.service(10ms);
  EXPECT_EQ(t.state(), DeviceState::kLost);
  ASSERT_TRUE(t.lostReason());
  EXPECT_FALSE(t.push(s));
  EXPECT_FALSE(t.open(7, samples));
  EXPECT_EQ(t.state(), DeviceState::kLost);
  t.setPresent(true);
  ASSERT_TRUE(t.open(7, samples));
  EXPECT_EQ(t.state(), DeviceState::kLive);
  t.close();
  EXPECT_EQ(t.state(), DeviceState::kAbsent);
}

TEST(TrackerManager, ASyntheticTrackerIsUnpluggedAndReplugged) {
  ManualClock clock;
  BoundedQueue<Event> events(256);
  DeviceManager manager(clock, events, {Nanos{100ms}, Nanos{800ms}});
  auto owned = std::make_unique<sim::SyntheticProvider>(std::vector<sim::SyntheticProvider::Device>{});
  sim::SyntheticProvider* provider = owned.get();
  manager.addProvider(std::move(owned));
  sim::SyntheticProvider::Device head;
  head.candidate.info = {"Test head", "synthetic", "virtual", 0, 0, "synthetic:head", ""};
  head.candidate.kind = DeviceKind::kTracker;
  head.tracker.rate = 100;
  provider->plug(head);

  DeviceRequest request;
  request.name = "head";
  request.kind = DeviceKind::kTracker;
  request.match.backend = "synthetic";
  auto id = manager.request(request);
  ASSERT_TRUE(id);
  const auto samples = manager.trackerSamples("head");
  ASSERT_TRUE(samples);
  const auto run = [&](Nanos duration) {
    for (Nanos t{0}; t < duration; t += 10ms) {
      clock.advance(10ms);
      manager.step(clock.now());
    }
  };
  run(200ms);
  ASSERT_NE(manager.tracker("head"), nullptr);
  EXPECT_EQ(manager.status().front().state, DeviceState::kLive);
  std::size_t n = samples->takeDue(clock.now(), [](const runtime::TrackerSample&) {});
  EXPECT_GE(n, 19U);

  provider->unplug("synthetic:head");
  run(50ms);
  EXPECT_EQ(manager.status().front().state, DeviceState::kLost);
  EXPECT_EQ(manager.tracker("head"), nullptr);
  samples->takeDue(clock.now(), [](const runtime::TrackerSample&) {});
  run(50ms);
  EXPECT_EQ(samples->takeDue(clock.now(), [](const runtime::TrackerSample&) {}), 0U) << "nothing while lost";

  provider->plug(head);
  run(500ms);
  EXPECT_EQ(manager.status().front().state, DeviceState::kLive);
  EXPECT_EQ(manager.trackerSamples("head"), samples) << "the same buffer across the replug";
  EXPECT_GT(samples->takeDue(clock.now(), [](const runtime::TrackerSample&) {}), 10U);
  // The bindings heard it: live, lost, live again.
  std::vector<double> states;
  Event e;
  while (events.pop(e)) {
    if (e.kind == EventKind::kDeviceState && e.device == *id) states.push_back(e.value);
  }
  EXPECT_EQ(states, (std::vector<double>{1, 0, 1}));
}

TEST(ReplayTracker, ARecordedPathReplaysTheSameSamplesEveryTime) {
  sim::TrackerPath path;
  path.shape = sim::TrackerPath::Shape::kFigureEight;
  path.radius = 0.4f;
  path.period = 2s;
  sim::HidRecordedDevice recording;
  recording.name = "Synthetic tracker";
  recording.descriptor = virtualTrackerDescriptor();
  for (int i = 0; i < 100; ++i) {  // 1 s at 100 samples a second
    const runtime::TrackerSample s = sim::pathSample(path, Nanos{i * 10'000'000LL});
    const auto report = encodeVirtualTrackerReport(s);
    recording.reports.push_back({s.time, {report.begin(), report.end()}});
  }
  const auto play = [&] {
    ManualClock clock(Nanos{1s});
    auto tracker =
        sim::ReplayTracker::create({"replayed", "replay", "virtual", 0, 0, "head.hid", ""}, recording, clock, false);
    EXPECT_TRUE(tracker);
    TrackerSamples samples(1024);
    EXPECT_TRUE((*tracker)->open(1, samples));
    std::vector<runtime::TrackerSample> got;
    for (int frame = 0; frame < 70; ++frame) {  // 60 frames a second
      clock.set(Nanos{1s} + Nanos{frame * 1'000'000'000LL / 60});
      (*tracker)->service(clock.now());
      samples.takeDue(clock.now(), [&](const runtime::TrackerSample& s) { got.push_back(s); });
    }
    return got;
  };
  const auto first = play();
  const auto second = play();
  ASSERT_EQ(first.size(), 100U);
  EXPECT_EQ(first, second);  // bit for bit
  for (std::size_t i = 0; i < first.size(); ++i) {
    const runtime::TrackerSample expected = sim::pathSample(path, Nanos{static_cast<std::int64_t>(i) * 10'000'000LL});
    EXPECT_EQ(first[i].time, Nanos{1s} + expected.time);
    EXPECT_NEAR(first[i].position.x, expected.position.x, 1e-6f);
    EXPECT_NEAR(first[i].position.z, expected.position.z, 1e-6f);
  }
}

}  // namespace
}  // namespace basalt::devices
