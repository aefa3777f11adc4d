// The OSC router without sockets: which binding an address (or an OSC 1.0 pattern) reaches, the
// arguments' types and their scaling, the rate limit per sender, the allow-list, the tracker
// seam, and that what is refused is counted every time and logged once per address.
// Example failures: "/basalt/*" acting on nothing; a fader's 0..127 scaled as 0..1 and the
// object spinning 127 times too far; a string where a number belongs turned into 0; a flood
// from one sender logging a line per message; a sender outside osc.allow moving the show.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <mutex>

#include "kiosk/osc/osc_router.h"
#include "runtime/log.h"

namespace basalt::kiosk {
namespace {

using namespace std::chrono_literals;

OscArgument number(double v, char type = 'f') { return {type, v, {}}; }
OscArgument text(std::string s) { return {'s', 0, std::move(s)}; }

OscMessage message(std::string address, std::vector<OscArgument> arguments = {}, std::string sender = "127.0.0.1") {
  return {std::move(address), std::move(arguments), std::move(sender)};
}

OscBindingSpec dial(std::string address, runtime::Action action, std::array<double, 2> range,
                    std::array<double, 2> input = {0, 1}) {
  OscBindingSpec b;
  b.address = std::move(address);
  b.what = OscDo::kDial;
  b.action = action;
  b.types = "f";
  b.input = input;
  b.range = range;
  return b;
}

OscBindingSpec control(std::string address, OscDo what, std::string types = "") {
  OscBindingSpec b;
  b.address = std::move(address);
  b.what = what;
  b.types = std::move(types);
  return b;
}

OscBindingSpec command(std::string address, std::string text, std::string types) {
  OscBindingSpec b = control(std::move(address), OscDo::kCommand, std::move(types));
  b.command = std::move(text);
  return b;
}

/// The records of the "osc" category logged while it lives.
class OscLog : public log::Sink {
 public:
  void write(const log::Record& r) override {
    if (r.category != "osc") return;
    std::lock_guard lock(mutex_);
    lines_.push_back(r.message);
  }
  std::size_t count(const std::string& needle) {
    std::lock_guard lock(mutex_);
    std::size_t n = 0;
    for (const std::string& l : lines_) n += l.find(needle) != std::string::npos ? 1u : 0u;
    return n;
  }

