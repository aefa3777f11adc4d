// The SGI dial and button box: its byte protocol (dial counts wrapping at 16 bits, the four
// button banks, reset answers, messages split across reads) and, over a pseudo-terminal pair,
// the serial backend losing the box when the line hangs up during a pending read, and giving a
// clear error when nothing answers the reset.
// Example failures: a dial turning back past 0 read as +65535 counts; button 8 reported as 0; a
// reader thread blocked forever in read() after the adapter is unplugged; open() hanging on a
// port with nothing on it.

#include <gtest/gtest.h>

#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <thread>

#include "devices/serial/sgi_dial_box.h"
#include "runtime/unique_fd.h"

namespace basalt::devices {
namespace {

using namespace std::chrono_literals;

std::vector<Event> feed(SgiBoxDecoder& d, std::vector<std::uint8_t> bytes) {
  std::array<Event, 64> out;
  const std::size_t n = d.feed(bytes, out);
  return {out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n)};
}

TEST(SgiBoxProtocol, DialCountsWrapAndSplitMessagesJoin) {
  SgiBoxDecoder d;
  auto e = feed(d, {0x33, 0x00, 0x64});  // dial 3 at +100: half a turn
  ASSERT_EQ(e.size(), 1u);
  EXPECT_EQ(e[0].index, 3);
  EXPECT_DOUBLE_EQ(e[0].value, 0.5);
  e = feed(d, {0x33, 0xff});  // dial 3 at -2 (0xfffe), split across two reads
  EXPECT_TRUE(e.empty());
  e = feed(d, {0xfe});
  ASSERT_EQ(e.size(), 1u);
  EXPECT_DOUBLE_EQ(e[0].value, -102.0 / kSgiCountsPerTurn) << "the wrap is a small step back";
  e = feed(d, {0x20, 0x33, 0x00, 0x0a});  // a reset answer zeroes the counters
  ASSERT_EQ(e.size(), 1u);
  EXPECT_DOUBLE_EQ(e[0].value, 10.0 / kSgiCountsPerTurn);
}

TEST(SgiBoxProtocol, ButtonBanks) {
  SgiBoxDecoder d;
  const std::vector<std::pair<std::uint8_t, int>> presses = {{0xd8, 0},  {0xdf, 7},  {0xd0, 8},  {0xd7, 15},
                                                             {0xc8, 16}, {0xcf, 23}, {0xc0, 24}, {0xc7, 31}};
  for (const auto& [byte, button] : presses) {
    auto e = feed(d, {byte});
    ASSERT_EQ(e.size(), 1u) << std::hex << int{byte};
    EXPECT_EQ(e[0].kind, EventKind::kButton);
    EXPECT_EQ(e[0].index, button);
    EXPECT_EQ(e[0].value, 1);
    e = feed(d, {static_cast<std::uint8_t>(byte + 0x20)});
    ASSERT_EQ(e.size(), 1u);
    EXPECT_EQ(e[0].index, button);
    EXPECT_EQ(e[0].value, 0);
  }
  EXPECT_TRUE(feed(d, {0x01, 0x7f}).empty());
  EXPECT_EQ(d.unknownBytes(), 2u);
}

struct Pty {
  UniqueFd master;
  std::string slave;
  static std::optional<Pty> open() {
    Pty p;
    p.master.reset(::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC));
    if (!p.master || ::grantpt(p.master.get()) != 0 || ::unlockpt(p.master.get()) != 0) return std::nullopt;
    p.slave = ::ptsname(p.master.get());
    return p;
  }
};

TEST(SgiBoxSerial, HangUpDuringAPendingReadLosesTheBox) {
  auto pty = Pty::open();
  if (!pty) GTEST_SKIP() << "no pseudo-terminals here (/dev/ptmx)";
  SystemClock clock;
  SgiDialBox box(pty->slave, clock, 2s);
  std::thread answer([&] {
    pollfd p{pty->master.get(), POLLIN, 0};
    if (::poll(&p, 1, 2000) > 0) {
      std::uint8_t b[16];
      (void)!::read(pty->master.get(), b, sizeof b);
      const std::uint8_t ok = 0x20;
      (void)!::write(pty->master.get(), &ok, 1);
    }
  });
  BoundedQueue<Event> events(64);
  auto opened = box.open(1, events);
  answer.join();
  ASSERT_TRUE(opened) << opened.error().describe();
  const std::uint8_t turn[] = {0x30, 0x00, 0x14};
  ASSERT_EQ(::write(pty->master.get(), turn, 3), 3);
  Event e;
  for (int i = 0; i < 200 && !events.pop(e); ++i) std::this_thread::sleep_for(5ms);
  EXPECT_EQ(e.kind, EventKind::kDialDelta);
  EXPECT_DOUBLE_EQ(e.value, 0.1);
  // The reader is now blocked waiting for bytes; the line goes away under it.
  pty->master.reset();
  for (int i = 0; i < 200 && box.state() == DeviceState::kLive; ++i) {
    std::this_thread::sleep_for(5ms);
    box.service(clock.now());
  }
  EXPECT_EQ(box.state(), DeviceState::kLost);
  ASSERT_TRUE(box.lostReason());
  EXPECT_EQ(box.lostReason()->where(), pty->slave);
  box.close();
}

TEST(SgiBoxSerial, NothingAnsweringTheResetIsAClearError) {
  auto pty = Pty::open();
  if (!pty) GTEST_SKIP() << "no pseudo-terminals here (/dev/ptmx)";
  SystemClock clock;
  SgiDialBox box(pty->slave, clock, 150ms);
  BoundedQueue<Event> events(8);
  auto r = box.open(1, events);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code(), Errc::kTimeout);
  EXPECT_NE(r.error().message().find("connected and powered"), std::string::npos) << r.error().describe();
  EXPECT_EQ(box.state(), DeviceState::kAbsent);
}

TEST(SgiBoxSerial, AMissingPortSaysSo) {
  SystemClock clock;
  SgiDialBox box("/dev/does-not-exist-basalt", clock, 100ms);
  BoundedQueue<Event> events(8);
  auto r = box.open(1, events);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code(), Errc::kNotFound);
  EXPECT_EQ(r.error().where(), "/dev/does-not-exist-basalt");
}

}  // namespace
}  // namespace basalt::devices
