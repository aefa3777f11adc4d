// The status board's frame figures and LAVA's performance meter as /health and /metrics report
// them: late frames, frames really dropped (display refreshes that got no new frame) and input
// events lost to a full queue are three separate figures; the meter's counts and rates appear
// in both documents.
// Example failures: "dropped" repeating the late-frame count; a present three periods late
// counted as one dropped frame; the performance meter missing from /health.

#include <gtest/gtest.h>

#include "kiosk/status/status_board.h"
#include "kiosk/status/status_report.h"

namespace basalt::kiosk {
namespace {

bool has(const std::string& text, const std::string& needle) { return text.find(needle) != std::string::npos; }

TEST(StatusReport, DroppedFramesAndDroppedInputAreSeparate) {
  StatusBoard board(WallTime{}, 30);
  std::int64_t frame = 0;
  for (int i = 0; i < 10; ++i) board.recordFrame(frame++, 0.004, 1.0 / 30, 0.003, 0);
  board.recordFrame(frame++, 0.004, 4.0 / 30, 0.003, 5);  // three refreshes without a new frame
  board.recordFrame(frame++, 0.004, 2.0 / 30, 0.003, 7);  // one more
  board.recordFrame(frame++, 0.004, 1.2 / 30, 0.003, 7);  // a little late, not late enough to drop
  const FrameFigures f = board.frameFigures();
  EXPECT_EQ(f.lateFrames, 2);
  EXPECT_EQ(f.droppedFrames, 4);
  EXPECT_EQ(f.inputDropped, 7u);
  const StatusSnapshot s = board.snapshot(WallTime{});
  const std::string health = healthJson(s);
  EXPECT_TRUE(has(health, "\"late\": 2,")) << health;
  EXPECT_TRUE(has(health, "\"dropped\": 4,")) << health;
  EXPECT_TRUE(has(health, "\"input_events_dropped\": 7")) << health;
  const std::string metrics = metricsText(s, {});
  EXPECT_TRUE(has(metrics, "\nbasalt_frames_late_total 2\n")) << metrics;
  EXPECT_TRUE(has(metrics, "\nbasalt_frames_dropped_total 4\n")) << metrics;
  EXPECT_TRUE(has(metrics, "\nbasalt_input_events_dropped_total 7\n")) << metrics;
}

TEST(StatusReport, ThePerformanceMeterIsPublished) {
  StatusBoard board(WallTime{}, 60);
  const std::string before = healthJson(board.snapshot(WallTime{}));
  EXPECT_TRUE(has(before, "\"performance\": {\"triangles\": 0,")) << "present before the first sample: " << before;
  runtime::PerformanceMeter meter;
  meter.triangles = 12;
  meter.lines = 3;
  meter.points = 2;
  meter.parts = 6;
  meter.facets = 1;
  meter.framesPerSecond = 59.5;
  meter.primitivesPerSecond = 1011.5;
  meter.updates = 4;
  board.publishPerformance(meter);
  const StatusSnapshot s = board.snapshot(WallTime{});
  const std::string health = healthJson(s);
  EXPECT_TRUE(has(health,
                  "\"performance\": {\"triangles\": 12, \"lines\": 3, \"points\": 2, \"parts\": 6, "
                  "\"facets\": 1, \"fps\": 59.50, \"primitives_per_second\": 1012"))
      << health;
  EXPECT_TRUE(has(health, "\"samples\": 4}")) << health;
  const std::string metrics = metricsText(s, {});
  EXPECT_TRUE(has(metrics, "basalt_performance_primitives{kind=\"triangles\"} 12\n")) << metrics;
  EXPECT_TRUE(has(metrics, "basalt_performance_primitives{kind=\"lines\"} 3\n")) << metrics;
  EXPECT_TRUE(has(metrics, "basalt_performance_parts 6\n")) << metrics;
  EXPECT_TRUE(has(metrics, "basalt_performance_facets 1\n")) << metrics;
  EXPECT_TRUE(has(metrics, "basalt_performance_frames_per_second 59.500\n")) << metrics;
  EXPECT_TRUE(has(metrics, "basalt_performance_primitives_per_second 1012\n")) << metrics;
}

}  // namespace
}  // namespace basalt::kiosk
