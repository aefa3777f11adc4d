#pragma once

/// \file
/// \brief Time zones for opening hours: the system's tz database (TZif files under
/// /usr/share/zoneinfo, RFC 8536) with its POSIX TZ rule for times past the table. libstdc++ 12
/// has no `std::chrono::tzdb`, and the process-wide `TZ` variable cannot serve two shows (a
/// reload) or a test that runs a week in several zones, so Basalt reads the files itself.

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

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

/// \brief A POSIX TZ rule ("CET-1CEST,M3.5.0,M10.5.0/3"): a standard offset and optionally a
/// daylight-saving offset with the rules that start and end it each year.
struct PosixTzRule {
  struct Transition {
    enum class Form : std::uint8_t { kJulianNoLeap, kZeroBasedDay, kMonthWeekDay };
    Form form = Form::kMonthWeekDay;
    int day = 0;      ///< Jn: 1..365; n: 0..365; Mm.w.d: d 0..6 (0 = Sunday)
    int week = 0;     ///< Mm.w.d: 1..5 (5 = last)
    int month = 0;    ///< Mm.w.d: 1..12
    int time = 7200;  ///< local seconds after midnight (may be negative or past 24 h)
  };
  int stdOffset = 0;  ///< seconds east of UTC
  bool hasDst = false;
  int dstOffset = 0;
  Transition start;
  Transition end;

  /// \brief Parses the rule; errors say which part is wrong.
  static Result<PosixTzRule> parse(std::string_view text);
  /// \brief The offset in force at `utcSeconds`, and whether it is daylight-saving time.
  [[nodiscard]] int offsetAt(std::int64_t utcSeconds, bool* dst = nullptr) const;
};

/// \brief A time zone: a table of offset changes and the rule that continues it.
class TimeZone {
 public:
  /// \brief UTC.
  TimeZone();

  /// \brief Loads `name` ("Europe/Paris", "UTC") from $TZDIR or /usr/share/zoneinfo. Names
  /// cannot leave that folder.
  static Result<TimeZone> load(std::string_view name);
  /// \brief Reads the contents of a TZif file (versions 1 to 4).
  static Result<TimeZone> fromTzif(std::span<const std::uint8_t> data, std::string name);
  /// \brief A zone that only follows a POSIX TZ rule.
  static Result<TimeZone> fromPosix(std::string_view rule);

  [[nodiscard]] const std::string& name() const { return name_; }
  /// \brief The offset east of UTC in force at the UTC instant, in seconds.
  [[nodiscard]] int offsetAt(std::int64_t utcSeconds, bool* dst = nullptr) const;
  /// \brief The local calendar time at `t`.
  [[nodiscard]] LocalTime toLocal(WallTime t) const;

 private:
  struct Type {
    int offset = 0;
    bool dst = false;
  };
  std::string name_ = "UTC";
  std::vector<std::int64_t> transitions_;  // UTC seconds, ascending
  std::vector<std::uint8_t> typeOf_;       // type index in force from each transition
  std::vector<Type> types_;
  bool hasRule_ = false;
  PosixTzRule rule_;
};

/// \brief Days since 1970-01-01 of a proleptic Gregorian date, and back.
std::int64_t daysFromCivil(int year, unsigned month, unsigned day);
void civilFromDays(std::int64_t days, int& year, unsigned& month, unsigned& day);

}  // namespace basalt::kiosk
