// The DeviceManager's hotplug state machine, driven through every transition by the synthetic
// backends under a ManualClock: absent -> opening -> live -> lost -> reopening -> live, back-off,
// hotplug notifications, unplug in the middle of a read, a different device replugged at the
// same path, and a video stream that stays the same object for the renderer throughout.
// Example failures: a lost device that is never retried, or retried every frame; a replugged
// device of another model taken although the rule asks for vendor:product; a lost camera whose
// stale frames still reach the texture; a stream object that dangles after a reopen.

#include <gtest/gtest.h>

#include <chrono>

#include "devices/device_manager.h"
#include "sim/providers.h"
#include "sim/synthetic_camera.h"
#include "sim/synthetic_dial.h"

namespace basalt::devices {
namespace {

using namespace std::chrono_literals;

sim::SyntheticProvider::Device dialAt(const std::string& path, std::uint16_t vendor, std::uint16_t product) {
  sim::SyntheticProvider::Device d;
  d.candidate.info = {"Test knob", "synthetic", "virtual", vendor, product, path, ""};
  d.candidate.kind = DeviceKind::kDialBox;
  for (int i = 0; i < 100; ++i)
    d.script.push_back({std::chrono::milliseconds(10 * (i + 1)), EventKind::kDialDelta, 0, 0.01});
  d.loop = true;
  return d;
}

sim::SyntheticProvider::Device cameraAt(const std::string& path) {
  sim::SyntheticProvider::Device d;
  d.candidate.info = {"Test camera", "synthetic", "virtual", 0, 0, path, ""};
  d.candidate.kind = DeviceKind::kVideoSource;
  d.camera.mode = {PixelFormat::kYuyv, 64, 36, 30};
  return d;
}

struct Rig {
  ManualClock clock;
  BoundedQueue<Event> events{4096};
  DeviceManager manager{clock, events, {Nanos{100ms}, Nanos{800ms}}};
  sim::SyntheticProvider* provider = nullptr;

