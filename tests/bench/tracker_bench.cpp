// A tracked viewer (thesis §4.4.3): what following a head costs, headless.
//  - sampleToFrustum: a sample pushed by a fed tracker (the OSC seam) between two frames, taken
//    by the show director's HeadFollower at the next frame, smoothed, and the facet's
//    frustum computed from it; against frustumOnly, the same frustum from a fixed viewer. Also
//    counted: frames from the sample to the first frame whose frustum changed (target: the next
//    frame, 1).
//  - sixFacetsFixed, sixFacetsMoving: a six-facet display (a box around the viewer, each facet a
//    640 x 360 picture) drawn from a fixed viewer, and from a viewer whose head moves every frame
//    (a new sample, smoothed, every frame's frusta recomputed), the fixed viewer at the centre of
//    the moving one's circle; the two take turns (random interleaving, 5 repetitions each).
//    Target: moving within 5 % of fixed.
// Each frame ends in glFinish(), so llvmpipe's work is counted.

#include <benchmark/benchmark.h>

#include <GLES3/gl3.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string_view>
#include <vector>

#include "bench_main.h"
#include "devices/device_manager.h"
#include "devices/tracker.h"
#include "kiosk/show/head_follower.h"
#include "render/facet_view.h"
#include "render/output.h"
#include "render/renderer.h"
#include "runtime/facet_projection.h"
#include "runtime/formats/cave.h"
#include "runtime/show/show.h"

namespace {

using namespace basalt;
using namespace std::chrono_literals;

constexpr std::uint32_t kWidth = 640, kHeight = 360;
constexpr Nanos kFrame{16'666'667};

// A box display 4 x 2 x 2 around its origin, every facet wound inward.
constexpr const char* kBox =
    "v -2 -1 -1\nv 2 -1 -1\nv 2 1 -1\nv -2 1 -1\nv -2 -1 1\nv 2 -1 1\nv 2 1 1\nv -2 1 1\n"
    "f 1 2 3 4\nf 2 6 7 3\nf 6 5 8 7\nf 5 1 4 8\nf 4 3 7 8\nf 5 6 2 1\n";

/// A provider whose one tracker another component feeds (as an OSC receiver would).
class FeedProvider final : public devices::DeviceProvider {
 public:
  [[nodiscard]] std::string_view backend() const override { return "feed"; }
  std::vector<devices::DeviceCandidate> enumerate() override {
    return {{{"fed head", "feed", "network", 0, 0, "feed:head", ""}, devices::DeviceKind::kTracker, "", "fed"}};
  }
  Result<std::unique_ptr<devices::Tracker>> openTracker(const devices::DeviceCandidate& c,
                                                        const devices::DeviceRequest&, const Clock&) override {
    auto t = std::make_unique<devices::FedTracker>(c.info);
    fed = t.get();
    return std::unique_ptr<devices::Tracker>(std::move(t));
  }
  devices::FedTracker* fed = nullptr;  // owned by the manager
};

struct Rig {
  ManualClock clock;
  BoundedQueue<Event> events{64};
  devices::DeviceManager manager{clock, events};
  FeedProvider* feed = nullptr;
  std::optional<kiosk::HeadFollower> follower;
  runtime::Show show = runtime::Show::makeDefault();
  formats::CaveGeometry geometry;
  std::string problem;
  /// The next frame's number: it only rises, across every run of every benchmark, because a
  /// sample older than the one before carries no time and is not taken.
  std::int64_t next = 1;

