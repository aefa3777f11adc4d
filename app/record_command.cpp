#include "app/record_command.h"

#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <set>

#include <fmt/format.h>

#include "app/commands.h"
#include "app/options.h"
#include "kiosk/show/device_wiring.h"
#include "kiosk/show/trace_video_glue.h"
#include "runtime/event_loop.h"
#include "runtime/log.h"
#include "sim/raw_video.h"
#include "sim/trace.h"

namespace basalt::kiosk {

std::string_view recordUsage() {
  return R"(Usage: basalt record --output NAME.trace [options]

Records live devices into a trace folder: trace.toml, one hid-recorder file per dial box
(replayable with hid-replay too) and one video file per camera, with the original timestamps.
Replay it with 'basalt run --replay NAME.trace'. Devices that are unplugged while recording are
recorded again when they come back.

Options:
  --output DIR      the trace folder to create (must not exist or be empty)
  --dial SPEC       a dial box to record (repeatable): hid, hid:077d:0410, hid:/dev/hidraw3,
                    serial:/dev/ttyUSB0, synthetic
  --camera SPEC     a video source to record (repeatable): v4l2:/dev/video0, v4l2:NAME,
                    libcamera, synthetic
  --synthetic       record the synthetic dial box and camera (a demo trace, no hardware needed)
  --seconds S       stop after S seconds (default: until Ctrl-C or SIGTERM)
  --fast            run on a manual clock as fast as possible (synthetic devices only)
  --fps F           the show's frame rate noted in the trace (default 60)
  --raw-video       write camera video as uncompressed .bvraw files instead of Matroska
  -h, --help        this text

Camera video is written as Matroska (NAME.mkv): the frames as the camera gave them (raw YUV or
MJPEG, not re-encoded) with their timestamps to the microsecond.
See 'basalt devices' for what is connected.
Exit status: 0 recorded, 1 could not record, 2 usage error.
)";
}

int recordMain(std::span<const std::string_view> args) {
  auto parsed = parseOptions("record", args,
                             {{"--help|-h"},
                              {"--output", true},
                              {"--dial", true},
                              {"--camera", true},
                              {"--synthetic"},
                              {"--seconds", true},
                              {"--fast"},
                              {"--fps", true},
                              {"--raw-video"}});
  if (!parsed) return usageError(parsed.error().describe());
  std::filesystem::path output;
  std::vector<devices::DeviceRequest> requests;
  std::optional<double> seconds;
  bool fast = false;
  double fps = 60;
  bool rawVideo = false;
  int dials = 0, cameras = 0;
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
    if (o.name == "--seconds") {
      auto v = numberOption(o.name, o.value, 0.01, 1e7);
      if (!v) return usageError(v.error().describe());
      seconds = *v;
    }
    if (o.name == "--fast") fast = true;
    if (o.name == "--fps") {
      auto v = numberOption(o.name, o.value, 1, 1000);
      if (!v) return usageError(v.error().describe());
      fps = *v;
    }
  }
  if (output.empty()) return usageError("basalt record needs --output NAME.trace; see 'basalt record --help'");
  if (requests.empty()) {
    return usageError("nothing to record: give --dial, --camera or --synthetic; 'basalt devices' lists what is there");
  }
  if (fast && !seconds) return usageError("--fast needs --seconds (a manual clock never reaches Ctrl-C)");
  if (fast) {
    for (const auto& r : requests) {
      if (r.match.backend != "synthetic") {
        return usageError(fmt::format("--fast records simulated devices only; '{}' is a real device", r.name));
      }
    }
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
  for (auto& p : allProviders()) wiring.manager().addProvider(std::move(p));
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
  wiring.manager().setTaps(recorder->get(), recorder->get());
  wiring.start(fast);

  std::set<DeviceId> registered;
  auto registerLive = [&] {
    for (const devices::DeviceStatus& s : wiring.manager().status()) {
      if (s.state != devices::DeviceState::kLive || registered.contains(s.id)) continue;
      Result<void> r = s.kind == devices::DeviceKind::kDialBox
                           ? (*recorder)->addDialBox(s.id, s.name, s.device, s.reportDescriptor)
                           : (*recorder)->addVideoSource(s.id, s.name, s.device, s.mode.value_or(devices::VideoMode{}));
      if (!r) {
        fmt::print(stderr, "basalt: error: cannot record {}: {}\n", s.name, r.error().describe());
        stop = true;
        return;
      }
      registered.insert(s.id);
      fmt::print("basalt: recording {} from {}\n", s.name, devices::describeDevice(s.device));
    }
  };
  const Nanos start = clock.now();
  const Nanos step = fromSeconds(1.0 / fps);
  std::int64_t frame = 0;
  while (!stop) {
    if (fast) {
      manualClock.set(start + frameTime(++frame, fps));
      wiring.manager().step(clock.now());
      (*recorder)->drain();
      if (auto r = (*loop)->dispatch(Nanos{0}); !r) break;
    } else if (auto r = (*loop)->dispatch(std::min<Nanos>(step, std::chrono::milliseconds(50))); !r) {
      fmt::print(stderr, "basalt: error: the event loop failed: {}\n", r.error().describe());
      break;
    }
    registerLive();
    if (seconds && clock.now() - start >= fromSeconds(*seconds)) break;
  }
  wiring.manager().setTaps(nullptr, nullptr);
  wiring.stop();
  auto info = (*recorder)->finish();
  if (!info) {
    fmt::print(stderr, "basalt: error: the recording is incomplete: {}\n", info.error().describe());
    return 1;
  }
  for (const devices::DeviceStatus& s : wiring.manager().status()) {
    if (!registered.contains(s.id)) {
      fmt::print("basalt: {} was never live: {}\n", s.name, s.lastError.empty() ? "not found" : s.lastError);
    }
  }
  fmt::print("basalt: recorded {} device(s) for {:.1f} s into {}: {} reports, {} frames ({} dropped)\n",
             info->devices.size(), info->seconds, output.string(), (*recorder)->reportsWritten(),
             (*recorder)->framesWritten(), (*recorder)->framesDropped());
  std::fflush(stdout);
  return info->devices.empty() ? 1 : 0;
}

}  // namespace basalt::kiosk
