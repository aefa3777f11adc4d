#pragma once

/// \file
/// \brief The OSC output: the node's news sent to the `[[osc.send]]` destinations so that a show
/// controller can follow it: an item started, a device lost and back, the frame-lock state, and
/// chosen figures at a set rate. Read from the StatusBoard, on a thread of its own.

#include <condition_variable>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "kiosk/manifest/manifest.h"
#include "kiosk/status/status_board.h"
#include "runtime/error.h"

namespace basalt::kiosk {

/// \brief Sends to every destination until destroyed.
///
/// Threading: its thread reads the board (showStatus, deviceStatus, lockFigures, frameFigures,
/// oscFigures: copies under the board's mutex) every 50 ms and sends with liblo; the frame loop
/// does nothing for it. A destination that cannot be reached is logged once and counted
/// (`basalt_osc_send_failures_total`); sending goes on.
class OscOutput {
 public:
  /// \brief One liblo address per destination (a host name is looked up when first sent to).
  [[nodiscard]] static Result<std::unique_ptr<OscOutput>> start(const std::vector<OscSendSpec>& destinations,
                                                                StatusBoard& board);
  ~OscOutput();
  OscOutput(const OscOutput&) = delete;
  OscOutput& operator=(const OscOutput&) = delete;

  struct Destination;

 private:
  explicit OscOutput(StatusBoard& board);
  void run();

  StatusBoard& board_;
  std::vector<std::unique_ptr<Destination>> destinations_;  // the output's thread only (after start)
  std::mutex mutex_;                                        // guards stopping_
  std::condition_variable wake_;
  bool stopping_ = false;
  std::thread thread_;
};

/// \brief The lock's state as sent: "leader", "following", "holding" (the leader is lost and this
/// node holds its picture) or "waiting" (a follower that does not hear its leader).
[[nodiscard]] std::string_view oscLockState(const FrameLockFigures& figures);

}  // namespace basalt::kiosk
