// Devices (issue 7), three figures, each beside a floor or baseline measured in the same run:
//  (a) dial-event latency: from a dial report arriving (written to the serial line of an SGI box
//      on a pseudo-terminal) to the Show changed by LAVA's dial table, with an event-driven loop
//      woken by the event queue. Floor: the same bytes crossing the pty to a thread blocked in
//      poll() (the kernel and scheduler's share).
//  (b) camera latency: from a frame's capture timestamp to the end of drawing the frame that
//      picked it up, with a synthetic 30 fps camera on the SystemClock and the frame loop paced at
//      60 fps headless. Printed beside the floor of one display frame interval plus the measured
//      render time (the target). A frame counts once it is uploaded to its stream texture
//      (converted from NV12 in the shader) and drawn over the scene as LAVA's Zoom picture, read
//      back so that the GPU has really finished.
//  (c) replay speed: a 60 s trace (dial box plus a 640x360 NV12 camera at 30 fps, .bvraw) replayed
//      under a ManualClock as fast as the headless frame loop runs (160x90 output, the default
//      show), every new camera frame uploaded and drawn as in (b). Baseline: the same 3600
//      frames with no devices. Target: at least 20x real time.
//  (d) MIDI controller latency: from a Mackie V-Pot message sent on a sequencer port of the
//      bench's own to the Show changed, through the kernel's sequencer, the midi backend's reader
//      thread, the event queue's wake-up and LAVA's dial table; beside (a)'s SGI dial box on the
//      same show, measured in the same run. Target: the change makes the next frame (under one
//      frame interval, 16.7 ms at 60 fps). Needs ALSA's sequencer (snd-seq); skipped without it.

#include <benchmark/benchmark.h>

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "bench_main.h"
#include "devices/hid/dial_decoder.h"
#include "devices/midi/midi_backend.h"
#include "devices/serial/sgi_dial_box.h"
#include "kiosk/loop/frame_loop.h"
#include "kiosk/show/device_wiring.h"
#include "render/output.h"
#include "render/renderer.h"
#include "render/stream_texture.h"
#include "runtime/bindings.h"
#include "runtime/event_loop.h"
#include "runtime/show/show.h"
#include "runtime/unique_fd.h"
#include "sim/providers.h"
#include "sim/raw_video.h"
#include "sim/trace.h"

namespace {

using namespace basalt;
using namespace std::chrono_literals;

struct Pty {
  UniqueFd master;
  std::string slave;
  bool open() {
    master.reset(::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC));
    if (!master || ::grantpt(master.get()) != 0 || ::unlockpt(master.get()) != 0) return false;
    slave = ::ptsname(master.get());
    return true;
  }
};

double nowSeconds() { return toSeconds(SystemClock().now()); }

