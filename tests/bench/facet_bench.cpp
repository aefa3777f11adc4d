// Immersive displays (issue 10, "Speed"): six facet views drawn by one node, each a 1280 x 720
// picture (one per projector), against the same scene drawn as plain views, headless.
//  - plainOne: the default show as one plain view (what one node draws without facets);
//  - plainSix: the same plain view drawn six times (the extra draw work six pictures cost);
//  - unmaskedSix: six views through the facet's projection with no border: the same pixels as
//    the facet views, so the strictest baseline (the facet view shows less of the cube than the
//    plain view does, so it is cheaper to draw than plainSix);
//  - facetSix: six facet views of the cube display's front wall: the projection per facet and
//    the border.
//  - unmaskedSixGrey, facetSixGrey: the same over a grey background. Over LAVA's black one the
//    clear leaves everything outside the outline's box black and the border covers only the
//    box; over any other colour it covers the whole viewport outside the outline.
// Figures: facetSix / plainSix - 1, the facet machinery's cost beyond the extra draw work as
// the issue measures it (target under 10 %), and facetSix / unmaskedSix - 1, what the border and
// the projection cost beyond drawing the same pixels. Each frame ends in glFinish(), so
// llvmpipe's work is counted.

#include <benchmark/benchmark.h>

#include <GLES3/gl3.h>

#include <cstdio>
#include <string_view>

#include "bench_main.h"
#include "render/facet_view.h"
#include "render/output.h"
#include "render/renderer.h"
#include "runtime/formats/cave.h"
#include "runtime/show/show.h"

