#include "kiosk/run_command.h"

#include <unistd.h>

#include <algorithm>
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
#include "kiosk/script_player.h"
#include "media/image_io.h"
#include "render/output.h"
#include "render/renderer.h"
#include "runtime/event_loop.h"
#include "runtime/image.h"
#include "runtime/log.h"
#include "runtime/script/interpreter.h"
#include "runtime/script/save_model.h"
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
  return R"(Usage: basalt run [options] [SHOW]

Plays a show. With no show given it plays the default show: LAVA's start-up scene, a
coloured cube on black, 500x500, turning slowly under LAVA's default lights. With no display
it renders offscreen through EGL (headless) and writes a snapshot of the last frame.
Without --frames or --seconds it runs until interrupted (Ctrl-C, SIGTERM) and exits cleanly.

SHOW may be a LAVA script (.mdl), run as `lava -file SHOW.mdl` ran it: each `draw` is one
frame, `quit` ends the run, and a bad line is reported and skipped while the show goes on.
A script that quits runs as fast as possible on the manual clock unless --realtime is given.
'basalt help script' lists the language; 'basalt check SHOW.mdl' finds errors without running.

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
  --save-image PATH  where a script's save_image writes (default: OUTPUT_DIR/ras.im32)
  --save-model PATH  at the end, write the show as a LAVA script (LAVA's Save Model)
  --movie PART=FILE  play FILE as the texture of PART (LAVA's texture.switch = video),
                     looping with no gap; repeat the option for more streams, or for the
                     same PART to make a playlist
  --movie-once       play movies once instead of looping
  --zoom PART[=SCALE][@X,Y]
                     show PART's movie as a picture over the scene (LAVA's Zoom): SCALE of
                     its size (default 0.5), top-left corner at X,Y pixels (default 10,10)
  --audio            play the movies' sound on the default output
  --record PATH      record the rendered output to PATH (.mp4, .mkv, .mov, .avi, .webm)
  --record-codec C   h264, mjpeg, vp8, vp9 or auto (H.264; MJPEG for .avi; VP9 for .webm)
  --record-frames N  stop recording after N frames (LAVA's Rec slider); default: the run
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
                              {"--save-image", true},
                              {"--save-model", true},
                              {"--movie", true},
                              {"--movie-once"},
                              {"--zoom", true},
                              {"--audio"},
                              {"--record", true},
                              {"--record-codec", true},
                              {"--record-frames", true},
                              {"--replay", true},
                              {"--replay-once"}});
  if (!parsed) return std::unexpected(parsed.error());
  RunOptions run;
  for (const ParsedOption& o : *parsed) {
    if (o.name.empty()) {
      if (run.show) {
        return fail(Errc::kInvalidArgument,
                    fmt::format("'basalt run' plays one show; '{}' comes after '{}'", o.value, run.show->string()));
      }
      if (o.value.empty()) return fail(Errc::kInvalidArgument, "the show's file name is empty");
      run.show = std::filesystem::path(o.value);
      continue;
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
    } else if (o.name == "--save-image") {
      if (o.value.empty()) return fail(Errc::kInvalidArgument, "--save-image needs a file name");
      run.saveImage = std::filesystem::path(o.value);
    } else if (o.name == "--save-model") {
      if (o.value.empty()) return fail(Errc::kInvalidArgument, "--save-model needs a file name");
      run.saveModel = std::filesystem::path(o.value);
    } else if (o.name == "--movie") {
      auto m = parseMovieOption(o.value);
      if (!m) return std::unexpected(m.error());
      run.movies.push_back(std::move(*m));
    } else if (o.name == "--movie-once") {
      run.movieOnce = true;
    } else if (o.name == "--zoom") {
      auto z = parseZoomOption(o.value);
      if (!z) return std::unexpected(z.error());
      run.zooms.push_back(std::move(*z));
    } else if (o.name == "--audio") {
      run.audio = true;
    } else if (o.name == "--record") {
      if (o.value.empty()) return fail(Errc::kInvalidArgument, "--record needs a file name");
      run.record = std::filesystem::path(o.value);
    } else if (o.name == "--record-codec") {
      auto c = media::parseVideoCodec(o.value);
      if (!c) return std::unexpected(c.error());
      run.recordCodec = std::string(o.value);
    } else if (o.name == "--record-frames") {
      auto n = integerOption(o.name, o.value, 1, INT64_MAX);
      if (!n) return std::unexpected(n.error());
      run.recordFrames = *n;
    } else if (o.name == "--replay") {
      if (o.value.empty()) return fail(Errc::kInvalidArgument, "--replay needs a trace folder or .hid file");
      run.replay = std::filesystem::path(o.value);
    } else if (o.name == "--replay-once") {
      run.replayOnce = true;
    }
  }
  for (const auto& [name, zoom] : run.zooms) {
    const bool known =
        std::any_of(run.movies.begin(), run.movies.end(), [&](const auto& m) { return m.first == name; });
    if (!known) {
      return fail(Errc::kInvalidArgument,
                  fmt::format("--zoom {}: no movie of that name; give --movie {}=FILE too", name, name));
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
  if (options.show && !isScriptFile(*options.show)) {
    return usageError(fmt::format("basalt run plays LAVA scripts (.mdl); '{}' is not one", options.show->string()));
  }
  if (auto r = checkWritableFolder(snapshotPath); !r) return failWith(r.error(), "cannot start");

  std::optional<script::Interpreter> script;
  if (options.show) {
    auto loaded = loadScript(*options.show);
    if (!loaded) return failWith(loaded.error(), "cannot start");
    script.emplace(std::move(*loaded));
  }

  std::int64_t maxFrames = -1;
  if (options.frames) maxFrames = *options.frames;
  if (options.seconds) {
    const auto fromSeconds = static_cast<std::int64_t>(std::ceil(*options.seconds * options.fps));
    maxFrames = maxFrames < 0 ? fromSeconds : std::min(maxFrames, fromSeconds);
  }
  // A script that quits is a batch job (LAVA's test scripts): it runs as fast as it can.
  const bool batch = maxFrames >= 0 || (script && scriptQuits(script->program()));
  const bool manual = options.clock == ClockMode::kManual || (options.clock == ClockMode::kAuto && batch);
  SystemClock systemClock;
  ManualClock manualClock;
  const Clock& clock = manual ? static_cast<const Clock&>(manualClock) : systemClock;

  auto loop = runtime::EventLoop::create(clock);
  if (!loop) return failWith(loop.error(), "cannot start the event loop");
  // Watch SIGINT/SIGTERM before the slow set-up (EGL, shaders): a signal that comes meanwhile
  // stays pending on the signalfd and stops the loop at its first frame, instead of killing us.
  FrameLoop* running = nullptr;
  bool stopEarly = false;
  auto stopOnSignal = (*loop)->watchSignals({SIGINT, SIGTERM}, [&running, &stopEarly](int) {
    if (running) {
      running->requestStop();
    } else {
      stopEarly = true;
    }
  });
  if (!stopOnSignal) return failWith(stopOnSignal.error(), "cannot watch for signals");

  // Only the headless output exists in this build; KMS and window outputs plug in here.
  auto output = render::createHeadlessOutput({options.width, options.height});
  if (!output) return failWith(output.error(), "cannot open the headless output");
  auto renderer = render::Renderer::create();
  if (!renderer) return failWith(renderer.error(), "cannot set up the renderer");

  runtime::Show show = script ? script::startupShow() : runtime::Show::makeDefault();
  FrameLoop frameLoop({options.fps, maxFrames}, clock, manual ? &manualClock : nullptr, **loop, show, **output,
                      **renderer);

  running = &frameLoop;
  if (stopEarly) frameLoop.requestStop();
  std::optional<ScriptPlayer> player;
  if (script) {
    ScriptPlayerOptions playerOptions;
    playerOptions.outputDir = options.outputDir;
    if (options.saveImage) playerOptions.saveImage = *options.saveImage;
    player.emplace(std::move(*script), show, **renderer, std::move(playerOptions));
    player->setReporter(printScriptDiagnostic);
    frameLoop.addParticipant(*player);
  }

  // Movies: GStreamer starts only when a show has some (start-up stays fast without).
  std::unique_ptr<VideoStreams> videos;
  if (!options.movies.empty()) {
    std::vector<MovieStreamSpec> specs;
    for (const auto& [name, file] : options.movies) {
      auto same = std::find_if(specs.begin(), specs.end(), [&](const MovieStreamSpec& s) { return s.name == name; });
      if (same == specs.end()) {
        specs.push_back({name, {file}, !options.movieOnce, options.audio, std::nullopt});
      } else {
        same->files.push_back(file);  // the same part again: a playlist
      }
    }
    for (const auto& [name, zoom] : options.zooms) {
      for (MovieStreamSpec& s : specs) {
        if (s.name == name) s.zoom = zoom;
      }
    }
    auto v = VideoStreams::create(specs, show, **renderer, manual);
    if (!v) return failWith(v.error(), "cannot start the movies");
    videos = std::move(*v);
    frameLoop.addParticipant(*videos);
  }
  // Recording comes after the movies so that it sees the Zoom pictures.
  std::unique_ptr<ScreenRecorder> recorder;
  if (options.record) {
    media::RecorderOptions ro;
    ro.path = *options.record;
    ro.width = options.width;
    ro.height = options.height;
    ro.fps = options.fps;
    ro.codec = *media::parseVideoCodec(options.recordCodec);
    ro.maxFrames = options.recordFrames.value_or(-1);
    ro.waitForEncoder = manual;  // offline runs keep every frame; live shows drop rather than wait
    auto r = ScreenRecorder::create(ro);
    if (!r) return failWith(r.error(), "cannot record");
    recorder = std::move(*r);
    frameLoop.addParticipant(*recorder);
  }
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

  if (options.saveModel) {
    const script::ObjectSource object = player ? player->interpreter().objectSource() : script::ObjectSource{};
    if (auto r = writeSavedModel(*options.saveModel, script::saveModel(show, object)); !r) {
      return failWith(r.error(), "cannot save the model");
    }
  }

  const double fps = stats->wallSeconds > 0 ? static_cast<double>(stats->frames) / stats->wallSeconds : 0;
  const std::string what = options.show ? options.show->string() : std::string("the default show");
  fmt::print("basalt: played {}: {} frames in {:.2f} s ({:.1f} frames per second, {} clock)\n", what, stats->frames,
             stats->wallSeconds, fps, manual ? "manual" : "system");
  fmt::print("basalt: output: {}\n", (*output)->describe());
  fmt::print("basalt: first frame after {:.1f} ms\n", stats->firstFrameSeconds * 1000);
  if (player) printScriptSummary(*player);
  if (snapshotWritten) fmt::print("basalt: snapshot written to {}\n", snapshotPath.string());
  if (options.saveModel) fmt::print("basalt: model saved to {}\n", options.saveModel->string());
  if (videos) {
    for (const std::string& line : videos->status()) fmt::print("basalt: {}\n", line);
  }
  int status = 0;
  if (recorder) {
    if (auto r = recorder->finish(); !r) {
      std::fflush(stdout);
      status = failWith(r.error(), "the recording failed (the show itself ran)");
    } else {
      fmt::print("basalt: recorded {} frames to {} ({})\n", recorder->frames(), recorder->options().path.string(),
                 recorder->describe());
    }
  }
  if (devices) {
    for (const devices::DeviceStatus& s : deviceStatus) {
      fmt::print("basalt: replayed {} '{}' ({})\n", devices::deviceKindName(s.kind), s.name,
                 s.lastError.empty() ? std::string(devices::deviceStateName(s.state)) : s.lastError);
    }
  }
  std::fflush(stdout);
  return status;
}

}  // namespace basalt::kiosk
