#pragma once

/// \file
/// \brief Command-line option parsing shared by every `basalt` command: `--name value`,
/// `--name=value`, flags, positionals, and usage errors that name the command.

#include <cstdint>
#include <initializer_list>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/error.h"

namespace basalt::kiosk {

/// \brief One option a command accepts.
struct OptionSpec {
  std::string_view name;  ///< with dashes: "--frames"; a short alias may follow after '|': "--help|-h"
  bool takesValue = false;
};

/// \brief What was on the command line, in order.
struct ParsedOption {
  std::string_view name;   ///< the canonical (long) name, or "" for a positional argument
  std::string_view value;  ///< the value, or the positional argument
};

/// \brief Splits `args` by `specs`. Errors are usage errors naming the argument and pointing at
/// `basalt <command> --help`.
[[nodiscard]] Result<std::vector<ParsedOption>> parseOptions(std::string_view command,
                                                             std::span<const std::string_view> args,
                                                             std::initializer_list<OptionSpec> specs);

/// \brief Typed values with messages that name the option.
[[nodiscard]] Result<std::int64_t> integerOption(std::string_view option, std::string_view text, std::int64_t min,
                                                 std::int64_t max);
[[nodiscard]] Result<double> numberOption(std::string_view option, std::string_view text, double min, double max);

}  // namespace basalt::kiosk