double median(std::vector<double> v) {
  if (v.empty()) return -1;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// Per-sample latencies: the machine is shared, so medians of samples, not means of batches.
std::vector<double> floorSamples, dialSamples, midiSamples, syntheticSamples;

// (a) floor: bytes across the pty to a blocked reader.
void dialFloor(benchmark::State& state) {
  Pty pty;
  if (!pty.open()) {
    state.SkipWithError("no pseudo-terminals");
    return;
  }
  UniqueFd slave(::open(pty.slave.c_str(), O_RDWR | O_NOCTTY | O_CLOEXEC));
  termios tio{};
  ::tcgetattr(slave.get(), &tio);
  ::cfmakeraw(&tio);
  ::tcsetattr(slave.get(), TCSANOW, &tio);
  std::atomic<double> sent{0};
  for (auto _ : state) {
    std::thread writer([&] {
      std::this_thread::sleep_for(200us);
      const std::uint8_t msg[] = {0x30, 0x00, 0x01};
      sent.store(nowSeconds());
      (void)!::write(pty.master.get(), msg, 3);
    });
    pollfd p{slave.get(), POLLIN, 0};
    ::poll(&p, 1, 1000);
    const double got = nowSeconds();
    std::uint8_t buf[8];
    (void)!::read(slave.get(), buf, sizeof buf);
    writer.join();
    state.SetIterationTime(got - sent.load());
    floorSamples.push_back(got - sent.load());
  }
}

// (a) the figure: report arrival to Show change through the real SGI backend.
void dialToShow(benchmark::State& state) {
  Pty pty;
  if (!pty.open()) {
    state.SkipWithError("no pseudo-terminals");
    return;
  }
  SystemClock clock;
  auto loop = runtime::EventLoop::create(clock);
  BoundedQueue<Event> events(1024, [l = loop->get()] { l->wake(); });
  devices::SgiDialBox box(pty.slave, clock, 2s);
  std::thread answer([&] {
    pollfd p{pty.master.get(), POLLIN, 0};
    if (::poll(&p, 1, 2000) > 0) {
      std::uint8_t b[16];
      (void)!::read(pty.master.get(), b, sizeof b);
      const std::uint8_t ok = 0x20;
      (void)!::write(pty.master.get(), &ok, 1);
    }
  });
  auto opened = box.open(1, events);
  answer.join();
  if (!opened) {
    state.SkipWithError(opened.error().describe().c_str());
    return;
  }
  std::this_thread::sleep_for(50ms);
  for (pollfd p{pty.master.get(), POLLIN, 0}; ::poll(&p, 1, 0) > 0 && (p.revents & POLLIN);) {
    std::uint8_t drain[64];  // the enable commands the box was sent
    if (::read(pty.master.get(), drain, sizeof drain) <= 0) break;
  }
  runtime::Show show = runtime::Show::makeDefault();
  runtime::Bindings bindings = runtime::Bindings::lavaDefaults();
  std::uint16_t count = 0;
  std::atomic<double> sent{0};
  for (auto _ : state) {
    count = static_cast<std::uint16_t>(count + 1);
    std::thread writer([&, c = count] {
      std::this_thread::sleep_for(200us);
      const std::uint8_t msg[] = {0x30, static_cast<std::uint8_t>(c >> 8), static_cast<std::uint8_t>(c & 0xff)};
      sent.store(nowSeconds());
      (void)!::write(pty.master.get(), msg, 3);
    });
    bool changed = false;
    while (!changed) {
      if (!(*loop)->dispatch(Nanos{std::chrono::seconds(1)})) break;
      Event e;
      while (events.pop(e)) changed |= bindings.apply(e, show);
    }
    const double done = nowSeconds();
    writer.join();
    state.SetIterationTime(done - sent.load());
    dialSamples.push_back(done - sent.load());
  }
  box.close();
}

// (d) baseline: a dial event pushed into the queue by a device thread of its own (what a
// synthetic or HID dial box's emit() does), to Show change on the same show.
void syntheticToShow(benchmark::State& state) {
  SystemClock clock;
  auto loop = runtime::EventLoop::create(clock);
  BoundedQueue<Event> events(1024, [l = loop->get()] { l->wake(); });
  runtime::Show show = runtime::Show::makeDefault();
  runtime::Bindings bindings = runtime::Bindings::lavaDefaults();
  std::atomic<double> sent{0};
  for (auto _ : state) {
    std::thread device([&] {
      std::this_thread::sleep_for(200us);
      sent.store(nowSeconds());
      (void)events.push(Event{clock.now(), 1, EventKind::kDialDelta, 0, 1.0 / 24});
    });
    bool changed = false;
    while (!changed) {
      if (!(*loop)->dispatch(Nanos{std::chrono::seconds(1)})) break;
      Event e;
      while (events.pop(e)) changed |= bindings.apply(e, show);
    }
    const double done = nowSeconds();
    device.join();
    state.SetIterationTime(done - sent.load());
    syntheticSamples.push_back(done - sent.load());
  }
}

// (d) a MIDI controller's message to Show change through ALSA's sequencer and the midi backend.
void midiToShow(benchmark::State& state) {
  auto port = devices::VirtualMidiPort::create("X-TOUCH MINI");
  if (!port) {
    state.SkipWithError(("no ALSA sequencer here: " + port.error().describe()).c_str());
    return;
  }
  SystemClock clock;
  auto loop = runtime::EventLoop::create(clock);
  BoundedQueue<Event> events(1024, [l = loop->get()] { l->wake(); });
  auto box = devices::openMidiDialBox((*port)->address(), {{"profile", "xtouch-mini-mc"}}, clock);
  if (!box) {
    state.SkipWithError(box.error().describe().c_str());
    return;
  }
  if (auto opened = (*box)->open(1, events); !opened) {
    state.SkipWithError(opened.error().describe().c_str());
    return;
  }
  runtime::Show show = runtime::Show::makeDefault();
  runtime::Bindings bindings = runtime::Bindings::lavaDefaults();
  std::atomic<double> sent{0};
  for (auto _ : state) {
    std::thread writer([&] {
      std::this_thread::sleep_for(200us);
      const std::uint8_t msg[] = {0xB0, 0x10, 0x01};  // V-Pot 1 one detent clockwise
      sent.store(nowSeconds());
      (void)(*port)->send(msg);
    });
    bool changed = false;
    while (!changed) {
      if (!(*loop)->dispatch(Nanos{std::chrono::seconds(1)})) break;
      Event e;
      while (events.pop(e)) changed |= bindings.apply(e, show);
    }
    const double done = nowSeconds();
    writer.join();
    state.SetIterationTime(done - sent.load());
    midiSamples.push_back(done - sent.load());
  }
  (*box)->close();
}

// (b) camera latency, measured inside one paced run.
struct CameraFigures {
  double medianLatency = -1;
  double renderTime = -1;
  double displayInterval = 1.0 / 60;
  double cameraInterval = 1.0 / 30;
  std::size_t frames = 0;
  std::int64_t lateFrames = 0;
  double p90 = -1;
};
CameraFigures cameraFigures;

/// Shows a camera the way a show does: each new frame uploaded to a stream texture (converted
/// in the shader) and drawn, here over the scene as the Zoom picture. Counts what was drawn.
class CameraPicture {
 public:
  /// Uploads the frame due at `time`; true when it was new (and will be drawn this frame).
  Result<bool> upload(FrameSource& source, Nanos time, Nanos& captured) {
    if (!texture_) {
      auto texture = render::StreamTexture::create("camera");
      if (!texture) return std::unexpected(texture.error());
      texture_ = std::move(*texture);
      auto overlay = render::PictureOverlay::create();
      if (!overlay) return std::unexpected(overlay.error());
      overlay_ = std::move(*overlay);
    }
    const FrameRef f = source.frameAt(time);
    auto changed = texture_->update(f);
    if (!changed) return std::unexpected(changed.error());
    if (*changed) captured = f->captureTime;
    return *changed;
  }
  /// Draws the texture over the scene (a quarter of the output), once it has had a frame.
  void draw(render::Output& output) {
    if (!texture_ || texture_->showingFallback()) return;
    const render::Size size = output.size();
    overlay_->draw(texture_->view(), {0, 0, static_cast<float>(size.width) / 2, static_cast<float>(size.height) / 2},
                   size);
    ++drawn_;
  }
  [[nodiscard]] std::uint64_t drawn() const { return drawn_; }

 private:
  std::unique_ptr<render::StreamTexture> texture_;
  std::unique_ptr<render::PictureOverlay> overlay_;
  std::uint64_t drawn_ = 0;
};

class LatencyProbe final : public kiosk::FrameParticipant {
 public:
  LatencyProbe(FrameSource& source, const Clock& clock) : source_(source), clock_(clock) {}
  Result<void> beforeDraw(const kiosk::FrameContext& frame) override {
    drawStart_ = clock_.now();
    auto uploaded = picture_.upload(source_, frame.time, captured_);
    if (!uploaded) return std::unexpected(uploaded.error());
    if (!*uploaded) captured_ = Nanos{0};  // no new frame: nothing to time this frame
    return {};
  }
  Result<void> afterDraw(const kiosk::FrameContext&, render::Output& output) override {
    picture_.draw(output);
    if (auto r = output.readBack(image_); !r) return r;  // waits for the GPU: the frame is really drawn
    const Nanos now = clock_.now();
    render_.push_back(toSeconds(now - drawStart_));
    if (captured_.count() > 0) latency_.push_back(toSeconds(now - captured_));
    captured_ = Nanos{0};
    return {};
  }
  std::vector<double> latency_, render_;

 private:
  FrameSource& source_;
  const Clock& clock_;
  Nanos drawStart_{0}, captured_{0};
  Image image_;
  CameraPicture picture_;
};

void cameraLatency(benchmark::State& state) {
  for (auto _ : state) {
    SystemClock clock;
    auto loop = runtime::EventLoop::create(clock);
    auto output = render::createHeadlessOutput({320, 180});
    auto renderer = render::Renderer::create();
    if (!loop || !output || !renderer) {
      state.SkipWithError("no headless EGL here");
      return;
    }
    BoundedQueue<Event> events(1024, [l = loop->get()] { l->wake(); });
    kiosk::DeviceWiring wiring(clock, events);
    wiring.manager().addProvider(std::make_unique<sim::SyntheticProvider>());
    devices::DeviceRequest r;
    r.name = "camera";
    r.kind = devices::DeviceKind::kVideoSource;
    r.options = {{"format", "NV12"}, {"size", "640x360"}, {"fps", "30"}};
    if (!wiring.manager().request(r)) {
      state.SkipWithError("cannot request the camera");
      return;
    }
    wiring.start(false);
    runtime::Show show = runtime::Show::makeDefault();
    auto stream = wiring.manager().videoStream("camera");
    LatencyProbe probe(*stream, clock);
    kiosk::FrameLoop frameLoop({60, 150}, clock, nullptr, **loop, show, **output, **renderer);
    frameLoop.addParticipant(probe);
    const double t0 = nowSeconds();
    auto stats = frameLoop.run();
    state.SetIterationTime(nowSeconds() - t0);
    wiring.stop();
    if (stats) cameraFigures.lateFrames = stats->lateFrames;
    cameraFigures.medianLatency = median(probe.latency_);
    if (!probe.latency_.empty()) {
      std::sort(probe.latency_.begin(), probe.latency_.end());
      cameraFigures.p90 = probe.latency_[probe.latency_.size() * 9 / 10];
    }
    cameraFigures.renderTime = median(probe.render_);
    cameraFigures.frames = probe.latency_.size();
  }
}

// (c) replay speed.
struct ReplayFigures {
  double replayWall = -1;
  double baselineWall = -1;
  std::uint64_t cameraFrames = 0;
};
ReplayFigures replayFigures;

std::filesystem::path makeTrace() {
  auto dir = std::filesystem::temp_directory_path() / "basalt-bench-replay.trace";
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);
  ManualClock clock;
  auto recorder = sim::TraceRecorder::create(dir, clock, {"bench", "basalt bench", 60, {}});
  if (!recorder) return {};
  devices::DeviceInfo dialInfo = sim::SyntheticDial::defaultInfo();
  devices::DeviceInfo camInfo = sim::SyntheticCamera::defaultInfo();
  const devices::VideoMode mode{PixelFormat::kNv12, 640, 360, 30};
  if (!(*recorder)->addDialBox(1, "dials", dialInfo, devices::virtualDialBoxDescriptor()) ||
      !(*recorder)->addVideoSource(2, "camera", camInfo, mode)) {
    return {};
  }
  devices::VirtualReportEncoder enc;
  auto pool = FramePool::create({mode.format, mode.width, mode.height, 31, 1, true});
  std::vector<FrameRef> lap;  // one second of moving content, drawn once
  for (int i = 0; i < 30; ++i) {
    lap.push_back(pool->acquire());
    drawTestPattern(*lap.back(), TestPattern::kColourBars, static_cast<std::uint64_t>(i), true);
  }
  for (int i = 0; i < 60 * 30; ++i) {
    const Nanos t = frameTime(i, 30);
    clock.set(t);
    enc.encode(Event{t, 1, EventKind::kDialDelta, static_cast<std::uint16_t>(i % 7), 0.01},
               [&](std::span<const std::uint8_t> rep) { (*recorder)->onReport(1, t, rep); });
    const FrameRef& f = lap[static_cast<std::size_t>(i % 30)];
    f->pts = t;
    f->sequence = static_cast<std::uint64_t>(i);
    (*recorder)->onFrame(2, f);
    (*recorder)->drain();
  }
  clock.set(Nanos{std::chrono::seconds(60)});
  if (!(*recorder)->finish()) return {};
  return dir;
}

