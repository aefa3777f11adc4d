#pragma once

/// \file
/// \brief `basalt check FILE...`: validates show files without playing them. Dispatches by
/// extension to one checker per format (show manifests here; scripts, scenes and models as
/// their readers land), each printing its problems as `file:line: ...`.

#include <filesystem>
#include <map>
#include <span>
#include <string>
#include <string_view>

#include "kiosk/manifest.h"

namespace basalt::kiosk {

/// \brief The checkers for files a manifest refers to, by lower-case extension (".png").
/// Formats without a checker in this build are only checked to exist.
const std::map<std::string, FileChecker, std::less<>>& fileCheckers();

/// \brief Checks a show manifest and everything it refers to (kiosk/check_manifest.cpp).
/// Prints each problem on `out`; returns 0 when there is no error, 1 otherwise.
int checkManifestFile(const std::filesystem::path& file, std::FILE* out);

/// \brief The text of `basalt check --help`.
std::string_view checkUsage();

/// \brief `basalt check FILE...`; returns the exit status (0 all good, 1 problems, 2 usage).
int checkMain(std::span<const std::string_view> args);

}  // namespace basalt::kiosk
