// OSC (kiosk/osc), two figures, each beside a baseline measured in the same run, on the same show
// (the default demo, headless 160x120 at 60 fps on the system clock, its own motion stopped):
//  (a) latency: from an OSC message leaving a UDP socket (/basalt/spin ,f: rotate_y through the
//      OscInput, the control queue and the director) to the end of the first frame drawn with the
//      show turned, in time and in frames presented since the send. Baseline: a dial event pushed
//      into the run's event queue, as a device thread pushes it, applied through LAVA's dial table.
//      Target: the next frame for both.
//  (b) load: 1,000 OSC messages a second (rotate_y) for BASALT_OSC_LOAD_SECONDS (10 s; 3 under
//      ctest), once all let through (messages_per_second = 2000: each a control the loop runs and
//      the input logs) and once under the default limit (20 a second, bursts of 40: the rest
//      refused and counted), against the same show as long with no message: late frames, the
//      loop's work and CPU time per frame, OSC counts. Target: no late frame.
// Figures only; nothing here asserts a time.

#include <benchmark/benchmark.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <thread>
#include <vector>

#include "bench_main.h"
#include "kiosk/loop/frame_loop.h"
#include "kiosk/manifest/manifest.h"
#include "kiosk/osc/osc_input.h"
#include "kiosk/show/readers.h"
#include "kiosk/show/show_director.h"
#include "kiosk/show/show_loader.h"
#include "kiosk/status/frame_metrics.h"
#include "kiosk/status/status_board.h"
#include "render/output.h"
#include "render/renderer.h"
#include "runtime/bindings.h"
#include "runtime/event_loop.h"
#include "runtime/unique_fd.h"

namespace {

using namespace basalt;
using namespace basalt::kiosk;
using namespace std::chrono_literals;

constexpr DeviceId kDial = 900;  // the baseline's dial box: a replayed device of the director

int loadSeconds() {
  const char* s = std::getenv("BASALT_OSC_LOAD_SECONDS");
  return s && std::atoi(s) > 0 ? std::atoi(s) : 10;
}

/// Notes the frames in which the show's placement changed, and stops the show's own motion.
class Watcher final : public FrameParticipant {
 public:
  Result<void> beforeDraw(const FrameContext& frame) override {
    if (frame.frame == 0) show_->stopMotion();
    return {};
  }
  void afterPresent(const FrameContext& frame) override {
    presented.store(frame.frame, std::memory_order_release);
    if (!(show_->position() == last_)) {
      last_ = show_->position();
      changedAt.store(toSeconds(clock_.now()), std::memory_order_release);
      changedFrame.store(frame.frame, std::memory_order_release);
      changes.fetch_add(1, std::memory_order_acq_rel);
    }
  }
  explicit Watcher(runtime::Show& show) : show_(&show), last_(show.position()) {}
  std::atomic<std::int64_t> presented{-1};
  std::atomic<std::int64_t> changes{0};
  std::atomic<std::int64_t> changedFrame{-1};
  std::atomic<double> changedAt{0};

 private:
  runtime::Show* show_;
  runtime::Position last_;
  SystemClock clock_;
};

struct Rig {
  SystemClock clock;
  std::filesystem::path dir;
  std::unique_ptr<render::Output> output;
  std::unique_ptr<render::Renderer> renderer;
  std::unique_ptr<runtime::EventLoop> loop;
  StatusBoard board{WallTime{}, 60};
  BoundedQueue<Event> events{256};
  runtime::Show show;
  std::unique_ptr<ShowDirector> director;
  std::unique_ptr<OscInput> osc;
  runtime::Bindings dials = runtime::Bindings::lavaDefaults();
  std::string why;

  bool open(double oscRate) {
    dir = std::filesystem::temp_directory_path() / "basalt-osc-bench";
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "show.toml") << "[show]\nentry = \"default\"\nfps = 60\n[osc]\nlisten = \"127.0.0.1:0\"\n"
                                     << "messages_per_second = " << oscRate << "\n"
                                     << "[[osc.bind]]\naddress = \"/basalt/spin\"\naction = \"rotate_y\"\n";
    auto out = render::createHeadlessOutput({160, 120});
    if (!out) return fail(out.error().describe());
    output = std::move(*out);
    auto r = render::Renderer::create();
    if (!r) return fail(r.error().describe());
    renderer = std::move(*r);
    auto l = runtime::EventLoop::create(clock);
    if (!l) return fail(l.error().describe());
    loop = std::move(*l);
    board.setWake([l = loop.get()] { l->wake(); });
    Diagnostics d;
    auto m = readManifest(dir / "show.toml", d);
    if (!m) return fail(d.format());
    ShowFactories factories;
    factories.commands = runControlCommand;
    auto loaded = loadShow(*m, clock, factories);
    if (!loaded) return fail(loaded.error().describe());
    director = std::make_unique<ShowDirector>(
        DirectorContext{clock, *loop, show, *renderer, *output, board, events, nullptr, nullptr, 60}, factories);
    director->install(std::move(*loaded), clock.now(), std::nullopt);
    director->setReplayInput(&dials, {kDial});
    auto input = OscInput::start(m->osc, board);
    if (!input) return fail(input.error().describe());
    osc = std::move(*input);
    return true;
  }
  bool fail(std::string text) {
    why = std::move(text);
    return false;
  }
};

