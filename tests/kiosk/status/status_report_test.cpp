// The status board's frame figures and LAVA's performance meter as /health and /metrics report
// them: late frames, frames really dropped (display refreshes that got no new frame) and input
// events lost to a full queue are three separate figures; the meter's counts and rates appear
// in both documents.
// Example failures: "dropped" repeating the late-frame count; a present three periods late
// counted as one dropped frame; the performance meter missing from /health.
// And /health is valid JSON whatever its strings hold, read back by Python's json module.

#include <gtest/gtest.h>

#include <cmath>
#include <ctime>
#include <fstream>
#include <limits>
#include <sstream>

#include <unistd.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "kiosk/status/build_info.h"
#include "kiosk/status/status_board.h"
#include "kiosk/status/status_report.h"
#include "support/kiosk_process.h"
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

/// A snapshot with everything /metrics can say: devices and streams in several states, a
/// frame-locked node's figures, the process's figures, and some frames.
StatusSnapshot everything(bool leader) {
  StatusBoard board(WallTime{}, 60);
  std::int64_t frame = 0;
  for (const double interval : {0.5, 0.016, 0.017, 0.018, 0.020, 0.034, 0.050, 3.0}) {
    board.recordFrame(frame++, 0.002, interval, 0.001, 0);
  }
  StatusSnapshot s = board.snapshot(WallTime{});
  const auto device = [](std::string name, std::string state) {
    DeviceStatus d;
    d.name = std::move(name);
    d.kind = "dial_box";
    d.backend = "hid";
    d.state = std::move(state);
    return d;
  };
  s.devices = {device("dials", "live"), device("knob \"2\"", "absent"), device("cam", "idle")};
  StreamStatus st;
  st.name = "live";
  st.kind = "camera";
  st.state = "lost";
  s.streams = {st};
  FrameLockFigures lock;
  lock.leader = leader;
  lock.node = "north";
  lock.clockOffsetUs = -35;
  lock.barrierWaitP50Ms = 1.5;
  s.lock = lock;
  TrackerFigures tracker;
  tracker.tracker = "head";
  tracker.samples = 900;
  tracker.dropped = 3;
  tracker.lastLatency = std::chrono::milliseconds(7);
  tracker.maxLatency = std::chrono::milliseconds(16);
  tracker.latencySum = 4.5;
  tracker.frames = 600;
  s.tracker = tracker;
  s.process = readProcessFigures();
  return s;
}

// Makes sure a tracked viewer's sample-to-frame latency reaches /metrics in seconds, with its
// counts, labelled by the tracker's name, and that a show without one has none of it. Example
// failure: latency in nanoseconds under a _seconds name.
TEST(StatusMetrics, TheTrackedViewersLatencyIsPublished) {
  const std::string text = metricsText(everything(true), {});
  EXPECT_NEAR(test::metric(text, "basalt_tracker_latency_last_seconds{tracker=\"head\"}").value_or(-1), 0.007, 1e-9)
      << text;
  EXPECT_NEAR(test::metric(text, "basalt_tracker_latency_max_seconds{tracker=\"head\"}").value_or(-1), 0.016, 1e-9)
      << text;
  EXPECT_NEAR(test::metric(text, "basalt_tracker_latency_seconds_sum{tracker=\"head\"}").value_or(-1), 4.5, 1e-9)
      << text;
  EXPECT_NEAR(test::metric(text, "basalt_tracker_latency_seconds_count{tracker=\"head\"}").value_or(-1), 600.0, 1e-9)
      << text;
  EXPECT_NEAR(test::metric(text, "basalt_tracker_samples_total{tracker=\"head\"}").value_or(-1), 900.0, 1e-9) << text;
  EXPECT_NEAR(test::metric(text, "basalt_tracker_samples_dropped_total{tracker=\"head\"}").value_or(-1), 3.0, 1e-9)
      << text;
  StatusSnapshot none = everything(true);
  none.tracker.reset();
  EXPECT_EQ(metricsText(none, {}).find("basalt_tracker"), std::string::npos);
}

/// `promtool check metrics` on `text`: its output, and whether it found nothing to say.
std::pair<bool, std::string> promtool(const std::string& text) {
  const auto file = test::scratchDir("status-promtool") / "metrics.txt";
  std::ofstream(file) << text;
  const auto r = test::run({"/bin/sh", "-c", "promtool check metrics < '" + file.string() + "'"});
  return {r.exitCode == 0 && r.output.empty(), r.output};
}

// Makes sure /metrics follows Prometheus' conventions as promtool checks them (names, units,
// help, types), whatever the show has: a leader's and a follower's lock figures, devices and
// streams in every state, the process's figures. Example failure: a gauge named in
// milliseconds; a counter without _total.
TEST(StatusMetrics, PromtoolFindsNothingToSay) {
  if (::access("/usr/bin/promtool", X_OK) != 0) {
    GTEST_SKIP() << "promtool is not installed (apt-get install prometheus; it is in scripts/packages-test.txt)";
  }
  for (const bool leader : {true, false}) {
    const std::string text = metricsText(everything(leader), ServerCounters{});
    const auto [clean, output] = promtool(text);
    EXPECT_TRUE(clean) << output << "\n" << text;
  }
}

