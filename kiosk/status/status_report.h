#pragma once

/// \file
/// \brief The status server's documents, as pure functions of a StatusSnapshot: the /health
/// JSON, the /metrics Prometheus text and the status page a technician reads on a phone.

#include <cstdint>
#include <string>
#include <string_view>

#include "kiosk/status/status_board.h"
#include "runtime/image.h"

namespace basalt::kiosk {

/// \brief Counters the HTTP server keeps about itself.
struct ServerCounters {
  std::uint64_t requests = 0;
  std::uint64_t rejectedRate = 0;         ///< 429
  std::uint64_t rejectedAuth = 0;         ///< 401 and 403
  std::uint64_t rejectedSize = 0;         ///< 413
  std::uint64_t rejectedConnections = 0;  ///< 503: past the connection limits or the descriptor reserve
  std::uint64_t rejectedTimeout = 0;      ///< 408: a request not all there in time
  std::uint64_t rejectedHead = 0;         ///< 431: a head too large
  std::uint64_t evicted = 0;              ///< 503: the slowest connection of a full server, dropped
};

/// \brief "ok" when every device is live and every stream plays, "degraded" otherwise.
std::string_view overallState(const StatusSnapshot& s);

/// \brief GET /health: state, uptime, show and item, frame figures, devices, streams, reloads,
/// the last errors, the log's tail; the build, and what the server filled in: the process, the
/// machine, the server's set-up.
std::string healthJson(const StatusSnapshot& s);

/// \brief GET /log.txt: the log records the board keeps, one line each, oldest first.
std::string logText(const std::vector<log::Record>& records);

/// \brief GET /metrics in the Prometheus text format (version 0.0.4): the same figures.
std::string metricsText(const StatusSnapshot& s, const ServerCounters& server);

/// \brief GET /: the status page (HTML, CSS and script in one document, no outside resources).
std::string_view statusPageHtml();

/// \brief A copy of `image` scaled down to `width` pixels wide (box filter), for thumbnails.
Image scaleDown(const Image& image, std::uint32_t width);

/// \brief `text` as a JSON string literal, quotes included.
std::string jsonString(std::string_view text);

}  // namespace basalt::kiosk