/// One /basalt/spin ,f 0.001 message, written by hand (OSC 1.0).
std::vector<char> spinMessage() {
  std::vector<char> m;
  for (const std::string_view part : {std::string_view("/basalt/spin"), std::string_view(",f")}) {
    m.insert(m.end(), part.begin(), part.end());
    m.push_back('\0');
    while (m.size() % 4 != 0) m.push_back('\0');
  }
  const float value = 0.001f;
  std::uint32_t bits = 0;
  std::memcpy(&bits, &value, 4);
  bits = htonl(bits);
  const auto* b = reinterpret_cast<const char*>(&bits);
  m.insert(m.end(), b, b + 4);
  return m;
}

struct Sender {
  UniqueFd fd{::socket(AF_INET, SOCK_DGRAM, 0)};
  sockaddr_in to{};
  std::vector<char> message = spinMessage();
  explicit Sender(std::uint16_t port) {
    to.sin_family = AF_INET;
    to.sin_port = htons(port);
    to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  }
  void send() const {
    (void)::sendto(fd.get(), message.data(), message.size(), 0, reinterpret_cast<const sockaddr*>(&to), sizeof to);
  }
};

struct Latency {
  std::vector<double> oscMs, dialMs;
  std::vector<std::int64_t> oscFrames, dialFrames;
  std::string why;
} latency;

double median(std::vector<double> v) {
  if (v.empty()) return -1;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}
double percentile(std::vector<double> v, double p) {
  if (v.empty()) return -1;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(p * static_cast<double>(v.size())))];
}

void oscLatency(benchmark::State& state) {
  for (auto _ : state) {
    Rig rig;
    if (!rig.open(1000)) {
      latency.why = rig.why;
      state.SkipWithError(rig.why.c_str());
      return;
    }
    Watcher watcher(rig.show);
    FrameLoop loop({60, -1}, rig.clock, nullptr, *rig.loop, rig.show, *rig.output, *rig.renderer);
    loop.addParticipant(*rig.director);
    loop.addParticipant(watcher);
    std::atomic<bool> done{false};
    std::thread driver([&] {
      Sender sender(rig.osc->port());
      std::this_thread::sleep_for(500ms);  // the first frames, and the motion stopped
      for (int i = 0; i < 120; ++i) {
        // Off the frame's phase: a different point of the frame each time.
        std::this_thread::sleep_for(std::chrono::microseconds(20000 + (i * 3917) % 17000));
        const bool osc = i % 2 == 0;
        const std::int64_t before = watcher.changes.load(std::memory_order_acquire);
        const std::int64_t frameAtSend = watcher.presented.load(std::memory_order_acquire);
        const double t0 = toSeconds(rig.clock.now());
        if (osc) {
          sender.send();
        } else {
          Event e{};
          e.kind = EventKind::kDialDelta;
          e.device = kDial;
          e.index = 1;  // LAVA's dial 1: rotate about Y
          e.value = 0.001;
          e.time = rig.clock.now();
          (void)rig.events.push(e);
          rig.loop->wake();
        }
        for (int w = 0; w < 500 && watcher.changes.load(std::memory_order_acquire) == before; ++w) {
          std::this_thread::sleep_for(200us);
        }
        if (watcher.changes.load(std::memory_order_acquire) == before) continue;  // lost: not counted
        const double ms = (watcher.changedAt.load() - t0) * 1e3;
        const std::int64_t frames = watcher.changedFrame.load() - frameAtSend;
        (osc ? latency.oscMs : latency.dialMs).push_back(ms);
        (osc ? latency.oscFrames : latency.dialFrames).push_back(frames);
      }
      done = true;
      loop.requestStop();
      rig.loop->wake();
    });
    const auto start = std::chrono::steady_clock::now();
    auto stats = loop.run();
    driver.join();
    state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    if (!stats) latency.why = stats.error().describe();
  }
}

struct Load {
  double frames = 0, late = 0, workMs = 0, cpuMs = 0, p99Ms = 0, maxMs = 0;
  OscFigures osc;
  std::string why;
};
Load quiet, loaded, limited;