// Makes sure the state is a gauge of its own and basalt_up is 0 or 1, and that a device's and a
// stream's series keep their labels when their state changes. Example failures: basalt_up 0.5
// when degraded; basalt_device_up{...,state="lost"}, a new series at every change.
TEST(StatusMetrics, StateIsAValueNotALabel) {
  StatusSnapshot s = everything(false);
  const std::string degraded = metricsText(s, {});
  EXPECT_EQ(test::metric(degraded, "basalt_up"), 1.0) << degraded;
  EXPECT_EQ(test::metric(degraded, "basalt_state{state=\"degraded\"}"), 1.0) << degraded;
  EXPECT_EQ(test::metric(degraded, "basalt_state{state=\"ok\"}"), 0.0) << degraded;
  EXPECT_EQ(test::metric(degraded, "basalt_device_up{device=\"dials\"}"), 1.0);
  EXPECT_EQ(test::metric(degraded, "basalt_device_up{device=\"knob \\\"2\\\"\"}"), 0.0) << degraded;
  EXPECT_EQ(test::metric(degraded, "basalt_device_state{device=\"dials\"}"), 2.0);
  EXPECT_EQ(test::metric(degraded, "basalt_device_state{device=\"knob \\\"2\\\"\"}"), 0.0);
  EXPECT_EQ(test::metric(degraded, "basalt_device_state{device=\"cam\"}"), 5.0);
  EXPECT_EQ(test::metric(degraded, "basalt_device_info{device=\"dials\",kind=\"dial_box\",backend=\"hid\"}"), 1.0);
  EXPECT_EQ(test::metric(degraded, "basalt_stream_up{stream=\"live\"}"), 0.0);
  EXPECT_EQ(test::metric(degraded, "basalt_stream_state{stream=\"live\"}"), 3.0);

  // Everything back: the same series, other values.
  s.devices[1].state = "live";
  s.streams[0].state = "playing";
  s.lock->leaderPresent = true;
  const std::string ok = metricsText(s, {});
  EXPECT_EQ(test::metric(ok, "basalt_up"), 1.0);
  EXPECT_EQ(test::metric(ok, "basalt_state{state=\"ok\"}"), 1.0) << ok;
  EXPECT_EQ(test::metric(ok, "basalt_state{state=\"degraded\"}"), 0.0);
  EXPECT_EQ(test::metric(ok, "basalt_device_state{device=\"knob \\\"2\\\"\"}"), 2.0);
  EXPECT_EQ(test::metric(ok, "basalt_stream_state{stream=\"live\"}"), 2.0);
  // A movie whose file is broken: its own number, and the node is degraded.
  s.streams[0].state = "degraded";
  const std::string broken = metricsText(s, {});
  EXPECT_EQ(test::metric(broken, "basalt_stream_state{stream=\"live\"}"), 4.0) << broken;
  EXPECT_EQ(test::metric(broken, "basalt_state{state=\"degraded\"}"), 1.0);
  s.streams[0].state = "playing";
  const auto series = [](const std::string& text) {
    std::vector<std::string> names;
    std::istringstream lines(text);
    for (std::string line; std::getline(lines, line);) {
      if (!line.starts_with("#")) names.push_back(line.substr(0, line.rfind(' ')));
    }
    return names;
  };
  EXPECT_EQ(series(degraded), series(ok)) << "the same series whatever the states";

  // Before the first frame the show does not run yet.
  StatusBoard fresh(WallTime{}, 60);
  EXPECT_EQ(test::metric(metricsText(fresh.snapshot(WallTime{}), {}), "basalt_up"), 0.0);
}

