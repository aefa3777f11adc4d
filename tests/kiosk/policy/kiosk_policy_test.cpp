// Kiosk policy: opening hours, the attract loop, the idle time-out and the playlist, run for a
// whole week of a museum's calendar in Paris under a ManualClock (a second per step, a week in a
// fraction of a second), across the change to summer time and a closed holiday.
// Example failures: opening an hour late on the Sunday clocks go forward; the attract loop never
// coming back after the last visitor; a visitor at night waking a closed exhibit; an item with
// a duration that never moves on; a resumed show starting at the wrong item.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "kiosk/policy/kiosk_policy.h"
#include "kiosk/policy/schedule.h"
#include "runtime/clock.h"

namespace basalt::kiosk {
namespace {

using std::chrono::hours;
using std::chrono::minutes;
using std::chrono::seconds;

EntrySpec builtin(EntryKind kind = EntryKind::kBuiltinDefault) { return {kind, "default", {}, 0}; }
EntrySpec script(const char* name) { return {EntryKind::kScript, name, std::string("/show/") + name, 0}; }

/// The museum of the lava-script example: closed on Mondays, late on Thursdays, closed on one
/// Friday; attract loop; a playlist of a script (ends by itself) and the cube for 2 minutes.
Manifest museum() {
  Manifest m = Manifest::builtinDefault();
  m.name = "museum";
  ScheduleSpec& s = m.kiosk.schedule;
  s.present = true;
  s.timezone = "Europe/Paris";
  for (auto& day : s.week) day = {{600, 1080}};
  s.week[0] = {};
  s.week[3] = {{600, 1080}, {1140, 1320}};
  s.exceptions.push_back({{2026, 3, 27}, {}, "strike", 0});
  s.outside = OutsideHours::kStandby;
  s.standby = builtin();
  m.kiosk.attract.present = true;
  m.kiosk.attract.items = {{"attract", builtin(), Nanos{0}, 0}};
  m.kiosk.attract.idleTimeout = seconds(90);
  m.kiosk.playlist = {{"tour", script("tour.mdl"), Nanos{0}, 0}, {"cube", builtin(), minutes(2), 0}};
  return m;
}

Schedule scheduleOf(const Manifest& m) {
  auto s = Schedule::create(m.kiosk.schedule);
  EXPECT_TRUE(s) << s.error().describe();
  return std::move(*s);
}

/// Local Paris time of day as "Tue 10:30:00".
std::string localLabel(const Schedule& s, WallTime t) {
  static constexpr const char* kDays[] = {"Mon", "Tue", "Wed", "Thu", "Fri", "Sat", "Sun"};
  const LocalTime l = s.zone().toLocal(t);
  return fmt::format("{} {:02}:{:02}:{:02}", kDays[l.weekday], l.secondOfDay / 3600, l.secondOfDay / 60 % 60,
                     l.secondOfDay % 60);
}

std::string describe(const Programme& p) {
  return fmt::format("{} {}", kioskModeName(p.mode), p.item ? p.item->name : std::string(displayStateName(p.display)));
}

TEST(KioskPolicy, AWeekAtTheMuseum) {
  const Manifest m = museum();
  Schedule schedule = scheduleOf(m);
  // Monday 2026-03-23 00:00 in Paris is Sunday 23:00 UTC.
  const WallTime mondayMidnight{seconds(daysFromCivil(2026, 3, 22) * 86400 + std::int64_t{23} * 3600)};
  ManualClock clock(Nanos{0}, mondayMidnight);
  KioskPolicy policy(m, schedule);
  policy.start(clock.now(), clock.wallNow());

  // Visitors: (local time of the first touch, minutes of touching every 20 s).
  struct Visit {
    int day;     // days after Monday
    int minute;  // local minute of the day
    int length;  // minutes
  };
  const std::vector<Visit> visits{{1, 630, 10}, {2, 1200, 1}, {5, 900, 0}};
  const auto touching = [&](Nanos t) {
    const auto s = std::chrono::duration_cast<seconds>(t).count();
    for (const Visit& v : visits) {
      // The schedule's days are local days; Monday started at t = 0, and the clocks go forward
      // on Sunday only, so local minute = t / 60 - day * 1440 before then.
      const std::int64_t begin = (v.day * 1440LL + v.minute) * 60;
      if (s >= begin && s <= begin + v.length * 60LL && (s - begin) % 20 == 0) return true;
    }
    return false;
  };

  std::vector<std::string> log{localLabel(schedule, clock.wallNow()) + " " + describe(policy.current())};
  const Nanos week = hours(24 * 7) - hours(1);  // summer time makes this week an hour short
  while (clock.now() < week) {
    clock.advance(seconds(1));
    const Nanos now = clock.now();
    bool changed = policy.update(now, clock.wallNow());
    if (touching(now)) changed = policy.noteInput(now) || changed;
    // The tour script ends by itself three minutes after it starts.
    const Programme& p = policy.current();
    if (p.item && p.item->name == "tour" && now - p.itemStart >= minutes(3)) changed = policy.itemEnded(now) || changed;
    if (changed) log.push_back(localLabel(schedule, clock.wallNow()) + " " + describe(policy.current()));
  }
  const std::vector<std::string> expected{
      "Mon 00:00:00 closed standby",   // closed all Monday
      "Tue 10:00:00 attract attract",  // opens
      "Tue 10:30:00 active tour",      // a visitor turns a dial
      "Tue 10:33:00 active cube",      // the script ended
      "Tue 10:35:00 active tour",      // the cube's two minutes are up
      "Tue 10:38:00 active cube",      // the visitor is still there
      "Tue 10:40:00 active tour",
      "Tue 10:41:30 attract attract",  // 90 s after the last touch at 10:40:00
      "Tue 18:00:00 closed standby",  "Wed 10:00:00 attract attract",
      "Wed 18:00:00 closed standby",  // the visitor at 20:00 changes nothing
      "Thu 10:00:00 attract attract", "Thu 18:00:00 closed standby",
      "Thu 19:00:00 attract attract",  // late opening
      "Thu 22:00:00 closed standby",   // Friday: closed for the strike
      "Sat 10:00:00 attract attract",
      "Sat 15:00:00 active tour",  // one touch
      "Sat 15:01:30 attract attract", "Sat 18:00:00 closed standby",
      "Sun 10:00:00 attract attract",  // summer time: 08:00 UTC, an hour earlier than Saturday
      "Sun 18:00:00 closed standby",
  };
  EXPECT_EQ(log, expected);
}

TEST(KioskPolicy, OpeningFollowsLocalTimeAcrossTheChangeToSummerTime) {
  const Manifest m = museum();
  const Schedule s = scheduleOf(m);
  const auto at = [](int d, int h, int min) {
    return WallTime{seconds(daysFromCivil(2026, 3, static_cast<unsigned>(d)) * 86400 + std::int64_t{h} * 3600 +
                            std::int64_t{min} * 60)};
  };
  EXPECT_FALSE(s.isOpen(at(28, 8, 59)));
  EXPECT_TRUE(s.isOpen(at(28, 9, 0))) << "Saturday 10:00 CET is 09:00 UTC";
  EXPECT_FALSE(s.isOpen(at(29, 7, 59)));
  EXPECT_TRUE(s.isOpen(at(29, 8, 0))) << "Sunday 10:00 CEST is 08:00 UTC";
  EXPECT_FALSE(s.isOpen(at(27, 12, 0))) << "the exception closes Friday";
  EXPECT_FALSE(s.isOpen(at(23, 12, 0))) << "closed on Mondays";
  const auto next = s.nextChange(at(27, 12, 0));
  ASSERT_TRUE(next);
  EXPECT_EQ(*next, at(28, 9, 0)) << "from the closed Friday the next change is Saturday's opening";
  Manifest never = m;
  for (auto& day : never.kiosk.schedule.week) day = {};
  EXPECT_FALSE(scheduleOf(never).nextChange(at(27, 12, 0)));
}

TEST(KioskPolicy, OutsideHoursTheScreenIsBlackOrOff) {
  Manifest m = museum();
  const WallTime monday{seconds(daysFromCivil(2026, 3, 23) * 86400 + std::int64_t{12} * 3600)};
  m.kiosk.schedule.outside = OutsideHours::kBlack;
  KioskPolicy black(m, scheduleOf(m));
  black.start(Nanos{0}, monday);
  EXPECT_EQ(black.current().mode, KioskMode::kClosed);
  EXPECT_EQ(black.current().display, DisplayState::kBlack);
  EXPECT_EQ(black.current().item, nullptr);
  m.kiosk.schedule.outside = OutsideHours::kDisplayOff;
  KioskPolicy off(m, scheduleOf(m));
  off.start(Nanos{0}, monday);
  EXPECT_EQ(off.current().display, DisplayState::kOff);
  EXPECT_FALSE(off.noteInput(seconds(1))) << "a touch does not wake a closed exhibit";
  EXPECT_FALSE(off.next(seconds(1)));
  EXPECT_EQ(off.describe(), "closed, closed: display off");
}

TEST(KioskPolicy, WithoutScheduleOrPlaylistTheEntryPlaysForEver) {
  Manifest m = Manifest::builtinDefault();
  KioskPolicy policy(m, std::nullopt);
  policy.start(Nanos{0}, WallTime{});
  const std::uint64_t generation = policy.current().generation;
  ASSERT_NE(policy.current().item, nullptr);
  EXPECT_EQ(policy.current().mode, KioskMode::kActive);
  for (int h = 1; h <= 48; ++h) EXPECT_FALSE(policy.update(hours(h), WallTime{hours(h)}));
  EXPECT_EQ(policy.current().generation, generation);
  EXPECT_FALSE(policy.next(hours(49))) << "a list of one has no next";
  EXPECT_EQ(policy.describe(), "open, playing: 'default show' (1/1)");
}

TEST(KioskPolicy, NextPreviousAndFailures) {
  Manifest m = museum();
  m.kiosk.schedule.present = false;
  m.kiosk.attract.present = false;
  m.kiosk.playlist.push_back({"third", script("third.mdl"), minutes(1), 0});
  KioskPolicy policy(m, std::nullopt);
  policy.start(Nanos{0}, WallTime{});
  EXPECT_EQ(policy.current().item->name, "tour");
  EXPECT_TRUE(policy.previous(seconds(1)));
  EXPECT_EQ(policy.current().item->name, "third") << "previous wraps to the end";
  EXPECT_TRUE(policy.next(seconds(2)));
  EXPECT_EQ(policy.current().item->name, "tour");
  EXPECT_EQ(policy.current().itemStart, seconds(2));
  // Every item fails: black, not a loop of retries.
  EXPECT_TRUE(policy.itemFailed(seconds(3)));
  EXPECT_EQ(policy.current().item->name, "cube");
  EXPECT_TRUE(policy.itemFailed(seconds(3)));
  EXPECT_TRUE(policy.itemFailed(seconds(3)));
  EXPECT_EQ(policy.current().item, nullptr);
  EXPECT_EQ(policy.current().display, DisplayState::kBlack);
  EXPECT_FALSE(policy.itemFailed(seconds(4)));
  EXPECT_FALSE(policy.update(hours(1), WallTime{}));
}

TEST(KioskPolicy, ResumesTheItemAndPositionItWasAt) {
  Manifest m = museum();
  m.kiosk.schedule.present = false;
  m.kiosk.attract.idleTimeout = minutes(10);
  const auto fresh = [&] { return KioskPolicy(m, std::nullopt); };
  {
    KioskPolicy p = fresh();
    p.start(hours(5), WallTime{}, ResumePoint{KioskMode::kActive, 1, "cube", seconds(30)});
    EXPECT_EQ(p.current().mode, KioskMode::kActive);
    EXPECT_EQ(p.current().item->name, "cube");
    EXPECT_EQ(p.position(hours(5)), seconds(30));
    EXPECT_TRUE(p.update(hours(5) + seconds(90), WallTime{})) << "the rest of the two minutes, then on";
    EXPECT_EQ(p.current().item->name, "tour");
    const ResumePoint saved = p.resumePoint(hours(5) + seconds(100));
    EXPECT_EQ(saved.item, "tour");
    EXPECT_EQ(saved.index, 0u);
    EXPECT_EQ(saved.position, seconds(10));
  }
  {
    KioskPolicy p = fresh();
    p.start(Nanos{0}, WallTime{}, ResumePoint{KioskMode::kActive, 1, "renamed", seconds(30)});
    EXPECT_EQ(p.current().mode, KioskMode::kAttract) << "an item that is no longer there is not resumed";
    EXPECT_EQ(p.position(Nanos{0}), Nanos{0});
  }
  {
    KioskPolicy p = fresh();
    p.start(Nanos{0}, WallTime{}, ResumePoint{KioskMode::kActive, 1, "cube", minutes(5)});
    EXPECT_EQ(p.current().item->name, "cube");
    EXPECT_EQ(p.position(Nanos{0}), Nanos{0}) << "a position past the item's end starts it again";
  }
  {
    KioskPolicy p = fresh();
    p.start(Nanos{0}, WallTime{}, ResumePoint{KioskMode::kClosed, 0, "standby", seconds(3)});
    EXPECT_EQ(p.current().mode, KioskMode::kAttract) << "closed then, open now: the schedule wins";
  }
}

}  // namespace
}  // namespace basalt::kiosk
