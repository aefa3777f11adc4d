// Time zones from the system's tz database: TZif files (RFC 8536, versions 1-4) and the POSIX
// TZ rule in their footer, which covers the years after the table ends.

#include "kiosk/manifest/time_zone.h"

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <iterator>

#include <fmt/format.h>
#include <fmt/std.h>

namespace basalt::kiosk {

std::int64_t daysFromCivil(int year, unsigned month, unsigned day) {
  // Howard Hinnant's days_from_civil.
  const std::int64_t y = static_cast<std::int64_t>(year) - (month <= 2 ? 1 : 0);
  const std::int64_t era = (y >= 0 ? y : y - 399) / 400;
  const auto yoe = static_cast<unsigned>(y - era * 400);
  const unsigned doy = (153 * (month > 2 ? month - 3 : month + 9) + 2) / 5 + day - 1;
  const unsigned doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + static_cast<std::int64_t>(doe) - 719468;
}

void civilFromDays(std::int64_t days, int& year, unsigned& month, unsigned& day) {
  days += 719468;
  const std::int64_t era = (days >= 0 ? days : days - 146096) / 146097;
  const auto doe = static_cast<unsigned>(days - era * 146097);
  const unsigned yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;
  const unsigned doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
  const unsigned mp = (5 * doy + 2) / 153;
  day = doy - (153 * mp + 2) / 5 + 1;
  month = mp < 10 ? mp + 3 : mp - 9;
  year = static_cast<int>(static_cast<std::int64_t>(yoe) + era * 400 + (month <= 2 ? 1 : 0));
}

namespace {

constexpr std::int64_t kDay = 86400;

bool isLeap(int year) { return (year % 4 == 0 && year % 100 != 0) || year % 400 == 0; }

/// Floor division for negative seconds.
std::int64_t floorDiv(std::int64_t a, std::int64_t b) { return a / b - ((a % b != 0) && ((a < 0) != (b < 0))); }

// ---- POSIX TZ rule parsing ------------------------------------------------------------------

class RuleParser {
 public:
  explicit RuleParser(std::string_view text) : text_(text) {}

  Result<PosixTzRule> parse() {
    PosixTzRule rule;
    if (!name()) return bad("a zone name (three or more letters, or <+0330>)");
    int offset = 0;
    if (!hms(offset, true)) return bad("the standard offset (hours west of UTC, e.g. 5 or -1)");
    rule.stdOffset = -offset;  // POSIX counts west as positive
    if (atEnd()) return rule;
    if (!name()) return bad("a daylight-saving zone name");
    rule.hasDst = true;
    rule.dstOffset = rule.stdOffset + 3600;
    if (!atEnd() && peek() != ',') {
      if (!hms(offset, true)) return bad("the daylight-saving offset");
      rule.dstOffset = -offset;
    }
    if (atEnd()) {
      // No rule given: the US rules that POSIX implementations assume.
      rule.start = {PosixTzRule::Transition::Form::kMonthWeekDay, 0, 2, 3, 7200};
      rule.end = {PosixTzRule::Transition::Form::kMonthWeekDay, 0, 1, 11, 7200};
      return rule;
    }
    if (!take(',') || !transition(rule.start)) return bad("the start rule (Mm.w.d[/time], Jn or n)");
    if (!take(',') || !transition(rule.end)) return bad("the end rule (Mm.w.d[/time], Jn or n)");
    if (!atEnd()) return bad("the end of the rule");
    return rule;
  }

 private:
  [[nodiscard]] bool atEnd() const { return pos_ >= text_.size(); }
  [[nodiscard]] char peek() const { return atEnd() ? '\0' : text_[pos_]; }
  bool take(char c) {
    if (peek() != c) return false;
    ++pos_;
    return true;
  }
  std::unexpected<Error> bad(std::string_view expected) const {
    return fail(Errc::kParse,
                fmt::format("time zone rule '{}': expected {} at character {}", text_, expected, pos_ + 1));
  }
  bool name() {
    if (take('<')) {
      const auto close = text_.find('>', pos_);
      if (close == std::string_view::npos || close - pos_ < 3) return false;
      pos_ = close + 1;
      return true;
    }
    const std::size_t start = pos_;
    while (!atEnd() && ((peek() >= 'A' && peek() <= 'Z') || (peek() >= 'a' && peek() <= 'z'))) ++pos_;
    return pos_ - start >= 3;
  }
  bool number(int& out, int maxDigits) {
    const std::size_t start = pos_;
    out = 0;
    while (!atEnd() && peek() >= '0' && peek() <= '9' && pos_ - start < static_cast<std::size_t>(maxDigits)) {
      out = out * 10 + (peek() - '0');
      ++pos_;
    }
    return pos_ > start;
  }
  // [+-]hh[:mm[:ss]]; hours up to 167 for transition times (RFC 8536 extension).
  bool hms(int& seconds, bool allowSign) {
    int sign = 1;
    if (allowSign && (peek() == '+' || peek() == '-')) sign = text_[pos_++] == '-' ? -1 : 1;
    int h = 0;
    int m = 0;
    int s = 0;
    if (!number(h, 3) || h > 167) return false;
    if (take(':')) {
      if (!number(m, 2) || m > 59) return false;
      if (take(':') && (!number(s, 2) || s > 59)) return false;
    }
    seconds = sign * (h * 3600 + m * 60 + s);
    return true;
  }
  bool transition(PosixTzRule::Transition& t) {
    using Form = PosixTzRule::Transition::Form;
    if (take('M')) {
      t.form = Form::kMonthWeekDay;
      if (!number(t.month, 2) || t.month < 1 || t.month > 12 || !take('.')) return false;
      if (!number(t.week, 1) || t.week < 1 || t.week > 5 || !take('.')) return false;
      if (!number(t.day, 1) || t.day > 6) return false;
    } else if (take('J')) {
      t.form = Form::kJulianNoLeap;
      if (!number(t.day, 3) || t.day < 1 || t.day > 365) return false;
    } else {
      t.form = Form::kZeroBasedDay;
      if (!number(t.day, 3) || t.day > 365) return false;
    }
    t.time = 7200;
    if (take('/') && !hms(t.time, true)) return false;
    return true;
  }

