// Traces: record live devices with `TraceRecorder`, replay them with the `replay` backend, and
// get the same event stream and the same frames back; the hid-recorder files of
// ../shared/testdata/hid replay through the provider; trace.toml and .bvraw files that are
// damaged or hostile give clear errors.
// Example failures: a replay whose events drift from the recording's timing; a turn lost between
// recording and replay; a trace.toml whose file name climbs out of the trace folder; a truncated
// trace video that crashes the reader.

#include <gtest/gtest.h>

#include <chrono>
#include <fstream>

#include "devices/device_manager.h"
#include "devices/hid/dial_decoder.h"
#include "sim/providers.h"
#include "sim/raw_video.h"
#include "sim/replay.h"
#include "sim/trace.h"
#include "support/test_paths.h"

namespace basalt::sim {
namespace {

using namespace std::chrono_literals;
using devices::DeviceKind;
using devices::DeviceRequest;

std::uint64_t checksum(const Frame& f) {
  std::uint64_t h = 1469598103934665603ull;
  for (int p = 0; p < f.planeCount; ++p) {
    const Plane& pl = f.planes[static_cast<std::size_t>(p)];
    for (std::size_t i = 0; i < pl.size; ++i) h = (h ^ pl.data[i]) * 1099511628211ull;
  }
  return h;
}

struct ShowRun {
  std::vector<Event> events;
  std::vector<std::uint64_t> frames;
};

/// Steps a manager for `seconds` at 60 fps, collecting dial events and the frames of "camera".
ShowRun runShow(devices::DeviceManager& manager, ManualClock& clock, BoundedQueue<Event>& events, double seconds,
                TraceRecorder* recorder = nullptr) {
  ShowRun run;
  auto stream = manager.videoStream("camera");
  for (int frame = 0; frame < static_cast<int>(seconds * 60); ++frame) {
    clock.advance(fromSeconds(1.0 / 60));
    manager.step(clock.now());
    if (recorder) recorder->drain();
    Event e;
    while (events.pop(e)) {
      if (e.kind == EventKind::kDialDelta || e.kind == EventKind::kButton) run.events.push_back(e);
    }
    if (stream) {
      if (FrameRef f = stream->frameAt(clock.now())) run.frames.push_back(checksum(*f));
    }
  }
  return run;
}

TEST(Traces, ARecordingReplaysItsEventsAndFramesExactly) {
  const auto folder = test::scratchDir("trace_roundtrip") / "show.trace";
  ShowRun recorded;
  {
    ManualClock clock(Nanos{std::chrono::seconds(100)});
    BoundedQueue<Event> events(4096);
    devices::DeviceManager manager(clock, events);
    SyntheticProvider::Device dial;
    dial.candidate = {SyntheticDial::defaultInfo(), DeviceKind::kDialBox, "", ""};
    for (int i = 0; i < 40; ++i) {
      dial.script.push_back({std::chrono::milliseconds(37 * (i + 1)), EventKind::kDialDelta,
                             static_cast<std::uint16_t>(i % 8), (i % 2 ? -1 : 1) * 0.05 * (i % 5 + 1)});
      if (i % 10 == 0)
        dial.script.push_back({std::chrono::milliseconds(37 * (i + 1) + 5), EventKind::kButton, 4, i % 20 ? 0.0 : 1.0});
    }
    dial.loop = false;
    SyntheticProvider::Device camera;
    camera.candidate = {SyntheticCamera::defaultInfo(), DeviceKind::kVideoSource, "", ""};
    camera.camera.mode = {PixelFormat::kNv12, 64, 36, 30};
    manager.addProvider(std::make_unique<SyntheticProvider>(std::vector<SyntheticProvider::Device>{dial, camera}));
    DeviceRequest d{"dials", DeviceKind::kDialBox, {}, {}, {}};
    DeviceRequest c{"camera", DeviceKind::kVideoSource, {}, {}, {}};
    auto dialId = manager.request(d);
    auto cameraId = manager.request(c);
    ASSERT_TRUE(dialId && cameraId);
    auto recorder = TraceRecorder::create(folder, clock, {"test-host", "basalt-test", 60, {}});
    ASSERT_TRUE(recorder) << recorder.error().describe();
    manager.setTaps(recorder->get(), recorder->get());
    manager.step(clock.now());  // opens both
    ASSERT_NE(manager.dialBox("dials"), nullptr);
    ASSERT_TRUE((*recorder)->addDialBox(*dialId, "dials", manager.dialBox("dials")->info(),
                                        manager.dialBox("dials")->reportDescriptor()));
    ASSERT_TRUE((*recorder)->addVideoSource(*cameraId, "camera", manager.videoSource("camera")->info(),
                                            manager.videoSource("camera")->mode()));
    recorded = runShow(manager, clock, events, 2.0, recorder->get());
    manager.setTaps(nullptr, nullptr);
    auto info = (*recorder)->finish();
    ASSERT_TRUE(info) << info.error().describe();
    EXPECT_EQ(info->devices.size(), 2u);
    EXPECT_GT((*recorder)->reportsWritten(), 40u);
    EXPECT_GE((*recorder)->framesWritten(), 55u);
    EXPECT_EQ((*recorder)->framesDropped(), 0u);
  }
  ASSERT_GE(recorded.events.size(), 40u);
  ASSERT_GE(recorded.frames.size(), 55u);

  // Replay under a fresh clock.
  ManualClock clock(Nanos{std::chrono::seconds(5)});
  BoundedQueue<Event> events(4096);
  devices::DeviceManager manager(clock, events);
  auto replay = std::make_unique<ReplayProvider>();
  ASSERT_TRUE(replay->addTrace(folder));
  auto requests = replay->requests();
  ASSERT_EQ(requests.size(), 2u);
  for (auto& r : requests) r.options["loop"] = "false";
  manager.addProvider(std::move(replay));
  for (auto& r : requests) ASSERT_TRUE(manager.request(r));
  manager.step(clock.now());
  ShowRun replayed = runShow(manager, clock, events, 2.0);

  ASSERT_EQ(replayed.events.size(), recorded.events.size());
  const Nanos t0r = recorded.events.front().time, t0p = replayed.events.front().time;
  for (std::size_t i = 0; i < recorded.events.size(); ++i) {
    EXPECT_EQ(replayed.events[i].kind, recorded.events[i].kind) << i;
    EXPECT_EQ(replayed.events[i].index, recorded.events[i].index) << i;
    EXPECT_DOUBLE_EQ(replayed.events[i].value, recorded.events[i].value) << i;
    EXPECT_EQ(replayed.events[i].time - t0p, recorded.events[i].time - t0r) << i;
  }
  ASSERT_GE(replayed.frames.size(), recorded.frames.size() - 1);
  for (std::size_t i = 0; i + 1 < recorded.frames.size(); ++i) {
    EXPECT_EQ(replayed.frames[i], recorded.frames[i]) << "frame " << i << " differs";
  }
}

TEST(Traces, TestdataKeydialReplaysAtItsRecordedTimes) {
  const auto dir = test::testdataDir();
  const auto file = dir / "hid" / "udev-hid-bpf" / "huion_keydial_mini050_bluetooth.hid";
  if (dir.empty() || !std::filesystem::exists(file)) GTEST_SKIP() << "../shared/testdata/hid is missing";
  auto provider = std::make_unique<ReplayProvider>();
  ASSERT_TRUE(provider->addHidRecording(file));
  const auto candidates = provider->enumerate();
  ASSERT_EQ(candidates.size(), 2u);
  EXPECT_EQ(candidates[1].info.path, file.string() + "#1");
  EXPECT_EQ(candidates[1].info.bus, "bluetooth");
  EXPECT_EQ(candidates[1].info.vendor, 0x256c);
  ManualClock clock;
  BoundedQueue<Event> events(64);
  devices::DeviceManager manager(clock, events);
  auto requests = provider->requests();
  manager.addProvider(std::move(provider));
  requests[1].options["loop"] = "false";
  ASSERT_TRUE(manager.request(requests[1]));
  manager.step(clock.now());
  std::vector<Event> got;
  for (int i = 0; i < 1400; ++i) {
    clock.advance(100ms);
    manager.step(clock.now());
    Event e;
    while (events.pop(e)) {
      if (e.kind != EventKind::kDeviceState) got.push_back(e);
    }
  }
  ASSERT_EQ(got.size(), 3u);
  EXPECT_EQ(got[0].time, Nanos{64'859'915'000});
  EXPECT_EQ(got[0].kind, EventKind::kDialDelta);
  EXPECT_EQ(got[1].time, Nanos{134'347'845'000});
  EXPECT_EQ(got[1].kind, EventKind::kButton);
  EXPECT_EQ(got[2].value, 0);
}

TEST(Traces, TestdataDescriptorOnlyFilesListWhatEachNodeIs) {
  const auto dir = test::testdataDir();
  if (dir.empty()) GTEST_SKIP() << "../shared/testdata is missing";
  ReplayProvider provider;
  ASSERT_TRUE(provider.addHidRecording(dir / "hid" / "udev-hid-bpf" / "huion_dial2_q630m_rdescs.hid"));
  ASSERT_TRUE(provider.addHidRecording(dir / "hid" / "udev-hid-bpf" / "microsoft_surface_dial_rdesc.hid"));
  const auto c = provider.enumerate();
  ASSERT_EQ(c.size(), 4u);
  EXPECT_NE(c[0].problem.find("no dial"), std::string::npos) << "the Huion vendor node is not a dial";
  EXPECT_TRUE(c[2].problem.empty()) << c[2].problem;
  EXPECT_NE(c[2].usage.find("1 dial"), std::string::npos) << c[2].usage;
  EXPECT_TRUE(c[3].problem.empty()) << c[3].problem;
  EXPECT_EQ(c[3].info.name, "Surface Dial");
}

TEST(Traces, TraceTomlErrorsNameTheLine) {
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"format = 2\n", "t.toml:1"},
      {"format = 1\n[[device]]\nname = \"a\"\nfile = \"../../etc/passwd\"\n", "t.toml:4"},
      {"format = 1\n[[device]]\nname = \"a\"\nfile = \"a.hid\"\nkind = \"toaster\"\n", "t.toml:5"},
      {"format = 1\nfps = \"fast\"\n", "t.toml:2"},
      {"format = 1\n[camera]\n", "t.toml:2"},
      {"format = 1\nhost = \"unterminated\n", "t.toml:2"},
      {"format = 1\n[[device]]\nname = \"a\"\n", "t.toml"},
      {"host = \"x\"\n", "t.toml"},
  };
  for (const auto& [text, where] : bad) {
    auto r = parseTraceToml(text, "t.toml");
    ASSERT_FALSE(r) << text;
    EXPECT_EQ(r.error().where(), where) << text << " -> " << r.error().describe();
  }
  TraceInfo info;
  info.recorded = "2026-01-01T00:00:00Z";
  info.host = "kiosk \"7\"";
  info.fps = 60;
  TraceDevice d;
  d.name = "camera";
  d.kind = DeviceKind::kVideoSource;
  d.file = "camera.bvraw";
  d.mode = {PixelFormat::kYuyv, 640, 360, 30};
  info.devices.push_back(d);
  auto back = parseTraceToml(formatTraceToml(info));
  ASSERT_TRUE(back) << back.error().describe();
  EXPECT_EQ(back->host, info.host);
  EXPECT_EQ(back->devices[0].mode, d.mode);
}

TEST(Traces, RawVideoRoundTripsOddSizesAndRejectsDamage) {
  const auto dir = test::scratchDir("raw_video");
  const devices::VideoMode mode{PixelFormat::kI420, 33, 17, 25};
  {
    auto w = RawVideoWriter::create(dir / "v.bvraw", mode);
    ASSERT_TRUE(w);
    auto pool = FramePool::create({mode.format, mode.width, mode.height, 1, 16, true});  // padded rows
    FrameRef f = pool->acquire();
    drawTestPattern(*f, TestPattern::kColourBars, 3, true);
    f->sequence = 9;
    ASSERT_TRUE((*w)->write(*f, Nanos{40'000'000}));
    ASSERT_TRUE((*w)->finish());
  }
  auto r = RawVideoReader::open(dir / "v.bvraw");
  ASSERT_TRUE(r) << r.error().describe();
  EXPECT_EQ((*r)->mode(), mode);
  auto f = (*r)->next();
  ASSERT_TRUE(f && *f);
  EXPECT_EQ((*f)->pts, Nanos{40'000'000});
  EXPECT_EQ((*f)->sequence, 9u);
  EXPECT_EQ(samplePixel(**f, 0, 0), (Rgb8{180, 180, 180})) << "75% white bar luma survives";
  auto end = (*r)->next();
  ASSERT_TRUE(end);
  EXPECT_FALSE(*end) << "end of file";
  // Truncate: the reader says so instead of reading past the end.
  std::filesystem::resize_file(dir / "v.bvraw", std::filesystem::file_size(dir / "v.bvraw") - 10);
  auto t = RawVideoReader::open(dir / "v.bvraw");
  ASSERT_TRUE(t);
  auto damaged = (*t)->next();
  ASSERT_FALSE(damaged);
  EXPECT_NE(damaged.error().message().find("ends in the middle"), std::string::npos);
  std::ofstream(dir / "junk.bvraw") << "not a video";
  EXPECT_FALSE(RawVideoReader::open(dir / "junk.bvraw"));
  auto factory = videoReaderFactory();
  auto mkv = factory(dir / "camera.mkv");
  ASSERT_FALSE(mkv);
  EXPECT_NE(mkv.error().message().find("media/"), std::string::npos);
}

// What a trace folder may already hold when a recording starts. Makes sure a folder left by a
// recording that never finished is replaced (it cannot be replayed: no trace.toml), while a
// finished trace, foreign files and a recording in progress are refused with the folder named,
// and that a discarded recording leaves nothing behind.
// Example failure: a crashed recording's half-written files make every retry fail.
TEST(TraceFolders, AnUnfinishedTraceIsReplacedOthersAreRefused) {
  const auto root = test::scratchDir("trace-folders");
  ManualClock clock(Nanos{std::chrono::seconds(1)});
  const auto write = [](const std::filesystem::path& file) { std::ofstream(file) << "x\n"; };

  // Left by a crash: recording files, its mark, no trace.toml.
  std::filesystem::create_directories(root / "crashed.trace");
  for (const char* name : {"dials.hid", "camera.bvraw", "camera2.mkv", ".recording"})
    write(root / "crashed.trace" / name);
  auto replaced = TraceRecorder::create(root / "crashed.trace", clock, {"h", "v", 60, {}});
  ASSERT_TRUE(replaced) << replaced.error().describe();
  EXPECT_EQ((*replaced)->replacedFiles(), (std::vector<std::string>{"camera.bvraw", "camera2.mkv", "dials.hid"}));
  EXPECT_FALSE(std::filesystem::exists(root / "crashed.trace" / "dials.hid"));
  EXPECT_TRUE(std::filesystem::exists(root / "crashed.trace" / ".recording")) << "the new recording's mark";

  // While that recording runs, its folder is refused to a second one.
  auto second = TraceRecorder::create(root / "crashed.trace", clock, {"h", "v", 60, {}});
  ASSERT_FALSE(second);
  EXPECT_NE(second.error().message().find("another 'basalt record' is writing this trace now (pid "), std::string::npos)
      << second.error().describe();
  EXPECT_EQ(second.error().where(), (root / "crashed.trace").string());
  ASSERT_TRUE((*replaced)->finish());
  EXPECT_TRUE(std::filesystem::exists(root / "crashed.trace" / "trace.toml"));
  EXPECT_FALSE(std::filesystem::exists(root / "crashed.trace" / ".recording")) << "a finished trace has no mark";
  replaced->reset();

  // A finished trace is refused, and so is a folder with other files; both are left as they were.
  auto finished = TraceRecorder::create(root / "crashed.trace", clock, {"h", "v", 60, {}});
  ASSERT_FALSE(finished);
  EXPECT_NE(finished.error().message().find("holds a finished trace"), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(root / "crashed.trace" / "trace.toml"));
  std::filesystem::create_directories(root / "photos");
  write(root / "photos" / "b.jpg");
  write(root / "photos" / "a.hid");
  auto foreign = TraceRecorder::create(root / "photos", clock, {"h", "v", 60, {}});
  ASSERT_FALSE(foreign);
  EXPECT_NE(foreign.error().message().find("is not empty and is not a trace (it holds b.jpg)"), std::string::npos)
      << foreign.error().message();
  EXPECT_TRUE(std::filesystem::exists(root / "photos" / "a.hid"));
}

TEST(TraceFolders, ADiscardedRecordingLeavesNothing) {
  const auto root = test::scratchDir("trace-discard");
  ManualClock clock(Nanos{std::chrono::seconds(1)});
  auto recorder = TraceRecorder::create(root / "new.trace", clock, {"h", "v", 60, {}});
  ASSERT_TRUE(recorder) << recorder.error().describe();
  ASSERT_TRUE((*recorder)->addDialBox(1, "dials", SyntheticDial::defaultInfo(), devices::virtualDialBoxDescriptor()));
  (*recorder)->onReport(1, clock.now(), std::vector<std::uint8_t>(21, 0));
  EXPECT_GT((*recorder)->bytesWritten(), 0u);
  (*recorder)->discard();
  EXPECT_FALSE(std::filesystem::exists(root / "new.trace")) << "the folder it made goes too";
  EXPECT_FALSE((*recorder)->finish()) << "nothing to finish after a discard";
  EXPECT_FALSE(std::filesystem::exists(root / "new.trace"));

  // A folder that was there before (empty) stays; only the recording's files go.
  std::filesystem::create_directories(root / "given.trace");
  auto given = TraceRecorder::create(root / "given.trace", clock, {"h", "v", 60, {}});
  ASSERT_TRUE(given) << given.error().describe();
  ASSERT_TRUE((*given)->addDialBox(1, "dials", SyntheticDial::defaultInfo(), devices::virtualDialBoxDescriptor()));
  (*given)->discard();
  EXPECT_TRUE(std::filesystem::exists(root / "given.trace"));
  EXPECT_TRUE(std::filesystem::is_empty(root / "given.trace"));
}

}  // namespace
}  // namespace basalt::sim