  Rig() {
    auto p = std::make_unique<sim::SyntheticProvider>(std::vector<sim::SyntheticProvider::Device>{});
    provider = p.get();
    manager.addProvider(std::move(p));
  }
  void run(Nanos duration, Nanos step = 10ms) {
    for (Nanos t{0}; t < duration; t += step) {
      clock.advance(step);
      manager.step(clock.now());
    }
  }
  DeviceStatus status(const std::string& name) {
    for (const auto& s : manager.status()) {
      if (s.name == name) return s;
    }
    ADD_FAILURE() << "no status for " << name;
    return {};
  }
  std::vector<DeviceState> drainStates(std::size_t* dialEvents = nullptr) {
    std::vector<DeviceState> states;
    Event e;
    while (events.pop(e)) {
      if (e.kind == EventKind::kDeviceState) states.push_back(e.value == 1 ? DeviceState::kLive : DeviceState::kLost);
      if (e.kind == EventKind::kDialDelta && dialEvents) ++*dialEvents;
    }
    return states;
  }
};

DeviceRequest dialRequest(const std::string& name, DeviceMatch match) {
  DeviceRequest r;
  r.name = name;
  r.kind = DeviceKind::kDialBox;
  r.match = std::move(match);
  return r;
}

TEST(DeviceManager, AbsentDeviceIsRetriedWithBackoffThenGoesLive) {
  Rig rig;
  DeviceMatch m;
  m.backend = "synthetic";
  m.path = "synthetic:knob";
  ASSERT_TRUE(rig.manager.request(dialRequest("knob", m)));
  rig.manager.step(rig.clock.now());
  auto s = rig.status("knob");
  EXPECT_EQ(s.state, DeviceState::kAbsent);
  EXPECT_EQ(s.attempts, 1u);
  EXPECT_NE(s.lastError.find("no device matches"), std::string::npos) << s.lastError;
  // Back-off doubles: 100, 200, 400, 800, 800 ms...
  rig.run(1600ms);
  s = rig.status("knob");
  EXPECT_EQ(s.state, DeviceState::kAbsent);
  EXPECT_GE(s.attempts, 4u);
  EXPECT_LE(s.attempts, 6u) << "retried far too often: no back-off";
  // Plugging it in and saying so retries at once, without waiting for the back-off.
  rig.provider->plug(dialAt("synthetic:knob", 1, 2));
  rig.manager.notifyHotplug({HotplugEvent::Action::kAdded, "sim", "synthetic:knob"});
  rig.clock.advance(1ms);
  rig.manager.step(rig.clock.now());
  s = rig.status("knob");
  EXPECT_EQ(s.state, DeviceState::kLive);
  EXPECT_EQ(s.device.path, "synthetic:knob");
  EXPECT_EQ(s.attempts, 0u);
  EXPECT_TRUE(s.lastError.empty());
  EXPECT_EQ(rig.drainStates(), std::vector<DeviceState>{DeviceState::kLive});
}

TEST(DeviceManager, UnplugDuringAReadLosesThenReopensTheSameDevice) {
  Rig rig;
  rig.provider->plug(dialAt("synthetic:knob", 1, 2));
  DeviceMatch m;
  m.path = "synthetic:knob";
  auto id = rig.manager.request(dialRequest("knob", m));
  ASSERT_TRUE(id);
  rig.run(200ms);
  ASSERT_EQ(rig.status("knob").state, DeviceState::kLive);
  std::size_t dialEvents = 0;
  rig.drainStates(&dialEvents);
  EXPECT_GT(dialEvents, 10u);
  // Unplug while events are due: a whole batch of them is pending in the next service().
  rig.clock.advance(100ms);
  rig.provider->unplug("synthetic:knob");
  rig.manager.step(rig.clock.now());
  auto s = rig.status("knob");
  EXPECT_EQ(s.state, DeviceState::kLost);
  EXPECT_NE(s.lastError.find("unplugged"), std::string::npos) << s.lastError;
  EXPECT_EQ(s.since, rig.clock.now()) << "the status says since when";
  EXPECT_EQ(rig.drainStates(), std::vector<DeviceState>{DeviceState::kLost}) << "the bindings are told";
  // While lost nothing flows, and reopening fails with back-off.
  rig.run(500ms);
  dialEvents = 0;
  rig.drainStates(&dialEvents);
  EXPECT_EQ(dialEvents, 0u);
  s = rig.status("knob");
  EXPECT_EQ(s.state, DeviceState::kLost);
  EXPECT_GE(s.attempts, 1u);
  // Replug: reopening -> live, events flow again, same id.
  rig.provider->plug(dialAt("synthetic:knob", 1, 2));
  rig.run(1s);
  s = rig.status("knob");
  EXPECT_EQ(s.state, DeviceState::kLive);
  EXPECT_EQ(s.id, *id);
  dialEvents = 0;
  EXPECT_EQ(rig.drainStates(&dialEvents), std::vector<DeviceState>{DeviceState::kLive});
  EXPECT_GT(dialEvents, 10u);
}

TEST(DeviceManager, HotplugRemovalLosesTheDeviceAtOnce) {
  Rig rig;
  rig.provider->plug(dialAt("synthetic:knob", 1, 2));
  DeviceMatch m;
  m.path = "synthetic:knob";
  ASSERT_TRUE(rig.manager.request(dialRequest("knob", m)));
  rig.run(50ms);
  ASSERT_EQ(rig.status("knob").state, DeviceState::kLive);
  rig.manager.notifyHotplug({HotplugEvent::Action::kRemoved, "hidraw", "synthetic:knob"});
  rig.manager.step(rig.clock.now());
  EXPECT_EQ(rig.status("knob").state, DeviceState::kLost);
  // Still there (the removal was for a node that came back at once): reopens after back-off.
  rig.run(150ms);
  EXPECT_EQ(rig.status("knob").state, DeviceState::kLive);
}

TEST(DeviceManager, ADifferentDeviceAtTheSamePathIsMatchedByItsRule) {
  Rig rig;
  rig.provider->plug(dialAt("/dev/hidraw0", 0x077d, 0x0410));
  DeviceMatch byId;
  byId.vendor = 0x077d;
  byId.product = 0x0410;
  DeviceMatch byPath;
  byPath.path = "/dev/hidraw0";
  ASSERT_TRUE(rig.manager.request(dialRequest("powermate", byId)));
  rig.run(50ms);
  ASSERT_EQ(rig.status("powermate").state, DeviceState::kLive);
  // Another model appears at the same node: the vendor:product rule refuses it.
  rig.provider->plug(dialAt("/dev/hidraw0", 0x0b33, 0x0020));
  rig.run(2s);
  auto s = rig.status("powermate");
  EXPECT_EQ(s.state, DeviceState::kLost);
  EXPECT_NE(s.lastError.find("no device matches"), std::string::npos) << s.lastError;
  // A second request that matches by path takes the new device, with its new identity.
  ASSERT_TRUE(rig.manager.request(dialRequest("any", byPath)));
  rig.run(50ms);
  s = rig.status("any");
  EXPECT_EQ(s.state, DeviceState::kLive);
  EXPECT_EQ(s.device.vendor, 0x0b33);
  // The PowerMate comes back elsewhere: the first request finds it.
  rig.provider->plug(dialAt("/dev/hidraw1", 0x077d, 0x0410));
  rig.run(2s);
  s = rig.status("powermate");
  EXPECT_EQ(s.state, DeviceState::kLive);
  EXPECT_EQ(s.device.path, "/dev/hidraw1");
}

TEST(DeviceManager, DuplicateNamesAreRefused) {
  Rig rig;
  ASSERT_TRUE(rig.manager.request(dialRequest("a", {})));
  auto again = rig.manager.request(dialRequest("a", {}));
  ASSERT_FALSE(again);
  EXPECT_NE(again.error().message().find("'a'"), std::string::npos);
}

TEST(DeviceManager, VideoStreamIsStableAndReportsWaitingLostAndLive) {
  Rig rig;
  DeviceRequest r;
  r.name = "camera";
  r.kind = DeviceKind::kVideoSource;
  r.match.path = "synthetic:cam";
  ASSERT_TRUE(rig.manager.request(r));
  auto stream = rig.manager.videoStream("camera");
  ASSERT_NE(stream, nullptr);
  EXPECT_EQ(rig.manager.videoStream("nothing"), nullptr);
  rig.manager.step(rig.clock.now());
  EXPECT_EQ(stream->health().state, SourceState::kWaiting);
  EXPECT_FALSE(stream->frameAt(rig.clock.now()));

  rig.provider->plug(cameraAt("synthetic:cam"));
  rig.manager.notifyHotplug({HotplugEvent::Action::kAdded, "video4linux", "synthetic:cam"});
  rig.run(100ms);
  EXPECT_EQ(stream->health().state, SourceState::kLive);
  FrameRef f = stream->frameAt(rig.clock.now());
  ASSERT_TRUE(f);
  EXPECT_EQ(f->width, 64u);
  EXPECT_LE(f->pts, rig.clock.now());
  ASSERT_TRUE(stream->mode());
  EXPECT_EQ(stream->mode()->format, PixelFormat::kYuyv);
  f.reset();

  rig.provider->unplug("synthetic:cam");
  rig.run(20ms);
  const auto health = stream->health();
  EXPECT_EQ(health.state, SourceState::kLost);
  EXPECT_GT(health.since, Nanos{0});
  EXPECT_FALSE(stream->frameAt(rig.clock.now())) << "no stale frame after a loss";
  EXPECT_EQ(rig.status("camera").state, DeviceState::kLost);

  rig.provider->plug(cameraAt("synthetic:cam"));
  rig.run(1s);
  EXPECT_EQ(stream->health().state, SourceState::kLive);
  EXPECT_TRUE(stream->frameAt(rig.clock.now())) << "the stream resumes without a restart";
}

TEST(DeviceManager, SignalLossRecoversWithoutReopening) {
  Rig rig;
  auto cam = cameraAt("synthetic:hdmi");
  cam.camera.faults.push_back({200ms, sim::CameraFault::Kind::kSignalLost, 300ms, 0, 0});
  cam.camera.faults.push_back({700ms, sim::CameraFault::Kind::kResolutionChange, 0ms, 128, 72});
  rig.provider->plug(cam);
  DeviceRequest r;
  r.name = "hdmi";
  r.kind = DeviceKind::kVideoSource;
  ASSERT_TRUE(rig.manager.request(r));
  auto stream = rig.manager.videoStream("hdmi");
  rig.run(100ms);
  auto source = rig.manager.videoSource("hdmi");
  ASSERT_NE(source, nullptr);
  rig.run(200ms);  // t = 300 ms: the signal went at 200 ms
  EXPECT_EQ(stream->health().state, SourceState::kLost);
  EXPECT_EQ(rig.status("hdmi").state, DeviceState::kLost);
  EXPECT_NE(rig.status("hdmi").lastError.find("no signal"), std::string::npos);
  rig.run(300ms);  // t = 600 ms: back since 500 ms
  EXPECT_EQ(stream->health().state, SourceState::kLive);
  EXPECT_EQ(rig.manager.videoSource("hdmi"), source) << "renegotiated by itself, not reopened";
  rig.run(200ms);  // t = 800 ms: 128x72 since 700 ms
  FrameRef f = stream->frameAt(rig.clock.now());
  ASSERT_TRUE(f);
  EXPECT_EQ(f->width, 128u);
  EXPECT_EQ(stream->mode()->width, 128u);
}

TEST(DeviceManager, AStallIsReportedAndClearsWhenFramesReturn) {
  Rig rig;
  auto cam = cameraAt("synthetic:cam");
  cam.camera.faults.push_back({100ms, sim::CameraFault::Kind::kStall, 2s, 0, 0});
  rig.provider->plug(cam);
  DeviceRequest r;
  r.name = "cam";
  r.kind = DeviceKind::kVideoSource;
  ASSERT_TRUE(rig.manager.request(r));
  auto stream = rig.manager.videoStream("cam");
  rig.run(400ms);
  EXPECT_EQ(stream->health().state, SourceState::kLive) << "a short gap is not a stall";
  rig.run(600ms);
  EXPECT_EQ(stream->health().state, SourceState::kLost);
  EXPECT_NE(rig.status("cam").lastError.find("stalled"), std::string::npos) << rig.status("cam").lastError;
  rig.run(1500ms);
  EXPECT_EQ(stream->health().state, SourceState::kLive);
}

TEST(DeviceManager, RunsOnItsOwnThreadWithTheSystemClock) {
  SystemClock clock;
  BoundedQueue<Event> events(1024);
  DeviceManager manager(clock, events);
  manager.addProvider(std::make_unique<sim::SyntheticProvider>());
  DeviceRequest r;
  r.name = "camera";
  r.kind = DeviceKind::kVideoSource;
  ASSERT_TRUE(manager.request(r));
  auto stream = manager.videoStream("camera");
  manager.start(std::chrono::milliseconds(5));
  FrameRef f;
  for (int i = 0; i < 400 && !f; ++i) {
    std::this_thread::sleep_for(5ms);
    f = stream->frameAt(clock.now());
  }
  EXPECT_TRUE(f) << "no frame within 2 s";
  f.reset();
  manager.stop();
  EXPECT_EQ(manager.status()[0].state, DeviceState::kAbsent);
  EXPECT_EQ(stream->health().state, SourceState::kWaiting);
}

}  // namespace
}  // namespace basalt::devices
