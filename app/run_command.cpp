#include "app/run_command.h"

#include <arpa/inet.h>
#include <ifaddrs.h>
#include <net/if.h>
#include <netinet/in.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <system_error>
#include <thread>

#include <fmt/format.h>
#include <fmt/std.h>

#include "app/commands.h"
#include "app/options.h"
#include "app/replay_report.h"
#include "app/show_factories.h"
#include "app/suggest.h"
#include "devices/evdev/evdev_input.h"
#include "kiosk/lock/frame_lock.h"
#include "kiosk/loop/display_views.h"
#include "kiosk/loop/frame_loop.h"
#include "kiosk/manifest/manifest.h"
#include "kiosk/osc/osc_input.h"
#include "kiosk/osc/osc_output.h"
#include "kiosk/policy/last_good.h"
#include "kiosk/policy/state_store.h"
#include "kiosk/policy/supervisor.h"
#include "kiosk/show/device_wiring.h"
#include "kiosk/show/osc_trackers.h"
#include "kiosk/show/script_player.h"
#include "kiosk/show/show_director.h"
#include "kiosk/show/show_loader.h"
#include "kiosk/show/stream_factories.h"
#include "kiosk/show/trace_video_glue.h"
#include "kiosk/status/frame_metrics.h"
#include "kiosk/status/status_board.h"
#include "kiosk/status/status_server.h"
#include "media/image_io.h"
#include "media/net_clock.h"
#include "render/output.h"
#include "render/renderer.h"
#include "runtime/event_loop.h"
#include "runtime/image.h"
#include "runtime/log.h"
#include "runtime/script/interpreter.h"
#include "runtime/script/save_model.h"
#include "runtime/show/show.h"

namespace basalt::kiosk {

BASALT_LOG_CATEGORY(Run, "kiosk");

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

/// A show folder's manifest: DIR/show.toml, or an error that says what the folder holds instead.
Result<std::filesystem::path> showFolderManifest(const std::filesystem::path& folder) {
  std::filesystem::path manifest = folder / "show.toml";
  std::error_code ec;
  if (std::filesystem::is_regular_file(manifest, ec)) return manifest;
  // What could be meant instead: the folder's manifests and scripts (the first few).
  constexpr std::size_t kListed = 6;
  std::vector<std::string> shows;
  std::size_t seen = 0;
  for (std::filesystem::directory_iterator it(folder, ec), end; !ec && it != end && seen < 1000; it.increment(ec)) {
    ++seen;
    const std::string ext = it->path().extension().string();
    if (ext == ".toml" || ext == ".mdl") shows.push_back(it->path().filename().string());
  }
  std::sort(shows.begin(), shows.end());
  std::string hint = "give a show manifest (show.toml) or a LAVA script (.mdl)";
  if (!shows.empty()) {
    std::string names;
    for (std::size_t i = 0; i < std::min(shows.size(), kListed); ++i)
      names += fmt::format("{}{}", i ? ", " : "", shows[i]);
    if (shows.size() > kListed) names += fmt::format(" and {} more", shows.size() - kListed);
    hint = fmt::format("it holds {}: give one of them", names);
  }
  return fail(Errc::kInvalidArgument,
              fmt::format("the folder {} has no show.toml (basalt run plays a show folder's show.toml); {}",
                          folder.string(), hint));
}

}  // namespace

std::string_view runUsage() {
  return R"(Usage: basalt run [options] [show.toml | SHOW_FOLDER | SCRIPT.mdl]
       basalt run [options] [DISPLAY.cave] [SCENE.sce | MODEL.obj]

Plays a show. With a show manifest (show.toml, see configs/shows/), or a show folder that
holds one (SHOW_FOLDER/show.toml), it plays that show: its outputs, entry, devices and
bindings, textures, kiosk policy (opening hours, attract loop, playlist) and status server.
With none it plays the default show: LAVA's start-up scene, a coloured cube on black, 500x500,
turning slowly under LAVA's default lights.
The output is the manifest's, or detected: KMS when Basalt can be DRM master (no desktop
running), a window when a display server is there, offscreen (headless) otherwise; the
headless output writes a snapshot of the last frame.
Without --frames or --seconds it runs until interrupted (Ctrl-C, SIGTERM) and exits cleanly.
SIGHUP re-reads the manifest; the show plays on until the new one is ready.

The thesis' command line (`3Deng [.cave] [.sce] [.obj]`) plays a scene or a model without a
manifest: a scene is drawn from its own camera in its own units, a model as LAVA shows it;
with a display file (.cave) the output shows the facet it names, seen through the display
that the scene's camera places in the world (Appendix B's set-up keys adjust it).

SHOW may be a LAVA script (.mdl), run as `lava -file SHOW.mdl` ran it: each `draw` is one
frame, `quit` ends the run, and a bad line is reported and skipped while the show goes on.
A script that quits runs as fast as possible on the manual clock unless --realtime is given.
'basalt help script' lists the language; 'basalt check SHOW.mdl' finds errors without running.