double runHeadless(const std::filesystem::path& trace, std::uint64_t* cameraFrames) {
  ManualClock clock;
  auto loop = runtime::EventLoop::create(clock);
  auto output = render::createHeadlessOutput({160, 90});
  auto renderer = render::Renderer::create();
  if (!loop || !output || !renderer) return -1;
  runtime::Show show = runtime::Show::makeDefault();
  runtime::Bindings bindings = runtime::Bindings::lavaDefaults();
  kiosk::FrameLoop frameLoop({60, 3600}, clock, &clock, **loop, show, **output, **renderer);
  BoundedQueue<Event> events(1024);
  std::unique_ptr<kiosk::DeviceWiring> wiring;
  // What the show director does with a replayed trace's input, without a show: the frame's
  // events in time order through LAVA's table, and the shuttles' motion.
  struct Input final : kiosk::FrameParticipant {
    BoundedQueue<Event>* events = nullptr;
    runtime::Bindings* bindings = nullptr;
    runtime::Show* show = nullptr;
    std::vector<Event> batch;
    std::vector<Event> later;
    Nanos last{-1};
    Result<void> beforeDraw(const kiosk::FrameContext& f) override {
      if (!events) return {};
      kiosk::takeDueInput(*events, f.time, batch, later);
      for (const Event& e : batch) bindings->apply(e, *show);
      if (last.count() >= 0 && f.time > last) bindings->advance(f.time - last, *show);
      last = f.time;
      return {};
    }
  } input;
  struct Pull final : kiosk::FrameParticipant {
    std::shared_ptr<devices::ManagedVideoStream> stream;
    std::uint64_t frames = 0;  // camera frames uploaded and drawn
    CameraPicture picture;
    Result<void> beforeDraw(const kiosk::FrameContext& f) override {
      if (!stream) return {};
      Nanos captured{0};
      auto uploaded = picture.upload(*stream, f.time, captured);
      if (!uploaded) return std::unexpected(uploaded.error());
      if (*uploaded) ++frames;
      return {};
    }
    Result<void> afterDraw(const kiosk::FrameContext&, render::Output& output) override {
      if (stream) picture.draw(output);
      return {};
    }
  } pull;
  if (!trace.empty()) {
    wiring = std::make_unique<kiosk::DeviceWiring>(clock, events);
    if (!wiring->addReplay(trace, false)) return -1;
    frameLoop.addParticipant(wiring->participant());
    input.events = &events;
    input.bindings = &bindings;
    input.show = &show;
    input.batch.reserve(events.capacity());
    frameLoop.addParticipant(input);
    wiring->start(true);
    pull.stream = wiring->manager().videoStream("camera");
  }
  frameLoop.addParticipant(pull);
  const double t0 = nowSeconds();
  auto stats = frameLoop.run();
  const double wall = nowSeconds() - t0;
  if (wiring) wiring->stop();
  if (cameraFrames) *cameraFrames = pull.frames;
  return stats ? wall : -1;
}

