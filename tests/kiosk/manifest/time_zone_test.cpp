// Time zones for opening hours, read from the system's tz database: offsets and local dates
// agree with the C library's own conversion for many instants in several zones, in both
// hemispheres and far beyond the table's end (where the POSIX rule in the footer takes over), and
// with zdump's account of every change from 2020 to 2040, to the second.
// Example failures: opening an hour late after the change to summer time; a southern-hemisphere
// zone with daylight-saving time inverted; a damaged TZif file read past its end; TZDIR ignored.

#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

#include "kiosk/manifest/time_zone.h"

namespace basalt::kiosk {
namespace {

WallTime utc(int y, unsigned m, unsigned d, int hour, int minute = 0) {
  return WallTime{
      std::chrono::seconds(daysFromCivil(y, m, d) * 86400 + std::int64_t{hour} * 3600 + std::int64_t{minute} * 60)};
}

TEST(TimeZone, CivilDaysRoundTrip) {
  EXPECT_EQ(daysFromCivil(1970, 1, 1), 0);
  EXPECT_EQ(daysFromCivil(2000, 3, 1), 11017);
  for (std::int64_t days = -800000; days < 800000; days += 997) {
    int y = 0;
    unsigned m = 0;
    unsigned d = 0;
    civilFromDays(days, y, m, d);
    ASSERT_EQ(daysFromCivil(y, m, d), days);
  }
}

TEST(TimeZone, ParisChangesToSummerTimeOnTheLastSundayOfMarch) {
  auto paris = TimeZone::load("Europe/Paris");
  ASSERT_TRUE(paris) << paris.error().describe();
  // 2026-03-29 01:00 UTC: 02:00 CET becomes 03:00 CEST.
  const LocalTime before = paris->toLocal(utc(2026, 3, 29, 0, 59));
  EXPECT_EQ(before.utcOffset, 3600);
  EXPECT_FALSE(before.dst);
  EXPECT_EQ(before.secondOfDay, 1 * 3600 + 59 * 60);
  const LocalTime after = paris->toLocal(utc(2026, 3, 29, 1, 0));
  EXPECT_EQ(after.utcOffset, 7200);
  EXPECT_TRUE(after.dst);
  EXPECT_EQ(after.secondOfDay, 3 * 3600);
  EXPECT_EQ(after.weekday, 6u) << "a Sunday";
  // And back on 2026-10-25 01:00 UTC.
  EXPECT_EQ(paris->toLocal(utc(2026, 10, 25, 0, 59)).utcOffset, 7200);
  EXPECT_EQ(paris->toLocal(utc(2026, 10, 25, 1, 0)).utcOffset, 3600);
}

TEST(TimeZone, SouthernHemisphereSummerSpansTheNewYear) {
  auto sydney = TimeZone::load("Australia/Sydney");
  ASSERT_TRUE(sydney) << sydney.error().describe();
  EXPECT_EQ(sydney->toLocal(utc(2026, 1, 15, 0)).utcOffset, 11 * 3600);
  EXPECT_EQ(sydney->toLocal(utc(2026, 7, 15, 0)).utcOffset, 10 * 3600);
  // The local date runs ahead of UTC: 2026-12-31 14:00 UTC is already New Year's Day.
  const LocalTime ny = sydney->toLocal(utc(2026, 12, 31, 14));
  EXPECT_EQ(ny.year, 2027);
  EXPECT_EQ(ny.month, 1u);
  EXPECT_EQ(ny.day, 1u);
}

TEST(TimeZone, BeyondTheTableTheFooterRuleApplies) {
  auto paris = TimeZone::load("Europe/Paris");
  ASSERT_TRUE(paris);
  EXPECT_EQ(paris->toLocal(utc(2100, 7, 1, 12)).utcOffset, 7200);
  EXPECT_EQ(paris->toLocal(utc(2100, 1, 1, 12)).utcOffset, 3600);
  auto ny = TimeZone::load("America/New_York");
  ASSERT_TRUE(ny);
  EXPECT_EQ(ny->toLocal(utc(2099, 7, 4, 12)).utcOffset, -4 * 3600);
}

/// The C library's conversion, for comparison.
int libcOffset(const char* zone, std::int64_t t) {
  ::setenv("TZ", zone, 1);
  ::tzset();
  std::tm tm{};
  const auto tt = static_cast<std::time_t>(t);
  ::localtime_r(&tt, &tm);
  return static_cast<int>(tm.tm_gmtoff);
}

TEST(TimeZone, AgreesWithTheCLibraryEverywhere) {
  for (const char* name : {"Europe/Paris", "America/New_York", "Australia/Sydney", "Asia/Kolkata", "Pacific/Chatham",
                           "America/Sao_Paulo", "Europe/London", "Africa/Casablanca"}) {
    auto zone = TimeZone::load(name);
    ASSERT_TRUE(zone) << name << ": " << zone.error().describe();
    int mismatches = 0;
    // Every 7 hours and 13 minutes from 1990 to 2060.
    for (std::int64_t t = 631152000; t < 2871763200 && mismatches < 3; t += 7 * 3600 + 13 * 60) {
      const int expected = libcOffset(name, t);
      const int actual = zone->offsetAt(t);
      if (expected != actual) {
        ADD_FAILURE() << name << " at " << t << ": " << actual << " != libc " << expected;
        ++mismatches;
      }
    }
  }
  ::unsetenv("TZ");
}

TEST(TimeZone, BerlinIn2026AsZdumpPrintsIt) {
  // `zdump -v -c 2026,2027 Europe/Berlin` (tzdata 2025b):
  //   Sun Mar 29 00:59:59 2026 UT = Sun Mar 29 01:59:59 2026 CET isdst=0 gmtoff=3600
  //   Sun Mar 29 01:00:00 2026 UT = Sun Mar 29 03:00:00 2026 CEST isdst=1 gmtoff=7200
  //   Sun Oct 25 00:59:59 2026 UT = Sun Oct 25 02:59:59 2026 CEST isdst=1 gmtoff=7200
  //   Sun Oct 25 01:00:00 2026 UT = Sun Oct 25 02:00:00 2026 CET isdst=0 gmtoff=3600
  // The UTC instants as seconds: `date -u -d '2026-03-29 01:00:00' +%s` and so on.
  auto berlin = TimeZone::load("Europe/Berlin");
  ASSERT_TRUE(berlin) << berlin.error().describe();
  struct Row {
    std::int64_t utc;
    unsigned month, day;
    int secondOfDay, offset;
    bool dst;
  };
  for (const Row& row :
       {Row{1774745999, 3, 29, 1 * 3600 + 59 * 60 + 59, 3600, false}, Row{1774746000, 3, 29, 3 * 3600, 7200, true},
        Row{1792889999, 10, 25, 2 * 3600 + 59 * 60 + 59, 7200, true}, Row{1792890000, 10, 25, 2 * 3600, 3600, false}}) {
    const LocalTime local = berlin->toLocal(WallTime{std::chrono::seconds(row.utc)});
    EXPECT_EQ(local.year, 2026) << row.utc;
    EXPECT_EQ(local.month, row.month) << row.utc;
    EXPECT_EQ(local.day, row.day) << row.utc;
    EXPECT_EQ(local.weekday, 6u) << row.utc << " is a Sunday";
    EXPECT_EQ(local.secondOfDay, row.secondOfDay) << row.utc;
    EXPECT_EQ(local.utcOffset, row.offset) << row.utc;
    EXPECT_EQ(local.dst, row.dst) << row.utc;
  }
}

/// What `zdump -v` prints about one instant: the second before and the second of each change.
struct ZdumpLine {
  std::int64_t utc = 0;
  std::tm local{};
  bool dst = false;
  int offset = 0;
};

int monthIndex(const char* name) {
  const std::string months = "JanFebMarAprMayJunJulAugSepOctNovDec";
  const auto at = months.find(name);
  return at == std::string::npos || std::string_view(name).size() != 3 ? -1 : static_cast<int>(at / 3);
}

/// Runs the C library's zdump (Debian's libc-bin) on `zone` for [from, to).
std::vector<ZdumpLine> zdump(const std::string& zone, int from, int to) {
  const std::string command = "zdump -v -c " + std::to_string(from) + "," + std::to_string(to) + " " + zone;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) {
    ADD_FAILURE() << command << " did not start";
    return {};
  }
  std::vector<ZdumpLine> lines;
  char text[512];
  while (std::fgets(text, sizeof text, pipe)) {
    if (std::string_view(text).find("= NULL") != std::string_view::npos) continue;  // the ends of time
    char utMonth[8] = {};
    char localMonth[8] = {};
    std::tm ut{};
    ZdumpLine line;
    int isdst = 0;
    const int fields = std::sscanf(
        text, "%*s %*s %7s %d %d:%d:%d %d UT = %*s %7s %d %d:%d:%d %d %*s isdst=%d gmtoff=%d", utMonth, &ut.tm_mday,
        &ut.tm_hour, &ut.tm_min, &ut.tm_sec, &ut.tm_year, localMonth, &line.local.tm_mday, &line.local.tm_hour,
        &line.local.tm_min, &line.local.tm_sec, &line.local.tm_year, &isdst, &line.offset);
    ut.tm_mon = monthIndex(utMonth);
    line.local.tm_mon = monthIndex(localMonth);
    if (fields != 14 || ut.tm_mon < 0 || line.local.tm_mon < 0) {
      ADD_FAILURE() << "cannot read zdump's line: " << text;
      continue;
    }
    ut.tm_year -= 1900;
    line.utc = ::timegm(&ut);
    line.dst = isdst != 0;
    lines.push_back(line);
  }
  EXPECT_EQ(::pclose(pipe), 0) << command;
  return lines;
}

TEST(TimeZone, EveryChangeFrom2020To2040AgreesWithZdump) {
  // Zones whose changes are of every kind: an hour each way in both hemispheres, half an hour
  // (Lord Howe), at odd local times (Santiago, Chatham), around Ramadan (Casablanca), none any
  // more (Tehran), and a half-hour standard offset (St John's).
  for (const char* name : {"Europe/Berlin", "America/New_York", "Australia/Lord_Howe", "America/Santiago",
                           "Pacific/Chatham", "Africa/Casablanca", "Asia/Tehran", "America/St_Johns"}) {
    auto zone = TimeZone::load(name);
    ASSERT_TRUE(zone) << name << ": " << zone.error().describe();
    const std::vector<ZdumpLine> lines = zdump(name, 2020, 2040);
    if (std::string_view(name) != "Asia/Tehran") {
      EXPECT_GE(lines.size(), 20u * 4) << name << ": too few changes";
    }
    int mismatches = 0;
    for (const ZdumpLine& z : lines) {
      const LocalTime local = zone->toLocal(WallTime{std::chrono::seconds(z.utc)});
      const bool same = local.year == z.local.tm_year && local.month == static_cast<unsigned>(z.local.tm_mon + 1) &&
                        local.day == static_cast<unsigned>(z.local.tm_mday) &&
                        local.secondOfDay == z.local.tm_hour * 3600 + z.local.tm_min * 60 + z.local.tm_sec &&
                        local.utcOffset == z.offset && local.dst == z.dst;
      if (!same && ++mismatches <= 3) {
        ADD_FAILURE() << name << " at " << z.utc << ": " << local.year << "-" << local.month << "-" << local.day
                      << " second " << local.secondOfDay << " offset " << local.utcOffset << " dst " << local.dst
                      << "; zdump says " << z.local.tm_year << "-" << z.local.tm_mon + 1 << "-" << z.local.tm_mday
                      << " " << z.local.tm_hour << ":" << z.local.tm_min << ":" << z.local.tm_sec << " offset "
                      << z.offset << " dst " << z.dst;
      }
    }
  }
}

TEST(TimeZone, BadNamesAndDamagedFilesAreErrors) {
  EXPECT_FALSE(TimeZone::load(""));
  EXPECT_FALSE(TimeZone::load("Nowhere/Atlantis"));
  const auto escape = TimeZone::load("../../etc/passwd");
  ASSERT_FALSE(escape);
  EXPECT_NE(escape.error().message().find("not a time zone name"), std::string::npos);
  EXPECT_TRUE(TimeZone::load("UTC"));

  std::ifstream in("/usr/share/zoneinfo/Europe/Paris", std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 100u);
  // Damaged copies in a zone folder of their own: every truncation is an error or a usable zone,
  // never a read past the end.
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("basalt-tzdir-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir / "Cut");
  ::setenv("TZDIR", dir.c_str(), 1);
  for (std::size_t n = 0; n < bytes.size(); n += 7) {
    const std::string name = "Cut/" + std::to_string(n);
    std::ofstream(dir / name, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(n));
    const auto zone = TimeZone::load(name);
    if (zone) (void)zone->offsetAt(0);
  }
  // The whole copy is a usable zone: $TZDIR is where zones are read from.
  std::filesystem::create_directories(dir / "Whole");
  std::ofstream(dir / "Whole/Paris", std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  const auto whole = TimeZone::load("Whole/Paris");
  auto wrong = bytes;
  wrong[0] = 'X';
  std::ofstream(dir / "Wrong", std::ios::binary).write(wrong.data(), static_cast<std::streamsize>(wrong.size()));
  const auto notTzif = TimeZone::load("Wrong");
  ::unsetenv("TZDIR");
  std::filesystem::remove_all(dir);
  ASSERT_TRUE(whole) << whole.error().describe();
  EXPECT_EQ(whole->toLocal(utc(2026, 7, 1, 12)).utcOffset, 7200);
  ASSERT_FALSE(notTzif);
  EXPECT_NE(notTzif.error().message().find("reinstall the tzdata package"), std::string::npos);
}

}  // namespace
}  // namespace basalt::kiosk
