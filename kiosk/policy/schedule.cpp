#include "kiosk/policy/schedule.h"

#include <algorithm>

namespace basalt::kiosk {

Result<Schedule> Schedule::create(const ScheduleSpec& spec) {
  auto zone = TimeZone::load(spec.timezone);
  if (!zone) return std::unexpected(zone.error());
  return Schedule(spec, std::move(*zone));
}

Schedule::Schedule(const ScheduleSpec& spec, TimeZone zone)
    : week_(spec.week), exceptions_(spec.exceptions), zone_(std::move(zone)) {
  std::sort(exceptions_.begin(), exceptions_.end(),
            [](const ExceptionDay& a, const ExceptionDay& b) { return a.date < b.date; });
}

const std::vector<TimeRange>& Schedule::hoursOn(const LocalTime& local) const {
  const Date date{local.year, local.month, local.day};
  const auto it = std::lower_bound(exceptions_.begin(), exceptions_.end(), date,
                                   [](const ExceptionDay& e, const Date& d) { return e.date < d; });
  if (it != exceptions_.end() && it->date == date) return it->hours;
  return week_[local.weekday];
}

bool Schedule::isOpen(WallTime t) const {
  const LocalTime local = zone_.toLocal(t);
  for (const TimeRange& r : hoursOn(local)) {
    if (local.secondOfDay >= r.begin * 60 && local.secondOfDay < r.end * 60) return true;
  }
  return false;
}

std::optional<WallTime> Schedule::nextChange(WallTime t, std::chrono::minutes horizon) const {
  // Opening hours and zone offsets change on whole minutes: step minute by minute.
  const bool now = isOpen(t);
  auto minute = std::chrono::ceil<std::chrono::minutes>(t);
  if (minute == t) minute += std::chrono::minutes(1);
  for (std::chrono::minutes step{0}; step < horizon; ++step) {
    const WallTime candidate = minute + step;
    if (isOpen(candidate) != now) return candidate;
  }
  return std::nullopt;
}

}  // namespace basalt::kiosk
