#pragma once

/// \file
/// \brief Kiosk policy: what an unattended exhibit shows right now. Opening hours decide open
/// or closed (and, when closed, a standby show, black, or the display off); while open, the
/// attract loop plays until a visitor touches an input, then the playlist plays until nobody
/// has touched anything for the idle time-out. Items move on after their duration or when they
/// end by themselves.
///
/// Pure logic on the times it is given (the frame's time on the injected Clock and the
/// Clock's calendar time), so a week of it runs in seconds under a ManualClock.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "kiosk/manifest/manifest.h"
#include "kiosk/policy/schedule.h"
#include "runtime/clock.h"

namespace basalt::kiosk {

enum class KioskMode : std::uint8_t { kClosed, kAttract, kActive };
std::string_view kioskModeName(KioskMode mode);

/// \brief What the display does.
enum class DisplayState : std::uint8_t { kOn, kBlack, kOff };
std::string_view displayStateName(DisplayState state);

/// \brief What should be on screen now.
struct Programme {
  KioskMode mode = KioskMode::kActive;
  DisplayState display = DisplayState::kOn;
  const PlaylistItem* item = nullptr;  ///< null while black or off
  std::size_t index = 0;               ///< the item's place in its list
  std::size_t count = 0;               ///< items in the current list
  Nanos itemStart{0};                  ///< Clock time the item started; position = now - itemStart
  std::uint64_t generation = 0;        ///< changes whenever the item or the display changes
};

/// \brief Where the show was, for resuming after a restart.
struct ResumePoint {
  KioskMode mode = KioskMode::kActive;
  std::size_t index = 0;
  std::string item;  ///< the item's name, to recognise it after the manifest changed
  Nanos position{0};
};

/// \brief The kiosk's state machine.
///
/// Threading: the frame loop's thread.
class KioskPolicy {
 public:
  /// \brief `schedule` empty means always open.
  KioskPolicy(const Manifest& manifest, std::optional<Schedule> schedule);
  // current_.item points into the lists: copies would point into the original.
  KioskPolicy(const KioskPolicy&) = delete;
  KioskPolicy& operator=(const KioskPolicy&) = delete;

  /// \brief Decides the first programme. With `resume`, continues at its item and position
  /// when the schedule allows that mode now and the item is still there.
  void start(Nanos now, WallTime wall, const std::optional<ResumePoint>& resume = std::nullopt);
  /// \brief Applies opening hours, item durations and the idle time-out. True when the
  /// programme changed.
  bool update(Nanos now, WallTime wall);
  /// \brief A visitor touched an input. Wakes the exhibit from its attract loop. True when the
  /// programme changed.
  bool noteInput(Nanos now);
  /// \brief The item ended by itself (a script's quit, a movie's end): the next one plays.
  bool itemEnded(Nanos now);
  /// \brief The item could not be played: the next one plays; when every item of the list has
  /// failed in a row the screen goes black until the mode changes.
  bool itemFailed(Nanos now);
  /// \brief An operator's or a button's next / previous. False when there is nothing to move
  /// (closed, or a list of one).
  bool next(Nanos now);
  bool previous(Nanos now);
  /// \brief A frame-locked follower plays what its leader plays: `mode`, `display`, and the item
  /// named `item` (found by name in the mode's list, else at `index`; none when `hasItem` is
  /// false) since `itemStart`. True when that changed what plays.
  bool follow(KioskMode mode, DisplayState display, bool hasItem, std::size_t index, std::string_view item,
              Nanos itemStart);

  [[nodiscard]] const Programme& current() const { return current_; }
  [[nodiscard]] Nanos position(Nanos now) const { return now - current_.itemStart; }
  [[nodiscard]] ResumePoint resumePoint(Nanos now) const;
  [[nodiscard]] Nanos lastInput() const { return lastInput_; }
  /// \brief True when the schedule says open at `wall` (always, without a schedule).
  [[nodiscard]] bool openAt(WallTime wall) const { return !schedule_ || schedule_->isOpen(wall); }
  [[nodiscard]] const std::optional<Schedule>& schedule() const { return schedule_; }
  /// \brief "open, attract loop: 'attract' (1/1)" and the like, for STATUS= and the status page.
  [[nodiscard]] std::string describe() const;

 private:
  [[nodiscard]] const std::vector<PlaylistItem>& listFor(KioskMode mode) const;
  void enter(KioskMode mode, std::size_t index, Nanos now);
  void play(std::size_t index, Nanos now);
  bool step(int direction, Nanos now);

  std::optional<Schedule> schedule_;
  std::vector<PlaylistItem> programme_;  // the playlist, or the show's entry alone
  std::vector<PlaylistItem> attract_;
  std::vector<PlaylistItem> standby_;
  bool hasAttract_ = false;
  Nanos idleTimeout_{0};
  OutsideHours outside_ = OutsideHours::kBlack;
  Programme current_;
  Nanos lastInput_{0};
  std::size_t failuresInARow_ = 0;
};

}  // namespace basalt::kiosk
