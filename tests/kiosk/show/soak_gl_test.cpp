// A day of unattended running in seconds: the default show in a playlist with the attract
// loop, opening hours and idle time-outs; a dial box replaying a real recording (the Huion
// Keydial mini's knob and play/pause key from ../shared/testdata/hid, put in a trace folder by
// the test and looped); a real movie (a VP9 clip the test records with media's recorder)
// looping on a texture all day and playing as a playlist item; crash-recovery saves; and the
// status server asked for /health, /metrics, / and /snapshot.png every simulated hour. 24 hours
// on a ManualClock at one frame per 4 s of show time (21,600 frames). Resident memory and open
// file descriptors are sampled every hour and must stay flat once the day's first opening
// (08:00) has drawn the cube and filled the caches.
// Example failures: a string or vector that grows with every item change or every request; a
// state file or socket descriptor opened per save or per request and never closed; a GStreamer
// pipeline, buffer or texture leaked per loop of the movie or per start of the movie item.

#include <gtest/gtest.h>

#include <fmt/format.h>
#include <httplib.h>
#include <malloc.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <fstream>
#include <set>
#include <thread>
#include <utility>

#include "kiosk/loop/frame_loop.h"
#include "kiosk/manifest/manifest.h"
#include "kiosk/manifest/time_zone.h"
#include "kiosk/policy/state_store.h"
#include "kiosk/show/movie_item.h"
#include "kiosk/show/show_director.h"
#include "kiosk/show/show_loader.h"
#include "kiosk/show/stream_factories.h"
#include "kiosk/status/frame_metrics.h"
#include "kiosk/status/status_board.h"
#include "kiosk/status/status_server.h"
#include "media/recorder.h"
#include "render/output.h"
#include "render/renderer.h"
#include "runtime/event_loop.h"
#include "support/test_paths.h"

namespace basalt::kiosk {
namespace {

std::size_t residentBytes() {
  std::ifstream statm("/proc/self/statm");
  std::size_t pages = 0;
  std::size_t resident = 0;
  statm >> pages >> resident;
  return resident * static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
}

/// Bytes malloc has handed out and not had back, over every arena (and its mmapped blocks): what a
/// leak grows. Resident memory also moves when a thread's malloc arena takes another heap.
std::size_t heapInUse() { return ::mallinfo2().uordblks + ::mallinfo2().hblkhd; }

std::size_t openFds() {
  std::size_t n = 0;
  for (const auto& e : std::filesystem::directory_iterator("/proc/self/fd")) {
    (void)e;
    ++n;
  }
  return n;
}

/// Open descriptors once the status server has closed the connections of the hour's requests.
std::size_t settledFds(std::size_t expected) {
  std::size_t n = openFds();
  for (int i = 0; i < 40 && n != expected; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(25));
    n = openFds();
  }
  return n;
}

/// What the open descriptors are, for a failure message.
std::string describeFds() {
  std::string out;
  for (const auto& e : std::filesystem::directory_iterator("/proc/self/fd")) {
    std::error_code ec;
    out += e.path().filename().string() + "=" + std::filesystem::read_symlink(e.path(), ec).string() + " ";
  }
  return out;
}

/// Notes every kiosk mode the day went through.
class ModeWatcher final : public FrameParticipant {
 public:
  explicit ModeWatcher(const ShowDirector& director) : director_(director) {}
  void afterPresent(const FrameContext& /*frame*/) override {
    seen_[static_cast<std::size_t>(director_.policy()->current().mode)] = true;
    const auto* item = director_.policy()->current().item;
    if (item && item->name == "clip") playedClip_ = true;
  }
  [[nodiscard]] bool playedClip() const { return playedClip_; }
  [[nodiscard]] std::set<std::string> seen() const {
    std::set<std::string> out;
    for (std::size_t i = 0; i < seen_.size(); ++i) {
      if (seen_[i]) out.insert(std::string(kioskModeName(static_cast<KioskMode>(i))));
    }
    return out;
  }

 private:
  const ShowDirector& director_;
  std::array<bool, 3> seen_{};
  bool playedClip_ = false;
};

/// The lowest small-block heap in use (malloc's, without its large mmapped blocks) seen in an
/// hour, sampled every simulated minute. Within an hour the heap swings by a few hundred KiB as
/// items start and end (pipelines, textures, the renderer's caches); one sample an hour lands on
/// a high or a low at random, while the low of an hour only moves when something stays.
class HeapLow final : public FrameParticipant {
 public:
  void afterPresent(const FrameContext& /*frame*/) override {
    if (frames_++ % 15 != 0) return;
    low_ = std::min(low_, ::mallinfo2().uordblks);
  }
  /// The hour's low; starts the next hour.
  std::size_t take() { return std::exchange(low_, SIZE_MAX); }

