// The show director in the frame loop, headless on a ManualClock, every frame read back: a
// reload takes over between two frames and never shows a black frame (and a broken manifest
// leaves the old show playing); dials turn the show through their bindings and buttons move the
// playlist; a visitor wakes the attract loop; items that cannot play (a scene with nothing to
// show, a movie) are skipped, and when none can, the screen is black rather than stuck; scripts,
// scenes and models play as items (a script that ends or quits moves the playlist on); control
// commands run on the show; a shuttle ring held off-centre turns the show frame after frame
// until it is let go; outside opening hours the display goes off (black where the output has no
// display to switch); a stream texture shows its fallback; a movie plays as an item, full screen
// and letterboxed, once (the list moves on at its end) or looping without a gap; the textures an
// item uploads leave the registry when it is replaced.
// Example failures: a black frame while the new show loads; a reload error that stops the show;
// a button that does nothing; an unplayable item retried every frame; a movie item stretched to
// the screen or stuck on its last frame; a model's textures piling up in GPU memory item after item.

#include <gtest/gtest.h>

#include <atomic>
#include <fstream>
#include <functional>
#include <thread>

#include "kiosk/loop/frame_loop.h"
#include "kiosk/manifest/manifest.h"
#include "kiosk/manifest/time_zone.h"
#include "kiosk/show/movie_item.h"
#include "kiosk/show/readers.h"
#include "kiosk/show/show_director.h"
#include "kiosk/show/show_loader.h"
#include "kiosk/status/status_board.h"
#include "kiosk/status/status_report.h"
#include "media/movie_probe.h"
#include "render/output.h"
#include "render/renderer.h"
#include "runtime/event_loop.h"
#include "support/test_paths.h"

namespace basalt::kiosk {
namespace {

using namespace std::chrono_literals;

/// Counts the lit pixels of every frame drawn.
class FrameRecorder final : public FrameParticipant {
 public:
  Result<void> afterDraw(const FrameContext& /*frame*/, render::Output& output) override {
    if (auto r = output.readBack(image_); !r) return r;
    std::size_t lit = 0;
    for (std::size_t i = 0; i < image_.pixels.size(); i += 4) {
      if (image_.pixels[i] + image_.pixels[i + 1] + image_.pixels[i + 2] > 30) ++lit;
    }
    lit_.push_back(lit);
    return {};
  }
  [[nodiscard]] const std::vector<std::size_t>& lit() const { return lit_; }
  /// The last frame read back (RGBA, top row first).
  [[nodiscard]] const Image& last() const { return image_; }
  [[nodiscard]] std::size_t blackFrames() const {
    return static_cast<std::size_t>(std::count(lit_.begin(), lit_.end(), std::size_t{0}));
  }

 private:
  Image image_;
  std::vector<std::size_t> lit_;
};

/// The content readers (scripts, scenes, models) and the control commands: what the director's
/// shows here play. No movie or camera stream: a movie texture shows its fallback. Tests that
/// play a movie item add its factory.
ShowFactories contentReaders() {
  ShowFactories f;
  f.items.script = makeScriptItem;
  f.items.scene = makeSceneItem;
  f.items.model = makeModelItem;
  f.commands = runControlCommand;
  return f;
}

/// A show run headless on a ManualClock, frame by frame.
class Harness {
 public:
  explicit Harness(const std::string& name, WallTime wallStart = WallTime{std::chrono::hours(24 * 20000)})
      : dir_(test::scratchDir("director-" + name)), clock_(Nanos{0}, wallStart), board_(wallStart, 30) {}

  bool open(std::string& why) {
    auto output = render::createHeadlessOutput({48, 48});
    if (!output) {
      why = output.error().describe();
      return false;
    }
    output_ = std::move(*output);
    renderer_ = std::move(*render::Renderer::create());
    loop_ = std::move(*runtime::EventLoop::create(clock_));
    return true;
  }

  void write(const std::string& manifest) { std::ofstream(dir_ / "show.toml") << manifest; }
  [[nodiscard]] const std::filesystem::path& dir() const { return dir_; }

  /// Reads the manifest and installs it.
  ::testing::AssertionResult install(const std::string& manifest) {
    write(manifest);
    Diagnostics d;
    auto m = readManifest(dir_ / "show.toml", d);
    if (!m) return ::testing::AssertionFailure() << d.format();
    auto loaded = loadShow(std::move(*m), clock_, factories_);
    if (!loaded) return ::testing::AssertionFailure() << loaded.error().describe();
    director_ = std::make_unique<ShowDirector>(
        DirectorContext{clock_, *loop_, show_, *renderer_, *output_, board_, events_, nullptr, nullptr, 30},
        factories_);
    director_->install(std::move(*loaded), clock_.now(), std::nullopt);
    return ::testing::AssertionSuccess();
  }

  /// Runs `frames` frames at 30 fps, recording each.
  void run(std::int64_t frames) {
    FrameLoop loop({30, frames}, clock_, &clock_, *loop_, show_, *output_, *renderer_);
    loop.addParticipant(*director_);
    loop.addParticipant(recorder_);
    auto stats = loop.run();
    ASSERT_TRUE(stats) << stats.error().describe();
  }

  /// Runs frames until `done` or `limit` frames; the loader thread works in real time meanwhile.
  template <typename Done>
  bool runUntil(Done done, int limit = 600) {
    for (int i = 0; i < limit; ++i) {
      if (done()) return true;
      run(1);
      std::this_thread::sleep_for(2ms);
    }
    return done();
  }