namespace {

using namespace basalt;

constexpr std::uint32_t kWidth = 1280, kHeight = 720;

// The cube display -1..1, facet 5 faces +Z (the wall ahead of the viewer).
constexpr const char* kCube =
    "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\n"
    "f 1 2 3 4\n";

struct Bench {
  std::unique_ptr<render::Output> output;
  std::unique_ptr<render::Renderer> renderer;
  std::unique_ptr<render::FacetRenderer> facets;
  formats::CaveGeometry geometry;
  runtime::Show show = runtime::Show::makeDefault();
  runtime::FacetProjection projection;
  std::string problem;
};

Bench& bench() {
  static Bench b = [] {
    Bench x;
    auto output = render::createHeadlessOutput({kWidth, kHeight});
    if (!output) return x.problem = output.error().describe(), std::move(x);
    x.output = std::move(*output);
    auto renderer = render::Renderer::create();
    if (!renderer) return x.problem = renderer.error().describe(), std::move(x);
    x.renderer = std::move(*renderer);
    auto facets = render::FacetRenderer::create();
    if (!facets) return x.problem = facets.error().describe(), std::move(x);
    x.facets = std::move(*facets);
    std::vector<formats::Diagnostic> warnings;
    auto g = formats::parseCaveGeometry(kCube, "wall.obj", {}, warnings);
    if (!g) return x.problem = g.error().describe(), std::move(x);
    x.geometry = std::move(*g);
    return x;
  }();
  return b;
}

enum class View { kPlain, kUnmasked, kFacet };

void frame(benchmark::State& state, int views, View kind, bool grey = false) {
  Bench& b = bench();
  if (!b.problem.empty()) {
    state.SkipWithError(b.problem.c_str());
    return;
  }
  b.show.global().background = grey ? runtime::Color3{0.3f, 0.4f, 0.5f} : runtime::Color3{0, 0, 0};
  const render::Viewport vp{0, 0, kWidth, kHeight};
  render::FacetPass pass;
  pass.facet = &b.geometry.facets[0];
  pass.input.worldFromCave = runtime::cavePlacement(b.show);
  pass.viewport = vp;
  for (auto _ : state) {
    for (int i = 0; i < views; ++i) {
      if (!b.output->beginFrame()) {
        state.SkipWithError("the output cannot begin a frame");
        return;
      }
      switch (kind) {
        case View::kFacet:
          if (!b.facets->draw(*b.renderer, b.show, pass)) {
            state.SkipWithError("the facet view cannot be drawn");
            return;
          }
          break;
        case View::kUnmasked: {
          runtime::FacetViewInput input = pass.input;
          input.aspect = static_cast<float>(kWidth) / static_cast<float>(kHeight);
          if (!runtime::computeFacetView(*pass.facet, input, b.projection)) {
            state.SkipWithError("the facet projection cannot be computed");
            return;
          }
          const Mat4 model = b.show.position().global * b.show.position().local * runtime::viewNormalisation(b.show);
          render::ViewPass viewPass;
          viewPass.viewport = vp;
          b.renderer->draw(b.show, {model, b.projection.view, b.projection.projection, b.projection.eye}, viewPass);
          break;
        }
        case View::kPlain: b.renderer->drawShow(b.show, vp); break;
      }
      glFinish();
    }
  }
}

void plainOne(benchmark::State& state) { frame(state, 1, View::kPlain); }
void plainSix(benchmark::State& state) { frame(state, 6, View::kPlain); }
void unmaskedSix(benchmark::State& state) { frame(state, 6, View::kUnmasked); }
void facetSix(benchmark::State& state) { frame(state, 6, View::kFacet); }
void unmaskedSixGrey(benchmark::State& state) { frame(state, 6, View::kUnmasked, true); }
void facetSixGrey(benchmark::State& state) { frame(state, 6, View::kFacet, true); }

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
  argc = kept;
  const double minTime = quick ? 0.2 : 2.0;
  benchmark::RegisterBenchmark("plainOne", plainOne)->Unit(benchmark::kMillisecond)->MinTime(minTime)->Repetitions(3);
  benchmark::RegisterBenchmark("plainSix", plainSix)->Unit(benchmark::kMillisecond)->MinTime(minTime)->Repetitions(3);
  benchmark::RegisterBenchmark("unmaskedSix", unmaskedSix)
      ->Unit(benchmark::kMillisecond)
      ->MinTime(minTime)
      ->Repetitions(3);
  benchmark::RegisterBenchmark("facetSix", facetSix)->Unit(benchmark::kMillisecond)->MinTime(minTime)->Repetitions(3);
  benchmark::RegisterBenchmark("unmaskedSixGrey", unmaskedSixGrey)
      ->Unit(benchmark::kMillisecond)
      ->MinTime(minTime)
      ->Repetitions(3);
  benchmark::RegisterBenchmark("facetSixGrey", facetSixGrey)
      ->Unit(benchmark::kMillisecond)
      ->MinTime(minTime)
      ->Repetitions(3);
  return basalt::bench::runBenchmarks(argc, argv, [](const basalt::bench::Medians& m) {
    const auto find = [&m](const std::string& name) { return m.find(name); };
    const auto one = find("plainOne"), six = find("plainSix"), unmasked = find("unmaskedSix"),
               facets = find("facetSix"), unmaskedGrey = find("unmaskedSixGrey"), facetsGrey = find("facetSixGrey");
    if (one == m.end() || six == m.end() || unmasked == m.end() || facets == m.end() || unmaskedGrey == m.end() ||
        facetsGrey == m.end()) {
      std::printf("facets: no figures (a benchmark failed)\n");
      return;
    }
    const double overhead = facets->second / six->second - 1.0;
    const double border = facets->second / unmasked->second - 1.0;
    std::printf(
        "facets: 6 facet views at 1280x720 each %.2f ms/frame (%.1f fps); the same scene as 6 plain views %.2f ms "
        "(%.1f fps), as one plain view %.2f ms (%.1f fps); facet machinery beyond the extra draw work %+.1f %%; "
        "target < 10 %%: %s\n"
        "facets: the same 6 facet projections without the border %.2f ms; the border and projection cost %+.1f %% "
        "beyond drawing the same pixels\n"
        "facets: over a grey background (the border over the whole viewport) %.2f ms against %.2f ms without the "
        "border: %+.1f %%\n",
        facets->second * 1e3, 1.0 / facets->second, six->second * 1e3, 1.0 / six->second, one->second * 1e3,
        1.0 / one->second, overhead * 100.0, overhead < 0.10 ? "met" : "NOT MET", unmasked->second * 1e3,
        border * 100.0, facetsGrey->second * 1e3, unmaskedGrey->second * 1e3,
        (facetsGrey->second / unmaskedGrey->second - 1.0) * 100.0);
  });
}
