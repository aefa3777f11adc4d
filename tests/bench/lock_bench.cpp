// Frame-locked nodes (kiosk/lock/frame_lock.h): what the lock costs the leader per frame, beside a
// baseline measured in the same run.
//  - baseline: the leader's frame without the lock (the show moved, its state captured);
//  - alone: the same with the lock and no follower (publishing the frame and "present");
//  - two followers: the same with two followers on loopback, each on its own thread answering as
//    soon as it has the frame (no drawing), so the leader's wait is the round trip itself.
// Target: the lock's overhead per frame on the leader under 1 ms here (a 60 Hz frame is 16.7 ms).

#include <benchmark/benchmark.h>

#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <memory>
#include <thread>

#include "bench_main.h"
#include "kiosk/lock/frame_lock.h"
#include "kiosk/manifest/manifest.h"
#include "render/output.h"
#include "runtime/event_loop.h"
#include "runtime/show/show.h"

namespace {

using namespace basalt;
using namespace basalt::kiosk;

class NullOutput final : public render::Output {
 public:
  [[nodiscard]] std::string_view kind() const override { return "null"; }
  [[nodiscard]] render::Size size() const override { return {4, 4}; }
  [[nodiscard]] std::string describe() const override { return "null"; }
  [[nodiscard]] Result<void> beginFrame() override { return {}; }
  [[nodiscard]] Result<void> present() override { return {}; }
};

// Apart from the lock tests' ports (10000 to 29200) and below the ephemeral range.
int basePort() { return 29200 + static_cast<int>(::getpid() % 200) * 8; }

void baseline(benchmark::State& state) {
  runtime::Show show;
  for (auto _ : state) {
    show.rotateGlobal({1.0f, 0.5f, 0.25f});
    benchmark::DoNotOptimize(captureLockedState(show));
  }
}

void leaderFrames(benchmark::State& state, int followers, int port) {
  SystemClock clock;
  auto loop = runtime::EventLoop::create(clock);
  runtime::Show show;
  LockSpec spec;
  spec.role = LockRole::kLeader;
  spec.node = "leader";
  spec.listen = "127.0.0.1";
  spec.port = port;
  spec.followers = followers;
  spec.timeoutMs = 100;
  auto leader = FrameLock::create(spec, clock, show);
  if (!loop || !leader) {
    state.SkipWithError("cannot start the leader");
    return;
  }
  std::atomic<bool> done{false};
  std::vector<std::thread> threads;
  threads.reserve(static_cast<std::size_t>(followers));
  for (int i = 0; i < followers; ++i) {
    threads.emplace_back([&, i] {
      auto own = runtime::EventLoop::create(clock);
      runtime::Show followerShow;
      LockSpec f;
      f.role = LockRole::kFollower;
      f.node = "f" + std::to_string(i);
      f.leader = "127.0.0.1";
      f.port = port;
      auto lock = FrameLock::create(f, clock, followerShow);
      if (!own || !lock) return;
      NullOutput out;
      while (!done) {
        auto next = (*lock)->nextFrame(**own, std::chrono::milliseconds(20));
        if (!next || !*next) continue;
        if ((*next)->end) break;
        FrameContext c{(*next)->frame, (*next)->time, false};
        if (!(*lock)->beforeDraw(c)) break;
        if (!(*lock)->afterDraw(c, out)) break;
      }
    });
  }
  if ((*leader)->awaitFollowers(**loop) != followers) state.SkipWithError("the followers did not join");
  NullOutput out;
  std::int64_t frame = 0;
  for (auto _ : state) {
    show.rotateGlobal({1.0f, 0.5f, 0.25f});
    FrameContext c{frame, std::chrono::milliseconds(16) * frame, false};
    if (!(*leader)->beforeDraw(c)) break;
    if (!(*leader)->afterDraw(c, out)) break;
    ++frame;
  }
  const FrameLockFigures f = (*leader)->figures();
  state.counters["timeouts"] = static_cast<double>(f.barrierTimeouts);
  (*leader)->sayBye(frame);
  done = true;
  for (std::thread& t : threads) t.join();
}

void alone(benchmark::State& state) { leaderFrames(state, 0, basePort()); }
void twoFollowers(benchmark::State& state) { leaderFrames(state, 2, basePort() + 2); }

}  // namespace

int main(int argc, char** argv) {
  benchmark::RegisterBenchmark("baseline", baseline)->Unit(benchmark::kMicrosecond)->Repetitions(3);
  benchmark::RegisterBenchmark("alone", alone)->Unit(benchmark::kMicrosecond)->Iterations(3000)->Repetitions(3);
  benchmark::RegisterBenchmark("twoFollowers", twoFollowers)
      ->Unit(benchmark::kMicrosecond)
      ->Iterations(3000)
      ->Repetitions(3)
      ->ReportAggregatesOnly(false);
  return basalt::bench::runBenchmarks(argc, argv, [](const basalt::bench::Medians& m) {
    const auto find = [&m](const std::string& name) {
      for (auto it = m.begin(); it != m.end(); ++it) {
        if (it->first.rfind(name, 0) == 0) return it->second;
      }
      return -1.0;
    };
    const double base = find("baseline"), solo = find("alone"), two = find("twoFollowers");
    if (base < 0 || solo < 0 || two < 0) {
      std::printf("frame lock: no figures (a benchmark failed)\n");
      return;
    }
    const double overhead = two - base;
    std::printf(
        "frame lock: leader frame with two followers on loopback %.1f us, with no follower %.1f us, without the "
        "lock %.2f us; the lock's overhead per frame on the leader %.1f us (%.2f %% of a 60 Hz frame); target < 1 "
        "ms: %s\n",
        two * 1e6, solo * 1e6, base * 1e6, overhead * 1e6, overhead / (1.0 / 60) * 100,
        overhead < 1e-3 ? "met" : "NOT MET");
  });
}
