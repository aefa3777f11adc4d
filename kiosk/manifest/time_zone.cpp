// Time zones from the system's tz database, read by cctz (Debian's libcctz): the TZif files and
// the POSIX rule in their footer, which covers the years after the table ends. Basalt finds the
// file itself ($TZDIR, default /usr/share/zoneinfo), so that a zone that does not exist and a
// file that is damaged get different advice, and hands cctz the full path. cctz keeps every
// zone it has loaded (and every file it could not read) until the process ends.

#include "kiosk/manifest/time_zone.h"

#include <cstdlib>
#include <filesystem>
#include <system_error>

#include <cctz/civil_time.h>
#include <cctz/time_zone.h>
#include <fmt/format.h>
#include <fmt/std.h>

namespace basalt::kiosk {

struct TimeZone::Rules {
  cctz::time_zone zone;
};

namespace {

constexpr cctz::civil_day kEpochDay{1970, 1, 1};
// LocalTime counts weekdays from Monday, as cctz does.
static_assert(static_cast<int>(cctz::weekday::monday) == 0 && static_cast<int>(cctz::weekday::sunday) == 6);

}  // namespace

std::int64_t daysFromCivil(int year, unsigned month, unsigned day) {
  return cctz::civil_day(year, month, day) - kEpochDay;
}

void civilFromDays(std::int64_t days, int& year, unsigned& month, unsigned& day) {
  const cctz::civil_day date = kEpochDay + days;
  year = static_cast<int>(date.year());
  month = static_cast<unsigned>(date.month());
  day = static_cast<unsigned>(date.day());
}

TimeZone::TimeZone() = default;

Result<TimeZone> TimeZone::load(std::string_view name) {
  if (name.empty()) return fail(Errc::kInvalidArgument, "empty time zone name; use a name like Europe/Paris or UTC");
  if (name == "UTC" || name == "Etc/UTC") return TimeZone();
  if (name.front() == '/' || name.find("..") != std::string_view::npos) {
    return fail(
        Errc::kInvalidArgument,
        fmt::format("'{}' is not a time zone name; use a name like Europe/Paris, as in /usr/share/zoneinfo", name));
  }
  const char* dirEnv = std::getenv("TZDIR");
  const std::filesystem::path dir = dirEnv && *dirEnv ? dirEnv : "/usr/share/zoneinfo";
  std::error_code ec;
  const std::filesystem::path file = std::filesystem::absolute(dir / name, ec);
  if (ec || !std::filesystem::is_regular_file(file, ec)) {
    return fail(Errc::kNotFound, fmt::format("unknown time zone '{}' (no {}); use a name like Europe/Paris, or "
                                             "install the tzdata package",
                                             name, dir / name));
  }
  // An absolute path: cctz opens it as it is rather than looking in $TZDIR again.
  cctz::time_zone zone;
  if (!cctz::load_time_zone(file.string(), &zone)) {
    return fail(Errc::kParse, fmt::format("time zone file {} for '{}' is damaged or not a TZif file; reinstall the "
                                          "tzdata package and restart Basalt",
                                          file, name));
  }
  TimeZone result;
  result.name_ = std::string(name);
  result.rules_ = std::make_shared<const Rules>(Rules{zone});
  return result;
}

int TimeZone::offsetAt(std::int64_t utcSeconds, bool* dst) const {
  if (!rules_) {
    if (dst) *dst = false;
    return 0;
  }
  const auto lookup = rules_->zone.lookup(cctz::time_point<cctz::seconds>(cctz::seconds(utcSeconds)));
  if (dst) *dst = lookup.is_dst;
  return lookup.offset;
}

LocalTime TimeZone::toLocal(WallTime t) const {
  const cctz::time_zone zone = rules_ ? rules_->zone : cctz::utc_time_zone();
  const auto lookup = zone.lookup(std::chrono::floor<cctz::seconds>(t));
  const cctz::civil_second& cs = lookup.cs;
  LocalTime local;
  local.year = static_cast<int>(cs.year());
  local.month = static_cast<unsigned>(cs.month());
  local.day = static_cast<unsigned>(cs.day());
  local.weekday = static_cast<unsigned>(cctz::get_weekday(cctz::civil_day(cs)));
  local.secondOfDay = cs.hour() * 3600 + cs.minute() * 60 + cs.second();
  local.utcOffset = lookup.offset;
  local.dst = lookup.is_dst;
  return local;
}

}  // namespace basalt::kiosk
