// The viewer of a facet display following a replayed tracker (thesis §4.4.3 and §4.5): under a
// ManualClock each frame's head is the newest recorded sample due by the frame's time, the
// facet's frustum moves with it on that frame, and a follower that receives the leader's frame
// message draws the same frustum, bit for bit, on the same frame.
// Example failures: the head a frame late (samples taken before the manager stepped, or the
// sample due exactly at the frame's time left for the next frame); a follower drawing from its
// own viewer instead of the leader's; latency figures that count frames without new samples.

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>

#include "devices/device_manager.h"
#include "devices/hid/tracker_decoder.h"
#include "kiosk/lock/lock_protocol.h"
#include "kiosk/show/head_follower.h"
#include "runtime/facet_projection.h"
#include "runtime/formats/cave.h"
#include "sim/hid_recording.h"
#include "sim/providers.h"
#include "sim/synthetic_tracker.h"

namespace basalt::kiosk {
namespace {

using namespace std::chrono_literals;

// The front facet (z = -1) of a box display 4 wide, 2 high, 2 deep.
constexpr const char* kBoxObj = "v -2 -1 -1\nv 2 -1 -1\nv 2 1 -1\nv -2 1 -1\nf 1 2 3 4\n";

constexpr Nanos kSampleStep = 10ms;  // the recording's 100 samples a second

std::filesystem::path writeRecording(const std::filesystem::path& folder) {
  sim::TrackerPath path;
  path.shape = sim::TrackerPath::Shape::kFigureEight;
  path.radius = 0.5f;
  path.period = 1s;
  path.centre = {0, 0.1f, 0.2f};
  sim::HidRecordedDevice device;
  device.name = "Synthetic tracker";
  device.bus = 6;
  device.descriptor = devices::virtualTrackerDescriptor();
  std::filesystem::create_directories(folder);
  const std::filesystem::path file = folder / "head.hid";
  std::ofstream out(file);
  out << sim::HidRecordingWriter::header(device, false);
  for (int i = 0; i < 200; ++i) {
    const runtime::TrackerSample s = sim::pathSample(path, kSampleStep * i);
    const auto report = devices::encodeVirtualTrackerReport(s);
    out << sim::HidRecordingWriter::reportLine(s.time, report);
  }
  return file;
}

TEST(HeadFollower, AReplayedTrackerMovesTheFrustaFrameExactlyOnLeaderAndFollower) {
  const auto folder = std::filesystem::path(::testing::TempDir()) / "basalt_head_follower";
  std::filesystem::remove_all(folder);
  const std::filesystem::path file = writeRecording(folder);
  auto recording = sim::readHidRecording(file);
  ASSERT_TRUE(recording) << recording.error().describe();
  auto parsed = devices::hid::parseReportDescriptor(recording->devices.front().descriptor);
  ASSERT_TRUE(parsed);
  auto decoder = devices::TrackerDecoder::create(*parsed);
  ASSERT_TRUE(decoder);

  std::vector<formats::Diagnostic> warnings;
  auto box = formats::parseCaveGeometry(kBoxObj, "box.obj", formats::LoadOptions{}, warnings);
  ASSERT_TRUE(box) << box.error().describe();

  ManualClock clock(Nanos{5s});
  BoundedQueue<Event> events(64);
  devices::DeviceManager manager(clock, events);
  auto replay = std::make_unique<sim::ReplayProvider>();
  ASSERT_TRUE(replay->addHidRecording(file));
  ASSERT_EQ(replay->enumerate().front().kind, devices::DeviceKind::kTracker);
  devices::DeviceRequest request;
  request.name = "head";
  request.kind = devices::DeviceKind::kTracker;
  request.match.backend = "replay";
  request.options["loop"] = "false";
  ASSERT_TRUE(manager.request(request, std::move(replay)));

  ViewerSpec viewer;
  viewer.tracker = "head";
  viewer.smoothing.kind = runtime::HeadSmoothing::Kind::kOff;  // the frames must show the samples themselves
  HeadFollower follower(viewer);
  runtime::Show leader, node;
  LockBuffer buffer{};

  const auto frustumOf = [&](const runtime::Show& show) {
    runtime::FacetViewInput in;
    in.viewer = show.head().position;
    in.worldFromCave = runtime::cavePlacement(show);
    in.aspect = 2;
    runtime::FacetProjection p;
    EXPECT_TRUE(runtime::computeFacetView(box->facets[0], in, p));
    return p;
  };

  // Frame 0 opens the tracker (the replay starts then); its samples come from frame 1 on.
  const Nanos opened = clock.now();
  float lastLeft = 0;
  int moved = 0;
  for (int frame = 0; frame <= 90; ++frame) {
    const Nanos t = Nanos{5s} + Nanos{frame * 1'000'000'000LL / 60};
    clock.set(t);
    manager.step(t);
    follower.update(t, manager, leader);
    // The leader's frame message carries the head to the follower.
    FrameMessage m;
    m.frame = frame;
    m.showTimeNs = t.count();
    m.state = captureLockedState(leader);
    auto decoded = decodeFrame(std::span<const std::byte>(buffer.data(), encode(m, buffer)));
    ASSERT_TRUE(decoded) << decoded.error().message();
    applyLockedState(decoded->state, node);

    SCOPED_TRACE(frame);
    if (frame == 0) continue;
    ASSERT_TRUE(leader.head().tracked);
    // The newest sample due by the frame: sample k is due at opened + k * 10 ms.
    const auto k = std::min<std::int64_t>((t - opened) / kSampleStep, 199);
    EXPECT_EQ(leader.head().sampleTime, opened + kSampleStep * k);
    const auto& report = recording->devices.front().reports[static_cast<std::size_t>(k)].bytes;
    const auto expected = decoder->decode(report, Nanos{0});
    ASSERT_TRUE(expected);
    EXPECT_EQ(leader.head().position, expected->position);

    const runtime::FacetProjection a = frustumOf(leader);
    const runtime::FacetProjection b = frustumOf(node);
    EXPECT_EQ(0, std::memcmp(a.projection.m.data(), b.projection.m.data(), sizeof(a.projection.m)));
    EXPECT_EQ(0, std::memcmp(a.view.m.data(), b.view.m.data(), sizeof(a.view.m)));
    if (frame > 1 && a.frustumLeft != lastLeft) ++moved;
    lastLeft = a.frustumLeft;
  }
  EXPECT_GT(moved, 80) << "the frustum follows the head frame by frame";
  // Latency: the newest sample a frame uses is at most one sample interval old.
  EXPECT_EQ(follower.figures().frames, 90U);
  EXPECT_LT(follower.figures().maxLatency, kSampleStep);
  std::filesystem::remove_all(folder);
}

TEST(HeadFollower, WithoutSamplesTheViewerStandsWhereTheManifestPutsIt) {
  ManualClock clock;
  BoundedQueue<Event> events(64);
  devices::DeviceManager manager(clock, events);
  ViewerSpec viewer;
  viewer.position = {0.25f, -0.5f, 0.75f};
  viewer.tracker = "absent";
  HeadFollower follower(viewer);
  runtime::Show show;
  follower.update(1s, manager, show);
  EXPECT_FALSE(show.head().tracked);
  EXPECT_EQ(show.head().position, (Vec3{0.25f, -0.5f, 0.75f}));
  EXPECT_EQ(follower.figures().frames, 0U);
}

}  // namespace
}  // namespace basalt::kiosk