// Makes sure frame intervals are a histogram with cumulative buckets, _sum and _count since the
// start (the first frame's start-up left out), and that the work summary's sum and count are
// totals too. Example failures: a summary without _sum; a count that stops at the window's 600.
TEST(StatusMetrics, FrameIntervalsAreAHistogram) {
  StatusBoard board(WallTime{}, 60);
  // 0.5 s of start-up (not an interval), then intervals around the bucket bounds.
  const std::vector<double> intervals{0.5, 0.016, 0.0175, 0.018, 0.020, 0.034, 0.050, 3.0};
  std::int64_t frame = 0;
  for (const double v : intervals) board.recordFrame(frame++, 0.002, v, 0.001, 0);
  for (int i = 0; i < 700; ++i) board.recordFrame(frame++, 0.001, 1.0 / 60, 0.0005, 0);
  const std::string text = metricsText(board.snapshot(WallTime{}), {});
  EXPECT_TRUE(has(text, "# TYPE basalt_frame_interval_seconds histogram\n")) << text;
  // Expected counts, worked out by hand from the intervals above and the bounds in
  // kiosk/status/README.md: 1/60 s falls in le="0.0175".
  const std::vector<std::pair<std::string, double>> buckets{
      {"0.005", 0},   {"0.01", 0},    {"0.0175", 702}, {"0.021", 704},  {"0.025", 704},
      {"0.035", 705}, {"0.042", 705}, {"0.05", 706},   {"0.0675", 706}, {"0.1", 706},
      {"0.25", 706},  {"0.5", 706},   {"1", 706},      {"2.5", 706},    {"+Inf", 707}};
  for (const auto& [le, count] : buckets) {
    EXPECT_EQ(test::metric(text, "basalt_frame_interval_seconds_bucket{le=\"" + le + "\"}"), count) << le << "\n"
                                                                                                    << text;
  }
  EXPECT_EQ(test::metric(text, "basalt_frame_interval_seconds_count"), 707.0);
  const double sum = 0.016 + 0.0175 + 0.018 + 0.020 + 0.034 + 0.050 + 3.0 + 700.0 / 60;
  EXPECT_NEAR(test::metric(text, "basalt_frame_interval_seconds_sum").value_or(0), sum, 1e-9);
  EXPECT_EQ(test::metric(text, "basalt_frame_work_seconds_count"), 708.0);
  EXPECT_NEAR(test::metric(text, "basalt_frame_work_seconds_sum").value_or(0), 8 * 0.002 + 700 * 0.001, 1e-9);
  EXPECT_NEAR(test::metric(text, "basalt_frame_work_cpu_seconds_sum").value_or(0), 8 * 0.001 + 700 * 0.0005, 1e-9);
  EXPECT_EQ(test::metric(text, "basalt_frame_work_cpu_seconds_count"), 708.0);
  EXPECT_FALSE(has(text, "basalt_frame_interval_seconds{quantile")) << "a histogram, not a summary";
}

// Makes sure the build and the process are reported under the names Prometheus' client
// libraries use, with figures that agree with what the kernel says through other files.
// Example failures: no basalt_build_info; open descriptors counted without the ones just opened.
TEST(StatusMetrics, BuildAndProcessFigures) {
  const StatusSnapshot s = everything(true);
  const std::string text = metricsText(s, {});
  const BuildInfo build = buildInfo();
  EXPECT_FALSE(build.version.empty());
  EXPECT_EQ(test::metric(text, fmt::format("basalt_build_info{{version=\"{}\",revision=\"{}\"}}", build.version,
                                           build.revision)),
            1.0)
      << text;
  // Resident memory as /proc/self/status says it (in kB), within what a few allocations move.
  std::ifstream status("/proc/self/status");
  double residentKb = 0;
  for (std::string line; std::getline(status, line);) {
    if (line.starts_with("VmRSS:")) residentKb = std::stod(line.substr(6));
  }
  const ProcessFigures before = readProcessFigures();
  EXPECT_NEAR(static_cast<double>(before.residentBytes) / 1024, residentKb, 4096);
  EXPECT_EQ(test::metric(text, "process_resident_memory_bytes").value_or(0) > 0, true) << text;
  // Ten more descriptors are ten more.
  std::vector<int> fds;
  for (int i = 0; i < 10; ++i) fds.push_back(::dup(1));
  const ProcessFigures opened = readProcessFigures();
  for (const int fd : fds) ::close(fd);
  EXPECT_EQ(opened.openFds, before.openFds + 10);
  EXPECT_GT(before.openFds, 2u) << "stdin, stdout and stderr at least";
  // CPU time grows with work done: 0.2 s of it by the process's own CPU clock (not by wall time,
  // which on a loaded machine holds less CPU), of which /proc's ticks (1/100 s) show at least 0.15.
  const auto cpuNow = [] {
    timespec t{};
    ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_nsec) * 1e-9;
  };
  volatile double x = 0;
  const double cpuStart = cpuNow();
  while (cpuNow() - cpuStart < 0.2) x = x + 1;
  const ProcessFigures later = readProcessFigures();
  EXPECT_GE(later.cpuSeconds - before.cpuSeconds, 0.15);
  // The process started before now, and not before this test binary's file was written.
  ASSERT_TRUE(before.startSeconds);
  const double now = std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  EXPECT_LE(*before.startSeconds, now);
  EXPECT_GT(*before.startSeconds, now - 3600) << "a test binary runs for less than an hour";
  for (const char* name : {"process_cpu_seconds_total", "process_resident_memory_bytes", "process_open_fds",
                           "process_max_fds", "process_virtual_memory_bytes", "process_start_time_seconds"}) {
    EXPECT_TRUE(test::metric(text, name)) << name << "\n" << text;
  }
}

}  // namespace
}  // namespace basalt::kiosk