  ShowDirector& director() { return *director_; }
  /// What install() loads the show with, and the director reloads it with.
  ShowFactories& factories() { return factories_; }
  StatusBoard& board() { return board_; }
  FrameRecorder& recorder() { return recorder_; }
  runtime::Show& show() { return show_; }
  render::Renderer& renderer() { return *renderer_; }
  [[nodiscard]] std::string item() const {
    const auto* p = director_->policy();
    return p && p->current().item ? p->current().item->name : std::string();
  }

 private:
  std::filesystem::path dir_;
  ManualClock clock_;
  StatusBoard board_;
  ShowFactories factories_ = contentReaders();
  std::unique_ptr<render::Output> output_;
  std::unique_ptr<render::Renderer> renderer_;
  std::unique_ptr<runtime::EventLoop> loop_;
  BoundedQueue<Event> events_{256};
  runtime::Show show_;
  std::unique_ptr<ShowDirector> director_;
  FrameRecorder recorder_;
};

#define OPEN_OR_SKIP(h)                                                  \
  do {                                                                   \
    std::string why;                                                     \
    if (!(h).open(why)) GTEST_SKIP() << "no headless EGL here: " << why; \
  } while (false)

constexpr const char* kCube = R"(
[show]
name = "A"
entry = "default"
)";

TEST(ShowDirector, AReloadTakesOverWithoutABlackFrame) {
  Harness h("reload");
  OPEN_OR_SKIP(h);
  ASSERT_TRUE(h.install(kCube));
  h.run(10);
  h.write(R"(
[show]
name = "B"
entry = "default"

[[kiosk.playlist]]
name = "cube again"
entry = "default"
)");
  h.director().requestReload();
  ASSERT_TRUE(h.runUntil([&] { return h.director().reloadsApplied() == 1; })) << "the reload never took over";
  h.run(10);
  EXPECT_EQ(h.item(), "cube again");
  EXPECT_EQ(h.board().snapshot(WallTime{}).show.name, "B");
  EXPECT_EQ(h.recorder().blackFrames(), 0u) << "every frame before, during and after the reload shows the cube";

  // A broken manifest: the reload fails, the show plays on unchanged.
  h.write("[show]\nentry = \n");
  h.director().requestReload();
  ASSERT_TRUE(h.runUntil([&] { return h.director().reloadsFailed() == 1; }));
  h.run(10);
  EXPECT_EQ(h.item(), "cube again");
  EXPECT_EQ(h.recorder().blackFrames(), 0u);
  const StatusSnapshot s = h.board().snapshot(WallTime{});
  EXPECT_EQ(s.reloadFailures, 1);
  EXPECT_NE(s.lastReload.find("failed"), std::string::npos) << s.lastReload;
}

// Makes sure a reload of a manifest that is empty, cut short in the middle of a write, not
// UTF-8, or deleted keeps the old show playing (no black frame, the same item) and makes
// /health "degraded" with the reason, and that the next good manifest clears it.
// Example failure: an empty file read as a show with no entry, which puts the built-in default
// show in place of the installation's.
TEST(ShowDirector, AReloadOfABrokenManifestKeepsTheOldShow) {
  Harness h("reload-broken");
  OPEN_OR_SKIP(h);
  const std::string good = R"(
[show]
name = "A"
entry = "default"

[[kiosk.playlist]]
name = "the cube"
entry = "default"
)";
  ASSERT_TRUE(h.install(good));
  h.run(10);
  ASSERT_EQ(h.item(), "the cube");
  const auto manifest = h.dir() / "show.toml";
  struct Case {
    const char* name;
    std::function<void()> damage;
    const char* reason;  // in the failure the status shows
  };
  const std::vector<Case> cases{
      {"empty", [&] { std::ofstream(manifest, std::ios::trunc).close(); }, "empty"},
      {"white space only", [&] { std::ofstream(manifest, std::ios::trunc) << "\n  \n"; }, "empty"},
      {"cut short mid-write", [&] { std::ofstream(manifest, std::ios::trunc) << good.substr(0, 25); }, "TOML"},
      {"invalid UTF-8", [&] { std::ofstream(manifest, std::ios::trunc) << "[show]\nname = \"\xff\xfe\"\n"; }, "UTF-8"},
      {"deleted", [&] { std::filesystem::remove(manifest); }, "show.toml"},
  };
  int failed = 0;
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    c.damage();
    h.director().requestReload();
    ++failed;
    ASSERT_TRUE(h.runUntil([&] { return h.director().reloadsFailed() == failed; }));
    h.run(5);
    EXPECT_EQ(h.item(), "the cube");
    EXPECT_EQ(h.recorder().blackFrames(), 0u) << "the old show plays on";
    const StatusSnapshot s = h.board().snapshot(WallTime{});
    EXPECT_EQ(s.show.name, "A");
    EXPECT_EQ(overallState(s), "degraded");
    EXPECT_NE(s.lastReload.find(c.reason), std::string::npos) << s.lastReload;
  }
  h.write(good);
  h.director().requestReload();
  ASSERT_TRUE(h.runUntil([&] { return h.director().reloadsApplied() == 1; }));
  h.run(2);
  EXPECT_EQ(overallState(h.board().snapshot(WallTime{})), "ok");
  EXPECT_EQ(h.recorder().blackFrames(), 0u);
}

