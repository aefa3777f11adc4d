#pragma once

/// \file
/// \brief The `.mdl` checker of `basalt check`: everything that can be known about a LAVA script
/// without running it.

#include <filesystem>
#include <vector>

#include "kiosk/manifest/content_check.h"
#include "runtime/script/program.h"

namespace basalt::kiosk {

/// \brief The problems in a parsed script beyond its syntax: files it names that are missing,
/// and part names the object does not have while the object is still the start-up cube (after
/// a load_object the parts are not known without loading it). `folder` is the script's folder.
std::vector<script::Diagnostic> checkScriptStatically(const script::Program& program,
                                                      const std::filesystem::path& folder);

/// \brief Checks one script file: every problem, as diagnostics.
CheckResult checkMdl(const std::filesystem::path& file);

}  // namespace basalt::kiosk
