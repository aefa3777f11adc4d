// The frame loop feeds LAVA's performance meter (§9) from what the renderer drew, so the status
// server can publish it: counts of the last frame (triangles, lines, points, parts, facets) and
// frames and primitives per second over the sample period, in real time.
// Example failures: the meter never updated by the loop; counts summed over frames instead of
// per frame; stereo frames counted once although drawn twice.

#include <gtest/gtest.h>

#include "kiosk/loop/frame_loop.h"
#include "runtime/event_loop.h"
#include "support/render_fixture.h"

namespace basalt::test {
namespace {

class FrameLoopMeter : public RenderTest {
 protected:
  runtime::Show runFrames(runtime::Show show, int frames) {
    ManualClock clock;
    auto loop = runtime::EventLoop::create(clock);
    EXPECT_TRUE(loop);
    kiosk::FrameLoop frameLoop({60, frames}, clock, &clock, **loop, show, output(), renderer());
    auto stats = frameLoop.run();
    EXPECT_TRUE(stats) << stats.error().describe();
    return show;
  }
};

TEST_F(FrameLoopMeter, CountsTheDefaultShow) {
  runtime::Show show = runtime::Show::makeDefault();
  show.performance().samplePeriodSeconds = 1e-9;  // update the rates every frame
  show = runFrames(std::move(show), 5);
  const runtime::PerformanceMeter& m = show.performance();
  EXPECT_EQ(m.triangles, 12u) << "six faces of two triangles";
  EXPECT_EQ(m.facets, 6u);
  EXPECT_EQ(m.parts, 6u);
  EXPECT_EQ(m.lines, 0u);
  EXPECT_GE(m.updates, 3u);
  EXPECT_GT(m.framesPerSecond, 0.0);
  EXPECT_GT(m.primitivesPerSecond, 0.0);
}

TEST_F(FrameLoopMeter, StereoDrawsTwice) {
  runtime::Show show = runtime::Show::makeDefault();
  show.global().stereo = true;
  show.editGlobalStyle([](runtime::PartStyle& s) { s.render.primType = runtime::PrimType::kWireframe; });
  show = runFrames(std::move(show), 2);
  EXPECT_EQ(show.performance().triangles, 0u);
  EXPECT_EQ(show.performance().lines, 2u * 24u) << "24 cube edges, once per eye";
}

}  // namespace
}  // namespace basalt::test
