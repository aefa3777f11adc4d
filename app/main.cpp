// basalt: the command-line entry point; app/commands.cpp dispatches to the commands.

#include <string_view>
#include <vector>

#include "app/commands.h"
#include "runtime/crash_report.h"

int main(int argc, char** argv) {
  // A crash on site leaves the signal and the call stack in the journal before systemd restarts
  // the show.
  basalt::runtime::installCrashReport("basalt");
  std::vector<std::string_view> args;
  args.reserve(static_cast<std::size_t>(argc > 0 ? argc - 1 : 0));
  for (int i = 1; i < argc; ++i) args.emplace_back(argv[i]);
  return basalt::kiosk::dispatch(args);
}