Options:
  --frames N         stop after N frames
  --seconds S        stop after S seconds of show time
  --size WxH         output size in pixels (default: the manifest's, or 500x500)
  --output KIND      auto, headless, kms or window (default: the manifest's, or auto)
  --headless         render offscreen even when a display is available (--output headless)
  --snapshot PATH    write the last frame to PATH (format from the extension: .png, .jpg,
                     .tif, .exr, ...); default: OUTPUT_DIR/snapshot.png
  --output-dir DIR   folder for snapshots (default: out)
  --fps F            show frame rate (default: the manifest's, or 60)
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
  --zoom-dials X,Y   dials X and Y move the Zoom pictures across and down (LAVA's Shift +
                     drag), a full turn the output's width or height; with --replay
  --audio            play the movies' sound on the default output
  --record PATH      record the rendered output to PATH (.mp4, .mkv, .mov, .avi, .webm)
  --record-codec C   h264, mjpeg, vp8, vp9 or auto (H.264; MJPEG for .avi; VP9 for .webm)
  --record-frames N  stop recording after N frames (LAVA's Rec slider); default: the run
  --replay PATH      play the devices recorded in a trace folder (basalt record) or an
                     hid-recorder file as if they were plugged in; dials drive LAVA's dial table
  --replay-once      play the recording once instead of looping
  --camera SPEC      the camera a script's `tv.camera = on` shows (LAVA's Camera):
                     v4l2:/dev/videoN, v4l2:NAME, libcamera[:ID], synthetic (colour bars) or
                     replay:NAME.trace (a camera recorded with basalt record); it
                     comes before the manifest's cameras
  --clock-start T    with --fast: the calendar time the show starts at, for trying opening
                     hours (2026-12-24T09:59:00Z)
  --status ADDR:PORT serve status and controls there (default: the manifest's [status];
                     port 0 picks a free one)
  --state-dir DIR    where the show's resume point and saved calibrations are kept
                     (default: $STATE_DIRECTORY, else ~/.local/state/basalt; calibrations
                     are saved to the show's cave files without either)
  --no-resume        start from the beginning, not where the show was before it stopped
  --strict           a show whose manifest or entry has errors does not start: exit 1 (for
                     CI); without it such a show never goes dark (below)
  -h, --help         this text

Never dark: every show that starts cleanly is kept as its last good copy in the state folder
(STATE_DIR/last-good/). When the manifest or its entry has errors, Basalt logs them (file:line)
and plays the last good copy instead; with none it shows the problem card (an amber screen)
while the status page says what is wrong, where, and the node's address. Either way the status
server runs and /health says "degraded" with the errors; fix the show and reload (SIGHUP or
POST /control/reload). A reload that fails keeps the show playing and is "degraded" too.

Exit status: 0 when the show ran, 1 when it could not start or failed (with --strict also when
the show has errors), 2 for usage errors.
)";
}

namespace {

Result<WallTime> parseClockStart(std::string_view text) {
  // 2026-12-24T09:59:00Z (UTC).
  const auto bad = [&] {
    return fail(Errc::kInvalidArgument,
                fmt::format("--clock-start needs a UTC time like 2026-12-24T09:59:00Z, not '{}'", text));
  };
  if (text.size() != 20 || text[10] != 'T' || text[19] != 'Z') return bad();
  auto date = parseDate(text.substr(0, 10));
  auto h = integerOption("--clock-start", text.substr(11, 2), 0, 23);
  auto m = integerOption("--clock-start", text.substr(14, 2), 0, 59);
  auto sec = integerOption("--clock-start", text.substr(17, 2), 0, 59);
  if (!date || !h || !m || !sec || text[13] != ':' || text[16] != ':') return bad();
  const std::int64_t days = daysFromCivil(date->year, date->month, date->day);
  return WallTime{std::chrono::seconds(days * 86400 + *h * 3600 + *m * 60 + *sec)};
}

}  // namespace

Result<RunOptions> parseRunOptions(std::span<const std::string_view> args) {
  auto parsed = parseOptions("run", args,
                             {{"--help|-h"},
                              {"--frames", true},
                              {"--seconds", true},
                              {"--size", true},
                              {"--output", true},
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
                              {"--zoom-dials", true},
                              {"--audio"},
                              {"--record", true},
                              {"--record-codec", true},
                              {"--record-frames", true},
                              {"--replay", true},
                              {"--replay-once"},
                              {"--camera", true},
                              {"--clock-start", true},
                              {"--status", true},
                              {"--state-dir", true},
                              {"--no-resume"},
                              {"--strict"}});
  if (!parsed) return std::unexpected(parsed.error());
  RunOptions run;
  for (const ParsedOption& o : *parsed) {
    if (o.name.empty()) {
      const std::string ext = std::filesystem::path(o.value).extension().string();
      if (ext == ".cave" || ext == ".sce" || ext == ".obj" || ext == ".off") {
        // The thesis' command line: [display.cave] [scene.sce | model.obj].
        std::optional<std::filesystem::path>& slot = ext == ".cave" ? run.cave : run.scene;
        if (slot || run.manifest || run.show) {
          return fail(Errc::kInvalidArgument,
                      fmt::format("'basalt run' plays one display file (.cave) with one scene (.sce) or model "
                                  "(.obj, .off); '{}' comes after '{}'",
                                  o.value,
                                  (slot           ? *slot
                                   : run.manifest ? *run.manifest
                                                  : *run.show)
                                      .string()));
        }
        slot = std::filesystem::path(o.value);
        continue;
      }
      if (run.manifest || run.show || run.cave || run.scene) {
        return fail(Errc::kInvalidArgument, fmt::format("'basalt run' plays one show; '{}' comes after '{}'", o.value,
                                                        (run.manifest ? *run.manifest
                                                         : run.show   ? *run.show
                                                         : run.cave   ? *run.cave
                                                                      : *run.scene)
                                                            .string()));
      }
      if (o.value.empty()) return fail(Errc::kInvalidArgument, "the show's file name is empty");
      if (std::error_code ec; std::filesystem::is_directory(o.value, ec)) {
        auto manifest = showFolderManifest(o.value);
        if (!manifest) return std::unexpected(manifest.error());
        run.manifest = std::move(*manifest);
      } else if (o.value.ends_with(".toml")) {
        run.manifest = std::filesystem::path(o.value);
      } else {
        run.show = std::filesystem::path(o.value);  // a LAVA script; runShow says if it is not one
      }
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
      run.sizeGiven = true;
    } else if (o.name == "--output") {
      static constexpr std::pair<std::string_view, render::OutputKind> kKinds[] = {
          {"auto", render::OutputKind::kAuto},
          {"headless", render::OutputKind::kHeadless},
          {"kms", render::OutputKind::kKms},
          {"window", render::OutputKind::kWindow}};
      const auto* it =
          std::find_if(std::begin(kKinds), std::end(kKinds), [&](const auto& k) { return k.first == o.value; });
      if (it == std::end(kKinds)) {
        return fail(Errc::kInvalidArgument,
                    fmt::format("--output must be auto, headless, kms or window, not '{}'", o.value));
      }
      run.output = it->second;
      run.headless = it->second == render::OutputKind::kHeadless;
    } else if (o.name == "--headless") {
      run.headless = true;
      run.output = render::OutputKind::kHeadless;
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
      run.fpsGiven = true;
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
    } else if (o.name == "--zoom-dials") {
      int x = -1;
      int y = -1;
      const auto comma = o.value.find(',');
      const auto number = [](std::string_view t, int& out) {
        const auto r = std::from_chars(t.data(), t.data() + t.size(), out);
        return r.ec == std::errc{} && r.ptr == t.data() + t.size() && out >= 0 &&
               out < static_cast<int>(runtime::kMaxBoundDials);
      };
      if (comma == std::string_view::npos || !number(o.value.substr(0, comma), x) ||
          !number(o.value.substr(comma + 1), y) || x == y) {
        return fail(Errc::kInvalidArgument,
                    fmt::format("--zoom-dials needs two different dial numbers from 0 to {}, like 6,7 (got '{}')",
                                runtime::kMaxBoundDials - 1, o.value));
      }
      run.zoomDials = std::pair{x, y};
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
    } else if (o.name == "--camera") {
      if (o.value.empty()) {
        return fail(Errc::kInvalidArgument,
                    "--camera needs v4l2:/dev/videoN, libcamera[:ID], synthetic or replay:NAME.trace");
      }
      run.camera = std::string(o.value);
    } else if (o.name == "--clock-start") {
      auto t = parseClockStart(o.value);
      if (!t) return std::unexpected(t.error());
      run.clockStart = *t;
    } else if (o.name == "--status") {
      if (o.value.empty()) return fail(Errc::kInvalidArgument, "--status needs ADDRESS:PORT, e.g. 127.0.0.1:8180");
      run.statusListen = std::string(o.value);
    } else if (o.name == "--state-dir") {
      if (o.value.empty()) return fail(Errc::kInvalidArgument, "--state-dir needs a folder");
      run.stateDir = std::filesystem::path(o.value);
    } else if (o.name == "--no-resume") {
      run.resume = false;
    } else if (o.name == "--strict") {
      run.strict = true;
    }
  }
  for (const auto& [name, zoom] : run.zooms) {
    const bool known =
        std::any_of(run.movies.begin(), run.movies.end(), [&](const auto& m) { return m.first == name; });
    if (!known) {
      std::vector<std::string_view> movies;
      movies.reserve(run.movies.size());
      for (const auto& m : run.movies) movies.emplace_back(m.first);
      return fail(Errc::kInvalidArgument,
                  fmt::format("--zoom {}: no movie of that name{}", name,
                              didYouMean(name, movies, fmt::format("; give --movie {}=FILE too", name))));
    }
  }
  if (run.zoomDials && run.zooms.empty()) {
    return fail(Errc::kInvalidArgument, "--zoom-dials moves the Zoom picture: give --zoom PART too");
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

namespace {

std::string_view kindName(render::OutputKind kind) {
  switch (kind) {
    case render::OutputKind::kAuto: return "auto";
    case render::OutputKind::kHeadless: return "headless";
    case render::OutputKind::kKms: return "kms";
    case render::OutputKind::kWindow: return "window";
  }
  return "?";
}

render::OutputKind toRenderKind(OutputKind kind) {
  switch (kind) {
    case OutputKind::kAuto: return render::OutputKind::kAuto;
    case OutputKind::kHeadless: return render::OutputKind::kHeadless;
    case OutputKind::kKms: return render::OutputKind::kKms;
    case OutputKind::kWindow: return render::OutputKind::kWindow;
  }
  return render::OutputKind::kAuto;
}

/// Reads and validates the manifest (the files it names must exist inside the show folder; their
/// contents are read as the show loads them, and `basalt check` parses them all beforehand);
/// prints its errors and warnings. The errors are added to `errors` ("file:line: message").
std::optional<Manifest> readShowManifest(const std::filesystem::path& file, bool strict,
                                         std::vector<std::string>& errors) {
  Diagnostics diagnostics;
  auto manifest = readManifest(file, diagnostics);
  for (const Diagnostic& d : diagnostics.items()) {
    if (d.severity != Severity::kNote) fmt::print(stderr, "{}\n", d.format());
    if (d.severity == Severity::kError) errors.push_back(d.format());
  }
  if (!manifest) {
    fmt::print(stderr, "basalt: error: {}{} has {} problem{} (above); 'basalt check {}' lists them without starting\n",
               strict ? "cannot start: " : "", file.string(), diagnostics.errorCount(),
               diagnostics.errorCount() == 1 ? "" : "s", file.string());
  }
  return manifest;
}

/// The show the thesis' command line asks for (Appendix B, `3Deng [.cave] [.sce] [.obj]`): the
/// scene or model as the entry, drawn as its kind is by default (a scene from its own camera),
/// and with a display file one facet view filling the output, on the facet the file names.
Result<Manifest> thesisManifest(const RunOptions& options) {
  Manifest m = Manifest::builtinDefault();
  std::error_code ec;
  if (options.scene) {
    const std::filesystem::path scene = std::filesystem::absolute(*options.scene, ec).lexically_normal();
    if (ec || !std::filesystem::is_regular_file(scene, ec)) {
      return fail(Errc::kNotFound, fmt::format("{}: no such file", options.scene->string()));
    }
    m.folder = scene.parent_path();
    m.name = scene.filename().string();
    const bool isScene = scene.extension() == ".sce";
    m.entry = {isScene ? EntryKind::kScene : EntryKind::kModel, options.scene->string(), scene, 0, EntryView::kDefault};
  }
  if (options.cave) {
    const std::filesystem::path cave = std::filesystem::absolute(*options.cave, ec).lexically_normal();
    if (ec || !std::filesystem::is_regular_file(cave, ec)) {
      return fail(Errc::kNotFound, fmt::format("{}: no such file", options.cave->string()));
    }
    if (m.folder.empty()) m.folder = cave.parent_path();
    ViewSpec view;
    view.name = cave.stem().string();
    view.kind = ViewKind::kFacet;
    view.cave = cave;
    m.views.push_back(std::move(view));
  }
  return m;
}

/// This node's addresses beside its name ("kiosk-3 (192.168.1.20, fe80::1)"), for the problem
/// card: what a technician types to reach its status page.
std::string nodeAddress() {
  std::array<char, 256> name{};
  std::string out = ::gethostname(name.data(), name.size() - 1) == 0 ? std::string(name.data()) : "this node";
  std::vector<std::string> addresses;
  ifaddrs* list = nullptr;
  if (::getifaddrs(&list) == 0) {
    for (const ifaddrs* a = list; a; a = a->ifa_next) {
      if (!a->ifa_addr || (a->ifa_flags & IFF_LOOPBACK) || !(a->ifa_flags & IFF_UP)) continue;
      std::array<char, INET6_ADDRSTRLEN> text{};
      const int family = a->ifa_addr->sa_family;
      const void* raw = nullptr;
      if (family == AF_INET) raw = &reinterpret_cast<const sockaddr_in*>(a->ifa_addr)->sin_addr;
      if (family == AF_INET6) raw = &reinterpret_cast<const sockaddr_in6*>(a->ifa_addr)->sin6_addr;
      if (raw && ::inet_ntop(family, raw, text.data(), text.size())) addresses.emplace_back(text.data());
    }
    ::freeifaddrs(list);
  }
  return addresses.empty() ? out + " (no network address)" : fmt::format("{} ({})", out, fmt::join(addresses, ", "));
}

/// What plays when the show has errors (and --strict is not given): its last good copy, or the
/// problem card. `problems` says what is wrong, for the log and /health.
struct Fallback {
  Manifest manifest;
  std::vector<std::string> problems;
  bool card = false;
};

Fallback fallBack(const RunOptions& options, std::vector<std::string> errors, bool tryCopy = true) {
  const std::filesystem::path original = std::filesystem::absolute(*options.manifest);
  const std::filesystem::path stateFolder = options.stateDir ? *options.stateDir : defaultStateFolder();
  Fallback f;
  for (const std::string& e : errors) log::error(kLogRun, "{}", e);
  if (auto copy = tryCopy ? findLastGood(stateFolder, original) : std::nullopt) {
    Diagnostics diagnostics;
    if (auto read = readManifest(copy->manifest, diagnostics)) {
      f.manifest = std::move(*read);
      // Reloads re-read the show's own manifest (fixed by then), and it resumes as itself.
      f.manifest.file = original;
      f.manifest.status.enabled = true;  // the status page says what is wrong
      f.problems = std::move(errors);
      f.problems.push_back(fmt::format("{} has errors: the last good copy from {} plays ({})", original.string(),
                                       copy->savedAt, copy->manifest.parent_path().string()));
      log::error(kLogRun, "{} has errors; the last good copy from {} plays instead; fix the show and reload",
                 original.string(), copy->savedAt);
      return f;
    }
    log::error(kLogRun, "the last good copy {} cannot be read either", copy->manifest.string());
  }
  f.card = true;
  f.manifest = Manifest::builtinDefault();
  f.manifest.name = "problem card";
  f.manifest.entry = {EntryKind::kBuiltinBlack, "black", {}, 0, EntryView::kDefault};
  f.manifest.file = original;  // a reload re-reads the show
  f.manifest.kiosk.resume = false;
  f.manifest.status.enabled = true;  // the technician's way in: the default 127.0.0.1:8180 unless --status
  f.problems = std::move(errors);
  f.problems.push_back(fmt::format("{} has errors and there is no last good copy: the problem card shows; node {}",
                                   original.string(), nodeAddress()));
  log::error(kLogRun, "{}", f.problems.back());
  return f;
}

/// The problem card: an amber screen while the show that should play has errors and no last good
/// copy (Basalt draws no text; the status page and /health say what is wrong). It goes once a
/// reload brings the fixed show.
class ProblemCard final : public FrameParticipant {
 public:
  ProblemCard(runtime::Show& show, const ShowDirector& director) : show_(show), director_(director) {}
  Result<void> beforeDraw(const FrameContext& /*frame*/) override {
    if (director_.reloadsApplied() == 0) show_.global().background = kAmber;
    return {};
  }
  static constexpr runtime::Color3 kAmber{1.0f, 0.6f, 0.0f};

 private:
  runtime::Show& show_;
  const ShowDirector& director_;
};

/// "127.0.0.1:8180" or "[::1]:0" into the status spec.
Result<void> applyStatusListen(std::string_view listen, StatusSpec& spec) {
  std::string_view host;
  std::string_view port;
  if (listen.starts_with('[')) {
    const auto close = listen.find("]:");
    if (close == std::string_view::npos) return fail(Errc::kInvalidArgument, "--status needs [ADDRESS]:PORT");
    host = listen.substr(1, close - 1);
    port = listen.substr(close + 2);
  } else {
    const auto colon = listen.rfind(':');
    if (colon == std::string_view::npos) return fail(Errc::kInvalidArgument, "--status needs ADDRESS:PORT");
    host = listen.substr(0, colon);
    port = listen.substr(colon + 1);
  }
  auto p = integerOption("--status", port, 0, 65535);
  if (!p) return std::unexpected(p.error());
  spec.enabled = true;
  spec.host = std::string(host);
  spec.port = static_cast<std::uint16_t>(*p);
  if (!spec.loopbackOnly() && spec.token.empty() && spec.tokenFile.empty()) {
    return fail(Errc::kInvalidArgument, fmt::format("--status {} opens the server beyond this machine; that needs a "
                                                    "token (status.token_file in show.toml)",
                                                    listen));
  }
  return {};
}

/// The lock's view of the network clock: its offset from this node's own clock.
class NetClockProbe final : public LockClockProbe {
 public:
  explicit NetClockProbe(const media::NetClock& clock) : clock_(clock) {}
  [[nodiscard]] Nanos offset() const override { return clock_.offset(); }

 private:
  const media::NetClock& clock_;
};

std::string hostName() {
  std::array<char, 256> name{};
  if (::gethostname(name.data(), name.size() - 1) != 0) return "node";
  std::string n(name.data());
  if (n.size() > 32) n.resize(32);
  return n;
}

/// The camera of `--camera SPEC` as a manifest device: the syntax of `basalt record --camera`
/// (v4l2:/dev/videoN, v4l2:NAME, libcamera[:ID], synthetic) and replay:NAME.trace.
Result<DeviceSpec> cameraOption(std::string_view text) {
  auto request = parseDeviceSpec(text, devices::DeviceKind::kVideoSource, "camera");
  if (!request) return std::unexpected(request.error());
  DeviceSpec d;
  d.kind = DeviceKind::kCamera;
  const std::string& backend = request->match.backend;
  if (backend == "v4l2") {
    d.backend = DeviceBackend::kV4l2;
  } else if (backend == "libcamera") {
    d.backend = DeviceBackend::kLibcamera;
  } else if (backend == "synthetic") {
    d.backend = DeviceBackend::kSynthetic;
  } else if (backend == "replay") {
    d.backend = DeviceBackend::kReplay;
    d.trace = request->match.path.empty() ? request->match.name : request->match.path;
    std::error_code ec;
    if (d.trace.empty() || !std::filesystem::is_regular_file(d.trace / "trace.toml", ec)) {
      return fail(Errc::kNotFound,
                  "no trace folder there: give replay:NAME.trace, a folder recorded with 'basalt "
                  "record'",
                  d.trace.string());
    }
  } else {
    return fail(
        Errc::kInvalidArgument,
        fmt::format("--camera {}: a camera is v4l2:/dev/videoN, libcamera[:ID], synthetic or replay:NAME.trace", text));
  }
  d.match.vendor = request->match.vendor;
  d.match.product = request->match.product;
  d.match.name = request->match.name;
  d.match.path = request->match.path;
  return d;
}

}  // namespace

int runShow(const RunOptions& options) {
  Manifest manifest = Manifest::builtinDefault();
  std::optional<Fallback> fallback;  // the show has errors: its last good copy or the card plays
  if (options.manifest) {
    std::vector<std::string> errors;
    auto read = readShowManifest(*options.manifest, options.strict, errors);
    if (read) {
      manifest = std::move(*read);
    } else if (options.strict) {
      return 1;
    } else {
      fallback = fallBack(options, std::move(errors));
      manifest = fallback->manifest;
    }
  }
  if (options.cave || options.scene) {
    auto thesis = thesisManifest(options);
    if (!thesis) return failWith(thesis.error(), "cannot start");
    manifest = std::move(*thesis);
  }
  if (stderrIsJournal()) logToJournal(manifest.name);
  if (options.camera) {
    // The command line's camera goes first, so that a script's tv.camera = on shows it.
    auto camera = cameraOption(*options.camera);
    if (!camera) return failWith(camera.error(), "cannot start");
    camera->name = "camera";
    for (const DeviceSpec& d : manifest.devices) {
      if (d.name == camera->name) camera->name = "command-line camera";
    }
    manifest.devices.insert(manifest.devices.begin(), std::move(*camera));
  }

  const std::filesystem::path snapshotPath = options.snapshot ? *options.snapshot : options.outputDir / "snapshot.png";
  if (options.show && !isScriptFile(*options.show)) {
    return usageError(
        fmt::format("basalt run plays show manifests and LAVA scripts (.mdl); '{}' is neither: give a show manifest "
                    "(show.toml) or a script",
                    options.show->string()));
  }
  if (auto r = checkWritableFolder(snapshotPath); !r) return failWith(r.error(), "cannot start");
  if (options.statusListen) {
    if (auto r = applyStatusListen(*options.statusListen, manifest.status); !r)
      return failWith(r.error(), "cannot start");
  }

  std::optional<script::Interpreter> script;
  if (options.show) {
    auto loaded = loadScript(*options.show);
    if (!loaded) return failWith(loaded.error(), "cannot start");
    script.emplace(std::move(*loaded));
  }

  const double fps = options.fpsGiven || !options.manifest ? options.fps : manifest.fps;
  std::int64_t maxFrames = -1;
  if (options.frames) maxFrames = *options.frames;
  if (options.seconds) {
    const auto fromSeconds = static_cast<std::int64_t>(std::ceil(*options.seconds * fps));
    maxFrames = maxFrames < 0 ? fromSeconds : std::min(maxFrames, fromSeconds);
  }
  // A script that quits is a batch job (LAVA's test scripts): it runs as fast as it can.
  const bool batch = maxFrames >= 0 || (script && scriptQuits(script->program()));
  const bool manual = options.clock == ClockMode::kManual || (options.clock == ClockMode::kAuto && batch);
  SystemClock systemClock;
  ManualClock manualClock(Nanos{0}, options.clockStart ? *options.clockStart : systemClock.wallNow());
  // Frame-locked nodes share the leader's clock (GStreamer's network clock): the leader serves
  // its monotonic clock, a follower paced in real time reads it as its show clock.
  const LockSpec& lockSpec = manifest.lock;
  std::unique_ptr<media::NetClockServer> clockServer;
  std::unique_ptr<media::NetClock> netClock;
  if (lockSpec.role != LockRole::kOff && lockSpec.clock) {
    // The shared clock's GStreamer threads start here, before the event loop watches the stop
    // signals: block those now so that the threads inherit the mask. Otherwise a SIGTERM could
    // land on a clock thread, whose default action ends the process without its summary.
    sigset_t stopSignals;
    sigemptyset(&stopSignals);
    for (const int s : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&stopSignals, s);
    (void)pthread_sigmask(SIG_BLOCK, &stopSignals, nullptr);
  }
  if (lockSpec.role == LockRole::kLeader && lockSpec.clock) {
    auto served = media::NetClockServer::start(lockSpec.listen, lockSpec.port + 2);
    if (!served) return failWith(served.error(), "cannot share the clock");
    clockServer = std::move(*served);
  } else if (lockSpec.role == LockRole::kFollower && lockSpec.clock) {
    auto followed = media::NetClock::connect(lockSpec.leader, lockSpec.port + 2);
    if (!followed) return failWith(followed.error(), "cannot follow the leader's clock");
    netClock = std::move(*followed);
    if (!netClock->waitForSync(std::chrono::seconds(2))) {
      log::warn(kLogRun, "the leader's clock at {}:{} did not answer within 2 s; following it when it does",
                lockSpec.leader, lockSpec.port + 2);
    }
  }
  const Clock& clock = manual     ? static_cast<const Clock&>(manualClock)
                       : netClock ? static_cast<const Clock&>(*netClock)
                                  : static_cast<const Clock&>(systemClock);

  auto loop = runtime::EventLoop::create(clock);
  if (!loop) return failWith(loop.error(), "cannot start the event loop");
  // Signals are blocked before any thread starts (the state writer, the status server, the
  // renderer's), so that every thread inherits the mask and only the loop receives them.
  FrameLoop* stopTarget = nullptr;
  ShowDirector* reloadTarget = nullptr;
  bool stopBeforeLoop = false;
  auto signals = (*loop)->watchSignals({SIGINT, SIGTERM, SIGHUP}, [&](int signal) {
    if (signal == SIGHUP) {
      if (reloadTarget) reloadTarget->requestReload();
    } else if (stopTarget) {
      stopTarget->requestStop();
    } else {
      stopBeforeLoop = true;
    }
  });
  if (!signals) return failWith(signals.error(), "cannot watch for signals");

  render::OutputRequest request;
  request.kind = options.output ? *options.output : toRenderKind(manifest.output.kind);
  request.size = {options.width, options.height};
  if (!options.sizeGiven && manifest.output.width > 0) request.size = {manifest.output.width, manifest.output.height};
  request.drmDevice = manifest.output.device;
  request.connector = manifest.output.connector;
  if (manifest.output.mode) {
    request.mode =
        render::ModeWish{manifest.output.mode->width, manifest.output.mode->height, manifest.output.mode->refresh};
  }
  request.fullscreen = manifest.output.fullscreen;
  request.title = "Basalt: " + manifest.name;
  std::string passedOver;
  auto output = render::openOutput(request, &passedOver);
  if (!output) {
    return failWith(output.error(), fmt::format("cannot open the {} output", request.kind == render::OutputKind::kAuto
                                                                                 ? std::string_view("headless")
                                                                                 : kindName(request.kind)));
  }
  if (!passedOver.empty()) {
    std::string_view lines = passedOver;
    while (!lines.empty()) {
      const auto nl = lines.find('\n');
      log::info(kLogRun, "output passed over: {}", lines.substr(0, nl));
      lines = nl == std::string_view::npos ? std::string_view{} : lines.substr(nl + 1);
    }
  }
  auto renderer = render::Renderer::create();
  if (!renderer) return failWith(renderer.error(), "cannot set up the renderer");

  StatusBoard board(systemClock.wallNow(), fps);
  runtime::EventLoop* eventLoop = loop->get();
  board.setWake([eventLoop] { eventLoop->wake(); });
  BoundedQueue<Event> events(1024, [eventLoop] { eventLoop->wake(); });
  auto supervisor = Supervisor::fromEnvironment();

  std::unique_ptr<StateStore> state;
  std::optional<ResumePoint> resume;
  if (options.manifest && manifest.kiosk.resume && options.resume) {
    const std::filesystem::path folder = options.stateDir ? *options.stateDir : defaultStateFolder();
    board.watchFolder("state", folder);  // the status page shows its free space
    auto store = StateStore::open(folder, manifest.file.string());
    if (store) {
      state = std::move(*store);
      resume = state->load();
    } else {
      log::warn(kLogRun, "{}; the show will not resume after a restart", store.error().message());
    }
  }

  // Texture images are read in the background: the first frame does not wait for them.
  ShowFactories factories = showFactories();
  // Trackers fed by OSC (/tracker/NAME): one set of feeds for the run, both the OSC input's
  // tracker sink and the provider the DeviceManager opens those trackers from.
  std::shared_ptr<OscTrackerFeeds> oscTrackers;
  if (const std::vector<std::string> names = OscTrackerFeeds::namesIn(manifest); !names.empty()) {
    oscTrackers = std::make_shared<OscTrackerFeeds>(names, clock);
    factories.devices = [inner = factories.devices, oscTrackers](const DeviceSpec& spec) -> Result<DeviceSource> {
      if (spec.backend == DeviceBackend::kOsc) return oscTrackers->sourceFor(spec);
      return inner(spec);
    };
  }
  auto loaded = loadShow(manifest, clock, factories, false);
  if (!loaded && options.manifest && !options.strict && !(fallback && fallback->card)) {
    // The entry has errors (a script that does not parse): the last good copy plays, or the card.
    const std::string error = loaded.error().describe();
    fmt::print(stderr, "basalt: error: cannot load the show: {}\n", error);
    const StatusSpec status = manifest.status;  // the manifest itself was good: its [status] holds
    const OscSpec osc = manifest.osc;           // and so do its OSC bindings and destinations
    fallback = fallBack(options, {error});
    manifest = fallback->manifest;
    loaded = loadShow(manifest, clock, factories, false);
    if (!loaded) {
      fallback =
          fallBack(options, {error, "its last good copy cannot load either: " + loaded.error().describe()}, false);
      manifest = fallback->manifest;
      loaded = loadShow(manifest, clock, factories, false);
    }
    manifest.status = status;
    manifest.status.enabled = true;
    manifest.osc = osc;
  }
  if (!loaded) return failWith(loaded.error(), "cannot load the show");
  if (fallback) board.setProblems(fallback->problems);

  runtime::Show show;
  FrameLoop frameLoop({fps, maxFrames}, clock, manual ? &manualClock : nullptr, **loop, show, **output, **renderer);
  board.setFrameWatch(frameLoop.watch());  // /health says when the loop is stuck
  ShowDirector director(
      DirectorContext{clock, **loop, show, **renderer, **output, board, events, supervisor.get(), state.get(), fps},
      std::move(factories));
  director.install(std::move(*loaded), clock.now(), resume);
  // The show started cleanly: keep it as the last good copy, in the background (the first
  // frame does not wait for the copy).
  std::jthread keeper;
  if (options.manifest && !fallback) {
    keeper = std::jthread([stateFolder = options.stateDir ? *options.stateDir : defaultStateFolder(),
                           file = manifest.file, folder = manifest.folder] {
      auto kept = keepLastGood(stateFolder, file, folder);
      if (!kept) {
        log::warn(kLogRun, "cannot keep the last good copy of the show: {}", kept.error().describe());
      } else if (*kept == KeptCopy::kWritten) {
        log::info(kLogRun, "kept the show as its last good copy in {}", lastGoodFolder(stateFolder, file).string());
      }
    });
  }
  // Keyboards and mice where no window delivers them (KMS): read from evdev on a thread of their
  // own, taken by the director each frame the way a window's keys are.
  std::unique_ptr<devices::EvdevInput> keyboardsAndMice;
  const EvdevMode evdevMode = manifest.input.evdev;
  if (evdevMode == EvdevMode::kOn || (evdevMode == EvdevMode::kAuto && (*output)->kind() == "kms")) {
    devices::EvdevOptions evdevOptions;
    evdevOptions.keyboards = manifest.input.keyboards;
    evdevOptions.pointers = manifest.input.pointers;
    evdevOptions.names = manifest.input.names;
    auto made = devices::EvdevInput::create(clock, std::move(evdevOptions), [eventLoop] { eventLoop->wake(); });
    if (made) {
      keyboardsAndMice = std::move(*made);
      keyboardsAndMice->start();
      director.setKeyboardsAndMice(keyboardsAndMice.get());
    } else {
      log::warn(kLogRun, "{}; keyboards and mice are not read", made.error().describe());
    }
  }
  if (script) show = script::startupShow();  // a script starts from LAVA's start-up state

  stopTarget = &frameLoop;
  reloadTarget = &director;
  if (stopBeforeLoop) frameLoop.requestStop();

  std::unique_ptr<StatusServer> server;
  if (manifest.status.enabled) {
    auto started = StatusServer::start(manifest.status, board);
    if (started) {
      server = std::move(*started);
      if (server->listening()) {
        fmt::print("basalt: status server: {}\n", server->url());
      } else {
        fmt::print("basalt: status server: not up yet: {}; trying again\n", server->notUpBecause());
      }
      std::fflush(stdout);
    } else {
      // The show matters more than its status page.
      log::error(kLogRun, "{}; the show plays without it", started.error().describe());
    }
  }

  // [osc]: bindings from OSC addresses to the show's controls (through the board's control
  // queue, as HTTP's), and the node's news to show controllers. The show plays without them when
  // they cannot start.
  std::unique_ptr<OscInput> oscInput;
  std::unique_ptr<OscOutput> oscOutput;
  if (manifest.osc.enabled) {
    auto started = OscInput::start(manifest.osc, board, oscTrackers.get());
    if (started) {
      oscInput = std::move(*started);
      fmt::print("basalt: osc: {}\n", oscInput->describe());
      std::fflush(stdout);
    } else {
      log::error(kLogRun, "{}; the show plays without OSC input", started.error().describe());
    }
    if (!manifest.osc.send.empty()) {
      auto sending = OscOutput::start(manifest.osc.send, board);
      if (sending) {
        oscOutput = std::move(*sending);
      } else {
        log::error(kLogRun, "{}; the show plays without OSC output", sending.error().describe());
      }
    }
  }

  // [[views]]: facets of an immersive display, stereo eyes, tiles (one plain view without).
  std::unique_ptr<DisplayViews> views;
  if (!manifest.views.empty()) {
    // Calibrations are saved in the state folder when there is one to write (a service's
    // StateDirectory=, or --state-dir): the show's folder may be read-only. Otherwise, by hand,
    // they go back to the show's cave files.
    std::filesystem::path calibrations;
    if (options.stateDir) {
      calibrations = *options.stateDir / "calibration";
    } else if (const char* dir = std::getenv("STATE_DIRECTORY"); dir && *dir) {
      calibrations = defaultStateFolder() / "calibration";
    }
    auto made = DisplayViews::create(manifest.views, **renderer, (*output)->size(), calibrations);
    if (!made) return failWith(made.error(), "cannot set up the show's views");
    views = std::move(*made);
    const auto& at = manifest.viewer.position;
    views->setViewer({at[0], at[1], at[2]});
    frameLoop.setViewDrawer(views.get());
    director.setViews(views.get());
  }

  // Devices beside the show's: a replayed trace (--replay) pushes into the run's one queue,
  // numbered apart from the show's devices, and the director applies its events with theirs,
  // through LAVA's dial table (and the Zoom dials, below). Its stepper comes before the director,
  // so that under a ManualClock what it has due by a frame is applied in that frame.
  runtime::Bindings bindings = runtime::Bindings::lavaDefaults();
  std::optional<ReplayReport> replayed;  // what the replay played, said once at the end (outlives `devices`)
  std::unique_ptr<DeviceWiring> devices;
  if (options.replay) {
    devices = std::make_unique<DeviceWiring>(clock, events, kReplayFirstId);
    auto ids = devices->addReplay(*options.replay, !options.replayOnce, matroskaTraceReaderFactory());
    if (!ids) return failWith(ids.error(), "cannot replay");
    devices->manager().setTaps(&replayed.emplace(*options.replay, clock), &*replayed);
    director.setReplayInput(&bindings, std::move(*ids));
    frameLoop.addParticipant(devices->participant());
    devices->start(manual);
  }

  FrameMetrics metrics(board, &events, (*output)->describe());
  frameLoop.addParticipant(metrics);
  frameLoop.addParticipant(director);
  std::optional<ProblemCard> card;
  if (fallback && fallback->card) {
    card.emplace(show, director);
    frameLoop.addParticipant(*card);
  }
  frameLoop.addParticipant(*supervisor);

  std::optional<ScriptPlayer> player;
  if (script) {
    ScriptPlayerOptions playerOptions;
    setScriptVcrOptions(playerOptions, manifest, clock, director.devices());
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
    ro.width = (*output)->size().width;
    ro.height = (*output)->size().height;
    ro.fps = fps;
    ro.codec = *media::parseVideoCodec(options.recordCodec);
    ro.maxFrames = options.recordFrames.value_or(-1);
    ro.waitForEncoder = manual;  // offline runs keep every frame; live shows drop rather than wait
    auto r = ScreenRecorder::create(ro);
    if (!r) return failWith(r.error(), "cannot record");
    recorder = std::move(*r);
    frameLoop.addParticipant(*recorder);
  }
  if (options.zoomDials && videos) {
    // A full turn moves the Zoom picture across the whole output (LAVA: Shift + drag).
    const render::Size size = (*output)->size();
    bindings.setDial(static_cast<std::size_t>(options.zoomDials->first),
                     {runtime::Action::kMoveZoomX, static_cast<double>(size.width)});
    bindings.setDial(static_cast<std::size_t>(options.zoomDials->second),
                     {runtime::Action::kMoveZoomY, static_cast<double>(size.height)});
    videos->followZoomDials(&bindings);
  }

  // [lock]: the frame lock is the last participant, so that the leader sends the frame's final
  // state and a follower's state from the leader is what is drawn.
  std::unique_ptr<FrameLock> lock;
  std::optional<NetClockProbe> clockProbe;
  if (lockSpec.role != LockRole::kOff) {
    LockSpec spec = lockSpec;
    if (spec.node.empty()) spec.node = hostName();
    auto made = FrameLock::create(spec, clock, show);
    if (!made) return failWith(made.error(), "cannot lock frames with the other nodes");
    lock = std::move(*made);
    if (netClock) {
      clockProbe.emplace(*netClock);
      lock->setClockProbe(&*clockProbe);
      lock->setSharedClock(*netClock);
    }
    lock->setDirector(&director);
    // Movies on the group's timeline. A follower waits (bounded) for the movie frame the leader
    // draws; the leader waits briefly too, so that a decoder a little late does not part its
    // picture from the followers'.
    const std::chrono::milliseconds patience(lock->leader() ? std::min(spec.timeoutMs, 50)
                                                            : std::min(spec.leaderTimeoutMs, 500));
    director.setLocked(lock->leader(), patience);
    // The script's VCR and the --movie streams, which no director plays, are shown by the
    // leader's frame number too (leaders keep their own timeline).
    if (player) {
      lock->addMovies(*player);
      if (!lock->leader()) player->followLeader(patience);
    }
    if (videos) {
      lock->addMovies(*videos);
      if (!lock->leader()) videos->followLeader(patience);
    }
    lock->setPublisher([&board, &director, supervision = supervisor.get(), holding = false,
                        leaderAt = spec.leader](const FrameLockFigures& figures) mutable {
      FrameLockFigures f = figures;
      f.watchdogPingsHolding = supervision->pingsWhileHolding();
      board.publishLock(f);
      // What `systemctl status` shows: a follower holding for a lost leader says so (its loop
      // keeps pinging the watchdog meanwhile), and says what plays again once the leader is back.
      if (f.holding) {
        holding = true;
        supervision->status(fmt::format("holding frame {}: the frame-lock leader at {} is lost; waiting for it",
                                        f.heldFrame, leaderAt));
      } else if (holding) {
        holding = false;
        if (const KioskPolicy* policy = director.policy()) supervision->status(policy->describe());
      }
    });
    frameLoop.addParticipant(*lock);
    if (lock->leader()) {
      const std::int64_t joined = lock->awaitFollowers(**loop);
      fmt::print("basalt: frame lock: leader '{}', {} of {} followers joined\n", spec.node, joined, spec.followers);
    } else {
      frameLoop.setGate(lock.get());
      fmt::print("basalt: frame lock: follower '{}' of the leader at {}\n", spec.node, spec.leader);
    }
    std::fflush(stdout);
  }

  Image snapshot;
  bool snapshotWritten = false;
  frameLoop.setFrameHook([&](std::int64_t, bool last, render::Output& out) -> Result<void> {
    if (!last || out.kind() != "headless") return {};
    if (auto r = out.readBack(snapshot); !r) return r;
    if (auto r = media::writeImage(snapshotPath, snapshot); !r) return r;
    snapshotWritten = true;
    return {};
  });

  auto stats = frameLoop.run();
  if (lock && lock->leader() && stats) lock->sayBye(stats->frames - 1);
  std::vector<devices::DeviceStatus> deviceStatus;
  if (devices) {
    deviceStatus = devices->manager().status();
    devices->manager().setTaps(nullptr, nullptr);
    devices->stop();
  }
  supervisor->stopping();
  server.reset();
  oscInput.reset();
  oscOutput.reset();
  if (!stats) return failWith(stats.error(), "the show stopped");

  if (options.saveModel) {
    const script::ObjectSource object = player ? player->interpreter().objectSource() : script::ObjectSource{};
    if (auto r = writeSavedModel(*options.saveModel, script::saveModel(show, object)); !r) {
      return failWith(r.error(), "cannot save the model");
    }
  }

  const double rate = stats->wallSeconds > 0 ? static_cast<double>(stats->frames) / stats->wallSeconds : 0;
  const std::string what = options.manifest ? fmt::format("'{}'", manifest.name)
                           : options.show   ? options.show->string()
                                            : std::string("the default show");
  fmt::print("basalt: played {}: {} frames in {:.2f} s ({:.1f} frames per second, {} clock)\n", what, stats->frames,
             stats->wallSeconds, rate, manual ? "manual" : "system");
  fmt::print("basalt: output: {}\n", (*output)->describe());
  fmt::print("basalt: first frame after {:.1f} ms\n", stats->firstFrameSeconds * 1000);
  if (player) printScriptSummary(*player);
  if (director.reloadsApplied() + director.reloadsFailed() > 0) {
    const FrameFigures f = board.frameFigures();
    fmt::print(
        "basalt: reloads: {} applied, {} failed; frames missed at a reload: {} (longest frame at a reload "
        "{:.1f} ms, median frame {:.1f} ms)\n",
        director.reloadsApplied(), director.reloadsFailed(), f.missedAtReload, f.longestAtReload * 1e3,
        f.intervalP50 * 1e3);
  }
  if (const KioskPolicy* policy = director.policy(); policy && options.manifest) {
    fmt::print("basalt: at the end: {}\n", policy->describe());
  }
  if (lock) fmt::print("basalt: {}\n", lock->describe());
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
  if (replayed) fmt::print("basalt: {}\n", replayed->summary(deviceStatus));
  std::fflush(stdout);
  return status;
}

}  // namespace basalt::kiosk