  Rig() {
    std::vector<formats::Diagnostic> warnings;
    auto g = formats::parseCaveGeometry(kBox, "box.obj", {}, warnings);
    if (!g) {
      problem = g.error().describe();
      return;
    }
    geometry = std::move(*g);
    auto p = std::make_unique<FeedProvider>();
    feed = p.get();
    devices::DeviceRequest request;
    request.name = "head";
    request.kind = devices::DeviceKind::kTracker;
    if (!manager.request(request, std::move(p))) problem = "the fed tracker cannot be requested";
    kiosk::ViewerSpec viewer;
    viewer.tracker = "head";
    follower.emplace(viewer);
    manager.step(clock.now());
    if (!feed->fed) problem = "the fed tracker did not open";
  }
  /// The head at frame n: a circle of 0.3 around the centre, one lap in 4 s.
  static Vec3 headAt(std::int64_t n) {
    const double a = 2.0 * 3.14159265358979 * static_cast<double>(n) / 240.0;
    return {static_cast<float>(0.3 * std::cos(a)), 0, static_cast<float>(0.3 * std::sin(a))};
  }
  /// One frame: a sample measured half a frame before it (between two frames) is pushed, and
  /// the frame takes it.
  void moveHead(std::int64_t n) {
    const Nanos t = kFrame * n;
    clock.set(t);
    runtime::TrackerSample s;
    s.time = t - kFrame / 2;
    s.position = headAt(n);
    feed->fed->push(s);
    manager.step(t);
    follower->update(t, manager, show);
  }
};

Rig& rig() {
  static Rig r;
  return r;
}

int framesToChange = 0;  ///< the most frames any run counted

void sampleToFrustum(benchmark::State& state) {
  Rig& r = rig();
  if (!r.problem.empty()) {
    state.SkipWithError(r.problem.c_str());
    return;
  }
  runtime::FacetViewInput in;
  in.worldFromCave = runtime::cavePlacement(r.show);
  in.aspect = 16.0f / 9.0f;
  runtime::FacetProjection p;
  // Frames from a sample to the first frame whose frustum changed.
  {
    const std::int64_t n = r.next++;
    r.moveHead(n);
    in.viewer = r.show.head().position;
    (void)runtime::computeFacetView(r.geometry.facets[0], in, p);
    const float before = p.frustumLeft;
    // A step of the head between frame n and n + 1, looked for from frame n + 1 on.
    int frames = 0;
    for (int k = 0; k < 10; ++k) {
      ++frames;
      r.moveHead(r.next++);
      in.viewer = r.show.head().position;
      (void)runtime::computeFacetView(r.geometry.facets[0], in, p);
      if (p.frustumLeft != before) break;
    }
    framesToChange = std::max(framesToChange, frames);
  }
  for (auto _ : state) {
    r.moveHead(r.next++);
    in.viewer = r.show.head().position;
    benchmark::DoNotOptimize(runtime::computeFacetView(r.geometry.facets[0], in, p));
  }
}

void frustumOnly(benchmark::State& state) {
  Rig& r = rig();
  runtime::FacetViewInput in;
  in.worldFromCave = runtime::cavePlacement(r.show);
  in.aspect = 16.0f / 9.0f;
  runtime::FacetProjection p;
  for (auto _ : state) benchmark::DoNotOptimize(runtime::computeFacetView(r.geometry.facets[0], in, p));
}

struct Gl {
  std::unique_ptr<render::Output> output;
  std::unique_ptr<render::Renderer> renderer;
  std::unique_ptr<render::FacetRenderer> facets;
  std::string problem;
};

Gl& gl() {
  static Gl g = [] {
    Gl x;
    auto output = render::createHeadlessOutput({kWidth, kHeight});
    if (!output) return x.problem = output.error().describe(), std::move(x);
    x.output = std::move(*output);
    auto renderer = render::Renderer::create();
    if (!renderer) return x.problem = renderer.error().describe(), std::move(x);
    x.renderer = std::move(*renderer);
    auto facets = render::FacetRenderer::create();
    if (!facets) return x.problem = facets.error().describe(), std::move(x);
    x.facets = std::move(*facets);
    return x;
  }();
  return g;
}

void sixFacets(benchmark::State& state, bool moving) {
  Rig& r = rig();
  Gl& g = gl();
  if (!r.problem.empty() || !g.problem.empty()) {
    state.SkipWithError((r.problem + g.problem).c_str());
    return;
  }
  render::FacetPass pass;
  pass.input.worldFromCave = runtime::cavePlacement(r.show);
  pass.viewport = {0, 0, kWidth, kHeight};
  const Vec3 fixed{0, 0, 0};  // the centre of the moving head's circle
  // One untimed frame first: shaders and buffers made before either figure is taken.
  pass.input.viewer = fixed;
  pass.facet = &r.geometry.facets[0];
  if (g.output->beginFrame() && g.facets->draw(*g.renderer, r.show, pass)) glFinish();
  for (auto _ : state) {
    if (moving) r.moveHead(r.next++);
    pass.input.viewer = moving ? r.show.head().position : fixed;
    for (const formats::CaveFacet& facet : r.geometry.facets) {
      if (!g.output->beginFrame()) {
        state.SkipWithError("the output cannot begin a frame");
        return;
      }
      pass.facet = &facet;
      if (!g.facets->draw(*g.renderer, r.show, pass)) {
        state.SkipWithError("a facet view cannot be drawn");
        return;
      }
      glFinish();
    }
  }
}

void sixFacetsFixed(benchmark::State& state) { sixFacets(state, false); }
void sixFacetsMoving(benchmark::State& state) { sixFacets(state, true); }

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
  int kept = 1;
  for (int i = 1; i < argc; ++i) {
    if (std::string_view(argv[i]) == "--quick") {
      quick = true;
    } else {
      argv[kept++] = argv[i];
    }
  }
  // Fixed and moving take turns, repetition by repetition, so that a busy machine weighs on both.
  static char interleave[] = "--benchmark_enable_random_interleaving=true";
  std::vector<char*> args(argv, argv + kept);
  args.push_back(interleave);
  argc = static_cast<int>(args.size());
  argv = args.data();
  const double minTime = quick ? 0.2 : 2.0;
  for (const auto& [name, fn] :
       {std::pair{"frustumOnly", &frustumOnly}, std::pair{"sampleToFrustum", &sampleToFrustum}}) {
    benchmark::RegisterBenchmark(name, fn)->Unit(benchmark::kMicrosecond)->MinTime(minTime)->Repetitions(3);
  }
  for (const auto& [name, fn] :
       {std::pair{"sixFacetsFixed", &sixFacetsFixed}, std::pair{"sixFacetsMoving", &sixFacetsMoving}}) {
    benchmark::RegisterBenchmark(name, fn)->Unit(benchmark::kMillisecond)->MinTime(minTime)->Repetitions(5);
  }
  return basalt::bench::runBenchmarks(argc, argv, [](const basalt::bench::Medians& m) {
    const auto only = m.find("frustumOnly"), sample = m.find("sampleToFrustum"), fixed = m.find("sixFacetsFixed"),
               moving = m.find("sixFacetsMoving");
    if (only == m.end() || sample == m.end() || fixed == m.end() || moving == m.end()) {
      std::printf("tracker: no figures (a benchmark failed)\n");
      return;
    }
    const double cost = moving->second / fixed->second - 1.0;
    std::printf(
        "tracker: a sample changes the frustum %d frame(s) after it (target: the next frame, 1): %s; sample to "
        "frustum %.2f us a frame against %.2f us for the frustum alone\n"
        "tracker: six facets at %ux%u from a moving viewer %.2f ms/frame against %.2f ms from a fixed one: %+.1f %% "
        "(target within 5 %%): %s\n",
        framesToChange, framesToChange == 1 ? "met" : "NOT MET", sample->second * 1e6, only->second * 1e6, kWidth,
        kHeight, moving->second * 1e3, fixed->second * 1e3, cost * 100.0, cost <= 0.05 ? "met" : "NOT MET");
  });
}
