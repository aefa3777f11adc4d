#pragma once

/// \file
/// \brief Running under systemd (a `Type=notify` service with `WatchdogSec=`): READY=1 once the
/// first frame is on screen, STATUS= lines an operator reads in `systemctl status`, WATCHDOG=1
/// pings from the frame loop itself (so a hung loop gets the process restarted, not just a
/// crashed one), RELOADING=1 around a SIGHUP reload and STOPPING=1 on the way out; and log
/// records to the journal with structured fields when systemd connected stderr to it.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "kiosk/loop/frame_loop.h"
#include "runtime/clock.h"

namespace basalt::kiosk {

/// \brief The service manager's side of a run. Harmless when there is none: every call then
/// does nothing.
///
/// Threading: the frame loop's thread.
class Supervisor final : public FrameParticipant {
 public:
  /// \brief Reads $NOTIFY_SOCKET and $WATCHDOG_USEC/$WATCHDOG_PID (through libsystemd).
  static std::unique_ptr<Supervisor> fromEnvironment();

  /// \brief True when a service manager listens ($NOTIFY_SOCKET is set).
  [[nodiscard]] bool notifying() const { return notifying_; }
  /// \brief How often the manager expects a ping, when it does.
  [[nodiscard]] std::optional<Nanos> watchdogTimeout() const { return watchdog_; }
  [[nodiscard]] std::uint64_t pingsSent() const { return pings_; }
  /// \brief Watchdog pings sent while the loop held its picture (whileHolding).
  [[nodiscard]] std::uint64_t pingsWhileHolding() const { return holdingPings_; }

  /// \brief STATUS=...; sent only when it changed.
  void status(std::string_view text);
  /// \brief RELOADING=1 with the monotonic time, as systemd expects for a reload.
  void reloading();
  /// \brief READY=1 again after a reload (and the status).
  void reloaded(std::string_view text);
  /// \brief STOPPING=1.
  void stopping();

  /// \brief READY=1 after the first frame; a watchdog ping every half timeout.
  void afterPresent(const FrameContext& frame) override;
  /// \brief A frame-locked follower holding its picture for a lost leader is alive: its loop
  /// still pings, so that a long leader outage does not get every follower restarted.
  void whileHolding() override;

 private:
  Supervisor(bool notifying, std::optional<Nanos> watchdog);
  void notify(const std::string& message);

  bool notifying_;
  std::optional<Nanos> watchdog_;
  SystemClock wall_;  // the watchdog is real time, whatever clock the show runs on
  Nanos lastPing_{0};
  bool ready_ = false;
  std::uint64_t pings_ = 0;
  std::uint64_t holdingPings_ = 0;
  /// Pings when half the watchdog time has passed since the last; true when it did.
  bool pingIfDue();
  std::string status_;
};

/// \brief True when systemd connected stderr to the journal ($JOURNAL_STREAM names stderr's
/// device and inode).
bool stderrIsJournal();

/// \brief Sends log records to the journal with fields (PRIORITY, SYSLOG_IDENTIFIER=basalt,
/// BASALT_CATEGORY, BASALT_LEVEL, BASALT_SHOW) instead of writing lines to stderr. Records
/// the journal refuses are written to stderr.
void logToJournal(std::string_view showName);

}  // namespace basalt::kiosk
