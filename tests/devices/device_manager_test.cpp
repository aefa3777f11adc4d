// The DeviceManager's hotplug state machine, driven through every transition by the synthetic
// backends under a ManualClock: absent -> opening -> live -> lost -> reopening -> live, back-off,
// hotplug notifications, unplug in the middle of a read, a different device replugged at the
// same path, and a video stream that stays the same object for the renderer throughout. And what
// makes it the one owner of a show's devices: a request's own backend and back-off (1 s, 2 s,
// 4 s ... 30 s for a show's dial boxes), requests withdrawn, shared and made again under the same
// name while others run, a restart that reopens at once, and frame taps of one request.
// Example failures: a lost device that is never retried, or retried every frame; a replugged
// device of another model taken although the rule asks for vendor:product; a lost camera whose
// stale frames still reach the texture; a stream object that dangles after a reopen; a show's
// retries at the manager's 250 ms pace; a withdrawn device left open; a name that cannot be
// asked for again after a reload; two synthetic scripts refused as "the same device".

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

/// A backend that has one dial box or none, and notes the time of every look for it.
class CountingProvider final : public DeviceProvider {
 public:
  CountingProvider(const Clock& clock, std::vector<Nanos>& looks) : clock_(clock), looks_(looks) {}
  bool present = false;
  [[nodiscard]] std::string_view backend() const override { return "synthetic"; }
  std::vector<DeviceCandidate> enumerate() override {
    looks_.push_back(clock_.now());
    if (!present) return {};
    return {{sim::SyntheticDial::defaultInfo(), DeviceKind::kDialBox, "", ""}};
  }
  Result<std::unique_ptr<DialBox>> openDialBox(const DeviceCandidate& candidate, const DeviceRequest& /*request*/,
                                               const Clock& clock) override {
    return std::unique_ptr<DialBox>(
        std::make_unique<sim::SyntheticDial>(candidate.info, std::vector<sim::ScriptedInput>{}, clock, false, nullptr));
  }

 private:
  const Clock& clock_;
  std::vector<Nanos>& looks_;
};

// Makes sure a request's own back-off is kept exactly under a ManualClock: a show's dial box that
// is not there is looked for at 0 s, then 1, 2, 4, 8, 16 s after each failure, then every 30 s;
// a hotplug "add" looks at once and starts the back-off over.
// Example failure: the manager's own 250 ms back-off used for a show's dial box; a back-off that
// keeps growing past 30 s; a hotplug that retries but leaves the back-off at 30 s.
TEST(DeviceManager, ARequestsOwnBackoffDoublesFromOneSecondToThirty) {
  ManualClock clock;
  BoundedQueue<Event> events(64);
  DeviceManager manager(clock, events);
  std::vector<Nanos> looks;
  auto provider = std::make_unique<CountingProvider>(clock, looks);
  CountingProvider& knob = *provider;
  Upkeep upkeep;
  upkeep.backoff = Backoff{1s, 30s};
  ASSERT_TRUE(manager.request(dialRequest("knob", {}), std::move(provider), upkeep));
  for (Nanos t{0}; t <= 100s; t += 10ms) {
    clock.set(t);
    manager.step(t);
  }
  const std::vector<Nanos> expected{0s, 1s, 3s, 7s, 15s, 31s, 61s, 91s};
  EXPECT_EQ(looks, expected);
  EXPECT_EQ(manager.status().at(0).attempts, expected.size());
  EXPECT_EQ(manager.status().at(0).nextAttempt, 121s);

  // A device appears: tried at once, and a second failure waits 1 s again, not 30 s.
  looks.clear();
  manager.notifyHotplug({HotplugEvent::Action::kAdded, "hidraw", "/dev/hidraw7"});
  clock.set(100s + 5ms);
  manager.step(clock.now());
  EXPECT_EQ(looks, std::vector<Nanos>{100s + 5ms});
  EXPECT_EQ(manager.status().at(0).nextAttempt, 101s + 5ms);
  knob.present = true;
  clock.set(101s + 5ms);
  manager.step(clock.now());
  EXPECT_EQ(manager.status().at(0).state, DeviceState::kLive);
}