 private:
  std::mutex mutex_;
  std::vector<std::string> lines_;
};

struct CapturedLog {
  std::shared_ptr<OscLog> sink = std::make_shared<OscLog>();
  CapturedLog() { log::addSink(sink); }
  ~CapturedLog() { log::removeSink(sink); }
  CapturedLog(const CapturedLog&) = delete;
  CapturedLog& operator=(const CapturedLog&) = delete;
};

OscSpec spec(std::vector<OscBindingSpec> bindings, double rate = 1000) {
  OscSpec s;
  s.enabled = true;
  s.bindings = std::move(bindings);
  s.messagesPerSecond = rate;
  return s;
}

TEST(OscRouter, AnAddressReachesItsBindingAndAPatternEveryMatch) {
  OscRouter router(spec({control("/basalt/next", OscDo::kNext), control("/basalt/previous", OscDo::kPrevious),
                         control("/show/reload", OscDo::kReload)}));
  const OscRouted next = router.route(message("/basalt/next"), 0s);
  ASSERT_EQ(next.outcome, OscOutcome::kActed);
  ASSERT_EQ(next.controls.size(), 1u);
  EXPECT_EQ(next.controls[0].kind, ControlKind::kNext);
  // OSC 1.0 patterns in the message's address, matched by liblo.
  const OscRouted both = router.route(message("/basalt/*"), 0s);
  ASSERT_EQ(both.controls.size(), 2u);
  EXPECT_EQ(both.controls[0].kind, ControlKind::kNext);
  EXPECT_EQ(both.controls[1].kind, ControlKind::kPrevious);
  EXPECT_EQ(router.route(message("/basalt/{previous,other}"), 0s).controls.at(0).kind, ControlKind::kPrevious);
  EXPECT_EQ(router.route(message("/show/rel?ad"), 0s).controls.at(0).kind, ControlKind::kReload);
  EXPECT_EQ(router.route(message("/show/[q-s]eload"), 0s).controls.at(0).kind, ControlKind::kReload);
  // Near misses reach nothing.
  EXPECT_EQ(router.route(message("/basalt/nex"), 0s).outcome, OscOutcome::kUnmatched);
  EXPECT_EQ(router.route(message("/basalt/next/"), 0s).outcome, OscOutcome::kUnmatched);
  EXPECT_EQ(router.route(message("/BASALT/next"), 0s).outcome, OscOutcome::kUnmatched);
  EXPECT_EQ(router.route(message("/basalt"), 0s).outcome, OscOutcome::kUnmatched);
  EXPECT_EQ(router.figures().received, 9u);
  EXPECT_EQ(router.figures().acted, 5u);
  EXPECT_EQ(router.figures().unmatched, 4u);
}

TEST(OscRouter, NumbersOfAnyOscNumberTypeAreScaledIntoTheRange) {
  // A MIDI-style fader 0..127 onto -90..90 degrees: 31.75 is a quarter of the way, -45 degrees.
  OscRouter router(spec({dial("/spin", runtime::Action::kRotateY, {-90, 90}, {0, 127})}));
  for (const char type : {'f', 'd', 'i', 'h'}) {
    const double value = type == 'i' || type == 'h' ? 127 : 31.75;
    const double expected = type == 'i' || type == 'h' ? 90 : -45;
    const OscRouted r = router.route(message("/spin", {number(value, type)}), 0s);
    ASSERT_EQ(r.outcome, OscOutcome::kActed) << type;
    EXPECT_EQ(r.controls[0].kind, ControlKind::kAction);
    EXPECT_EQ(r.controls[0].action, runtime::Action::kRotateY);
    EXPECT_FLOAT_EQ(r.controls[0].amount, static_cast<float>(expected)) << type;
  }
  // Past the input's ends: clamped to them.
  EXPECT_FLOAT_EQ(router.route(message("/spin", {number(500)}), 0s).controls.at(0).amount, 90.f);
  EXPECT_FLOAT_EQ(router.route(message("/spin", {number(-3)}), 0s).controls.at(0).amount, -90.f);
  // A reversed input runs the other way: 0 is the high end.
  EXPECT_DOUBLE_EQ(OscRouter::scale(0, {1, 0}, std::array<double, 2>{10, 20}), 20);
  EXPECT_DOUBLE_EQ(OscRouter::scale(0.25, {1, 0}, std::array<double, 2>{10, 20}), 17.5);
  EXPECT_DOUBLE_EQ(OscRouter::scale(7.5, {0, 1}, std::nullopt), 7.5) << "no range: unchanged";
}

TEST(OscRouter, WrongTypesAndCountsAreRefused) {
  OscRouter router(spec({dial("/spin", runtime::Action::kRotateX, {0, 360}), command("/c", "x $1 $2", "fs")}));
  EXPECT_EQ(router.route(message("/spin", {text("90")}), 0s).outcome, OscOutcome::kWrongTypes);
  EXPECT_EQ(router.route(message("/spin"), 0s).outcome, OscOutcome::kWrongTypes) << "no argument";
  EXPECT_EQ(router.route(message("/spin", {number(1), number(2)}), 0s).outcome, OscOutcome::kWrongTypes);
  EXPECT_EQ(router.route(message("/spin", {{'T', 0, {}}}), 0s).outcome, OscOutcome::kWrongTypes) << "a bool";
  EXPECT_EQ(router.route(message("/spin", {number(std::numeric_limits<double>::quiet_NaN(), 'd')}), 0s).outcome,
            OscOutcome::kWrongTypes);
  EXPECT_EQ(router.route(message("/spin", {number(std::numeric_limits<double>::infinity(), 'd')}), 0s).outcome,
            OscOutcome::kWrongTypes);
  EXPECT_EQ(router.route(message("/c", {text("a"), number(1)}), 0s).outcome, OscOutcome::kWrongTypes)
      << "types in the wrong order";
  EXPECT_EQ(router.route(message("/c", {number(1), text("a")}), 0s).outcome, OscOutcome::kActed);
  EXPECT_EQ(router.figures().wrongTypes, 7u);
  EXPECT_EQ(router.figures().acted, 1u);
}

TEST(OscRouter, CommandsTakeTheirArgumentsAsWordsWithinTheHttpBound) {
  OscBindingSpec scaled = command("/size", "scale_object cube $1", "f");
  scaled.range = std::array<double, 2>{0, 4};
  OscRouter router(
      spec({command("/prim", "render.prim_type = $1", "s"), scaled, command("/two", "set $2 $1 $2", "fs")}));
  const OscRouted prim = router.route(message("/prim", {text("wireframe")}), 0s);
  ASSERT_EQ(prim.outcome, OscOutcome::kActed);
  EXPECT_EQ(prim.controls[0].kind, ControlKind::kRunCommand);
  EXPECT_EQ(prim.controls[0].argument, "render.prim_type = wireframe");
  EXPECT_EQ(router.route(message("/size", {number(0.5)}), 0s).controls.at(0).argument, "scale_object cube 2");
  EXPECT_EQ(router.route(message("/two", {number(1.5, 'd'), text("k")}), 0s).controls.at(0).argument, "set k 1.5 k");
  // A string that would be more than one word, or change how the command reads, is refused.
  for (const std::string& bad :
       std::vector<std::string>{"wire frame", "a;draw", "a\"b", "x#y", "tab\there", std::string(300, 'a'), ""}) {
    EXPECT_EQ(router.route(message("/prim", {text(bad)}), 0s).outcome, OscOutcome::kBadArgument) << bad;
  }
  // A command over the HTTP control's 1024 bytes is refused too.
  OscRouter longer(spec({command("/long", std::string(900, 'x') + " $1", "s")}));
  EXPECT_EQ(longer.route(message("/long", {text(std::string(200, 'y'))}), 0s).outcome, OscOutcome::kBadArgument);
  EXPECT_EQ(longer.figures().badArgument, 1u);
}

TEST(OscRouter, FadersMoveByTheirChangeAndButtonsActWhenPressed) {
  OscBindingSpec fader = dial("/fader", runtime::Action::kTranslateX, {0, 2});
  fader.absolute = true;
  OscRouter router(spec({fader, control("/next", OscDo::kNext, "f"), control("/reset", OscDo::kResetView)}));
  // The first position says where the fader stands: nothing moves.
  EXPECT_EQ(router.route(message("/fader", {number(0.5)}), 0s).outcome, OscOutcome::kHeld);
  // 0.5 -> 0.75 of a 0..2 range: 0.5 units on.
  EXPECT_FLOAT_EQ(router.route(message("/fader", {number(0.75)}), 0s).controls.at(0).amount, 0.5f);
  EXPECT_FLOAT_EQ(router.route(message("/fader", {number(0.25)}), 0s).controls.at(0).amount, -1.0f);
  EXPECT_EQ(router.route(message("/fader", {number(0.25)}), 0s).outcome, OscOutcome::kHeld) << "no change";
  EXPECT_EQ(router.route(message("/next", {number(1)}), 0s).outcome, OscOutcome::kActed);
  EXPECT_EQ(router.route(message("/next", {number(0)}), 0s).outcome, OscOutcome::kHeld) << "let go";
  EXPECT_EQ(router.route(message("/reset"), 0s).controls.at(0).kind, ControlKind::kResetView);
  EXPECT_EQ(router.figures().unmatched + router.figures().wrongTypes, 0u) << "held messages are no refusals";
}

TEST(OscRouter, EachSenderHasTheHttpControlsTokenBuckets) {
  // 10 a second, bursts of 20 (twice the rate), per sender, as [status] requests_per_second.
  OscRouter router(spec({control("/next", OscDo::kNext)}, 10));
  int acted = 0;
  for (int i = 0; i < 30; ++i) acted += router.route(message("/next"), 0s).outcome == OscOutcome::kActed ? 1 : 0;
  EXPECT_EQ(acted, 20);
  EXPECT_EQ(router.figures().rateLimited, 10u);
  // Another sender has a bucket of its own.
  EXPECT_EQ(router.route(message("/next", {}, "127.0.0.2"), 0s).outcome, OscOutcome::kActed);
  // Half a second later, 5 tokens have come back.
  acted = 0;
  for (int i = 0; i < 10; ++i) acted += router.route(message("/next"), 500ms).outcome == OscOutcome::kActed ? 1 : 0;
  EXPECT_EQ(acted, 5);
  // Unknown addresses spend the bucket too: a flood of them cannot be cheaper than real ones.
  OscRouter flood(spec({control("/next", OscDo::kNext)}, 1));
  EXPECT_EQ(flood.route(message("/nothing"), 0s).outcome, OscOutcome::kUnmatched);
  EXPECT_EQ(flood.route(message("/nothing"), 0s).outcome, OscOutcome::kUnmatched);
  EXPECT_EQ(flood.route(message("/next"), 0s).outcome, OscOutcome::kRateLimited);
}

TEST(OscRouter, OnlyAllowedSendersAreHeard) {
  OscSpec s = spec({control("/next", OscDo::kNext)});
  s.allow = {"10.0.0.5", "::1"};
  OscRouter router(s);
  EXPECT_EQ(router.route(message("/next", {}, "10.0.0.5"), 0s).outcome, OscOutcome::kActed);
  EXPECT_EQ(router.route(message("/next", {}, "::ffff:10.0.0.5"), 0s).outcome, OscOutcome::kActed)
      << "an IPv4 sender on a dual-stack socket";
  EXPECT_EQ(router.route(message("/next", {}, "::1"), 0s).outcome, OscOutcome::kActed);
  EXPECT_EQ(router.route(message("/next", {}, "127.0.0.1"), 0s).outcome, OscOutcome::kRefusedSender);
  EXPECT_EQ(router.route(message("/next", {}, "10.0.0.50"), 0s).outcome, OscOutcome::kRefusedSender);
  EXPECT_EQ(router.route(message("/tracker/1", {}, "10.0.0.50"), 0s).outcome, OscOutcome::kRefusedSender)
      << "the tracker seam is behind the allow-list too";
  EXPECT_EQ(router.figures().refusedSender, 3u);
  EXPECT_EQ(router.figures().acted, 3u);
}

TEST(OscRouter, RefusalsAreCountedEveryTimeAndLoggedOncePerAddress) {
  CapturedLog captured;
  OscRouter router(spec({dial("/spin", runtime::Action::kRotateZ, {0, 360})}));
  for (int i = 0; i < 50; ++i) {
    (void)router.route(message("/nowhere/a"), 0s);
    (void)router.route(message("/nowhere/b"), 0s);
    (void)router.route(message("/spin", {text("x")}), 0s);
  }
  EXPECT_EQ(router.figures().unmatched, 100u);
  EXPECT_EQ(router.figures().wrongTypes, 50u);
  EXPECT_EQ(captured.sink->count("/nowhere/a"), 1u);
  EXPECT_EQ(captured.sink->count("/nowhere/b"), 1u);
  EXPECT_EQ(captured.sink->count("/spin ,s from 127.0.0.1: the types are ,s"), 1u);
  // Past 256 addresses, one line says the rest are only counted.
  for (int i = 0; i < 300; ++i) (void)router.route(message("/many/" + std::to_string(i)), 0s);
  EXPECT_EQ(router.figures().unmatched, 400u);
  EXPECT_EQ(captured.sink->count("/many/"), 256u - 3u);
  EXPECT_EQ(captured.sink->count("the rest are counted, not logged"), 1u);
}

/// A tracker device's end of the seam: takes what it can use.
class FakeTracker : public OscTrackerSink {
 public:
  bool take(const OscMessage& m) override {
    if (m.arguments.size() != 3) return false;
    taken.push_back(m.address);
    return true;
  }
  std::vector<std::string> taken;
};

TEST(OscRouter, TrackerMessagesGoToTheTrackerSink) {
  OscRouter router(spec({control("/next", OscDo::kNext)}, 1));
  EXPECT_EQ(router.route(message("/tracker/1/position", {number(1), number(2), number(3)}), 0s).outcome,
            OscOutcome::kUnmatched)
      << "no tracker yet";
  FakeTracker tracker;
  router.setTrackerSink(&tracker);
  for (int i = 0; i < 10; ++i) {
    EXPECT_EQ(router.route(message("/tracker/1/position", {number(1), number(2), number(3)}), 0s).outcome,
              OscOutcome::kHeld)
        << "a tracker sends every frame: no rate limit (" << i << ")";
  }
  EXPECT_EQ(tracker.taken.size(), 10u);
  EXPECT_EQ(router.route(message("/tracker/1/position", {number(1)}), 0s).outcome, OscOutcome::kWrongTypes);
  EXPECT_EQ(router.figures().acted, 0u) << "a tracker's messages are no controls";
}

}  // namespace
}  // namespace basalt::kiosk