  std::string_view text_;
  std::size_t pos_ = 0;
};

/// Local seconds since the epoch (in the offset of the day) at which `t` happens in `year`.
std::int64_t transitionLocalSeconds(const PosixTzRule::Transition& t, int year) {
  using Form = PosixTzRule::Transition::Form;
  std::int64_t days = 0;
  switch (t.form) {
    case Form::kJulianNoLeap: {
      // Day 1..365, February 29 never counted.
      int d = t.day;
      if (isLeap(year) && d >= 60) ++d;
      days = daysFromCivil(year, 1, 1) + d - 1;
      break;
    }
    case Form::kZeroBasedDay: days = daysFromCivil(year, 1, 1) + t.day; break;
    case Form::kMonthWeekDay: {
      const std::int64_t first = daysFromCivil(year, static_cast<unsigned>(t.month), 1);
      // 1970-01-01 was a Thursday (4, with Sunday = 0).
      const int firstWeekday = static_cast<int>(((first % 7) + 7 + 4) % 7);
      int day = 1 + ((t.day - firstWeekday) + 7) % 7 + (t.week - 1) * 7;
      static constexpr int kMonthDays[] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
      int monthDays = kMonthDays[t.month - 1];
      if (t.month == 2 && isLeap(year)) ++monthDays;
      while (day > monthDays) day -= 7;
      days = first + day - 1;
      break;
    }
  }
  return days * kDay + t.time;
}

std::uint32_t be32(const std::uint8_t* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) | std::uint32_t{p[3]};
}
std::int64_t be64(const std::uint8_t* p) {
  return static_cast<std::int64_t>((static_cast<std::uint64_t>(be32(p)) << 32) | be32(p + 4));
}

}  // namespace

Result<PosixTzRule> PosixTzRule::parse(std::string_view text) { return RuleParser(text).parse(); }

int PosixTzRule::offsetAt(std::int64_t utcSeconds, bool* dst) const {
  if (dst) *dst = false;
  if (!hasDst) return stdOffset;
  int year = 0;
  unsigned month = 0;
  unsigned day = 0;
  civilFromDays(floorDiv(utcSeconds + stdOffset, kDay), year, month, day);
  // Start is given in standard time, end in daylight-saving time.
  const std::int64_t startAt = transitionLocalSeconds(start, year) - stdOffset;
  const std::int64_t endAt = transitionLocalSeconds(end, year) - dstOffset;
  const bool inDst = startAt < endAt ? (utcSeconds >= startAt && utcSeconds < endAt)    // northern
                                     : !(utcSeconds >= endAt && utcSeconds < startAt);  // southern
  if (dst) *dst = inDst;
  return inDst ? dstOffset : stdOffset;
}

TimeZone::TimeZone() = default;

Result<TimeZone> TimeZone::fromPosix(std::string_view rule) {
  auto parsed = PosixTzRule::parse(rule);
  if (!parsed) return std::unexpected(parsed.error());
  TimeZone zone;
  zone.name_ = std::string(rule);
  zone.hasRule_ = true;
  zone.rule_ = *parsed;
  return zone;
}

