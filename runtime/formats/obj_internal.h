#pragma once

/// \file
/// \brief Entry points of the model readers inside runtime/formats (not for other folders).

#include <filesystem>
#include <string>

#include "runtime/formats/model.h"

namespace basalt::formats {

/// \brief Reads OBJ text (already decoded), with material libraries from the file's folder. The
/// text is released as soon as it is parsed, before the meshes are built (a lower peak).
Result<LoadedModel> readObjFile(std::string text, const std::filesystem::path& path, const LoadOptions& options);
/// \brief Reads an OBJ file a chunk at a time, so that the whole text is never in memory. Sets
/// `fallback` (and returns nothing useful) when the file must be read whole instead: it is
/// UTF-16, or its content is OFF.
Result<LoadedModel> readObjStreamed(const std::filesystem::path& path, const LoadOptions& options, bool& fallback,
                                    std::size_t chunkBytes = std::size_t{1} << 20);

/// \brief Reads OFF file bytes.
Result<LoadedModel> readOffFile(std::string bytes, const std::filesystem::path& path, const LoadOptions& options);

}  // namespace basalt::formats
