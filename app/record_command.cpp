#include "app/record_command.h"

#include <sys/statvfs.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <deque>
#include <set>

#include <fmt/format.h>

#include "app/commands.h"
#include "app/options.h"
#include "kiosk/show/device_wiring.h"
#include "kiosk/show/trace_video_glue.h"
#include "runtime/event_loop.h"
#include "runtime/log.h"
#include "sim/providers.h"
#include "sim/raw_video.h"
#include "sim/synthetic_tracker.h"
#include "sim/trace.h"

namespace basalt::kiosk {

namespace {

constexpr std::uint64_t kMiB = std::uint64_t{1024} * 1024;
/// What `basalt record` keeps free on the disk it writes to, unless --keep-free says otherwise.
constexpr std::uint64_t kDefaultKeepFree = 256 * kMiB;

/// "13.6 MiB", "1.2 GiB", "512 KiB".
std::string bytesText(std::uint64_t bytes) {
  const auto b = static_cast<double>(bytes);
  if (bytes >= 1024 * kMiB) return fmt::format("{:.1f} GiB", b / static_cast<double>(1024 * kMiB));
  if (bytes >= kMiB) return fmt::format("{:.1f} MiB", b / static_cast<double>(kMiB));
  if (bytes >= 1024) return fmt::format("{:.0f} KiB", b / 1024.0);
  return fmt::format("{} bytes", bytes);
}

/// "256M", "1G", "500K", "1073741824" (bytes; K, M, G and T are powers of 1024, with an
/// optional "B" or "iB" after them).
Result<std::uint64_t> parseSizeOption(std::string_view option, std::string_view text) {
  const auto bad = [&] {
    return fail(Errc::kInvalidArgument,
                fmt::format("{} needs a size such as 256M, 2G or 500000000 (bytes), not '{}'", option, text));
  };
  std::uint64_t number = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), number);
  if (ec != std::errc{} || end == text.data()) return bad();
  std::string_view unit(end, static_cast<std::size_t>(text.data() + text.size() - end));
  if (unit.ends_with("iB")) {
    unit.remove_suffix(2);
  } else if (unit.size() == 2 && unit.ends_with("B")) {
    unit.remove_suffix(1);
  }
  std::uint64_t scale = 1;
  if (unit == "K" || unit == "k") {
    scale = 1024;
  } else if (unit == "M") {
    scale = kMiB;
  } else if (unit == "G") {
    scale = 1024 * kMiB;
  } else if (unit == "T") {
    scale = kMiB * 1024 * 1024;
  } else if (!unit.empty() && unit != "B") {
    return bad();
  }
  if (number > UINT64_MAX / scale) return bad();
  return number * scale;
}

/// Free bytes for an unprivileged writer on the file system that holds `path` (or its nearest
/// existing parent).
Result<std::uint64_t> freeBytes(std::filesystem::path path) {
  std::error_code ec;
  if (auto absolute = std::filesystem::absolute(path, ec); !ec) path = std::move(absolute);
  while (!std::filesystem::exists(path, ec) && path.has_relative_path()) path = path.parent_path();
  struct statvfs fs{};
  if (::statvfs(path.c_str(), &fs) != 0) {
    return fail(Errc::kIo, fmt::format("cannot tell the free space: {}", std::strerror(errno)), path.string());
  }
  return static_cast<std::uint64_t>(fs.f_bavail) * static_cast<std::uint64_t>(fs.f_frsize);
}

/// One line on a terminal that is rewritten in place ('\r' and erase to the end of the line);
/// nothing at all when neither stdout nor stderr is a terminal (a log, a pipe, systemd).
class ProgressLine {
 public:
  ProgressLine() : out_(::isatty(STDERR_FILENO) ? stderr : (::isatty(STDOUT_FILENO) ? stdout : nullptr)) {}
  ~ProgressLine() { clear(); }
  ProgressLine(const ProgressLine&) = delete;
  ProgressLine& operator=(const ProgressLine&) = delete;

