#include "app/options.h"

#include <charconv>
#include <cmath>
#include <vector>

#include <fmt/format.h>

#include "app/suggest.h"

namespace basalt::kiosk {

namespace {

/// Whether `arg` is one of the spec's spellings ("--help|-h").
bool matches(std::string_view spellings, std::string_view arg) {
  while (!spellings.empty()) {
    const auto bar = spellings.find('|');
    if (spellings.substr(0, bar) == arg) return true;
    if (bar == std::string_view::npos) break;
    spellings.remove_prefix(bar + 1);
  }
  return false;
}

std::string_view canonical(std::string_view spellings) { return spellings.substr(0, spellings.find('|')); }

}  // namespace

Result<std::vector<ParsedOption>> parseOptions(std::string_view command, std::span<const std::string_view> args,
                                               std::initializer_list<OptionSpec> specs) {
  std::vector<ParsedOption> parsed;
  bool onlyPositionals = false;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string_view arg = args[i];
    if (onlyPositionals || arg == "-" || !arg.starts_with("-")) {
      parsed.push_back({"", arg});
      continue;
    }
    if (arg == "--") {
      onlyPositionals = true;
      continue;
    }
    std::string_view name = arg;
    std::string_view value;
    bool inlineValue = false;
    if (const auto eq = arg.find('='); eq != std::string_view::npos && arg.starts_with("--")) {
      name = arg.substr(0, eq);
      value = arg.substr(eq + 1);
      inlineValue = true;
    }
    const OptionSpec* spec = nullptr;
    for (const OptionSpec& s : specs) {
      if (matches(s.name, name)) spec = &s;
    }
    if (!spec) {
      std::vector<std::string_view> known;
      for (const OptionSpec& s : specs) known.push_back(canonical(s.name));
      return fail(Errc::kInvalidArgument,
                  fmt::format("unknown option '{}' for 'basalt {}'{}", name, command,
                              didYouMean(name, known, fmt::format("; see 'basalt {} --help'", command))));
    }
    if (!spec->takesValue) {
      if (inlineValue) {
        return fail(Errc::kInvalidArgument, fmt::format("{} takes no value; see 'basalt {} --help'", name, command));
      }
      parsed.push_back({canonical(spec->name), ""});
      continue;
    }
    if (!inlineValue) {
      if (i + 1 >= args.size()) {
        return fail(Errc::kInvalidArgument, fmt::format("{} needs a value; see 'basalt {} --help'", name, command));
      }
      value = args[++i];
    }
    parsed.push_back({canonical(spec->name), value});
  }
  return parsed;
}

Result<std::int64_t> integerOption(std::string_view option, std::string_view text, std::int64_t min, std::int64_t max) {
  std::int64_t value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc{} || end != text.data() + text.size()) {
    return fail(Errc::kInvalidArgument, fmt::format("{} needs a whole number, not '{}'", option, text));
  }
  if (value < min || value > max) {
    return fail(Errc::kInvalidArgument, fmt::format("{} must be between {} and {}, not {}", option, min, max, value));
  }
  return value;
}

Result<double> numberOption(std::string_view option, std::string_view text, double min, double max) {
  double value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc{} || end != text.data() + text.size() || !std::isfinite(value)) {
    return fail(Errc::kInvalidArgument, fmt::format("{} needs a number, not '{}'", option, text));
  }
  if (value < min || value > max) {
    return fail(Errc::kInvalidArgument, fmt::format("{} must be between {} and {}, not {}", option, min, max, text));
  }
  return value;
}

}  // namespace basalt::kiosk