TEST(ShowDirector, DialsTurnTheShowThroughTheirBindings) {
  const std::string manifest = R"(
[show]
entry = "default"
[devices.dials]
kind = "dial_box"
backend = "synthetic"
loop = false
script = [ { at = "0.1s", dial = 1, turns = 0.25 }, { at = "0.2s", dial = 5, turns = 1.0 },
           { at = "0.2s", dial = 4, turns = 0.5 } ]
[[bindings]]
device = "dials"
dial = 1
action = "rotate_y"
[[bindings]]
device = "dials"
dial = 5
action = "none"
)";
  Harness turned("dials");
  OPEN_OR_SKIP(turned);
  ASSERT_TRUE(turned.install(manifest));
  Harness still("dials-still");
  OPEN_OR_SKIP(still);
  ASSERT_TRUE(still.install(kCube));
  turned.run(12);
  still.run(12);
  // The same free-run motion, plus a quarter turn about Y: the matrices differ.
  const Mat4& a = turned.show().position().global;
  const Mat4& b = still.show().position().global;
  float difference = 0;
  for (int i = 0; i < 16; ++i)
    difference += std::abs(a.m[static_cast<std::size_t>(i)] - b.m[static_cast<std::size_t>(i)]);
  EXPECT_GT(difference, 0.5f) << "the dial's quarter turn is in the show";
  // Dial 4 keeps LAVA's translate X (bindings override one dial each), half a turn: half a
  // window unit, rotated since by the free run; dial 5 is bound to nothing, so no Y on top.
  const float moved = std::hypot(a.m[12], a.m[13], a.m[14]);
  EXPECT_NEAR(moved, 0.5f, 1e-4f) << "dial 4 moved the show by LAVA's table and dial 5 did not";
  EXPECT_FLOAT_EQ(std::hypot(b.m[12], b.m[13], b.m[14]), 0.0f);
  const StatusSnapshot s = turned.board().snapshot(WallTime{});
  ASSERT_EQ(s.devices.size(), 1u);
  EXPECT_EQ(s.devices[0].state, "live");
}

/// What the test says to the gated knobs, and what they say back.
struct Gate {
  std::atomic<bool> release{false};       // an open may end
  std::atomic<bool> refuse{false};        // ... with an error
  std::atomic<bool> unplugged{false};     // the live knob fails its next read
  std::atomic<int> attempts{0};           // opens begun
  std::atomic<std::thread::id> openedOn;  // the thread of the last open
};

/// A dial box whose open waits until the test lets it go (a slow enumeration, a serial port's
/// reset wait), and says on which thread it ran.
class GatedDialBox final : public devices::DialBox {
 public:
  explicit GatedDialBox(std::shared_ptr<Gate> gate)
      : DialBox(devices::DeviceInfo{"gated knob", "test", "", 0, 0, "test:knob", ""}, 1, 0), gate_(std::move(gate)) {}
  ~GatedDialBox() override { close(); }
  GatedDialBox(const GatedDialBox&) = delete;
  GatedDialBox& operator=(const GatedDialBox&) = delete;

 private:
  Result<void> doOpen() override {
    gate_->openedOn = std::this_thread::get_id();
    ++gate_->attempts;
    for (int i = 0; i < 1000 && !gate_->release.load(); ++i) std::this_thread::sleep_for(10ms);
    if (gate_->refuse.load()) return fail(Errc::kNotFound, "the gated knob is not there");
    return {};
  }
  void doClose() override {}
  void doService(Nanos /*now*/) override {
    if (gate_->unplugged.load()) reportLost(Error(Errc::kIo, "the gated knob was unplugged"));
  }

  std::shared_ptr<Gate> gate_;
};

/// The backend of the gated knob: always one there, opened through the gate.
class GatedProvider final : public devices::DeviceProvider {
 public:
  explicit GatedProvider(std::shared_ptr<Gate> gate) : gate_(std::move(gate)) {}
  [[nodiscard]] std::string_view backend() const override { return "test"; }
  std::vector<devices::DeviceCandidate> enumerate() override {
    return {{{"gated knob", "test", "", 0, 0, "test:knob", ""}, devices::DeviceKind::kDialBox, "", ""}};
  }
  Result<std::unique_ptr<devices::DialBox>> openDialBox(const devices::DeviceCandidate& /*candidate*/,
                                                        const devices::DeviceRequest& /*request*/,
                                                        const Clock& /*clock*/) override {
    return std::make_unique<GatedDialBox>(gate_);
  }

 private:
  std::shared_ptr<Gate> gate_;
};