  [[nodiscard]] bool shown() const { return out_ != nullptr; }
  void show(const std::string& text) {
    if (!out_) return;
    fmt::print(out_, "\r{}\x1b[K", text);
    std::fflush(out_);
    visible_ = true;
  }
  /// Before any other line is printed, so that it does not land in the middle of this one.
  void clear() {
    if (!out_ || !visible_) return;
    fmt::print(out_, "\r\x1b[K");
    std::fflush(out_);
    visible_ = false;
  }

 private:
  std::FILE* out_;
  bool visible_ = false;
};

/// Watches the disk a recording fills: its rate over the last second and what must stay free.
class DiskGuard {
 public:
  DiskGuard(std::uint64_t keepFree, Nanos start) : keepFree_(keepFree) { samples_.push_back({start, 0}); }

  /// Notes `bytes` written by `now` (system clock); returns the bytes per second over about the
  /// last second.
  double note(Nanos now, std::uint64_t bytes) {
    samples_.push_back({now, bytes});
    while (samples_.size() > 2 && now - samples_[1].time >= std::chrono::seconds(1)) samples_.pop_front();
    const Sample& from = samples_.front();
    const double seconds = toSeconds(now - from.time);
    rate_ = seconds > 0.05 && bytes >= from.bytes ? static_cast<double>(bytes - from.bytes) / seconds : rate_;
    return rate_;
  }
  /// What must stay free: --keep-free, or two seconds at the current rate if that is more.
  [[nodiscard]] std::uint64_t reserve() const { return std::max(keepFree_, static_cast<std::uint64_t>(2 * rate_)); }
  [[nodiscard]] double rate() const { return rate_; }

 private:
  struct Sample {
    Nanos time;
    std::uint64_t bytes;
  };
  std::uint64_t keepFree_;
  std::deque<Sample> samples_;
  double rate_ = 0;
};

}  // namespace

std::string_view recordUsage() {
  return R"(Usage: basalt record --output NAME.trace [options]

Records live devices into a trace folder: trace.toml, one hid-recorder file per dial box
(replayable with hid-replay too; a MIDI controller's is a Standard MIDI File that aplaymidi
plays) and one video file per camera, with the original timestamps.
Replay it with 'basalt run --replay NAME.trace'. Devices that are unplugged while recording are
recorded again when they come back.

Options:
  --output DIR      the trace folder to create (must not exist or be empty)
  --dial SPEC       a dial box to record (repeatable): hid, hid:077d:0410, hid:/dev/hidraw3,
                    serial:/dev/ttyUSB0, midi:X-TOUCH MINI, midi:seq:24:0, synthetic
  --camera SPEC     a video source to record (repeatable): v4l2:/dev/video0, v4l2:NAME,
                    libcamera, synthetic
  --tracker SPEC    a head or object tracker to record (repeatable): hid, hid:VVVV:PPPP,
                    hid:/dev/hidraw3, synthetic (a head going round a circle)
  --synthetic       record the synthetic dial box and camera (a demo trace, no hardware needed)
  --seconds S       stop after S seconds (default: until Ctrl-C or SIGTERM)
  --fast            run on a manual clock as fast as possible (synthetic devices only)
  --fps F           the show's frame rate noted in the trace (default 60)
  --raw-video       write camera video as uncompressed .bvraw files instead of Matroska
  --keep-free SIZE  stop before the disk holding the trace has less than SIZE free, or less
                    than two seconds of recording at the current rate if that is more
                    (default 256M; K, M, G, T are powers of 1024; 0 keeps only the two seconds)
  -h, --help        this text

Camera video is written as Matroska (NAME.mkv): the frames as the camera gave them (raw YUV or
MJPEG, not re-encoded) with their timestamps to the microsecond. Raw camera video fills a disk
fast (640x360 YUYV at 30 fps is 13 MiB a second): on a terminal a line shows the time, the
reports and frames recorded, the trace's size and the free space, every second, and the
recording stops, keeping what it has, before the disk is full (--keep-free).
A trace that cannot be finished is removed. A folder left by a recording that never finished
(no trace.toml) is replaced; one that holds a finished trace or other files is refused.
See 'basalt devices' for what is connected.
Exit status: 0 recorded, 1 could not record or stopped early (the disk nearly full), 2 usage
error.
)";
}

