#pragma once

/// \file
/// \brief The status and control server: GET /health (JSON), /metrics (Prometheus text),
/// /snapshot.png (the frame on screen now, unless the show turns it off) and / (a status page
/// for a phone); POST /control/{next,previous,reload,command,restart-device,calibrate} with a
/// bearer token. Loopback only unless the manifest opens it, and then GETs from other machines
/// may need a read token; request sizes and rates are limited.

#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "kiosk/manifest/manifest.h"
#include "kiosk/status/status_board.h"
#include "kiosk/status/status_report.h"
#include "runtime/error.h"

namespace basalt::kiosk {

class GuardedHttpServer;  // kiosk/status/guarded_http_server.h

/// \brief An HTTP server on its own threads (one accepting, two answering).
///
/// The port is its own: the socket has SO_REUSEADDR (a restart need not wait for TIME_WAIT) and
/// never SO_REUSEPORT, so a second process cannot bind the same port and take half the
/// requests. When the port is taken, the server says so and tries again with back-off on its own
/// thread; the show plays on meanwhile.
///
/// Threading: handlers run on the server's threads; they read the StatusBoard and hand controls
/// and snapshot requests to the frame loop through its queues, waiting a bounded time for the
/// answer. They never touch the show.
class StatusServer {
 public:
  /// \brief Binds `spec.host`:`spec.port` (0 picks a free port) and starts serving. When the
  /// address cannot be bound (the port is taken: another Basalt may be running), the server is
  /// returned all the same, not listening(), and binds as soon as it can (after 1 s, 2 s, 4 s ...
  /// at most 30 s apart).
  static Result<std::unique_ptr<StatusServer>> start(const StatusSpec& spec, StatusBoard& board);
  ~StatusServer();
  StatusServer(const StatusServer&) = delete;
  StatusServer& operator=(const StatusServer&) = delete;

  /// \brief The port it listens on, or will listen on once it can bind.
  [[nodiscard]] std::uint16_t port() const { return port_.load(std::memory_order_acquire); }
  /// \brief "http://127.0.0.1:8180/".
  [[nodiscard]] std::string url() const;
  /// \brief True once the address is bound and requests are answered.
  [[nodiscard]] bool listening() const { return bound_.load(std::memory_order_acquire); }
  /// \brief Why the server is not up yet ("" once it is listening).
  [[nodiscard]] std::string notUpBecause() const;
  [[nodiscard]] ServerCounters counters() const;
  /// \brief True when POST controls are on (a token is configured and readable).
  [[nodiscard]] bool controlsEnabled() const { return !token_.empty(); }
  /// \brief What the page shows and hides.
  [[nodiscard]] ServerFacts facts() const { return {controlsEnabled(), spec_.snapshot, readGuarded_}; }

  class Limiter;
  class SnapshotCache;

 private:
  StatusServer(const StatusSpec& spec, StatusBoard& board, std::string token);
  void routes();
  /// Binds the address; false (and `notUpBecause_` says why) when it cannot.
  bool bind();
  /// The server's thread: binds, retrying with back-off until it can or the server is stopped,
  /// then serves.
  void serve();
  /// The machine's facts, with the show's folder (that of `manifest`) and the board's folders;
  /// read again when a second old.
  MachineFacts machineFacts(const std::string& manifest);

  StatusSpec spec_;
  StatusBoard& board_;
  std::string token_;
  // GETs from other machines need a token: readToken_ (or token_); none is readable when
  // readToken_ is empty, and readTokenProblem_ says why.
  bool readGuarded_ = false;
  std::string readToken_;
  std::string readTokenProblem_;
  std::unique_ptr<GuardedHttpServer> server_;
  std::unique_ptr<Limiter> limiter_;
  std::unique_ptr<SnapshotCache> snapshots_;
  std::thread thread_;
  std::atomic<std::uint16_t> port_{0};
  std::atomic<bool> bound_{false};
  std::atomic<bool> served_{false};   // serve() is done
  mutable std::mutex bindMutex_;      // guards stopping_, notUpBecause_
  std::condition_variable stopWake_;  // wakes a back-off wait when the server is stopped
  bool stopping_ = false;             // guarded by bindMutex_
  std::string notUpBecause_;          // guarded by bindMutex_
  std::mutex machineMutex_;           // guards machine_, machineRead_
  std::optional<MachineFacts> machine_;
  Nanos machineRead_{0};
  std::atomic<std::uint64_t> requests_{0};
  std::atomic<std::uint64_t> rejectedRate_{0};
  std::atomic<std::uint64_t> rejectedAuth_{0};
  std::atomic<std::uint64_t> rejectedSize_{0};
};

}  // namespace basalt::kiosk
