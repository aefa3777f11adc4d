#pragma once

/// \file
/// \brief The status and control server: GET /health (JSON), /metrics (Prometheus text),
/// /snapshot.png (the frame on screen now) and / (a status page for a phone); POST
/// /control/{next,previous,reload,command,restart-device} with a bearer token. Loopback only
/// unless the manifest opens it; request sizes and rates are limited.

#include <atomic>
#include <memory>
#include <string>
#include <thread>

#include "kiosk/manifest/manifest.h"
#include "kiosk/status/status_board.h"
#include "kiosk/status/status_report.h"
#include "runtime/error.h"

namespace httplib {
class Server;
}

namespace basalt::kiosk {

/// \brief An HTTP server on its own threads (one accepting, two answering).
///
/// Threading: handlers run on the server's threads; they read the StatusBoard and hand controls
/// and snapshot requests to the frame loop through its queues, waiting a bounded time for the
/// answer. They never touch the show.
class StatusServer {
 public:
  /// \brief Binds `spec.host`:`spec.port` (0 picks a free port) and starts serving.
  static Result<std::unique_ptr<StatusServer>> start(const StatusSpec& spec, StatusBoard& board);
  ~StatusServer();
  StatusServer(const StatusServer&) = delete;
  StatusServer& operator=(const StatusServer&) = delete;

  [[nodiscard]] std::uint16_t port() const { return port_; }
  /// \brief "http://127.0.0.1:8180/".
  [[nodiscard]] std::string url() const;
  [[nodiscard]] ServerCounters counters() const;
  /// \brief True when POST controls are on (a token is configured and readable).
  [[nodiscard]] bool controlsEnabled() const { return !token_.empty(); }

  class Limiter;

 private:
  StatusServer(const StatusSpec& spec, StatusBoard& board, std::string token);
  void routes();

  StatusSpec spec_;
  StatusBoard& board_;
  std::string token_;
  std::unique_ptr<httplib::Server> server_;
  std::unique_ptr<Limiter> limiter_;
  std::thread thread_;
  std::uint16_t port_ = 0;
  std::atomic<std::uint64_t> requests_{0};
  std::atomic<std::uint64_t> rejectedRate_{0};
  std::atomic<std::uint64_t> rejectedAuth_{0};
  std::atomic<std::uint64_t> rejectedSize_{0};
};

}  // namespace basalt::kiosk