// Makes sure a withdrawn request's device is closed by the manager and its name is free at once,
// so that a reloaded show asks for a device of the same name while the manager's thread runs;
// a request shared by two holders stays until both gave it up.
// Example failures: "two devices are named 'knob'" after a reload; the old device left open (or
// still sending events); a share that closes the device under the other holder.
TEST(DeviceManager, WithdrawnRequestsCloseAndTheirNamesAreFreeAtOnce) {
  Rig rig;
  rig.provider->plug(dialAt("synthetic:knob", 1, 2));
  DeviceMatch m;
  m.path = "synthetic:knob";
  auto first = rig.manager.request(dialRequest("knob", m));
  ASSERT_TRUE(first);
  rig.run(50ms);
  ASSERT_EQ(rig.status("knob").state, DeviceState::kLive);
  auto shared = rig.manager.share("knob");
  ASSERT_TRUE(shared);
  EXPECT_EQ(*shared, *first);
  EXPECT_FALSE(rig.manager.share("nothing"));

  rig.manager.withdraw("knob");  // one holder is left: it stays
  rig.run(50ms);
  EXPECT_EQ(rig.status("knob").state, DeviceState::kLive);
  rig.drainStates();

  rig.manager.withdraw("knob");  // the last one: gone from the status at once
  EXPECT_TRUE(rig.manager.status().empty());
  auto again = rig.manager.request(dialRequest("knob", m));
  ASSERT_TRUE(again) << "the name is free before the next step";
  EXPECT_NE(*again, *first) << "ids are never used twice";
  ASSERT_EQ(rig.manager.status().size(), 1u);
  EXPECT_EQ(rig.manager.status()[0].state, DeviceState::kAbsent);
  rig.run(200ms);
  EXPECT_EQ(rig.status("knob").state, DeviceState::kLive) << "the old device was closed, so its path is free";
  EXPECT_EQ(rig.status("knob").id, *again);
  Event e;
  bool oldEvents = false;
  bool newEvents = false;
  while (rig.events.pop(e)) {
    if (e.kind != EventKind::kDialDelta) continue;
    if (e.device == *first) oldEvents = true;  // drained before it was withdrawn
    if (e.device == *again) newEvents = true;
  }
  EXPECT_FALSE(oldEvents) << "the withdrawn device still sends";
  EXPECT_TRUE(newEvents);
}

// Makes sure a restart closes a live device and opens it again in the same step, whatever its
// back-off, that its bindings hear it go and come back, and that it is counted once done.
// Example failures: a restart that waits out the back-off; a restart the control server is
// never answered for; a shuttle that keeps turning through a restart that failed.
TEST(DeviceManager, ARestartReopensAtOnceAndIsCounted) {
  Rig rig;
  rig.provider->plug(dialAt("synthetic:knob", 1, 2));
  DeviceMatch m;
  m.path = "synthetic:knob";
  ASSERT_TRUE(rig.manager.request(dialRequest("knob", m)));
  rig.run(50ms);
  ASSERT_EQ(rig.status("knob").state, DeviceState::kLive);
  rig.drainStates();
  EXPECT_TRUE(rig.manager.restart("knob"));
  EXPECT_FALSE(rig.manager.restart("nothing"));
  rig.manager.step(rig.clock.now());
  EXPECT_EQ(rig.status("knob").state, DeviceState::kLive);
  EXPECT_EQ(rig.status("knob").restarts, 1u);
  EXPECT_EQ(rig.drainStates(), (std::vector<DeviceState>{DeviceState::kLost, DeviceState::kLive}));

  // Gone: the restart fails at once and says why; the device is lost, and retried later.
  rig.provider->unplug("synthetic:knob");
  rig.manager.restart("knob");
  rig.manager.step(rig.clock.now());
  const DeviceStatus s = rig.status("knob");
  EXPECT_EQ(s.restarts, 2u);
  EXPECT_EQ(s.state, DeviceState::kLost);
  EXPECT_NE(s.lastError.find("synthetic:knob"), std::string::npos) << s.lastError;
  EXPECT_GT(s.nextAttempt, rig.clock.now());
}