// On the system clock a dial box opens on the DeviceManager's thread: a frame never waits for a
// device enumeration or a serial port (the open below takes as long as the test wants), a lost
// box is retried after its back-off (1 s, then 2 s), and a device plugged in (udev) is tried at
// once instead of after its back-off.
// Example failures: the frame loop stuck in open(); a box used while its open still runs; a
// lost box retried every frame, or never; a replug noticed only 30 s later.
TEST(ShowDirector, DialBoxesOpenOffTheFrameLoopAndAHotplugRetriesAtOnce) {
  auto output = render::createHeadlessOutput({32, 32});
  if (!output) GTEST_SKIP() << "no headless EGL here: " << output.error().describe();
  auto renderer = render::Renderer::create();
  ASSERT_TRUE(renderer);
  const SystemClock clock;
  auto loop = runtime::EventLoop::create(clock);
  ASSERT_TRUE(loop);
  const auto dir = test::scratchDir("director-gated");
  std::ofstream(dir / "show.toml") << R"(
[show]
entry = "default"
[devices.knob]
kind = "dial_box"
backend = "synthetic"
)";
  Diagnostics d;
  auto m = readManifest(dir / "show.toml", d);
  ASSERT_TRUE(m) << d.format();
  auto loaded = loadShow(std::move(*m), clock, ShowFactories{});
  ASSERT_TRUE(loaded) << loaded.error().describe();
  ASSERT_EQ((*loaded)->devices.size(), 1u);
  auto gate = std::make_shared<Gate>();
  (*loaded)->devices[0].source.provider = std::make_unique<GatedProvider>(gate);
  (*loaded)->devices[0].source.request.match = {};
  runtime::Show show;
  StatusBoard board(clock.wallNow(), 30);
  BoundedQueue<Event> events(64);
  {
    ShowDirector director(
        DirectorContext{clock, **loop, show, **renderer, **output, board, events, nullptr, nullptr, 30},
        ShowFactories{});
    const Nanos t0 = clock.now();
    director.install(std::move(*loaded), t0, std::nullopt);
    // The show's time stands still at t0; the manager keeps its own time on the system clock.
    auto frame = [&](std::int64_t n) { return director.beforeDraw(FrameContext{n, t0, false}); };
    auto knobState = [&] { return board.snapshot(clock.wallNow()).devices.at(0).state; };
    auto frames = [&](int count) {
      for (int i = 0; i < count; ++i) {
        ASSERT_TRUE(frame(7));
        std::this_thread::sleep_for(10ms);
      }
    };

    // The open starts off the frame loop; the frames go on while it runs.
    ASSERT_TRUE(frame(0));
    for (int i = 0; i < 500 && gate->attempts.load() == 0; ++i) std::this_thread::sleep_for(10ms);
    ASSERT_EQ(gate->attempts.load(), 1) << "the open began";
    EXPECT_NE(gate->openedOn.load(), std::this_thread::get_id()) << "opened on the frame loop's thread";
    for (std::int64_t n = 1; n <= 5; ++n) ASSERT_TRUE(frame(n)) << "frames go on while the open runs";
    EXPECT_FALSE(gate->release.load());
    EXPECT_NE(knobState(), "live");
    gate->release = true;
    for (int i = 0; i < 500 && knobState() != "live"; ++i) {
      ASSERT_TRUE(frame(6));
      std::this_thread::sleep_for(10ms);
    }
    EXPECT_EQ(knobState(), "live") << board.snapshot(clock.wallNow()).devices.at(0).message;

    // Unplugged: lost, and opening it again fails. The first retry comes after 1 s, the next
    // one not before 2 s more; a hotplug notice has it tried again at once.
    gate->refuse = true;
    gate->unplugged = true;
    for (int i = 0; i < 300 && knobState() == "live"; ++i) frames(1);
    EXPECT_EQ(knobState(), "lost");
    for (int i = 0; i < 300 && gate->attempts.load() < 2; ++i) frames(1);
    const int settled = gate->attempts.load();
    ASSERT_EQ(settled, 2) << "a lost box is opened again after its back-off";
    frames(50);
    EXPECT_EQ(gate->attempts.load(), settled) << "no retry before the back-off ends";
    EXPECT_NE(board.snapshot(clock.wallNow()).devices.at(0).message.find("the gated knob is not there"),
              std::string::npos)
        << "the status says why";
    director.noteHotplug();
    for (int i = 0; i < 500 && gate->attempts.load() == settled; ++i) frames(1);
    EXPECT_EQ(gate->attempts.load(), settled + 1) << "a hotplug notice retries at once";
  }  // the director ends with its devices: the manager's thread first, then every box closed
}

/// A backend with no dial box in it, which notes the show time of every look for one.
class EmptyProvider final : public devices::DeviceProvider {
 public:
  EmptyProvider(const Clock& clock, std::shared_ptr<std::vector<Nanos>> looks)
      : clock_(clock), looks_(std::move(looks)) {}
  [[nodiscard]] std::string_view backend() const override { return "test"; }
  std::vector<devices::DeviceCandidate> enumerate() override {
    looks_->push_back(clock_.now());
    return {};
  }

 private:
  const Clock& clock_;
  std::shared_ptr<std::vector<Nanos>> looks_;
};

