#pragma once

/// \file
/// \brief Wavefront material libraries (`.mtl`): read and written.

#include <filesystem>
#include <string_view>
#include <vector>

#include "runtime/formats/text.h"
#include "runtime/show/mesh.h"

namespace basalt::formats {

/// \brief Parses MTL text. `diagnostics` names the file; texture names are resolved against
/// `folder` and `searchPaths` (see resolveReferencedFile); a texture that is not found is kept
/// with a warning, since it may arrive later. Never fails: an MTL file that is partly bad gives
/// the materials that are sound, and the warnings say what was skipped.
std::vector<runtime::Material> parseMtl(std::string_view text, const std::filesystem::path& folder,
                                        const std::vector<std::filesystem::path>& searchPaths,
                                        Diagnostics& diagnostics);

/// \brief Reads an MTL file (size cap and text decoding as for models).
[[nodiscard]] Result<std::vector<runtime::Material>> readMtlFile(const std::filesystem::path& path,
                                                                 const LoadOptions& options,
                                                                 std::vector<Diagnostic>& warnings);

/// \brief MTL text for `materials`; texture paths are written relative to `folder`.
std::string formatMtl(const std::vector<runtime::Material>& materials, const std::filesystem::path& folder);

}  // namespace basalt::formats
