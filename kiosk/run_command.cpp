#include "kiosk/run_command.h"

#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <memory>
#include <system_error>

#include <fmt/format.h>
#include <fmt/std.h>

#include "kiosk/commands.h"
#include "kiosk/device_wiring.h"
#include "kiosk/frame_loop.h"
#include "kiosk/options.h"
#include "media/image_io.h"
#include "render/output.h"
#include "render/renderer.h"
#include "runtime/event_loop.h"
#include "runtime/image.h"
#include "runtime/log.h"
#include "runtime/show/show.h"

namespace basalt::kiosk {

namespace {

int failWith(const Error& error, std::string_view what) {
  fmt::print(stderr, "basalt: error: {}: {}\n", what, error.describe());
  return 1;
}

/// Makes sure snapshots can be written before anything is rendered.
Result<void> checkWritableFolder(const std::filesystem::path& file) {
  const std::filesystem::path folder = file.has_parent_path() ? file.parent_path() : std::filesystem::path(".");
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (ec) {
    return fail(Errc::kIo, fmt::format("cannot create the output folder {}: {}; choose another with "
                                       "--output-dir or --snapshot",
                                       folder, ec.message()));
  }
  if (::access(folder.c_str(), W_OK) != 0) {
    return fail(Errc::kPermissionDenied,
                fmt::format("the output folder {} is not writable ({}); choose another with --output-dir or "
                            "--snapshot",
                            folder, std::strerror(errno)));
  }
  return {};
}

constexpr std::uint32_t kMaxDimension = 16384;

Result<void> parseSize(std::string_view text, RunOptions& run) {
  const auto x = text.find_first_of("xX");
  const auto bad = [&] {
    return fail(
        Errc::kInvalidArgument,
        fmt::format("--size needs WIDTHxHEIGHT between 1 and {} each, e.g. 1280x720, not '{}'", kMaxDimension, text));
  };
  if (x == std::string_view::npos) return bad();
  auto w = integerOption("--size", text.substr(0, x), 1, kMaxDimension);
  auto h = integerOption("--size", text.substr(x + 1), 1, kMaxDimension);
  if (!w || !h) return bad();
  run.width = static_cast<std::uint32_t>(*w);
  run.height = static_cast<std::uint32_t>(*h);
  return {};
}

}  // namespace

std::string_view runUsage() {
  return R"(Usage: basalt run [options]

Plays a show. With no show given it plays the default show: LAVA's start-up scene, a
coloured cube on black, 500x500, turning slowly under LAVA's default lights. With no display
it renders offscreen through EGL (headless) and writes a snapshot of the last frame.
Without --frames or --seconds it runs until interrupted (Ctrl-C, SIGTERM) and exits cleanly.

Options:
  --frames N         stop after N frames
  --seconds S        stop after S seconds of show time
  --size WxH         output size in pixels (default 500x500)
  --headless         render offscreen even when a display is available
  --snapshot PATH    write the last frame to PATH (format from the extension: .png, .jpg,
                     .tif, .exr, ...); default: OUTPUT_DIR/snapshot.png
  --output-dir DIR   folder for snapshots (default: out)
  --fps F            show frame rate (default 60)
  --realtime         pace frames on the system clock at the frame rate
  --fast             step a manual clock exactly 1/fps per frame and render as fast as
                     possible (the default headless when --frames or --seconds is given)
  --replay PATH      play the devices recorded in a trace folder (basalt record) or an
                     hid-recorder file as if they were plugged in; dials drive LAVA's dial table
  --replay-once      play the recording once instead of looping
  -h, --help         this text

Exit status: 0 when the show ran, 1 when it could not start or failed, 2 for usage errors.
)";
}

Result<RunOptions> parseRunOptions(std::span<const std::string_view> args) {
  auto parsed = parseOptions("run", args,
                             {{"--help|-h"},
                              {"--frames", true},
                              {"--seconds", true},
                              {"--size", true},
                              {"--headless"},
                              {"--snapshot", true},
                              {"--output-dir", true},
                              {"--fps", true},
                              {"--realtime"},
                              {"--fast"},
                              {"--replay", true},
                              {"--replay-once"}});
  if (!parsed) return std::unexpected(parsed.error());
  RunOptions run;
  for (const ParsedOption& o : *parsed) {
    if (o.name.empty()) {
      return fail(Errc::kInvalidArgument,
                  fmt::format("unexpected argument '{}' for 'basalt run'; see 'basalt run --help'", o.value));
    }
    if (o.name == "--help") {
      run.help = true;
    } else if (o.name == "--frames") {
      auto n = integerOption(o.name, o.value, 1, INT64_MAX);
      if (!n) return std::unexpected(n.error());
      run.frames = *n;
    } else if (o.name == "--seconds") {
      auto v = numberOption(o.name, o.value, 1e-6, 1e9);
      if (!v) return std::unexpected(v.error());
      run.seconds = *v;
    } else if (o.name == "--size") {
      if (auto r = parseSize(o.value, run); !r) return std::unexpected(r.error());
    } else if (o.name == "--headless") {
      run.headless = true;
    } else if (o.name == "--snapshot") {
      if (o.value.empty()) return fail(Errc::kInvalidArgument, "--snapshot needs a file name");
      run.snapshot = std::filesystem::path(o.value);
    } else if (o.name == "--output-dir") {
      if (o.value.empty()) return fail(Errc::kInvalidArgument, "--output-dir needs a folder");
      run.outputDir = std::filesystem::path(o.value);
    } else if (o.name == "--fps") {
      auto v = numberOption(o.name, o.value, 1, 1000);
      if (!v) return std::unexpected(v.error());
      run.fps = *v;
    } else if (o.name == "--realtime") {
      run.clock = ClockMode::kSystem;
    } else if (o.name == "--fast") {
      run.clock = ClockMode::kManual;
    } else if (o.name == "--replay") {
      if (o.value.empty()) return fail(Errc::kInvalidArgument, "--replay needs a trace folder or .hid file");
      run.replay = std::filesystem::path(o.value);
    } else if (o.name == "--replay-once") {
      run.replayOnce = true;
    }
  }
  return run;
}

