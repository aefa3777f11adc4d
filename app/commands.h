#pragma once

/// \file
/// \brief The `basalt` commands. Each command is one entry in the table in commands.cpp and a
/// `main` of its own that parses its arguments (with app/options.h) and returns the exit
/// status: 0 done, 1 could not do it (one clear line on stderr), 2 usage error.

#include <span>
#include <string>
#include <string_view>

namespace basalt::kiosk {

struct CommandSpec {
  std::string_view name;                                ///< "run"
  std::string_view summary;                             ///< one line for `basalt --help`
  std::string_view (*usage)();                          ///< the whole text of `basalt <name> --help`
  int (*main)(std::span<const std::string_view> args);  ///< the arguments after the name
};

/// \brief Every command, in the order `basalt --help` lists them.
std::span<const CommandSpec> commands();

/// \brief `basalt [--help | --version | <command> ...]`: the whole program's dispatch.
int dispatch(std::span<const std::string_view> args);

/// \brief The overview printed by `basalt --help`.
std::string overviewHelp();

/// \brief Prints "basalt: error: ..." and returns 2, for usage errors.
int usageError(std::string_view message);

}  // namespace basalt::kiosk
