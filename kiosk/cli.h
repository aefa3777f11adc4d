#pragma once

/// \file
/// \brief The `basalt` command line: commands, options and their help texts.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "runtime/error.h"

namespace basalt::kiosk {

/// \brief Which clock drives a run: the system clock paces frames in real time; the manual
/// clock advances exactly 1/fps per frame and renders as fast as the machine goes.
enum class ClockMode : std::uint8_t { kAuto, kSystem, kManual };

/// \brief Options of `basalt run`.
struct RunOptions {
  std::optional<std::int64_t> frames;  ///< stop after this many frames
  std::optional<double> seconds;       ///< stop after this much show time
  std::uint32_t width = 500;           ///< LAVA's start-up window is 500 x 500
  std::uint32_t height = 500;
  bool headless = false;                          ///< force the offscreen output
  std::optional<std::filesystem::path> snapshot;  ///< where the last frame goes
  std::filesystem::path outputDir = "out";        ///< default folder for snapshots
  double fps = 60;
  ClockMode clock = ClockMode::kAuto;
};

struct Command {
  enum class Kind : std::uint8_t { kHelp, kVersion, kRun };
  Kind kind = Kind::kHelp;
  std::string helpTopic;  ///< for kHelp: "" for the overview, or a command name
  RunOptions run;
};

/// \brief Parses the arguments after the program name. Errors are usage errors with a message
/// that names the argument and says where help is.
[[nodiscard]] Result<Command> parseCommandLine(std::span<const std::string_view> args);

/// \brief Help for `basalt --help` (topic "") or `basalt <command> --help`.
std::string helpText(std::string_view topic);

/// \brief "basalt 0.1.0".
std::string versionText();

}  // namespace basalt::kiosk
