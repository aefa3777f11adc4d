#pragma once

/// \file
/// \brief The content checks shared by `basalt check` and the show loader: a checker per kind
/// of file, and the checks a manifest runs on each file it names.

#include <cstddef>
#include <cstdio>
#include <filesystem>
#include <map>
#include <span>
#include <string>
#include <string_view>

#include "kiosk/manifest/manifest.h"

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

/// \brief Checks a show manifest and everything it refers to (kiosk/manifest/check_manifest.cpp).
/// Prints each problem on `out`; returns 0 when there is no error, 1 otherwise.
int checkManifestFile(const std::filesystem::path& file, std::FILE* out);

/// \brief The content checkers of this build by lower-case extension (".png", ".mdl"): what
/// `basalt check` and the show loader parse a referenced file with.
const std::map<std::string, ContentChecker, std::less<>>& contentCheckers();

}  // namespace basalt::kiosk