int recordMain(std::span<const std::string_view> args) {
  auto parsed = parseOptions("record", args,
                             {{"--help|-h"},
                              {"--output", true},
                              {"--dial", true},
                              {"--camera", true},
                              {"--tracker", true},
                              {"--synthetic"},
                              {"--seconds", true},
                              {"--fast"},
                              {"--fps", true},
                              {"--raw-video"},
                              {"--keep-free", true}});
  if (!parsed) return usageError(parsed.error().describe());
  std::filesystem::path output;
  std::vector<devices::DeviceRequest> requests;
  std::optional<double> seconds;
  bool fast = false;
  double fps = 60;
  bool rawVideo = false;
  std::uint64_t keepFree = kDefaultKeepFree;
  int dials = 0, cameras = 0, trackers = 0;
  bool syntheticTracker = false;
  for (const ParsedOption& o : *parsed) {
    if (o.name.empty()) return usageError(fmt::format("unexpected argument '{}'; see 'basalt record --help'", o.value));
    if (o.name == "--help") {
      fmt::print("{}", recordUsage());
      return 0;
    }
    if (o.name == "--output") output = std::filesystem::path(o.value);
    if (o.name == "--raw-video") rawVideo = true;
    if (o.name == "--dial" || o.name == "--camera" || o.name == "--synthetic") {
      const bool dial = o.name == "--dial";
      auto add = [&](std::string_view spec, bool isDial) -> Result<void> {
        const int n = isDial ? ++dials : ++cameras;
        std::string name = isDial ? "dials" : "camera";
        if (n > 1) name += std::to_string(n);
        auto r =
            parseDeviceSpec(spec, isDial ? devices::DeviceKind::kDialBox : devices::DeviceKind::kVideoSource, name);
        if (!r) return std::unexpected(r.error());
        requests.push_back(std::move(*r));
        return {};
      };
      Result<void> r;
      if (o.name == "--synthetic") {
        r = add("synthetic:synthetic:dial", true);
        if (r) r = add("synthetic:synthetic:camera", false);
      } else {
        r = add(o.value, dial);
      }
      if (!r) return usageError(r.error().describe());
    }
    if (o.name == "--tracker") {
      std::string name = "tracker";
      if (++trackers > 1) name += std::to_string(trackers);
      auto r = parseDeviceSpec(o.value, devices::DeviceKind::kTracker, name);
      if (!r) return usageError(r.error().describe());
      if (r->match.backend != "hid" && r->match.backend != "synthetic") {
        return usageError(fmt::format("--tracker {}: a tracker is recorded from hid or synthetic", o.value));
      }
      if (r->match.backend == "synthetic") {
        syntheticTracker = true;
        r->match.path = sim::SyntheticTracker::defaultInfo().path;
      }
      requests.push_back(std::move(*r));
    }
    if (o.name == "--seconds") {
      auto v = numberOption(o.name, o.value, 0.01, 1e7);
      if (!v) return usageError(v.error().describe());
      seconds = *v;
    }
    if (o.name == "--fast") fast = true;
    if (o.name == "--keep-free") {
      auto v = parseSizeOption(o.name, o.value);
      if (!v) return usageError(v.error().describe());
      keepFree = *v;
    }
    if (o.name == "--fps") {
      auto v = numberOption(o.name, o.value, 1, 1000);
      if (!v) return usageError(v.error().describe());
      fps = *v;
    }
  }
  if (output.empty()) return usageError("basalt record needs --output NAME.trace; see 'basalt record --help'");
  if (requests.empty()) {
    return usageError(
        "nothing to record: give --dial, --camera, --tracker or --synthetic; 'basalt devices' lists what is there");
  }
  if (fast && !seconds) return usageError("--fast needs --seconds (a manual clock never reaches Ctrl-C)");
  if (fast) {
    for (const auto& r : requests) {
      if (r.match.backend != "synthetic") {
        return usageError(fmt::format("--fast records simulated devices only; '{}' is a real device", r.name));
      }
    }
  }

  // Before anything is opened: a disk already short of the reserve is said at once.
  if (auto free = freeBytes(output); !free) {
    fmt::print(stderr, "basalt: error: cannot record: {}\n", free.error().describe());
    return 1;
  } else if (*free < keepFree) {
    fmt::print(stderr,
               "basalt: error: cannot record into {}: only {} free there, and basalt record keeps {} free "
               "(--keep-free); free some space or record onto another disk\n",
               output.string(), bytesText(*free), bytesText(keepFree));
    return 1;
  }

  SystemClock systemClock;
  ManualClock manualClock;
  manualClock.setWallOrigin(systemClock.wallNow());
  const Clock& clock = fast ? static_cast<const Clock&>(manualClock) : systemClock;
  auto loop = runtime::EventLoop::create(clock);
  if (!loop) {
    fmt::print(stderr, "basalt: error: cannot start the event loop: {}\n", loop.error().describe());
    return 1;
  }
  bool stop = false;
  if (auto r = (*loop)->watchSignals({SIGINT, SIGTERM}, [&stop](int) { stop = true; }); !r) {
    fmt::print(stderr, "basalt: error: cannot watch for signals: {}\n", r.error().describe());
    return 1;
  }
  BoundedQueue<Event> events(4096);  // the devices' events: the recorder taps the reports instead
  DeviceWiring wiring(clock, events);
  for (auto& p : allProviders()) {
    if (auto* synthetic = dynamic_cast<sim::SyntheticProvider*>(p.get()); synthetic && syntheticTracker) {
      // The simulated tracker: a head going round a circle (sim::TrackerPath's defaults).
      sim::SyntheticProvider::Device tracker;
      tracker.candidate = {sim::SyntheticTracker::defaultInfo(), devices::DeviceKind::kTracker, "",
                           "a head going round a circle"};
      synthetic->plug(std::move(tracker));
    }
    wiring.manager().addProvider(std::move(p));
  }
  for (auto& r : requests) {
    if (auto id = wiring.manager().request(r); !id) return usageError(id.error().describe());
  }
  char host[256] = {};
  ::gethostname(host, sizeof host - 1);
  auto recorder = sim::TraceRecorder::create(
      output, clock,
      {host, "basalt 0.1.0", fps, rawVideo ? sim::rawVideoWriterFactory() : matroskaTraceWriterFactory()});
  if (!recorder) {
    fmt::print(stderr, "basalt: error: cannot record: {}\n", recorder.error().describe());
    return 1;
  }
  if (const auto& replaced = (*recorder)->replacedFiles(); !replaced.empty()) {
    std::string names;
    for (std::size_t i = 0; i < replaced.size(); ++i) names += (i ? ", " : "") + replaced[i];
    fmt::print(
        "basalt: {} held an unfinished trace (no trace.toml: a recording that stopped before it "
        "finished); recording over it (removed {})\n",
        output.string(), names);
  }
  ProgressLine progress;
  // Whatever ends the recording without a trace removes what it wrote.
  const auto discard = [&](std::string_view why) {
    progress.clear();
    (*recorder)->discard();
    fmt::print(stderr, "basalt: error: {}; removed the unfinished trace {}\n", why, output.string());
    return 1;
  };
  wiring.manager().setTaps(recorder->get(), recorder->get());
  wiring.start(fast);

  std::set<DeviceId> registered;
  std::string failure;  // why the recording cannot be kept
  auto registerLive = [&] {
    for (const devices::DeviceStatus& s : wiring.manager().status()) {
      if (s.state != devices::DeviceState::kLive || registered.contains(s.id)) continue;
      Result<void> r = s.kind == devices::DeviceKind::kDialBox
                           ? (*recorder)->addDialBox(s.id, s.name, s.device, s.reportDescriptor)
                       : s.kind == devices::DeviceKind::kTracker
                           ? (*recorder)->addTracker(s.id, s.name, s.device, s.reportDescriptor)
                           : (*recorder)->addVideoSource(s.id, s.name, s.device, s.mode.value_or(devices::VideoMode{}));
      if (!r) {
        failure = fmt::format("cannot record {}: {}", s.name, r.error().describe());
        stop = true;
        return;
      }
      registered.insert(s.id);
      progress.clear();
      fmt::print("basalt: recording {} from {}\n", s.name, devices::describeDevice(s.device));
      std::fflush(stdout);
    }
  };
  const Nanos start = clock.now();
  const Nanos step = fromSeconds(1.0 / fps);
  std::int64_t frame = 0;
  // The disk is looked at five times a second (wall time, also under --fast), the line redrawn
  // once a second.
  const Nanos wallStart = systemClock.now();
  DiskGuard disk(keepFree, wallStart);
  Nanos nextLook = wallStart;
  Nanos nextLine = wallStart + std::chrono::seconds(1);
  std::string diskFull;  // why the recording stopped early, keeping the trace
  while (!stop) {
    if (fast) {
      manualClock.set(start + frameTime(++frame, fps));
      wiring.manager().step(clock.now());
      (*recorder)->drain();
      if (auto r = (*loop)->dispatch(Nanos{0}); !r) break;
    } else if (auto r = (*loop)->dispatch(std::min<Nanos>(step, std::chrono::milliseconds(50))); !r) {
      failure = fmt::format("the event loop failed: {}", r.error().describe());
      break;
    }
    registerLive();
    if (seconds && clock.now() - start >= fromSeconds(*seconds)) break;
    // Under --fast the recording outruns any period (gigabytes a second): it looks every frame.
    if (const Nanos now = systemClock.now(); fast || now >= nextLook) {
      nextLook = now + std::chrono::milliseconds(200);
      const std::uint64_t bytes = (*recorder)->bytesWritten();
      disk.note(now, bytes);
      auto free = freeBytes(output);
      if (free && *free < disk.reserve()) {
        const std::string why =
            disk.rate() >= 1 ? fmt::format("--keep-free {}, or two seconds at the current {}/s if that is more",
                                           bytesText(keepFree), bytesText(static_cast<std::uint64_t>(disk.rate())))
                             : fmt::format("--keep-free {}", bytesText(keepFree));
        diskFull = fmt::format(
            "stopped after {:.1f} s, before the disk is full: {} free on the disk of {}, and basalt record keeps {} "
            "free ({}); the trace keeps what was recorded until then",
            toSeconds(clock.now() - start), bytesText(*free), output.string(), bytesText(disk.reserve()), why);
        break;
      }
      if (now >= nextLine && progress.shown()) {
        nextLine += std::chrono::seconds(1);
        const auto elapsed = static_cast<std::int64_t>(toSeconds(clock.now() - start));
        progress.show(fmt::format("basalt: recording {:02}:{:02}:{:02}  {} reports  {} frames  {}  {} free",
                                  elapsed / 3600, elapsed / 60 % 60, elapsed % 60, (*recorder)->reportsWritten(),
                                  (*recorder)->framesWritten(), bytesText(bytes),
                                  free ? bytesText(*free) : std::string("?")));
      }
    }
  }
  progress.clear();
  wiring.manager().setTaps(nullptr, nullptr);
  wiring.stop();
  if (!failure.empty()) return discard(failure);
  for (const devices::DeviceStatus& s : wiring.manager().status()) {
    if (!registered.contains(s.id)) {
      fmt::print("basalt: {} was never live: {}\n", s.name, s.lastError.empty() ? "not found" : s.lastError);
    }
  }
  std::fflush(stdout);
  if (registered.empty()) return discard("no device was live, so nothing was recorded");
  auto info = (*recorder)->finish();
  if (!info) return discard(fmt::format("the recording could not be finished: {}", info.error().describe()));
  fmt::print("basalt: recorded {} device(s) for {:.1f} s into {}: {} reports, {} frames ({} dropped), {}\n",
             info->devices.size(), info->seconds, output.string(), (*recorder)->reportsWritten(),
             (*recorder)->framesWritten(), (*recorder)->framesDropped(), bytesText((*recorder)->bytesWritten()));
  std::fflush(stdout);
  if (!diskFull.empty()) {
    fmt::print(stderr, "basalt: error: {}\n", diskFull);
    return 1;
  }
  return 0;
}

}  // namespace basalt::kiosk