void replaySpeed(benchmark::State& state) {
  const auto trace = makeTrace();
  if (trace.empty()) {
    state.SkipWithError("cannot write the trace");
    return;
  }
  for (auto _ : state) {
    replayFigures.baselineWall = runHeadless({}, nullptr);
    replayFigures.replayWall = runHeadless(trace, &replayFigures.cameraFrames);
    if (replayFigures.replayWall < 0) {
      state.SkipWithError("no headless EGL here, or the replay failed");
      break;
    }
    state.SetIterationTime(replayFigures.replayWall);
  }
  std::error_code ec;
  std::filesystem::remove_all(trace, ec);
}

BENCHMARK(dialFloor)->UseManualTime()->Unit(benchmark::kMicrosecond)->Iterations(50)->Repetitions(3);
BENCHMARK(dialToShow)->UseManualTime()->Unit(benchmark::kMicrosecond)->Iterations(50)->Repetitions(3);
BENCHMARK(syntheticToShow)->UseManualTime()->Unit(benchmark::kMicrosecond)->Iterations(50)->Repetitions(3);
BENCHMARK(midiToShow)->UseManualTime()->Unit(benchmark::kMicrosecond)->Iterations(50)->Repetitions(3);
BENCHMARK(cameraLatency)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(replaySpeed)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace

