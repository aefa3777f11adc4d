#pragma once

/// \file
/// \brief One clock for a group of display nodes (frame-locked nodes, thesis §4.5), through
/// GStreamer's network clock: the leader serves its monotonic clock with GstNetTimeProvider, the
/// followers follow it with GstNetClientClock, so that show time, and the movies that play on
/// it, read the same on every node.

#include <cstdint>
#include <memory>
#include <string>

#include "runtime/clock.h"
#include "runtime/error.h"

namespace basalt::media {

/// \brief Serves this node's monotonic clock (GStreamer's system clock, CLOCK_MONOTONIC, the
/// clock `basalt::SystemClock` reads) on a UDP port. Threading: GStreamer answers on a thread of
/// its own; the object only starts and stops it.
class NetClockServer {
 public:
  /// \brief Starts serving on `address` (an IP address; "0.0.0.0" for every interface) and
  /// `port` (0: any free port, see port()).
  [[nodiscard]] static Result<std::unique_ptr<NetClockServer>> start(const std::string& address, int port);
  ~NetClockServer();
  NetClockServer(const NetClockServer&) = delete;
  NetClockServer& operator=(const NetClockServer&) = delete;
  [[nodiscard]] int port() const { return port_; }

 private:
  NetClockServer() = default;
  void* provider_ = nullptr;  // GstNetTimeProvider*, owned
  int port_ = 0;
};

/// \brief The leader's monotonic clock, as this node estimates it (GstNetClientClock). Calendar
/// time is this node's own. Safe to read from any thread.
class NetClock final : public Clock {
 public:
  [[nodiscard]] static Result<std::unique_ptr<NetClock>> connect(const std::string& address, int port);
  ~NetClock() override;
  NetClock(const NetClock&) = delete;
  NetClock& operator=(const NetClock&) = delete;

  [[nodiscard]] Nanos now() const override;
  [[nodiscard]] WallTime wallNow() const override;
  [[nodiscard]] bool isManual() const override { return false; }

  /// \brief Waits up to `timeout` for the first synchronisation; false when none came.
  [[nodiscard]] bool waitForSync(Nanos timeout) const;
  [[nodiscard]] bool synced() const;
  /// \brief This clock minus this node's own monotonic clock, now.
  [[nodiscard]] Nanos offset() const;

 private:
  NetClock() = default;
  void* clock_ = nullptr;  // GstClock* (a GstNetClientClock), owned
};

}  // namespace basalt::media