 private:
  std::uint64_t frames_ = 0;
  std::size_t low_ = SIZE_MAX;
};

/// A trace folder replaying the Huion Keydial mini recording's second device (D:1, the one that
/// sends: its knob arrives as a mouse wheel, its key as Consumer Play/Pause).
bool writeKeydialTrace(const std::filesystem::path& folder, std::string& why) {
  const std::filesystem::path source = test::testdataDir() / "hid/udev-hid-bpf/huion_keydial_mini050_bluetooth.hid";
  std::ifstream in(source);
  if (!in) {
    why = "no " + source.string() + " (../shared/testdata is not here)";
    return false;
  }
  std::filesystem::create_directories(folder);
  std::ofstream hid(folder / "dials.hid");
  std::string line;
  bool second = false;
  while (std::getline(in, line)) {
    if (line.starts_with("D:")) second = line == "D:1";
    if (second && !line.starts_with("D:")) hid << line << "\n";
  }
  std::ofstream(folder / "trace.toml") << "format = 1\nfps = 60\n\n[[device]]\nname = \"dials\"\nkind = \"dial box\"\n"
                                          "file = \"dials.hid\"\ndevice = \"Keydial mini-050\"\nvendor = \"256c\"\n"
                                          "product = \"8251\"\n";
  return true;
}

/// A six-second VP9 clip at one frame a second, each frame another colour.
bool recordClip(const std::filesystem::path& file, std::string& why) {
  media::RecorderOptions options;
  options.path = file;
  options.width = 32;
  options.height = 32;
  options.fps = 1;
  auto recorder = media::Recorder::create(options);
  if (!recorder) {
    why = recorder.error().describe();
    return false;
  }
  Image frame;
  frame.width = 32;
  frame.height = 32;
  frame.channels = 4;
  for (int i = 0; i < 6; ++i) {
    frame.pixels.assign(32 * 32 * 4, 255);
    for (std::size_t p = 0; p < frame.pixels.size(); p += 4) frame.pixels[p + static_cast<std::size_t>(i % 3)] = 40;
    if (auto r = (*recorder)->push(frame); !r) {
      why = r.error().describe();
      return false;
    }
  }
  if (auto r = (*recorder)->finish(); !r) {
    why = r.error().describe();
    return false;
  }
  return true;
}

TEST(Soak, ADayOfTheDefaultShowStaysFlat) {
  auto output = render::createHeadlessOutput({48, 48});
  if (!output) GTEST_SKIP() << "no headless EGL here: " << output.error().describe();
  auto renderer = render::Renderer::create();
  ASSERT_TRUE(renderer);

  const auto dir = test::scratchDir("soak");
  std::string why;
  if (!writeKeydialTrace(dir / "keydial.trace", why)) GTEST_SKIP() << why;
  ASSERT_TRUE(recordClip(dir / "clip.webm", why)) << why;
  std::filesystem::copy_file(test::sourceDir() / "configs/shows/video-wall/screens.png", dir / "bars.png");
  std::ofstream(dir / "show.toml") << R"(
[show]
name = "Soak"
entry = "default"

[devices.dials]
kind = "dial_box"
backend = "replay"
trace = "keydial.trace"
loop = true

[[bindings]]
device = "dials"
dial = 0
action = "rotate_y"

[media.loop]
kind = "movie"
file = "clip.webm"

[textures."screens.png"]
source = "loop"
fallback = "bars.png"

[[kiosk.playlist]]
name = "cube"
entry = "default"
duration = "5m"

[[kiosk.playlist]]
name = "dark"
entry = "black"
duration = "3m"

[[kiosk.playlist]]
name = "clip"
entry = "clip.webm"
duration = "4m"

[[kiosk.playlist]]
name = "cube again"
entry = "default"
duration = "7m"

[kiosk.attract]
idle_timeout = "3m"
items = [ { entry = "default", name = "attract" } ]

[kiosk.schedule]
timezone = "UTC"
daily = "08:00-20:00"
outside = "black"

[status]
listen = "127.0.0.1:0"
requests_per_second = 1000
)";
  Diagnostics d;
  auto manifest = readManifest(dir / "show.toml", d);
  ASSERT_TRUE(manifest) << d.format();