/// `rate`: the show's messages_per_second; 0 sends nothing (the baseline).
void oscLoad(benchmark::State& state, double rate) {
  const bool send = rate > 0;
  Load& out = !send ? quiet : rate > 1000 ? loaded : limited;
  for (auto _ : state) {
    Rig rig;
    if (!rig.open(send ? rate : 20)) {
      out.why = rig.why;
      state.SkipWithError(rig.why.c_str());
      return;
    }
    FrameMetrics metrics(rig.board, &rig.events);
    Watcher watcher(rig.show);
    const auto frames = static_cast<std::int64_t>(60 * loadSeconds());
    FrameLoop loop({60, frames}, rig.clock, nullptr, *rig.loop, rig.show, *rig.output, *rig.renderer);
    loop.addParticipant(metrics);
    loop.addParticipant(*rig.director);
    loop.addParticipant(watcher);
    std::atomic<bool> stop{false};
    std::thread driver([&] {
      if (!send) return;
      Sender sender(rig.osc->port());
      // 1,000 a second: one each millisecond, on a schedule that does not drift.
      auto next = std::chrono::steady_clock::now();
      while (!stop.load()) {
        sender.send();
        next += 1ms;
        std::this_thread::sleep_until(next);
      }
    });
    const auto start = std::chrono::steady_clock::now();
    auto stats = loop.run();
    stop = true;
    driver.join();
    state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    if (!stats) out.why = stats.error().describe();
    std::this_thread::sleep_for(200ms);  // the input publishes its last counts
    const FrameFigures f = rig.board.frameFigures();
    out.frames = static_cast<double>(f.frames);
    out.late = static_cast<double>(f.lateFrames);
    out.workMs = f.workCount ? f.workSum / static_cast<double>(f.workCount) * 1e3 : 0;
    out.cpuMs = f.workCount ? f.cpuSum / static_cast<double>(f.workCount) * 1e3 : 0;
    out.p99Ms = f.intervalP99 * 1e3;
    out.maxMs = f.intervalMax * 1e3;
    if (auto o = rig.board.oscFigures()) out.osc = *o;
    state.counters["late"] = out.late;
  }
}

BENCHMARK(oscLatency)->UseManualTime()->Iterations(1)->Repetitions(1);
BENCHMARK_CAPTURE(oscLoad, quiet, 0.0)->UseManualTime()->Iterations(1)->Repetitions(1);
BENCHMARK_CAPTURE(oscLoad, osc_1000_per_second_all_run, 2000.0)->UseManualTime()->Iterations(1)->Repetitions(1);
BENCHMARK_CAPTURE(oscLoad, osc_1000_per_second_limited, 20.0)->UseManualTime()->Iterations(1)->Repetitions(1);

void printLoad(const char* name, const Load& l) {
  std::printf(
      "osc load, %s: %.0f frames at 60 fps; late %.0f; frame interval p99 %.2f ms, max %.2f ms; the loop's work "
      "%.3f ms and CPU %.3f ms per frame\n",
      name, l.frames, l.late, l.p99Ms, l.maxMs, l.workMs, l.cpuMs);
}

}  // namespace

int main(int argc, char** argv) {
  return basalt::bench::runBenchmarks(argc, argv, [](const basalt::bench::Medians&) {
    if (!latency.why.empty()) std::printf("osc latency: no figure (%s)\n", latency.why.c_str());
    const auto frames = [](const std::vector<std::int64_t>& v) {
      std::vector<double> d(v.begin(), v.end());
      return std::make_pair(median(d), percentile(d, 1.0));
    };
    const auto [oscFramesMedian, oscFramesMax] = frames(latency.oscFrames);
    const auto [dialFramesMedian, dialFramesMax] = frames(latency.dialFrames);
    std::printf(
        "osc latency: OSC message to the changed frame: median %.2f ms, p90 %.2f ms over %zu; frames "
        "presented since the send: median %.0f, max %.0f\n",
        median(latency.oscMs), percentile(latency.oscMs, 0.9), latency.oscMs.size(), oscFramesMedian, oscFramesMax);
    std::printf(
        "osc latency: dial event (baseline) to the changed frame: median %.2f ms, p90 %.2f ms over %zu; "
        "frames presented since the event: median %.0f, max %.0f\n",
        median(latency.dialMs), percentile(latency.dialMs, 0.9), latency.dialMs.size(), dialFramesMedian,
        dialFramesMax);
    std::printf("osc latency: target: the next frame (1) for both; a 60 Hz frame is 16.7 ms\n");
    if (!quiet.why.empty() || !loaded.why.empty() || !limited.why.empty()) {
      std::printf("osc load: no figure (%s %s %s)\n", quiet.why.c_str(), loaded.why.c_str(), limited.why.c_str());
      return;
    }
    std::printf("osc load: %d s each, the default show at 60 fps; target: no late frame\n", loadSeconds());
    printLoad("no messages (baseline)", quiet);
    for (const auto& [name, load] : {std::pair<const char*, const Load*>{"1,000 a second, all run", &loaded},
                                     {"1,000 a second, 20 let through", &limited}}) {
      printLoad(name, *load);
      const OscFigures& o = load->osc;
      std::printf("osc load, %s: received %llu, acted %llu, queue full %llu, rate limited %llu\n", name,
                  static_cast<unsigned long long>(o.received), static_cast<unsigned long long>(o.acted),
                  static_cast<unsigned long long>(o.queueFull), static_cast<unsigned long long>(o.rateLimited));
    }
  });
}
