// The status board's frame figures and LAVA's performance meter as /health and /metrics report
// them: late frames, frames really dropped (display refreshes that got no new frame) and input
// events lost to a full queue are three separate figures; the meter's counts and rates appear
// in both documents.
// Example failures: "dropped" repeating the late-frame count; a present three periods late
// counted as one dropped frame; the performance meter missing from /health.
// And /health is valid JSON whatever its strings hold, read back by Python's json module.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>

#include <nlohmann/json.hpp>

#include "kiosk/status/status_board.h"
#include "kiosk/status/status_report.h"
#include "support/process.h"
#include "support/test_paths.h"

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
  const auto health = nlohmann::json::parse(healthJson(s));
  EXPECT_EQ(health["frames"]["late"], 2) << health;
  EXPECT_EQ(health["frames"]["dropped"], 4) << health;
  EXPECT_EQ(health["frames"]["input_events_dropped"], 7) << health;
  const std::string metrics = metricsText(s, {});
  EXPECT_TRUE(has(metrics, "\nbasalt_frames_late_total 2\n")) << metrics;
  EXPECT_TRUE(has(metrics, "\nbasalt_frames_dropped_total 4\n")) << metrics;
  EXPECT_TRUE(has(metrics, "\nbasalt_input_events_dropped_total 7\n")) << metrics;
}

TEST(StatusReport, ThePerformanceMeterIsPublished) {
  StatusBoard board(WallTime{}, 60);
  const auto before = nlohmann::json::parse(healthJson(board.snapshot(WallTime{})));
  EXPECT_EQ(before["performance"]["triangles"], 0) << "present before the first sample: " << before;
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
  const auto health = nlohmann::json::parse(healthJson(s));
  const nlohmann::json expected = {{"triangles", 12},
                                   {"lines", 3},
                                   {"points", 2},
                                   {"parts", 6},
                                   {"facets", 1},
                                   {"fps", 59.5},
                                   {"primitives_per_second", 1012.0},
                                   {"sample_seconds", 2.0},
                                   {"samples", 4}};
  EXPECT_EQ(health["performance"], expected) << health["performance"];
  const std::string metrics = metricsText(s, {});
  EXPECT_TRUE(has(metrics, "basalt_performance_primitives{kind=\"triangles\"} 12\n")) << metrics;
  EXPECT_TRUE(has(metrics, "basalt_performance_primitives{kind=\"lines\"} 3\n")) << metrics;
  EXPECT_TRUE(has(metrics, "basalt_performance_parts 6\n")) << metrics;
  EXPECT_TRUE(has(metrics, "basalt_performance_facets 1\n")) << metrics;
  EXPECT_TRUE(has(metrics, "basalt_performance_frames_per_second 59.500\n")) << metrics;
  EXPECT_TRUE(has(metrics, "basalt_performance_primitives_per_second 1012\n")) << metrics;
}

// Makes sure /health is valid JSON, as a strict reader other than the writer's library reads it
// (Python's json module, refusing NaN and Infinity), whatever its strings and figures hold: quotes,
// backslashes, control characters, bytes that are not UTF-8 (each becomes U+FFFD, as Python's
// own "replace" decoding does), NaN and infinities (null). Example failures: a raw control
// character or a lone 0xff byte that makes the scraper's parser give up; NaN written bare.
TEST(StatusReport, HealthIsValidJsonWhateverItsStringsHold) {
  StatusSnapshot s;
  s.show.name = "the \"quoted\" show";
  const auto device = [](std::string name, std::string message) {
    DeviceStatus d;
    d.name = std::move(name);
    d.kind = "dial_box";
    d.backend = "hid";
    d.state = "lost";
    d.message = std::move(message);
    return d;
  };
  s.devices.push_back(device("say \"hi\"", "back\\slash"));
  s.devices.push_back(device(std::string("tab\there\x01\x1f\x7f", 11), "line\nbreak\r"));
  s.devices.push_back(device("bad \xff\xfe bytes", "cut \xe2\x82"));
  s.devices.push_back(device("euro \xe2\x82\xac", std::string("nul\0inside", 10)));
  s.frames.framesPerSecond = std::numeric_limits<double>::quiet_NaN();
  s.frames.intervalP99 = std::numeric_limits<double>::infinity();
  s.performance.framesPerSecond = -std::numeric_limits<double>::infinity();
  log::Record record;
  record.level = log::Level::kError;
  record.category = "hid";
  record.message = "read failed: \"\x80\x80\" \x1b[31mred\x1b[0m";
  s.lastErrors.push_back(record);
  s.logTail.push_back(record);

  const std::string text = healthJson(s);
  const auto file = test::scratchDir("status-json") / "health.json";
  std::ofstream(file, std::ios::binary) << text;
  // Python prints what it read, every string escaped to ASCII, so that the expectations below
  // are written out by hand.
  const char* script = R"py(
import json, sys
def refuse(constant):
    raise ValueError("not JSON: " + constant)
with open(sys.argv[1], "rb") as f:
    raw = f.read()
doc = json.loads(raw.decode("utf-8"), parse_constant=refuse)
for d in doc["devices"]:
    print(json.dumps([d["name"], d["message"]]))
print(json.dumps([doc["show"]["name"], doc["frames"]["per_second"], doc["frames"]["frame_time_ms"]["p99"],
                  doc["performance"]["fps"]]))
print(json.dumps(doc["last_errors"][0]["message"]))
print(json.dumps(doc["log_tail"][0][-35:]))
)py";
  const auto python = test::run({"/usr/bin/python3", "-c", script, file.string()});
  ASSERT_EQ(python.exitCode, 0) << python.output << "\n" << text;
  const std::string expected =
      "[\"say \\\"hi\\\"\", \"back\\\\slash\"]\n"
      "[\"tab\\there\\u0001\\u001f\\u007f\", \"line\\nbreak\\r\"]\n"
      "[\"bad \\ufffd\\ufffd bytes\", \"cut \\ufffd\"]\n"
      "[\"euro \\u20ac\", \"nul\\u0000inside\"]\n"
      "[\"the \\\"quoted\\\" show\", null, null, null]\n"
      "\"read failed: \\\"\\ufffd\\ufffd\\\" \\u001b[31mred\\u001b[0m\"\n"
      "\"hid: read failed: \\\"\\ufffd\\ufffd\\\" \\u001b[31mred\\u001b[0m\"\n";
  EXPECT_EQ(python.output, expected) << text;
  // The writer's own library reads it too, strictly (no NaN).
  EXPECT_TRUE(nlohmann::json::accept(text)) << text;
}

}  // namespace
}  // namespace basalt::kiosk