  const WallTime midnight{std::chrono::seconds(daysFromCivil(2026, 6, 1) * 86400)};
  ManualClock clock(Nanos{0}, midnight);
  auto loop = runtime::EventLoop::create(clock);
  ASSERT_TRUE(loop);
  StatusBoard board(midnight, 0.25);
  runtime::EventLoop* eventLoop = loop->get();
  board.setWake([eventLoop] { eventLoop->wake(); });
  BoundedQueue<Event> events(1024, [eventLoop] { eventLoop->wake(); });
  auto state = StateStore::open(dir / "state", manifest->file.string());
  ASSERT_TRUE(state);
  auto server = StatusServer::start(manifest->status, board);
  ASSERT_TRUE(server) << server.error().describe();
  // What the show plays: the replay dial box, the movie stream and the movie item.
  ShowFactories factories;
  factories.devices = makeDeviceSource;
  factories.movieStreams = makeMovieStream;
  factories.items.movie = makeMovieItem;
  auto loaded = loadShow(*manifest, clock, factories);
  ASSERT_TRUE(loaded);

  runtime::Show show;
  ShowDirector director(
      DirectorContext{clock, **loop, show, **renderer, **output, board, events, nullptr, state->get(), 0.25},
      std::move(factories));
  director.install(std::move(*loaded), clock.now(), std::nullopt);
  FrameMetrics metrics(board, &events);
  ModeWatcher modes(director);