// Makes sure a show's dial box that is not there is retried as it always was, now by the
// DeviceManager: under a ManualClock at the first frame, then 1 s, 2 s, 4 s, 8 s, 16 s after each
// failure and every 30 s after that, and that its status row says since when it is absent and why.
// Example failures: the manager's own 250 ms back-off for a show's knob (a hidapi enumeration
// four times a second); a retry per frame; a status row without the reason.
TEST(ShowDirector, AMissingDialBoxIsRetriedAfterOneTwoFourSecondsUpToThirty) {
  auto output = render::createHeadlessOutput({32, 32});
  if (!output) GTEST_SKIP() << "no headless EGL here: " << output.error().describe();
  auto renderer = render::Renderer::create();
  ASSERT_TRUE(renderer);
  const WallTime wallStart{std::chrono::hours(24 * 20000)};
  ManualClock clock(Nanos{0}, wallStart);
  auto loop = runtime::EventLoop::create(clock);
  ASSERT_TRUE(loop);
  const auto dir = test::scratchDir("director-backoff");
  std::ofstream(dir / "show.toml") << R"(
[show]
entry = "default"
[devices.knob]
kind = "dial_box"
backend = "synthetic"
)";
  Diagnostics d;
  auto m = readManifest(dir / "show.toml", d);
  ASSERT_TRUE(m) << d.format();
  auto loaded = loadShow(std::move(*m), clock, ShowFactories{});
  ASSERT_TRUE(loaded) << loaded.error().describe();
  auto looks = std::make_shared<std::vector<Nanos>>();
  (*loaded)->devices[0].source.provider = std::make_unique<EmptyProvider>(clock, looks);
  (*loaded)->devices[0].source.request.match = {};
  runtime::Show show;
  StatusBoard board(wallStart, 10);
  BoundedQueue<Event> events(64);
  ShowDirector director(DirectorContext{clock, **loop, show, **renderer, **output, board, events, nullptr, nullptr, 10},
                        ShowFactories{});
  director.install(std::move(*loaded), clock.now(), std::nullopt);
  for (std::int64_t n = 0; n <= 700; ++n) {  // 70 s at 10 frames a second
    const Nanos t = frameTime(n, 10);
    clock.set(t);
    ASSERT_TRUE(director.beforeDraw(FrameContext{n, t, false}));
  }
  const std::vector<Nanos> expected{0s, 1s, 3s, 7s, 15s, 31s, 61s};
  EXPECT_EQ(*looks, expected);
  const StatusSnapshot s = board.snapshot(clock.wallNow());
  ASSERT_EQ(s.devices.size(), 1u);
  EXPECT_EQ(s.devices[0].state, "absent");
  EXPECT_NE(s.devices[0].message.find("is plugged in"), std::string::npos) << s.devices[0].message;
  EXPECT_EQ(s.devices[0].since, wallStart) << "absent since the show started";
}

/// How far apart two shows' placements are (Frobenius norm of the difference): unchanged by the
/// free-run rotation both shows go on to apply.
float placementDistance(const runtime::Show& x, const runtime::Show& y) {
  const Mat4& a = x.position().global;
  const Mat4& b = y.position().global;
  float sum = 0;
  for (std::size_t i = 0; i < 16; ++i) sum += (a.m[i] - b.m[i]) * (a.m[i] - b.m[i]);
  return std::sqrt(sum);
}

TEST(ShowDirector, AHeldShuttleRingKeepsTurningTheShowUntilReleased) {
  // Dial 0 is LAVA's rotate X; its shuttle ring is held at half deflection from 0.1 s to 0.5 s.
  const std::string manifest = R"(
[show]
entry = "default"
[devices.shuttle]
kind = "dial_box"
backend = "synthetic"
loop = false
script = [ { at = "0.1s", shuttle = 0, position = 0.5 }, { at = "0.5s", shuttle = 0, position = 0 } ]
)";
  Harness held("shuttle");
  OPEN_OR_SKIP(held);
  ASSERT_TRUE(held.install(manifest));
  Harness still("shuttle-still");
  OPEN_OR_SKIP(still);
  ASSERT_TRUE(still.install(kCube));
  std::vector<float> distance;
  for (int step = 0; step < 6; ++step) {  // 0.2, 0.4, 0.6, 0.8, 1.0, 1.2 s
    held.run(6);
    still.run(6);
    distance.push_back(placementDistance(held.show(), still.show()));
  }
  EXPECT_GT(distance[0], 0.01f) << "the held ring turns the show";
  EXPECT_GT(distance[1], distance[0] + 0.05f) << "and goes on turning it, frame after frame, while held";
  EXPECT_NEAR(distance[3], distance[2], 1e-4f) << "a released ring stops turning the show";
  EXPECT_NEAR(distance[5], distance[3], 1e-4f);
  EXPECT_EQ(held.recorder().blackFrames(), 0u);
}