int runMain(std::span<const std::string_view> args) {
  auto options = parseRunOptions(args);
  if (!options) return usageError(options.error().describe());
  if (options->help) {
    fmt::print("{}", runUsage());
    return 0;
  }
  return runShow(*options);
}

int runShow(const RunOptions& options) {
  const std::filesystem::path snapshotPath = options.snapshot ? *options.snapshot : options.outputDir / "snapshot.png";
  if (auto r = checkWritableFolder(snapshotPath); !r) return failWith(r.error(), "cannot start");

  std::int64_t maxFrames = -1;
  if (options.frames) maxFrames = *options.frames;
  if (options.seconds) {
    const auto fromSeconds = static_cast<std::int64_t>(std::ceil(*options.seconds * options.fps));
    maxFrames = maxFrames < 0 ? fromSeconds : std::min(maxFrames, fromSeconds);
  }
  const bool manual = options.clock == ClockMode::kManual || (options.clock == ClockMode::kAuto && maxFrames >= 0);
  SystemClock systemClock;
  ManualClock manualClock;
  const Clock& clock = manual ? static_cast<const Clock&>(manualClock) : systemClock;

  auto loop = runtime::EventLoop::create(clock);
  if (!loop) return failWith(loop.error(), "cannot start the event loop");

  // Only the headless output exists in this build; KMS and window outputs plug in here.
  auto output = render::createHeadlessOutput({options.width, options.height});
  if (!output) return failWith(output.error(), "cannot open the headless output");
  auto renderer = render::Renderer::create();
  if (!renderer) return failWith(renderer.error(), "cannot set up the renderer");

  runtime::Show show = runtime::Show::makeDefault();
  FrameLoop frameLoop({options.fps, maxFrames}, clock, manual ? &manualClock : nullptr, **loop, show, **output,
                      **renderer);

  // Devices: a replayed trace drives the show through LAVA's dial table.
  runtime::Bindings bindings = runtime::Bindings::lavaDefaults();
  std::unique_ptr<DeviceWiring> devices;
  if (options.replay) {
    runtime::EventLoop* eventLoop = loop->get();
    devices = std::make_unique<DeviceWiring>(clock, [eventLoop] { eventLoop->wake(); });
    if (auto r = devices->addReplay(*options.replay, !options.replayOnce); !r) {
      return failWith(r.error(), "cannot replay");
    }
    frameLoop.addParticipant(devices->participant());
    frameLoop.setEvents(&devices->events(), &bindings);
    devices->start(manual);
  }

  auto stopOnSignal = (*loop)->watchSignals({SIGINT, SIGTERM}, [&frameLoop](int) { frameLoop.requestStop(); });
  if (!stopOnSignal) return failWith(stopOnSignal.error(), "cannot watch for signals");

  Image snapshot;
  bool snapshotWritten = false;
  frameLoop.setFrameHook([&](std::int64_t, bool last, render::Output& out) -> Result<void> {
    if (!last) return {};
    if (auto r = out.readBack(snapshot); !r) return r;
    if (auto r = media::writeImage(snapshotPath, snapshot); !r) return r;
    snapshotWritten = true;
    return {};
  });

  auto stats = frameLoop.run();
  std::vector<devices::DeviceStatus> deviceStatus;
  if (devices) {
    deviceStatus = devices->manager().status();
    devices->stop();
  }
  if (!stats) return failWith(stats.error(), "the show stopped");

  const double fps = stats->wallSeconds > 0 ? static_cast<double>(stats->frames) / stats->wallSeconds : 0;
  fmt::print("basalt: played the default show: {} frames in {:.2f} s ({:.1f} frames per second, {} clock)\n",
             stats->frames, stats->wallSeconds, fps, manual ? "manual" : "system");
  fmt::print("basalt: output: {}\n", (*output)->describe());
  fmt::print("basalt: first frame after {:.1f} ms\n", stats->firstFrameSeconds * 1000);
  if (snapshotWritten) fmt::print("basalt: snapshot written to {}\n", snapshotPath.string());
  if (devices) {
    for (const devices::DeviceStatus& s : deviceStatus) {
      fmt::print("basalt: replayed {} '{}' ({})\n", devices::deviceKindName(s.kind), s.name,
                 s.lastError.empty() ? std::string(devices::deviceStateName(s.state)) : s.lastError);
    }
  }
  std::fflush(stdout);
  return 0;
}

}  // namespace basalt::kiosk
