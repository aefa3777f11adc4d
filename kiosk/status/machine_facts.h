#pragma once

/// \file
/// \brief What the status server says about the process and the machine it runs on, read from
/// /proc and the C library when a report is asked for (on the server's threads, never the frame
/// loop's).

#include <cstdint>
#include <optional>

namespace basalt::kiosk {

/// \brief The process's own figures, as Prometheus' client libraries name them (process_*).
struct ProcessFigures {
  double cpuSeconds = 0;               ///< user and system CPU time since the start
  std::uint64_t residentBytes = 0;     ///< resident set size
  std::uint64_t virtualBytes = 0;      ///< virtual memory size
  std::uint64_t openFds = 0;           ///< open file descriptors
  std::uint64_t maxFds = 0;            ///< the soft limit on them
  std::optional<double> startSeconds;  ///< when the process started, seconds since 1970
};

/// \brief This process's figures.
[[nodiscard]] ProcessFigures readProcessFigures();

}  // namespace basalt::kiosk