// Makes sure a request with a backend of its own looks there only, and that two such requests
// may each hold a device at the same path (two synthetic scripts, two replays of one file): only
// devices found through the same backend can be the same device.
// Example failure: a show's second synthetic dial box refused because the first holds
// "synthetic:dial"; a request taking a device from the shared backends instead of its own.
TEST(DeviceManager, RequestsWithABackendOfTheirOwnFindTheirDevicesThere) {
  Rig rig;
  rig.provider->plug(dialAt("synthetic:dial", 9, 9));  // the shared backend's
  auto own = [](std::uint16_t vendor) {
    return std::make_unique<sim::SyntheticProvider>(
        std::vector<sim::SyntheticProvider::Device>{dialAt("synthetic:dial", vendor, 1)});
  };
  ASSERT_TRUE(rig.manager.request(dialRequest("a", {}), own(1)));
  ASSERT_TRUE(rig.manager.request(dialRequest("b", {}), own(2)));
  ASSERT_TRUE(rig.manager.request(dialRequest("c", {})));
  rig.run(50ms);
  EXPECT_EQ(rig.status("a").state, DeviceState::kLive);
  EXPECT_EQ(rig.status("a").device.vendor, 1);
  EXPECT_EQ(rig.status("b").state, DeviceState::kLive);
  EXPECT_EQ(rig.status("b").device.vendor, 2);
  EXPECT_EQ(rig.status("c").state, DeviceState::kLive);
  EXPECT_EQ(rig.status("c").device.vendor, 9);
}

/// Counts the frames it is handed.
struct CountingTap final : FrameTap {
  std::atomic<int> frames{0};
  void onFrame(DeviceId /*device*/, const FrameRef& /*frame*/) override { ++frames; }
};

// Makes sure a frame tap added for one video request sees that camera's frames and no other's,
// and stops when it is removed; and that two readers of one stream asking for the same show time
// both get the frame (two textures showing one camera).
// Example failures: an MJPEG decoder fed another camera's frames; a second texture of a camera
// that never shows a frame because the first took it.
TEST(DeviceManager, AFrameTapSeesItsRequestsFramesOnly) {
  Rig rig;
  rig.provider->plug(cameraAt("synthetic:cam1"));
  rig.provider->plug(cameraAt("synthetic:cam2"));
  DeviceRequest one;
  one.name = "one";
  one.kind = DeviceKind::kVideoSource;
  one.match.path = "synthetic:cam1";
  DeviceRequest two = one;
  two.name = "two";
  two.match.path = "synthetic:cam2";
  ASSERT_TRUE(rig.manager.request(one));
  ASSERT_TRUE(rig.manager.request(two));
  auto tap = std::make_shared<CountingTap>();
  rig.manager.addFrameTap("one", tap);
  rig.manager.addFrameTap("nothing", tap);  // no such request: nothing happens
  rig.run(500ms);
  const std::uint64_t delivered = rig.manager.videoSource("one")->framesDelivered();
  EXPECT_GT(delivered, 10u);
  EXPECT_EQ(static_cast<std::uint64_t>(tap->frames.load()), delivered) << "every frame of 'one', none of 'two'";
  auto stream = rig.manager.videoStream("one");
  FrameRef a = stream->frameAt(rig.clock.now());
  FrameRef b = stream->frameAt(rig.clock.now());
  ASSERT_TRUE(a);
  EXPECT_EQ(a.get(), b.get()) << "a second reader of the same show time gets the same frame";
  a.reset();
  b.reset();
  rig.manager.removeFrameTap("one", tap.get());
  const int before = tap->frames.load();
  rig.run(200ms);
  EXPECT_EQ(tap->frames.load(), before);
}

}  // namespace
}  // namespace basalt::devices