Result<TimeZone> TimeZone::fromTzif(std::span<const std::uint8_t> data, std::string name) {
  const auto bad = [&name](std::string_view why) {
    return fail(Errc::kParse,
                fmt::format("time zone file for '{}' is damaged: {}; reinstall the tzdata package", name, why));
  };
  if (data.size() < 44 || data[0] != 'T' || data[1] != 'Z' || data[2] != 'i' || data[3] != 'f') {
    return bad("it does not start with 'TZif'");
  }
  const std::uint8_t version = data[4];
  struct Counts {
    std::uint32_t isut, isstd, leap, time, type, chars;
  };
  const auto counts = [&](std::size_t at) {
    const std::uint8_t* p = data.data() + at + 20;
    return Counts{be32(p), be32(p + 4), be32(p + 8), be32(p + 12), be32(p + 16), be32(p + 20)};
  };
  const auto blockSize = [](const Counts& c, std::size_t timeBytes) {
    return std::size_t{c.time} * timeBytes + c.time + std::size_t{c.type} * 6 + c.chars +
           std::size_t{c.leap} * (timeBytes + 4) + c.isstd + c.isut;
  };
  Counts c = counts(0);
  std::size_t at = 44;
  std::size_t timeBytes = 4;
  if (version >= '2') {
    // Skip the 32-bit block and read the 64-bit one.
    at += blockSize(c, 4);
    if (data.size() < at + 44) return bad("the second header is missing");
    c = counts(at);
    at += 44;
    timeBytes = 8;
  }
  if (c.type == 0 || c.type > 256) return bad("it has no local time types");
  if (data.size() < at + blockSize(c, timeBytes)) return bad("it is shorter than its header says");

  TimeZone zone;
  zone.name_ = std::move(name);
  zone.transitions_.reserve(c.time);
  const std::uint8_t* p = data.data() + at;
  for (std::uint32_t i = 0; i < c.time; ++i, p += timeBytes) {
    zone.transitions_.push_back(timeBytes == 8 ? be64(p) : static_cast<std::int32_t>(be32(p)));
  }
  zone.typeOf_.assign(p, p + c.time);
  p += c.time;
  for (std::uint32_t i = 0; i < c.type; ++i, p += 6) {
    zone.types_.push_back({static_cast<std::int32_t>(be32(p)), p[4] != 0});
  }
  for (const std::uint8_t t : zone.typeOf_) {
    if (t >= c.type) return bad("a transition names a type that does not exist");
  }
  if (!std::is_sorted(zone.transitions_.begin(), zone.transitions_.end())) return bad("transitions out of order");
  at += blockSize(c, timeBytes);
  if (version >= '2' && at < data.size() && data[at] == '\n') {
    const auto* begin = data.data() + at + 1;
    const auto* end = std::find(begin, data.data() + data.size(), std::uint8_t{'\n'});
    const std::string_view footer(reinterpret_cast<const char*>(begin), static_cast<std::size_t>(end - begin));
    if (!footer.empty()) {
      auto rule = PosixTzRule::parse(footer);
      if (!rule) return bad(rule.error().message());
      zone.hasRule_ = true;
      zone.rule_ = *rule;
    }
  }
  return zone;
}

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
  const std::filesystem::path file = dir / name;
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    return fail(Errc::kNotFound, fmt::format("unknown time zone '{}' (no {}); use a name like Europe/Paris, or "
                                             "install the tzdata package",
                                             name, file));
  }
  std::vector<std::uint8_t> bytes;
  char buffer[4096];
  while (in.read(buffer, sizeof buffer) || in.gcount() > 0) {
    bytes.insert(bytes.end(), buffer, buffer + in.gcount());
    if (bytes.size() > (1u << 20)) return fail(Errc::kParse, fmt::format("time zone file {} is too large", file));
  }
  return fromTzif(bytes, std::string(name));
}

int TimeZone::offsetAt(std::int64_t utcSeconds, bool* dst) const {
  if (dst) *dst = false;
  if (transitions_.empty() || utcSeconds < transitions_.front()) {
    if (transitions_.empty() && hasRule_) return rule_.offsetAt(utcSeconds, dst);
    if (types_.empty()) return 0;
    if (dst) *dst = types_.front().dst;
    return types_.front().offset;
  }
  if (utcSeconds >= transitions_.back() && hasRule_) return rule_.offsetAt(utcSeconds, dst);
  const auto it = std::upper_bound(transitions_.begin(), transitions_.end(), utcSeconds);
  const auto index = static_cast<std::size_t>(std::distance(transitions_.begin(), it)) - 1;
  const Type& type = types_[typeOf_[index]];
  if (dst) *dst = type.dst;
  return type.offset;
}

LocalTime TimeZone::toLocal(WallTime t) const {
  const std::int64_t utc =
      std::chrono::duration_cast<std::chrono::seconds>(t.time_since_epoch()).count() -
      (t.time_since_epoch() < WallTime::duration::zero() &&
               std::chrono::duration_cast<std::chrono::seconds>(t.time_since_epoch()) != t.time_since_epoch()
           ? 1
           : 0);
  LocalTime local;
  local.utcOffset = offsetAt(utc, &local.dst);
  const std::int64_t seconds = utc + local.utcOffset;
  const std::int64_t days = floorDiv(seconds, kDay);
  civilFromDays(days, local.year, local.month, local.day);
  local.secondOfDay = static_cast<int>(seconds - days * kDay);
  // 1970-01-01 was a Thursday: 3 with Monday = 0.
  local.weekday = static_cast<unsigned>(((days % 7) + 7 + 3) % 7);
  return local;
}

}  // namespace basalt::kiosk
