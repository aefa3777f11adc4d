#include "app/commands.h"

#include <cstdio>
#include <vector>

#include <fmt/format.h>

#include "app/check_command.h"
#include "app/devices_command.h"
#include "app/record_command.h"
#include "app/run_command.h"
#include "app/suggest.h"
#include "runtime/script/reference.h"

namespace basalt::kiosk {

namespace {

// One line per command; each command lives in its own file.
constexpr CommandSpec kCommands[] = {
    {"run", "play a show (the default show when none is given)", runUsage, runMain},
    {"check", "find every error in a show's files (show.toml, LAVA scripts) without running them", checkUsage,
     checkMain},
    {"devices", "list dial boxes, cameras and capture cards, and why one cannot be used", devicesUsage, devicesMain},
    {"record", "record live devices into a trace folder for replay", recordUsage, recordMain},
};

constexpr std::string_view kVersion = "basalt 0.1.0";

/// "unknown command 'rnu'; did you mean 'run'?" (`basalt rnu`), or "no command 'rnu'; ..."
/// (`basalt help rnu`, where "script" is a topic too).
int unknownCommand(std::string_view name, bool asHelpTopic) {
  std::vector<std::string_view> names;
  for (const CommandSpec& c : kCommands) names.push_back(c.name);
  names.emplace_back(asHelpTopic ? "script" : "help");
  return usageError(fmt::format("{} '{}'{}", asHelpTopic ? "no command" : "unknown command", name,
                                didYouMean(name, names, "; see 'basalt --help'")));
}

}  // namespace

std::span<const CommandSpec> commands() { return kCommands; }

std::string overviewHelp() {
  std::string text =
      "Usage: basalt <command> [options]\n\n"
      "Basalt runs unattended 3D and video installations: a fullscreen OpenGL ES renderer driven by\n"
      "dial boxes, cameras and video files, with a simulated twin for every device.\n\n"
      "Commands:\n";
  for (const CommandSpec& c : kCommands) text += fmt::format("  {:<16} {}\n", c.name, c.summary);
  text += fmt::format("  {:<16} {}\n", "help [COMMAND]", "show help for a command");
  text +=
      fmt::format("  {:<16} {}\n", "help script", "the LAVA script language: every command, its values and defaults");
  text +=
      "\nOptions:\n"
      "  -h, --help       this text\n"
      "  -V, --version    print the version\n\n"
      "Environment variables are listed in ENV_VARS.md; BASALT_LOG sets log levels\n"
      "(for example BASALT_LOG=render=debug).\n";
  return text;
}

int usageError(std::string_view message) {
  fmt::print(stderr, "basalt: error: {}\n", message);
  return 2;
}

int dispatch(std::span<const std::string_view> args) {
  if (args.empty() || args[0] == "--help" || args[0] == "-h") {
    fmt::print("{}", overviewHelp());
    return 0;
  }
  if (args[0] == "--version" || args[0] == "-V") {
    fmt::print("{}\n", kVersion);
    return 0;
  }
  if (args[0] == "help") {
    if (args.size() == 1) {
      fmt::print("{}", overviewHelp());
      return 0;
    }
    if (args[1] == "script") {
      fmt::print("{}", script::scriptReference());
      return 0;
    }
    for (const CommandSpec& c : kCommands) {
      if (c.name == args[1]) {
        fmt::print("{}", c.usage());
        return 0;
      }
    }
    return unknownCommand(args[1], true);
  }
  for (const CommandSpec& c : kCommands) {
    if (c.name == args[0]) return c.main(args.subspan(1));
  }
  if (args[0].starts_with("-")) {
    constexpr std::string_view kOptions[] = {"--help", "--version"};
    return usageError(
        fmt::format("unknown option '{}'{}", args[0], didYouMean(args[0], kOptions, "; see 'basalt --help'")));
  }
  return unknownCommand(args[0], false);
}

}  // namespace basalt::kiosk
