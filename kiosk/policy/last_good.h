#pragma once

/// \file
/// \brief The last good copy of a show: every show that starts cleanly is copied into the state
/// folder, so that a later start whose manifest or entry has errors plays that copy instead of
/// going dark. The copy is written beside the old one and swapped in with one rename, so that a
/// power cut leaves either the old copy or the new one, never half of one.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "runtime/error.h"

namespace basalt::kiosk {

/// \brief Where the last good copy of the show whose manifest is `manifestFile` is kept:
/// STATE/last-good/NAME-HASH/, one folder per show.
std::filesystem::path lastGoodFolder(const std::filesystem::path& stateFolder,
                                     const std::filesystem::path& manifestFile);

/// \brief A show folder larger than this is not copied (a warning says so).
inline constexpr std::uintmax_t kLastGoodMaxBytes = std::uintmax_t{512} * 1024 * 1024;

/// \brief What keepLastGood() did.
enum class KeptCopy : std::uint8_t { kWritten, kUnchanged };

/// \brief Copies the show folder `showFolder` (the manifest `manifestFile` is inside it) as the
/// last good copy. The state folder itself is left out when it lies inside the show folder. A
/// copy whose files have the same names, sizes and times as the show's is left as it is.
Result<KeptCopy> keepLastGood(const std::filesystem::path& stateFolder, const std::filesystem::path& manifestFile,
                              const std::filesystem::path& showFolder);

/// \brief A last good copy found in the state folder.
struct LastGoodCopy {
  std::filesystem::path manifest;  ///< the copy's manifest, to read as the show's
  std::string savedAt;             ///< when it was kept, ISO 8601 UTC
};

/// \brief The last good copy of the show whose manifest is `manifestFile`, or nothing.
std::optional<LastGoodCopy> findLastGood(const std::filesystem::path& stateFolder,
                                         const std::filesystem::path& manifestFile);

}  // namespace basalt::kiosk
