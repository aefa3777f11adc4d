#pragma once

/// \file
/// \brief The content checks shared by `basalt check` and the show loader: a checker per kind
/// of file, and the checks a manifest runs on each file it names.

#include <cstddef>
#include <filesystem>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "kiosk/manifest/manifest.h"

namespace basalt::kiosk {

/// \brief What one checker found. Checkers print nothing: `basalt check` prints the diagnostics
/// (formatCheckDiagnostic) or writes them as JSON, and counts errors and warnings from them, so
/// that every count agrees with what is shown.
struct CheckResult {
  std::vector<Diagnostic> diagnostics;  ///< errors, warnings and notes, in the order found
  std::size_t items = 0;                ///< commands, entries, ... checked (for the summary line)
  /// A checker's last word on the whole file, if it has one: a manifest's "ok: 'Name' plays ..."
  /// or "its last good copy plays until it is fixed".
  std::string verdict;

  [[nodiscard]] std::size_t errors() const;
  [[nodiscard]] std::size_t warnings() const;
};

/// \brief "file:line: error: what is wrong" (warnings and notes alike; no line for 0): how
/// `basalt check` prints each diagnostic, whatever file kind it came from.
std::string formatCheckDiagnostic(const Diagnostic& d);

/// \brief "error", "warning", "note".
std::string_view severityName(Severity severity);

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
CheckResult checkManifestFile(const std::filesystem::path& file);

/// \brief The content checkers of this build by lower-case extension (".png", ".mdl"): what
/// `basalt check` and the show loader parse a referenced file with.
const std::map<std::string, ContentChecker, std::less<>>& contentCheckers();

}  // namespace basalt::kiosk
