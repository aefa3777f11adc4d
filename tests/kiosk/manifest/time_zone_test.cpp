// Time zones for opening hours, read from the system's tz database: offsets and local dates
// agree with the C library's own conversion for many instants in several zones, in both
// hemispheres and far beyond the table's end (where the POSIX rule in the footer takes over).
// Example failures: opening an hour late after the change to summer time; a southern-hemisphere
// zone with daylight-saving time inverted; a damaged TZif file read past its end.

#include <gtest/gtest.h>

#include <cstdlib>
#include <ctime>
#include <fstream>
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

TEST(TimeZone, PosixRules) {
  auto us = PosixTzRule::parse("EST5EDT,M3.2.0,M11.1.0");
  ASSERT_TRUE(us);
  EXPECT_EQ(us->stdOffset, -5 * 3600);
  EXPECT_EQ(us->dstOffset, -4 * 3600);
  auto india = PosixTzRule::parse("<+0530>-5:30");
  ASSERT_TRUE(india);
  EXPECT_EQ(india->stdOffset, 5 * 3600 + 30 * 60);
  EXPECT_FALSE(india->hasDst);
  auto julian = TimeZone::fromPosix("XXX3YYY,J60/0,J300/0");
  ASSERT_TRUE(julian);
  EXPECT_EQ(julian->toLocal(utc(2026, 6, 1, 12)).utcOffset, -2 * 3600);
  for (const char* bad : {"", "E5", "EST", "EST5EDT,M13.1.0,M11.1.0", "EST5EDT,M3.2.0", "EST5EDT,M3.2.0,M11.1.0x"}) {
    EXPECT_FALSE(PosixTzRule::parse(bad)) << bad;
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
  std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 100u);
  // Every truncation is an error or a usable zone, never a read past the end.
  for (std::size_t n = 0; n < bytes.size(); n += 7) {
    const auto zone = TimeZone::fromTzif(std::span(bytes.data(), n), "cut");
    if (zone) (void)zone->offsetAt(0);
  }
  auto wrong = bytes;
  wrong[0] = 'X';
  const auto notTzif = TimeZone::fromTzif(wrong, "wrong");
  ASSERT_FALSE(notTzif);
  EXPECT_NE(notTzif.error().message().find("reinstall the tzdata package"), std::string::npos);
}

}  // namespace
}  // namespace basalt::kiosk
