// The LAVA script interpreter's speed (issue 5):
// - a generated 10 000-line script, parsed and run to its end: lines per second, beside the
//   cost of only reading its lines (the baseline in the same run);
// - the interpreter's cost per frame on the manual's example motion script, beside the
//   renderer's frame time for the same show headless (500x500): it must be under 5% of it.

#include <benchmark/benchmark.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "bench_main.h"
#include "render/output.h"
#include "render/renderer.h"
#include "runtime/script/host.h"
#include "runtime/script/interpreter.h"
#include "runtime/script/lexer.h"
#include "runtime/script/program.h"

namespace {

using namespace basalt;

constexpr int kLines = 10000;

/// Every kind of line a show script has: per-part and global attributes, op-equals, lights,
/// moves, comments and continuations, in loops that draw.
std::string generatedScript() {
  static const char* const kBody[] = {
      "  render.prim_type \"face 1\" = wireframe",
      "  lines.line_width += 0.5          ! fatter",
      "  front_surf.color = 0.5 0.25 1",
      "  front_surf.color \"face 3\" *= 0.99",
      "  lighting.color [3] = 1 \\",
      "      0.5 0.25",
      "  position.global_y_rotate = 1.5",
      "  position.local_x_translate = 0.001",
      "  depth_cue.front_ref_plane -= 0.001",
      "  markers.marker_type face_2 = asterisk",
      "  global.background_color = 0 0 0.1",
      "  obj_colors.part_color \"face 4\" = 1 0 1",
      "  render.prim_type = solid",
      "  draw",
  };
  constexpr int kBodyLines = static_cast<int>(std::size(kBody));
  std::string text;
  int lines = 0;
  while (lines + kBodyLines + 2 <= kLines) {
    text += "loop 2\n";
    for (const char* line : kBody) text += std::string(line) + "\n";
    text += "end_loop\n";
    lines += kBodyLines + 2;
  }
  while (lines < kLines) {
    text += "! padding to 10 000 lines\n";
    ++lines;
  }
  return text;
}

/// A host that has everything: no "not rendered yet" notes, no unavailable services.
class QuietHost final : public script::OfflineHost {
 public:
  [[nodiscard]] bool renders(script::Feature) const override { return true; }
};

void readLines(benchmark::State& state) {
  const std::string text = generatedScript();
  script::LogicalLine line;
  for (auto _ : state) {
    script::LineReader reader(text);
    std::size_t n = 0;
    while (reader.next(line)) ++n;
    benchmark::DoNotOptimize(n);
  }
}

void parseAndRun(benchmark::State& state) {
  const std::string text = generatedScript();
  QuietHost host;
  std::uint64_t draws = 0;
  for (auto _ : state) {
    script::Interpreter interpreter(script::parseScript(text, "generated.mdl"), ".");
    runtime::Show show = script::startupShow();
    while (interpreter.step(show, host).stop == script::StepStop::kDraw) show.advanceFrame();
    draws = interpreter.draws();
  }
  state.counters["draws"] = static_cast<double>(draws);
}

std::string exampleScript() {
  std::ifstream in(std::string(BASALT_SOURCE_DIR) + "/tests/runtime/script/scripts/example_motion.mdl");
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

constexpr double kExampleFrames = 1001;  // the example's draws

/// One iteration plays the whole example (1001 frames) through step(); set-up is not timed.
void interpreterExample(benchmark::State& state) {
  const script::Program program = script::parseScript(exampleScript(), "example_motion.mdl");
  QuietHost host;
  for (auto _ : state) {
    state.PauseTiming();
    script::Interpreter interpreter(program, ".");
    runtime::Show show = script::startupShow();
    state.ResumeTiming();
    while (interpreter.step(show, host).stop == script::StepStop::kDraw) show.advanceFrame();
  }
}

/// One iteration draws 60 frames of the example's show headless and waits for the last.
void rendererFrames(benchmark::State& state) {
  auto output = render::createHeadlessOutput({500, 500});
  if (!output) {
    state.SkipWithError("no headless EGL");
    return;
  }
  auto renderer = render::Renderer::create();
  if (!renderer) {
    state.SkipWithError("no renderer");
    return;
  }
  runtime::Show show = script::startupShow();
  show.rotateLocal({30, 0, 0});
  Image sync;
  for (auto _ : state) {
    for (int i = 0; i < 60; ++i) {
      if (!(*output)->beginFrame()) state.SkipWithError("beginFrame failed");
      (*renderer)->draw(show, runtime::computeView(show, 1.0f), (*output)->size());
      if (!(*output)->present()) state.SkipWithError("present failed");
      show.rotateLocal({1, 0, 0});
    }
    if (!(*output)->readBack(sync)) state.SkipWithError("read-back failed");
  }
}

BENCHMARK(readLines)->Unit(benchmark::kMillisecond)->Repetitions(5)->ReportAggregatesOnly(true);
BENCHMARK(parseAndRun)->Unit(benchmark::kMillisecond)->Repetitions(5)->ReportAggregatesOnly(true);
BENCHMARK(interpreterExample)->Unit(benchmark::kMillisecond)->Repetitions(5)->ReportAggregatesOnly(true);
BENCHMARK(rendererFrames)->Unit(benchmark::kMillisecond)->Iterations(3)->Repetitions(5)->ReportAggregatesOnly(true);

}  // namespace

int main(int argc, char** argv) {
  return bench::runBenchmarks(argc, argv, [](const bench::Medians& m) {
    const auto read = m.find("readLines");
    const auto run = m.find("parseAndRun");
    if (read != m.end() && run != m.end()) {
      std::printf(
          "script: a %d-line script parsed and run to its end in %.2f ms: %.0f lines per second; reading its "
          "lines alone (baseline) %.2f ms, %.0f lines per second; parsing and running cost %.1f times the reading\n",
          kLines, run->second * 1e3, kLines / run->second, read->second * 1e3, kLines / read->second,
          run->second / read->second);
    } else {
      std::printf("script: no lines-per-second figure (a benchmark failed)\n");
    }
    const auto interp = m.find("interpreterExample");
    const auto render = m.find("rendererFrames");
    if (interp != m.end() && render != m.end()) {
      const double perFrame = interp->second / kExampleFrames;
      const double frame = render->second / 60;
      const double ratio = perFrame / frame;
      std::printf(
          "script: interpreter per frame on the manual's example %.2f us; renderer frame time (500x500 headless) "
          "%.1f us; the interpreter is %.3f%% of a frame; target < 5%%: %s\n",
          perFrame * 1e6, frame * 1e6, ratio * 100, ratio < 0.05 ? "met" : "NOT MET");
    } else {
      std::printf("script: no per-frame figure (no headless EGL?)\n");
    }
  });
}
