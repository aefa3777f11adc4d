// basalt: the command-line entry point. Parses the command and hands over to kiosk/.

#include <cstdio>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "kiosk/cli.h"
#include "kiosk/run_command.h"

int main(int argc, char** argv) {
  std::vector<std::string_view> args;
  args.reserve(static_cast<std::size_t>(argc > 0 ? argc - 1 : 0));
  for (int i = 1; i < argc; ++i) args.emplace_back(argv[i]);

  auto command = basalt::kiosk::parseCommandLine(args);
  if (!command) {
    fmt::print(stderr, "basalt: error: {}\n", command.error().describe());
    return 2;
  }
  switch (command->kind) {
    case basalt::kiosk::Command::Kind::kHelp: {
      const std::string_view topic = command->helpTopic;
      if (!topic.empty() && topic != "run") {
        fmt::print(stderr, "basalt: error: no help for '{}'; see 'basalt --help'\n", topic);
        return 2;
      }
      fmt::print("{}", basalt::kiosk::helpText(topic));
      return 0;
    }
    case basalt::kiosk::Command::Kind::kVersion: fmt::print("{}\n", basalt::kiosk::versionText()); return 0;
    case basalt::kiosk::Command::Kind::kRun: return basalt::kiosk::runShow(command->run);
  }
  return 2;
}
