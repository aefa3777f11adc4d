#pragma once

/// \file
/// \brief What was built: Basalt's version, the source revision and the build, for /health,
/// /metrics (`basalt_build_info`) and the status page. The definitions are written at build time
/// by build_info.cmake.

#include <string_view>

namespace basalt::kiosk {

/// \brief Facts fixed when the program was built.
struct BuildInfo {
  std::string_view version;   ///< the project's version, "0.1.0"
  std::string_view revision;  ///< the git commit ("3f0ff9e2a1b4", "-dirty" with local changes), or "unknown"
  std::string_view build;     ///< the build type and compiler, "RelWithDebInfo, GNU 12.2.0"
};

/// \brief This program's build.
[[nodiscard]] BuildInfo buildInfo();

}  // namespace basalt::kiosk
