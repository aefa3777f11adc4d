#pragma once

/// \file
/// \brief The OSC input: UDP and TCP sockets on `[osc] listen` (loopback unless the manifest
/// opens it), one thread that reads packets, has liblo take them apart and the OscRouter route
/// them, and hands controls to the frame loop through the StatusBoard's control queue, as the
/// HTTP controls do.

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>

#include "kiosk/manifest/manifest.h"
#include "kiosk/osc/osc_router.h"
#include "kiosk/status/status_board.h"
#include "runtime/error.h"
#include "runtime/unique_fd.h"

namespace basalt::kiosk {

/// \brief The largest packet read (UDP datagram or TCP frame); larger ones are counted
/// `malformed` and dropped unread (a TCP connection that announces one is closed).
inline constexpr std::size_t kOscMaxPacketBytes = 8192;
/// \brief TCP connections open at once; a further one is closed at once.
inline constexpr std::size_t kOscMaxConnections = 8;

/// \brief Listens for OSC on its own thread (at nice 10) until destroyed.
///
/// Threading: the input's thread reads the sockets, routes and pushes ControlRequests into
/// `board.controls()` (then `board.wake()`), logs each control when the frame loop has answered
/// it, and publishes its counts with `board.publishOsc`. It never touches the show.
class OscInput {
 public:
  /// \brief Binds UDP and TCP (as `spec` says) on `spec.host`:`spec.port` (0: a free port, the
  /// same for both) and starts the thread. `tracker` (borrowed, may be null) takes /tracker/.
  [[nodiscard]] static Result<std::unique_ptr<OscInput>> start(const OscSpec& spec, StatusBoard& board,
                                                               OscTrackerSink* tracker = nullptr);
  ~OscInput();
  OscInput(const OscInput&) = delete;
  OscInput& operator=(const OscInput&) = delete;

  /// \brief The port bound.
  [[nodiscard]] std::uint16_t port() const { return port_; }
  /// \brief "udp+tcp 127.0.0.1:9000".
  [[nodiscard]] std::string describe() const;

 private:
  struct Connection;
  struct Pending;
  OscInput(const OscSpec& spec, StatusBoard& board);
  Result<void> bind();
  void run();
  void readUdp();
  void acceptTcp();
  /// Reads what a connection has; false when it is to be closed.
  bool readTcp(Connection& c);
  void handle(std::span<const std::byte> packet, const std::string& sender);
  void sweepReplies(bool all);
  void publish();

  OscSpec spec_;
  StatusBoard& board_;
  OscRouter router_;  // the input's thread only (after start)
  SystemClock clock_;
  UniqueFd udp_;
  UniqueFd tcp_;
  UniqueFd stop_;  // an eventfd: written to stop the thread
  std::uint16_t port_ = 0;
  std::vector<std::unique_ptr<Connection>> connections_;  // the input's thread only
  std::vector<Pending> pending_;                          // the input's thread only
  std::uint64_t published_ = ~std::uint64_t{0};           // the input's thread only
  std::thread thread_;
};

}  // namespace basalt::kiosk
