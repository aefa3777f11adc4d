#pragma once

/// \file
/// \brief Time zones for opening hours: the system's tz database (under $TZDIR or
/// /usr/share/zoneinfo), read through cctz. libstdc++ 12 has no `std::chrono::tzdb`, and the
/// process-wide `TZ` variable cannot serve two shows (a reload) or a test that runs a week in
/// several zones, so each zone is a value of its own.

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "runtime/clock.h"
#include "runtime/error.h"

namespace basalt::kiosk {

/// \brief A calendar moment in some zone.
struct LocalTime {
  int year = 1970;
  unsigned month = 1;    ///< 1..12
  unsigned day = 1;      ///< 1..31
  unsigned weekday = 3;  ///< 0 = Monday ... 6 = Sunday
  int secondOfDay = 0;   ///< 0..86399
  int utcOffset = 0;     ///< seconds east of UTC in force
  bool dst = false;
};

/// \brief A time zone: its offsets from UTC through history and the rule that continues them.
/// Copies are cheap and share the loaded zone; any thread may use one.
class TimeZone {
 public:
  /// \brief UTC.
  TimeZone();

  /// \brief Loads `name` ("Europe/Paris", "UTC") from $TZDIR or /usr/share/zoneinfo. Names
  /// cannot leave that folder. A zone once loaded is kept for the life of the process (a tzdata
  /// update takes effect at the next start).
  static Result<TimeZone> load(std::string_view name);

  [[nodiscard]] const std::string& name() const { return name_; }
  /// \brief The offset east of UTC in force at the UTC instant, in seconds.
  [[nodiscard]] int offsetAt(std::int64_t utcSeconds, bool* dst = nullptr) const;
  /// \brief The local calendar time at `t`.
  [[nodiscard]] LocalTime toLocal(WallTime t) const;

 private:
  struct Rules;  // the cctz zone; kept out of this header so that only this room includes cctz
  std::string name_ = "UTC";
  std::shared_ptr<const Rules> rules_;  // null: UTC
};

/// \brief Days since 1970-01-01 of a proleptic Gregorian date, and back. An out-of-range month
/// or day counts on into the next (2026-02-30 is 2026-03-02).
std::int64_t daysFromCivil(int year, unsigned month, unsigned day);
void civilFromDays(std::int64_t days, int& year, unsigned& month, unsigned& day);

}  // namespace basalt::kiosk
