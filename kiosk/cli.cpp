#include "kiosk/cli.h"

#include <charconv>
#include <cmath>

#include <fmt/format.h>

namespace basalt::kiosk {

namespace {

constexpr std::uint32_t kMaxDimension = 16384;

Result<std::int64_t> parseInteger(std::string_view option, std::string_view text) {
  std::int64_t value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc{} || end != text.data() + text.size()) {
    return fail(Errc::kInvalidArgument, fmt::format("{} needs a whole number, not '{}'", option, text));
  }
  return value;
}

Result<double> parseNumber(std::string_view option, std::string_view text) {
  double value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc{} || end != text.data() + text.size() || !std::isfinite(value)) {
    return fail(Errc::kInvalidArgument, fmt::format("{} needs a number, not '{}'", option, text));
  }
  return value;
}

Result<void> parseSize(std::string_view text, RunOptions& run) {
  const auto x = text.find_first_of("xX");
  if (x == std::string_view::npos) {
    return fail(Errc::kInvalidArgument, fmt::format("--size needs WIDTHxHEIGHT, e.g. 1280x720, not '{}'", text));
  }
  auto w = parseInteger("--size", text.substr(0, x));
  auto h = parseInteger("--size", text.substr(x + 1));
  if (!w || !h || *w < 1 || *h < 1 || *w > kMaxDimension || *h > kMaxDimension) {
    return fail(Errc::kInvalidArgument,
                fmt::format("--size needs WIDTHxHEIGHT between 1 and {} each, not '{}'", kMaxDimension, text));
  }
  run.width = static_cast<std::uint32_t>(*w);
  run.height = static_cast<std::uint32_t>(*h);
  return {};
}

Result<void> parseRunOption(std::string_view name, std::string_view value, RunOptions& run) {
  if (name == "--frames") {
    auto n = parseInteger(name, value);
    if (!n) return std::unexpected(n.error());
    if (*n < 1) return fail(Errc::kInvalidArgument, fmt::format("--frames must be at least 1, not {}", *n));
    run.frames = *n;
  } else if (name == "--seconds") {
    auto s = parseNumber(name, value);
    if (!s) return std::unexpected(s.error());
    if (*s <= 0) return fail(Errc::kInvalidArgument, fmt::format("--seconds must be more than 0, not {}", value));
    run.seconds = *s;
  } else if (name == "--size") {
    return parseSize(value, run);
  } else if (name == "--snapshot") {
    if (value.empty()) return fail(Errc::kInvalidArgument, "--snapshot needs a file name");
    run.snapshot = std::filesystem::path(value);
  } else if (name == "--output-dir") {
    if (value.empty()) return fail(Errc::kInvalidArgument, "--output-dir needs a folder");
    run.outputDir = std::filesystem::path(value);
  } else if (name == "--fps") {
    auto f = parseNumber(name, value);
    if (!f) return std::unexpected(f.error());
    if (*f < 1 || *f > 1000)
      return fail(Errc::kInvalidArgument, fmt::format("--fps must be between 1 and 1000, not {}", value));
    run.fps = *f;
  } else {
    return fail(Errc::kInvalidArgument,
                fmt::format("unknown option '{}' for 'basalt run'; see 'basalt run --help'", name));
  }
  return {};
}

bool takesValue(std::string_view name) {
  return name == "--frames" || name == "--seconds" || name == "--size" || name == "--snapshot" ||
         name == "--output-dir" || name == "--fps";
}

Result<Command> parseRun(std::span<const std::string_view> args) {
  Command command;
  command.kind = Command::Kind::kRun;
  RunOptions& run = command.run;
  for (std::size_t i = 0; i < args.size(); ++i) {
    std::string_view arg = args[i];
    if (arg == "--help" || arg == "-h") {
      command.kind = Command::Kind::kHelp;
      command.helpTopic = "run";
      return command;
    }
    if (arg == "--headless") {
      run.headless = true;
      continue;
    }
    if (arg == "--realtime") {
      run.clock = ClockMode::kSystem;
      continue;
    }
    if (arg == "--fast") {
      run.clock = ClockMode::kManual;
      continue;
    }
    if (arg.starts_with("--")) {
      std::string_view name = arg;
      std::string_view value;
      bool hasValue = false;
      if (const auto eq = arg.find('='); eq != std::string_view::npos) {
        name = arg.substr(0, eq);
        value = arg.substr(eq + 1);
        hasValue = true;
      }
      if (!takesValue(name)) {
        return fail(Errc::kInvalidArgument,
                    fmt::format("unknown option '{}' for 'basalt run'; see 'basalt run --help'", name));
      }
      if (!hasValue) {
        if (i + 1 >= args.size()) {
          return fail(Errc::kInvalidArgument, fmt::format("{} needs a value; see 'basalt run --help'", name));
        }
        value = args[++i];
      }
      if (auto r = parseRunOption(name, value, run); !r) return std::unexpected(r.error());
      continue;
    }
    return fail(Errc::kInvalidArgument,
                fmt::format("unexpected argument '{}' for 'basalt run'; see 'basalt run --help'", arg));
  }
  return command;
}

}  // namespace

Result<Command> parseCommandLine(std::span<const std::string_view> args) {
  Command command;
  if (args.empty()) {
    command.kind = Command::Kind::kHelp;
    return command;
  }
  const std::string_view first = args[0];
  if (first == "--help" || first == "-h" || first == "help") {
    command.kind = Command::Kind::kHelp;
    if (args.size() > 1) command.helpTopic = std::string(args[1]);
    return command;
  }
  if (first == "--version" || first == "-V") {
    command.kind = Command::Kind::kVersion;
    return command;
  }
  if (first == "run") return parseRun(args.subspan(1));
  if (first.starts_with("-")) {
    return fail(Errc::kInvalidArgument, fmt::format("unknown option '{}'; see 'basalt --help'", first));
  }
  return fail(Errc::kInvalidArgument, fmt::format("unknown command '{}'; see 'basalt --help'", first));
}

std::string helpText(std::string_view topic) {
  if (topic == "run") {
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
  -h, --help         this text

Exit status: 0 when the show ran, 1 when it could not start or failed, 2 for usage errors.
)";
  }
  return R"(Usage: basalt <command> [options]

Basalt runs unattended 3D and video installations: a fullscreen OpenGL ES renderer driven by
dial boxes, cameras and video files, with a simulated twin for every device.

Commands:
  run [options]      play the default show (see 'basalt run --help')
  help [COMMAND]     show help for a command

Options:
  -h, --help         this text
  -V, --version      print the version

Environment variables are listed in ENV_VARS.md; BASALT_LOG sets log levels
(for example BASALT_LOG=render=debug).
)";
}

std::string versionText() { return "basalt 0.1.0"; }

}  // namespace basalt::kiosk