int main(int argc, char** argv) {
  return basalt::bench::runBenchmarks(argc, argv, [](const basalt::bench::Medians& m) {
    (void)m;
    const double floor = median(floorSamples), dial = median(dialSamples);
    if (floor >= 0 && dial >= 0) {
      std::printf(
          "devices: (a) dial-event latency, report arrival to Show change: %.1f us (median of %zu); pty floor %.1f us "
          "(median of %zu); Basalt's share %.1f us. A paced frame loop adds up to one frame interval (16.7 ms at "
          "60 fps) before the change is drawn.\n",
          dial * 1e6, dialSamples.size(), floor * 1e6, floorSamples.size(), (dial - floor) * 1e6);
    } else {
      std::printf("devices: (a) no figure (no pseudo-terminals?)\n");
    }
    const double midi = median(midiSamples), synthetic = median(syntheticSamples);
    if (midi >= 0 && synthetic >= 0) {
      std::printf(
          "devices: (d) MIDI controller latency, message sent to Show change: %.1f us (median of %zu); baseline, a "
          "dial event from a device thread of its own on the same show: %.1f us (median of %zu)%s; target: the next "
          "frame (< 16.7 ms at 60 fps): %s\n",
          midi * 1e6, midiSamples.size(), synthetic * 1e6, syntheticSamples.size(),
          dial >= 0 ? fmt::format(", the SGI dial box of (a): {:.1f} us", dial * 1e6).c_str() : "",
          midi < 1.0 / 60 ? "met" : "NOT MET");
    } else {
      std::printf("devices: (d) no figure (no ALSA sequencer here: snd-seq; the virtual lab has it)\n");
    }
    const CameraFigures& c = cameraFigures;
    if (c.medianLatency >= 0) {
      const double target = c.displayInterval + c.renderTime;
      std::printf(
          "devices: (b) camera latency, capture timestamp to frame drawn: %.1f ms (median of %zu frames, 90th "
          "percentile %.1f ms, %lld late frames of 150); floor: one frame interval %.1f ms (display, 60 fps; the "
          "camera's is %.1f ms at 30 fps); render time %.1f ms; target <= %.1f ms: %s\n",
          c.medianLatency * 1e3, c.frames, c.p90 * 1e3, static_cast<long long>(c.lateFrames), c.displayInterval * 1e3,
          c.cameraInterval * 1e3, c.renderTime * 1e3, target * 1e3, c.medianLatency <= target ? "met" : "NOT MET");
    } else {
      std::printf("devices: (b) no figure (no headless EGL?)\n");
    }
    const ReplayFigures& r = replayFigures;
    if (r.replayWall > 0) {
      std::printf(
          "devices: (c) replay of a 60 s trace (dial box + 640x360 NV12 camera at 30 fps, .bvraw; %llu camera frames "
          "uploaded and drawn), headless 160x90, ManualClock: %.2f s = %.1fx real time; the same 3600 frames without "
          "devices "
          "%.2f s (%.1fx); target >= 20x: %s\n",
          static_cast<unsigned long long>(r.cameraFrames), r.replayWall, 60.0 / r.replayWall, r.baselineWall,
          60.0 / r.baselineWall, 60.0 / r.replayWall >= 20 ? "met" : "NOT MET");
    } else {
      std::printf("devices: (c) no figure (no headless EGL?)\n");
    }
  });
}
