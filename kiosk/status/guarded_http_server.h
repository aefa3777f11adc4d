#pragma once

/// \file
/// \brief cpp-httplib's server with Basalt's own connection handling: admission (connections per
/// client and in all, a descriptor budget), a reception thread that reads each request whole
/// before a worker sees it (head and body time-outs, head size and field count), and a fixed
/// number of workers fed by a queue of fixed size. Private to kiosk/status (includes httplib.h).

#include <httplib.h>

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace basalt::kiosk {

/// \brief What the status server allows one client and all of them; the table in
/// kiosk/status/README.md documents each value and what happens past it.
struct HttpLimits {
  std::size_t workers = 4;                          ///< threads that answer requests (nice 10)
  std::size_t maxConnections = 32;                  ///< open at once, all clients (also the work queue's size)
  std::size_t maxPerClient = 4;                     ///< open at once from one address
  int reservedDescriptors = 64;                     ///< descriptors always left to the show
  std::size_t maxHeadBytes = 16384;                 ///< request line and header fields
  std::size_t maxHeaderFields = 64;                 ///< header fields in one request
  std::size_t maxBodyBytes = 16384;                 ///< a body, whatever its transfer encoding
  std::chrono::milliseconds requestTimeout{10000};  ///< a request (head and body) from its first byte
  std::chrono::milliseconds idleTimeout{5000};      ///< a kept-alive connection with no request
  std::chrono::milliseconds writeTimeout{10000};    ///< writing one answer
  std::size_t keepAliveRequests = 20;               ///< requests on one connection
  std::chrono::milliseconds linger{1000};           ///< reading what a refused client still sends
};

/// \brief Connections refused or dropped, by reason.
struct GuardCounters {
  std::uint64_t refusedPerClient = 0;    ///< 503: the address has maxPerClient open
  std::uint64_t refusedTotal = 0;        ///< 503: maxConnections open
  std::uint64_t refusedDescriptors = 0;  ///< 503: the show's descriptors would run short
  std::uint64_t timedOut = 0;            ///< 408: a request not all there within requestTimeout
  std::uint64_t headTooLarge = 0;        ///< 431: head over maxHeadBytes or maxHeaderFields
  std::uint64_t bodyTooLarge = 0;        ///< 413 before the body was read (Content-Length)
  std::uint64_t evicted = 0;             ///< 503: dropped to make room, the slowest of a full server
};

/// \brief An httplib::Server whose connections Basalt handles: httplib parses requests and
/// routes them; accepting, reading and time-outs are here.
///
/// Threading: httplib's acceptor thread admits connections (through the task queue this class
/// installs); one reception thread reads requests until they are whole; `workers` threads run
/// httplib's request processing on a whole request. Counters are atomics.
class GuardedHttpServer final : public httplib::Server {
 public:
  explicit GuardedHttpServer(HttpLimits limits);
  ~GuardedHttpServer() override;
  GuardedHttpServer(const GuardedHttpServer&) = delete;
  GuardedHttpServer& operator=(const GuardedHttpServer&) = delete;

  [[nodiscard]] const HttpLimits& limits() const { return limits_; }
  [[nodiscard]] GuardCounters guardCounters() const;
  /// \brief Connections open now (admitted, not yet closed).
  [[nodiscard]] std::size_t openConnections() const;
  /// \brief On a worker thread: true when the request being read ran past requestTimeout (the
  /// error handler then answers 408 rather than 400).
  [[nodiscard]] static bool currentRequestTimedOut();
  /// \brief On a worker thread: closes the connection after the answer (a body left unread
  /// would be taken for the next request).
  static void closeAfterAnswer();

  struct Connection;

 private:
  // httplib calls this for each accepted socket (through the inline task queue, on its acceptor
  // thread): admission, then the socket goes to reception.
  bool process_and_close_socket(socket_t sock) override;

  void receive();
  /// On reception: drops as many of the slowest admitted connections as were admitted past
  /// maxConnections.
  void evictSlowest(std::vector<std::unique_ptr<Connection>>& waiting);
  void work();
  void serve(std::unique_ptr<Connection> c);
  void toReception(std::unique_ptr<Connection> c);
  void refuse(std::unique_ptr<Connection> c, int status, std::string_view why);
  void close(std::unique_ptr<Connection> c);
  void wakeReception() const;
  /// Logs a refusal: the first of each kind at once, then at most one line a minute with the
  /// number refused meanwhile, so that a flood is told without filling the log.
  void noteRefusal(std::string_view kind, std::string_view what);

  HttpLimits limits_;
  int wakeFd_ = -1;  // eventfd: wakes reception for new connections and on stop
  std::atomic<bool> stopping_{false};

  mutable std::mutex mutex_;          // guards perClient_, open_, inbox_, work_
  std::condition_variable workWake_;  // a connection in work_, or stopping_
  std::map<std::string, std::size_t> perClient_;
  std::size_t open_ = 0;
  std::size_t evictWanted_ = 0;  // admitted past maxConnections: reception drops as many of the slowest
  std::vector<std::unique_ptr<Connection>> inbox_;  // for reception
  std::deque<std::unique_ptr<Connection>> work_;    // whole requests, at most maxConnections

  std::thread reception_;
  std::vector<std::thread> workers_;

  std::atomic<std::uint64_t> refusedPerClient_{0};
  std::atomic<std::uint64_t> refusedTotal_{0};
  std::atomic<std::uint64_t> refusedDescriptors_{0};
  std::atomic<std::uint64_t> timedOut_{0};
  std::atomic<std::uint64_t> headTooLarge_{0};
  std::atomic<std::uint64_t> bodyTooLarge_{0};
  std::atomic<std::uint64_t> evicted_{0};
  // Admitted connections in reception not yet answered (reading a request, or kept alive and
  // idle): what a full server may drop to make room. Written by reception.
  std::atomic<std::size_t> evictable_{0};

  struct Noted {
    std::chrono::steady_clock::time_point logged;
    std::uint64_t since = 0;  // refused since that line
  };
  std::mutex notedMutex_;
  std::map<std::string, Noted, std::less<>> noted_;
};

}  // namespace basalt::kiosk
