#pragma once

/// \file
/// \brief `basalt check FILE...`: finds every error in the files a show is made of, without
/// running anything. Each kind of file has its own checker, chosen by the file's extension
/// (check_command.cpp holds the table; each checker lives in its own file).

#include <cstddef>
#include <cstdio>
#include <filesystem>
#include <span>
#include <string_view>

namespace basalt::kiosk {

/// \brief What one checker found. It prints each problem itself, one per line, as
/// `file:line: error: what is wrong`.
struct CheckResult {
  std::size_t errors = 0;
  std::size_t warnings = 0;
  std::size_t items = 0;  ///< commands, entries, ... checked (for the summary line)
};

/// \brief A checker for one kind of file.
struct FileChecker {
  std::string_view extension;  ///< lower case, with the dot: ".mdl"
  std::string_view what;       ///< "LAVA script"
  std::string_view items;      ///< what CheckResult::items counts: "commands"
  CheckResult (*check)(const std::filesystem::path& file);
};

/// \brief Every kind of file `basalt check` knows.
std::span<const FileChecker> fileCheckers();

/// \brief Checks a show manifest and everything it refers to (kiosk/check_manifest.cpp).
/// Prints each problem on `out`; returns 0 when there is no error, 1 otherwise.
int checkManifestFile(const std::filesystem::path& file, std::FILE* out);

std::string_view checkUsage();
/// \brief `basalt check ...`: 0 when every file is free of errors, 1 when one has errors or
/// cannot be read, 2 for usage errors.
int checkMain(std::span<const std::string_view> args);

}  // namespace basalt::kiosk