  // An hour at a time: 900 frames of 4 s.
  constexpr int kHours = 24;
  std::vector<std::size_t> rss;
  std::vector<std::size_t> fds;
  std::vector<std::size_t> heap;
  std::vector<std::size_t> mmapped;  // the part of heap in large mmapped blocks
  std::vector<std::size_t> lows;     // each hour's low of the small-block heap
  HeapLow heapLow;
  std::vector<std::string> fdLists;  // what was open when the count was over the bound
  httplib::Client client("127.0.0.1", (*server)->port());
  for (int hour = 0; hour < kHours; ++hour) {
    FrameLoop frameLoop({0.25, 900}, clock, &clock, **loop, show, **output, **renderer);
    frameLoop.addParticipant(metrics);
    frameLoop.addParticipant(director);
    frameLoop.addParticipant(modes);
    frameLoop.addParticipant(heapLow);
    auto stats = frameLoop.run();
    ASSERT_TRUE(stats) << stats.error().describe();
    // The hour's requests, as a monitoring system and a technician's phone would make them.
    for (const char* path : {"/health", "/metrics", "/"}) {
      auto r = client.Get(path);
      ASSERT_TRUE(r) << path;
      EXPECT_EQ(r->status, 200) << path;
    }
    std::thread snapshot([&] {
      auto r = client.Get("/snapshot.png?w=24");
      EXPECT_TRUE(r && r->status == 200) << (r ? r->body : std::string("no answer"));
    });
    // Once the request is queued, the next frame answers it.
    for (int i = 0; i < 2000 && board.snapshotRequests().size() == 0; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    FrameLoop one({0.25, 1}, clock, &clock, **loop, show, **output, **renderer);
    one.addParticipant(metrics);
    one.addParticipant(director);
    ASSERT_TRUE(one.run());
    snapshot.join();
    (*state)->flush();
    rss.push_back(residentBytes());
    heap.push_back(heapInUse());
    mmapped.push_back(::mallinfo2().hblkhd);
    lows.push_back(heapLow.take());
    fds.push_back(fds.empty() ? openFds() : settledFds(fds.front()));
    if (fds.back() > fds[std::min<std::size_t>(fds.size() - 1, 2)] + 8)
      fdLists.push_back(fmt::format("hour {}: {}", hour, describeFds()));
  }
  EXPECT_EQ(modes.seen(), (std::set<std::string>{"active", "attract", "closed"}))
      << "the day went through every mode (active: the replayed knob and key woke the attract loop)";
  const StatusSnapshot status = board.snapshot(midnight);
  ASSERT_EQ(status.devices.size(), 1u);
  EXPECT_EQ(status.devices[0].state, "live") << status.devices[0].message;
  ASSERT_EQ(status.streams.size(), 1u);
  EXPECT_EQ(status.streams[0].state, "playing") << status.streams[0].message;
  EXPECT_NE(status.streams[0].message.find("loops"), std::string::npos) << status.streams[0].message;
  EXPECT_TRUE(modes.playedClip()) << "the movie item played";
  // Flat after the warm-up: the first opening at 08:00 draws the cube (shaders, meshes, the GL
  // driver's buffers) and the log's ring of recent records fills; from then on nothing grows.
  // Mesa's llvmpipe takes a 1 MiB block for its caches once in a while, on its own schedule (a
  // mmap catchpoint in gdb shows it under Renderer::drawSurface, late in the day): large mmapped
  // blocks may grow by at most 1.1 MiB; the rest of the heap in use, where every small object
  // lives, by at most 256 KiB over 14 hours (12 bytes a frame), so that a leak per frame, per movie
  // loop or per request fails. The small heap is compared by its lows (HeapLow: one sample an
  // hour would catch the swings within an hour, which are as large), the highest hourly low of
  // 11:00-16:00 against that of 20:00-midnight: an hour's low itself sits about 250 KiB lower in
  // about one hour of five, at random, so one hour against one could differ by that much.
  // The small heap warms up for longer than the rest: Mesa keeps about 400 KiB more between 10:00
  // and 12:00 (seen with the packed conversion pass, then flat for the next 36 hours of a 48-hour
  // run). The eight hours between the windows at 256 KiB still fail a leak of 36 bytes a frame
  // or 11 KiB a start of the movie item.
  const auto highestLow = [&](std::size_t from, std::size_t to) {
    return static_cast<std::ptrdiff_t>(*std::max_element(lows.begin() + static_cast<std::ptrdiff_t>(from),
                                                         lows.begin() + static_cast<std::ptrdiff_t>(to)));
  };
  const std::ptrdiff_t grown = highestLow(20, 24) - highestLow(11, 16);
  EXPECT_LE(grown, std::ptrdiff_t{256} * 1024) << "the heap in use (without large blocks) grew by " << grown / 1024
                                               << " KiB from the lows of 11:00-16:00 to those of 20:00-midnight";
  EXPECT_LE(mmapped.back(), mmapped[9] + std::size_t{1126} * 1024)
      << "large blocks grew by " << (mmapped.back() - mmapped[9]) / 1024 << " KiB";
  const std::size_t baseline = rss[9];
  const std::size_t highest = *std::max_element(rss.begin() + 9, rss.end());
  EXPECT_LE(rss.back(), baseline + std::size_t{2048} * 1024)
      << "resident memory grew by " << (rss.back() - baseline) / 1024 << " KiB from 10:00 to midnight";
  EXPECT_LE(highest, baseline + std::size_t{3072} * 1024) << "a peak of " << (highest - baseline) / 1024 << " KiB";
  // GStreamer's pipelines open and close socket pairs as the clips loop and the item restarts, so
  // the count at a given moment varies by a few; a descriptor leaked per loop (every 6 s) or
  // per request would add hundreds an hour.
  for (int hour = 2; hour < kHours; ++hour) {
    EXPECT_LE(fds[static_cast<std::size_t>(hour)], fds[2] + 8) << "hour " << hour;
  }
  if (!fdLists.empty()) {
    for (const std::string& l : fdLists) std::printf("soak: %s\n", l.c_str());
  }
  const FrameFigures figures = board.frameFigures();
  EXPECT_GT(figures.frames, 0);
  RecordProperty("rss_first_kib", static_cast<int>(rss.front() / 1024));
  RecordProperty("rss_last_kib", static_cast<int>(rss.back() / 1024));
  RecordProperty("fds", static_cast<int>(fds.back()));
  std::string series;
  for (const std::size_t r : rss) series += std::to_string(r / 1024) + " ";
  std::printf("soak: resident KiB by hour: %s\n", series.c_str());
  series.clear();
  for (const std::size_t h : heap) series += std::to_string(h / 1024) + " ";
  std::printf("soak: heap in use KiB by hour: %s\n", series.c_str());
  series.clear();
  for (const std::size_t h : mmapped) series += std::to_string(h / 1024) + " ";
  std::printf("soak: of which mmapped blocks, KiB: %s\n", series.c_str());
  series.clear();
  for (const std::size_t h : lows) series += std::to_string(h / 1024) + " ";
  std::printf("soak: the small-block heap's low in each hour, KiB: %s\n", series.c_str());
  series.clear();
  for (const std::size_t n : fds) series += std::to_string(n) + " ";
  std::printf("soak: open descriptors by hour: %s\n", series.c_str());
  std::printf(
      "soak: 24 simulated hours, %lld frames; resident %zu KiB at 10:00, %zu KiB at midnight (highest %zu "
      "KiB); %zu open descriptors at midnight\n",
      static_cast<long long>(figures.frames), baseline / 1024, rss.back() / 1024, highest / 1024, fds.back());
}

}  // namespace
}  // namespace basalt::kiosk
