#pragma once

/// \file
/// \brief Opening hours: a week of ranges per weekday and exception dates, read in the show's
/// time zone. Pure calendar logic on the time it is given (the injected Clock's wallNow()), so
/// a week of opening and closing is tested in seconds.

#include <chrono>
#include <optional>
#include <vector>

#include "kiosk/manifest/manifest.h"
#include "kiosk/manifest/time_zone.h"
#include "runtime/clock.h"
#include "runtime/error.h"

namespace basalt::kiosk {

/// \brief When the exhibit is open.
///
/// A day's hours are its exception's when the local date has one, otherwise its weekday's.
/// Ranges are read on the local wall clock, so daylight-saving changes move the UTC opening
/// time as visitors expect. Threading: immutable after creation; safe from any thread.
class Schedule {
 public:
  /// \brief Loads the spec's time zone; fails when it does not exist.
  static Result<Schedule> create(const ScheduleSpec& spec);
  Schedule(const ScheduleSpec& spec, TimeZone zone);

  [[nodiscard]] bool isOpen(WallTime t) const;
  /// \brief The ranges that apply on the local date of `local`.
  [[nodiscard]] const std::vector<TimeRange>& hoursOn(const LocalTime& local) const;
  /// \brief The first moment after `t` (to the minute) when isOpen() changes, looking at most
  /// `horizon` ahead; empty when it does not change in that time.
  [[nodiscard]] std::optional<WallTime> nextChange(WallTime t,
                                                   std::chrono::minutes horizon = std::chrono::hours(24 * 8)) const;
  [[nodiscard]] const TimeZone& zone() const { return zone_; }

 private:
  std::array<std::vector<TimeRange>, 7> week_;
  std::vector<ExceptionDay> exceptions_;  // sorted by date
  TimeZone zone_;
};

}  // namespace basalt::kiosk