TEST(ShowDirector, ButtonsMoveThePlaylistAndInputWakesTheAttractLoop) {
  Harness h("buttons");
  OPEN_OR_SKIP(h);
  ASSERT_TRUE(h.install(R"(
[devices.dials]
kind = "dial_box"
backend = "synthetic"
loop = false
script = [ { at = "0.5s", dial = 0, turns = 0.01 }, { at = "1s", button = 2 }, { at = "1.1s", button = 2, pressed = false } ]
[[bindings]]
device = "dials"
button = 2
action = "next"
[[kiosk.playlist]]
name = "one"
entry = "default"
duration = "1h"
[[kiosk.playlist]]
name = "two"
entry = "default"
duration = "1h"
[kiosk.attract]
idle_timeout = "5s"
items = [ { entry = "default", name = "attract" } ]
)"));
  EXPECT_EQ(h.item(), "attract");
  h.run(18);  // 0.6 s: the dial turned at 0.5 s
  EXPECT_EQ(h.item(), "one") << "a visitor's touch starts the playlist";
  h.run(18);  // 1.2 s: the button was pressed at 1 s
  EXPECT_EQ(h.item(), "two");
  h.run(std::int64_t{30} * 6);  // 7.2 s: five seconds after the last touch
  EXPECT_EQ(h.item(), "attract");
  EXPECT_EQ(h.recorder().blackFrames(), 0u);
}

TEST(ShowDirector, ItemsThatCannotPlayAreSkipped) {
  Harness h("unplayable");
  OPEN_OR_SKIP(h);
  std::ofstream(h.dir() / "wall.sce") << "import gone.obj\n";
  std::ofstream(h.dir() / "clip.webm") << "not a movie";
  ASSERT_TRUE(h.install(R"(
[[kiosk.playlist]]
name = "wall"
entry = "wall.sce"
duration = "10s"
[[kiosk.playlist]]
name = "cube"
entry = "default"
duration = "10s"
)"));
  EXPECT_EQ(h.item(), "cube") << "the scene imports nothing that loads: the cube plays";
  h.run(5);
  EXPECT_EQ(h.recorder().blackFrames(), 0u);
  const StatusSnapshot s = h.board().snapshot(WallTime{});
  bool said = false;
  for (const auto& r : s.lastErrors) {
    said = said || (r.message.find("'wall' cannot play") != std::string::npos &&
                    r.message.find("none of its 1 imports could be loaded") != std::string::npos);
  }
  EXPECT_TRUE(said) << "the operator is told why";

  Harness none("none-playable");
  OPEN_OR_SKIP(none);
  std::ofstream(none.dir() / "clip.webm") << "not a movie";
  std::ofstream(none.dir() / "wall.sce") << "import gone.obj\n";
  ASSERT_TRUE(none.install(R"(
[[kiosk.playlist]]
name = "clip"
entry = "clip.webm"
[[kiosk.playlist]]
name = "wall"
entry = "wall.sce"
duration = "10s"
)"));
  none.run(5);
  EXPECT_EQ(none.item(), "");
  EXPECT_EQ(none.recorder().blackFrames(), 5u) << "nothing can play: black, and the loop goes on";
  EXPECT_EQ(none.board().snapshot(WallTime{}).show.display, "black");
}

constexpr const char* kTriangle = "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\n";

TEST(ShowDirector, AScriptItemPlaysToItsEndAndThePlaylistMovesOn) {
  Harness h("script-item");
  OPEN_OR_SKIP(h);
  std::ofstream(h.dir() / "tri.obj") << kTriangle;
  std::ofstream(h.dir() / "tour.mdl") << "load_object tri.obj\nloop 3\n  position.global_y_rotate = 5\n  draw\n"
                                         "end_loop\nsave_image\n";
  std::ofstream(h.dir() / "quits.mdl") << "draw\nquit\ndraw\n";
  ASSERT_TRUE(h.install(R"(
[[kiosk.playlist]]
name = "tour"
entry = "tour.mdl"
[[kiosk.playlist]]
name = "quits"
entry = "quits.mdl"
[[kiosk.playlist]]
name = "cube"
entry = "default"
duration = "10s"
)"));
  EXPECT_EQ(h.item(), "tour");
  h.run(2);
  EXPECT_EQ(h.item(), "tour") << "three draws: still playing";
  EXPECT_EQ(h.show().partCount(), 1u) << "load_object put the triangle on the show";
  h.run(2);
  EXPECT_EQ(h.item(), "quits") << "the script ended: the next item plays";
  h.run(2);
  EXPECT_EQ(h.item(), "cube") << "quit ends the item";
  EXPECT_EQ(h.show().partCount(), 6u);
  EXPECT_EQ(h.recorder().blackFrames(), 0u);
}

TEST(ShowDirector, SceneAndModelItemsPlay) {
  Harness h("scene-model");
  OPEN_OR_SKIP(h);
  std::ofstream(h.dir() / "tri.obj") << kTriangle;
  std::ofstream(h.dir() / "room.sce") << "bgcolor[0,0,0]\nposition[0,0,4]\n"
                                         "light position[0,0,10,0] ambient[90,90,90] diffuse[230,230,230] "
                                         "specular[0,0,0]\nimport tri.obj\nimport tri.obj\n";
  ASSERT_TRUE(h.install(R"(
[[kiosk.playlist]]
name = "room"
entry = "room.sce"
duration = "1s"
[[kiosk.playlist]]
name = "triangle"
entry = "tri.obj"
duration = "1s"
)"));
  EXPECT_EQ(h.item(), "room");
  h.run(3);
  EXPECT_EQ(h.show().nodes().size(), 2u) << "both imports are on the show";
  EXPECT_TRUE(h.show().viewer().fromScene);
  EXPECT_GT(h.recorder().lit().back(), 0u) << "the scene's triangles are drawn";
  h.run(30);
  EXPECT_EQ(h.item(), "triangle");
  EXPECT_EQ(h.show().partCount(), 1u);
  EXPECT_GT(h.recorder().lit().back(), 0u) << "the model is drawn";
}

TEST(ShowDirector, ControlCommandsRunOnTheShow) {
  const auto dir = test::scratchDir("director-commands");
  std::ofstream(dir / "tri.obj") << kTriangle;
  runtime::Show show = runtime::Show::makeDefault();
  const CommandTarget target{show, nullptr, dir};
  auto ok = runControlCommand("load_object tri.obj", target);
  ASSERT_TRUE(ok) << ok.error().describe();
  EXPECT_NE(ok->find("ran: load_object tri.obj"), std::string::npos) << *ok;
  EXPECT_EQ(show.partCount(), 1u);
  auto gone = runControlCommand("load_object gone.obj", target);
  ASSERT_FALSE(gone);
  EXPECT_NE(gone.error().message().find("gone.obj"), std::string::npos) << gone.error().describe();
  EXPECT_EQ(show.partCount(), 1u) << "a failed load leaves the show as it was";
  EXPECT_FALSE(runControlCommand("render.prim_typ = wireframe", target));
  EXPECT_FALSE(runControlCommand("draw\ndraw", target));
  EXPECT_FALSE(runControlCommand("  ", target));
  EXPECT_FALSE(runControlCommand("load_texture pic.png", target)) << "no renderer to give it to";
}

TEST(ShowDirector, OutsideOpeningHoursTheDisplayGoesDark) {
  // Monday 2026-03-23 12:00 UTC; the show opens on Tuesdays only.
  const WallTime monday{std::chrono::seconds(daysFromCivil(2026, 3, 23) * 86400 + std::int64_t{12} * 3600)};
  Harness h("closed", monday);
  OPEN_OR_SKIP(h);
  ASSERT_TRUE(h.install(R"(
[show]
entry = "default"
[kiosk.schedule]
timezone = "UTC"
tuesday = "10:00-18:00"
outside = "display_off"
)"));
  h.run(3);
  const StatusSnapshot s = h.board().snapshot(WallTime{});
  EXPECT_EQ(s.show.mode, "closed");
  EXPECT_EQ(s.show.display, "off");
  EXPECT_EQ(h.recorder().blackFrames(), 3u) << "the headless output has no display to switch off: black instead";
  bool warned = false;
  for (const auto& r : s.lastErrors) warned = warned || r.message.find("showing black instead") != std::string::npos;
  EXPECT_TRUE(warned);
}

TEST(ShowDirector, AStreamTextureShowsItsFallback) {
  Harness h("fallback");
  OPEN_OR_SKIP(h);
  std::filesystem::copy_file(test::sourceDir() / "configs/shows/video-wall/screens.png", h.dir() / "bars.png");
  std::ofstream(h.dir() / "loop.webm") << "not a movie";
  ASSERT_TRUE(h.install(R"(
[media.loop]
kind = "movie"
file = "loop.webm"
[textures."screens.png"]
source = "loop"
fallback = "bars.png"
[textures.plain]
file = "bars.png"
)"));
  const render::TextureView* screens = h.renderer().textures().find("screens.png");
  ASSERT_NE(screens, nullptr) << "the fallback stands in for the movie";
  EXPECT_EQ(screens->size.width, 128u);
  EXPECT_NE(h.renderer().textures().find("plain"), nullptr);
  const StatusSnapshot s = h.board().snapshot(WallTime{});
  ASSERT_EQ(s.streams.size(), 1u);
  EXPECT_EQ(s.streams[0].state, "absent");
  EXPECT_NE(s.streams[0].message.find("showing the fallback image"), std::string::npos) << s.streams[0].message;
}

/// Lit pixels in the rows [from, to) of an RGBA image.
std::size_t litInRows(const Image& image, std::uint32_t from, std::uint32_t to) {
  std::size_t lit = 0;
  for (std::uint32_t y = from; y < to; ++y) {
    for (std::uint32_t x = 0; x < image.width; ++x) {
      const std::size_t i = (static_cast<std::size_t>(y) * image.width + x) * 4;
      if (image.pixels[i] + image.pixels[i + 1] + image.pixels[i + 2] > 30) ++lit;
    }
  }
  return lit;
}

TEST(MovieItem, LetterboxKeepsTheAspectAndCentres) {
  const render::PictureRect wide = letterbox(1920, 1080, {1000, 1000});
  EXPECT_FLOAT_EQ(wide.width, 1000);
  EXPECT_FLOAT_EQ(wide.height, 562.5f);
  EXPECT_NEAR(wide.x, 0, 1e-3);
  EXPECT_FLOAT_EQ(wide.y, 218.75f);
  const render::PictureRect tall = letterbox(480, 640, {1280, 720});  // pillarbox
  EXPECT_FLOAT_EQ(tall.height, 720);
  EXPECT_FLOAT_EQ(tall.width, 540);
  EXPECT_FLOAT_EQ(tall.x, 370);
  EXPECT_FLOAT_EQ(letterbox(0, 10, {10, 10}).width, 0) << "an empty picture draws nothing";
}

/// The clip the video-wall example loops: its size, rate and length as GStreamer reads them.
struct Clip {
  std::filesystem::path file = test::sourceDir() / "configs/shows/video-wall/clips/loop.webm";
};

TEST(ShowDirector, AMovieItemPlaysLetterboxedAndTheListMovesOnAtItsEnd) {
  Clip clip;
  auto info = media::probeMovie(clip.file);
  ASSERT_TRUE(info) << info.error().describe();
  ASSERT_GT(info->width, info->height) << "the test expects a landscape clip";
  ASSERT_GT(info->duration, Nanos{0});
  Harness h("movie-item");
  h.factories().items.movie = makeMovieItem;
  OPEN_OR_SKIP(h);
  std::filesystem::copy_file(clip.file, h.dir() / "clip.webm");
  ASSERT_TRUE(h.install(R"(
[[kiosk.playlist]]
name = "clip"
entry = "clip.webm"
[[kiosk.playlist]]
name = "cube"
entry = "default"
duration = "1h"
)"));
  ASSERT_EQ(h.item(), "clip");
  h.run(1);
  const Image& first = h.recorder().last();
  const render::PictureRect rect = letterbox(info->width * info->pixelAspect, info->height, {48, 48});
  const auto top = static_cast<std::uint32_t>(rect.y);
  ASSERT_GT(top, 1u);
  EXPECT_EQ(litInRows(first, 0, top - 1), 0u) << "black bars above the picture";
  EXPECT_EQ(litInRows(first, 48 - top + 1, 48), 0u) << "and below";
  EXPECT_GT(litInRows(first, top + 1, 48 - top - 1), 0u) << "the movie's first frame is on screen at once";
  // Played once through, at 30 frames a second of show time, then the cube. (run(n) draws n
  // frames and moves the clock on by n - 1 of them: each run starts where the last one ended.)
  const auto frames = static_cast<int>(toSeconds(info->duration) * 30);
  h.run(frames - 5);
  EXPECT_EQ(h.item(), "clip") << "still playing just before its end";
  EXPECT_EQ(h.recorder().blackFrames(), 0u);
  int played = frames - 6;
  while (h.item() == "clip" && played < frames + 60) {
    h.run(2);
    ++played;
  }
  EXPECT_EQ(h.item(), "cube") << "the movie ended by itself and the list moved on";
  EXPECT_NEAR(played, frames, 3) << "it played for its length, not less, not longer";
  h.run(1);
  EXPECT_GT(litInRows(h.recorder().last(), 0, 8), 0u) << "the cube fills the screen, no bars";
}

TEST(ShowDirector, AMovieAloneInItsListLoopsWithoutAGap) {
  Clip clip;
  auto info = media::probeMovie(clip.file);
  ASSERT_TRUE(info) << info.error().describe();
  Harness h("movie-loop");
  h.factories().items.movie = makeMovieItem;
  OPEN_OR_SKIP(h);
  std::filesystem::copy_file(clip.file, h.dir() / "clip.webm");
  ASSERT_TRUE(h.install("[show]\nentry = \"clip.webm\"\n"));
  const auto frames = static_cast<std::int64_t>(toSeconds(info->duration) * 30);
  h.run(frames * 2 + 10);
  EXPECT_EQ(h.item(), "clip.webm");
  EXPECT_EQ(h.recorder().blackFrames(), 0u) << "no empty frame at the loop point";
  const StatusSnapshot s = h.board().snapshot(WallTime{});
  for (const auto& r : s.lastErrors) ADD_FAILURE() << "unexpected: " << r.message;
}

TEST(ShowDirector, AMovieItemThatCannotPlayIsReportedWithItsLine) {
  Harness h("movie-broken");
  h.factories().items.movie = makeMovieItem;
  OPEN_OR_SKIP(h);
  std::ofstream(h.dir() / "clip.webm") << "not a movie";
  ASSERT_TRUE(h.install(R"(
[[kiosk.playlist]]
name = "clip"
entry = "clip.webm"
[[kiosk.playlist]]
name = "cube"
entry = "default"
duration = "10s"
)"));
  EXPECT_EQ(h.item(), "cube");
  h.run(2);
  EXPECT_EQ(h.recorder().blackFrames(), 0u);
  bool said = false;
  for (const auto& r : h.board().snapshot(WallTime{}).lastErrors) {
    said = said || (r.message.find("'clip' cannot play") != std::string::npos &&
                    r.message.find("show.toml:4") != std::string::npos);
  }
  EXPECT_TRUE(said) << "the operator is told which line names the movie";
}

TEST(ShowDirector, AnItemsTexturesLeaveTheRegistryWhenItIsReplaced) {
  Harness h("item-textures");
  OPEN_OR_SKIP(h);
  std::filesystem::copy_file(test::sourceDir() / "configs/shows/camera-sculpture/camera.png", h.dir() / "pic.png");
  std::filesystem::copy_file(test::sourceDir() / "configs/shows/camera-sculpture/camera.png", h.dir() / "skin.png");
  std::ofstream(h.dir() / "tri.mtl") << "newmtl skin\nKd 1 1 1\nmap_Kd skin.png\n";
  std::ofstream(h.dir() / "tri.obj") << "mtllib tri.mtl\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0.5 1\n"
                                        "vn 0 0 1\nusemtl skin\nf 1/1/1 2/2/1 3/3/1\n";
  ASSERT_TRUE(h.install(R"(
[textures.plain]
file = "pic.png"
[[kiosk.playlist]]
name = "cube"
entry = "default"
duration = "1s"
[[kiosk.playlist]]
name = "triangle"
entry = "tri.obj"
duration = "1s"
)"));
  h.run(2);
  ASSERT_EQ(h.item(), "cube");
  const std::size_t base = h.renderer().textures().size();
  EXPECT_NE(h.renderer().textures().find("plain"), nullptr);
  h.run(32);  // one second on: the next item
  ASSERT_EQ(h.item(), "triangle");
  EXPECT_EQ(h.renderer().textures().size(), base + 1) << "the model's map is uploaded while it plays";
  for (int round = 0; round < 3; ++round) {
    h.run(31);
    ASSERT_EQ(h.item(), "cube");
    EXPECT_EQ(h.renderer().textures().size(), base) << "its map leaves with it (round " << round << ")";
    EXPECT_NE(h.renderer().textures().find("plain"), nullptr) << "the manifest's texture stays";
    h.run(31);
    ASSERT_EQ(h.item(), "triangle");
    EXPECT_EQ(h.renderer().textures().size(), base + 1) << "and comes back when it plays again";
  }
}

}  // namespace
}  // namespace basalt::kiosk
