// The frame loop allocates nothing per frame in steady state (DESIGN.md §7), and the script
// interpreter runs inside it: once a script is loaded, stepping it frame after frame must not
// touch the heap. Counted by replacing the global operator new in this test binary.
// Example failure: a part name copied into a std::string on every per-part command, or an
// error message formatted for a line that is fine.

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <fstream>
#include <new>
#include <sstream>

#include "script_support.h"
#include "support/test_paths.h"

namespace {
std::atomic<std::uint64_t> gAllocations{0};
}  // namespace

void* operator new(std::size_t size) {
  gAllocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) { return ::operator new(size); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace basalt::script {
namespace {

TEST(SteadyState, SteppingAScriptAllocatesNothing) {
  std::ifstream in(basalt::test::sourceDir() / "tests/runtime/script/scripts/example_motion.mdl");
  std::stringstream text;
  text << in.rdbuf();
  // Per-part commands, op-equals, loops and position moves, beside the manual's example.
  const std::string script = text.str() +
                             "loop 50\n render.prim_type \"face 2\" = markers\n lines.line_width \"face 3\" += 0.5\n"
                             " lighting.color [2] *= 0.99\n obj_colors.part_color \"face 4\" = 1 0 1\n"
                             " part.deselect \"face 5\"\n part.select \"face 5\"\n jitter_offset = 0.1 0.1\n draw\n"
                             "end_loop\n";
  const std::uint64_t counted = gAllocations.load();
  Interpreter interpreter(test::parse(script), ".");
  ASSERT_GT(gAllocations.load(), counted) << "the counter does not count: loading a script allocates";
  runtime::Show show = startupShow();
  test::RecordingHost host;
  for (int i = 0; i < 5; ++i) {
    ASSERT_EQ(interpreter.step(show, host).stop, StepStop::kDraw);
    show.advanceFrame();
  }
  const std::uint64_t before = gAllocations.load();
  std::uint64_t frames = 0;
  while (interpreter.step(show, host).stop == StepStop::kDraw) {
    show.advanceFrame();
    ++frames;
  }
  const std::uint64_t allocations = gAllocations.load() - before;
  EXPECT_EQ(frames, 1001u + 50u - 5u);
  EXPECT_EQ(allocations, 0u) << "stepping " << frames << " frames allocated " << allocations << " times";
  EXPECT_EQ(interpreter.runtimeProblems(), 0u);
}

}  // namespace
}  // namespace basalt::script
