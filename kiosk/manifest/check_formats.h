#pragma once

/// \file
/// \brief `basalt check` for the content formats of runtime/formats: scenes (.sce), models
/// (.obj, .off) and cave files (.cave), as whole files and as files a manifest names.

#include <filesystem>
#include <string_view>
#include <vector>

#include "kiosk/manifest/content_check.h"
#include "kiosk/manifest/manifest.h"

namespace basalt::kiosk {

/// \brief `basalt check FILE`: every problem of the file, as diagnostics.
CheckResult checkSceneFile(const std::filesystem::path& file);
CheckResult checkModelFile(const std::filesystem::path& file);
CheckResult checkCaveFile(const std::filesystem::path& file);

/// \brief The same checks for files a manifest names, as manifest diagnostics.
std::vector<Diagnostic> checkSceneContent(const std::filesystem::path& file);
std::vector<Diagnostic> checkModelContent(const std::filesystem::path& file);
std::vector<Diagnostic> checkCaveContent(const std::filesystem::path& file);

/// \brief Whether the facets of `cave`'s geometry face the viewer once a facet view's `winding`
/// is applied: one warning naming the geometry's `f` lines and the fix
/// (formats::caveFacingProblem), said for the facet view named `view`; none when they do or
/// when the cave does not load (its content check says why).
std::vector<Diagnostic> checkCaveFacing(const std::filesystem::path& cave, formats::FacetWinding winding,
                                        std::string_view view);

}  // namespace basalt::kiosk
