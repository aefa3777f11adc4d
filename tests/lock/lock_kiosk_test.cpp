// Frame-locked kiosks as real `basalt run` processes on loopback, each with its status and
// control server: one director for the group (a control request's `next` to the leader switches
// the follower's item in the same locked frame; a follower refuses to be moved on its own), and
// supervision of a follower whose leader is gone (it holds its picture, says so in its STATUS=
// and /health, and keeps pinging systemd's watchdog, emulated here through $NOTIFY_SOCKET, so
// that a long outage does not get it restarted; the leader's return shows in /health).
// Example failures: the follower switching a frame after the leader; a holding follower whose
// watchdog goes quiet (systemd would kill every follower while the leader is down); a lost
// leader the status page calls ok.

#include <gtest/gtest.h>

#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <fstream>
#include <optional>
#include <regex>
#include <string>
#include <thread>

#include "render/kiosk_process.h"
#include "support/datagram_socket.h"
#include "support/test_paths.h"

namespace basalt {
namespace {

using namespace std::chrono_literals;

constexpr const char* kToken = "0123456789abcdef0123456789abcdef";

int lockPort(int slot) { return 31000 + static_cast<int>(::getpid() % 1000) * 8 + slot * 4; }

std::string showManifest(const std::string& lock) {
  return std::string(R"(
[show]
name = "Locked kiosk"
entry = "default"
fps = 30

[output]
kind = "headless"
size = "64x48"

[[kiosk.playlist]]
name = "first"
entry = "default"
duration = "1h"

[[kiosk.playlist]]
name = "second"
entry = "black"
duration = "1h"

[status]
listen = "127.0.0.1:0"
token_file = "token"

[lock]
)") + lock;
}

std::filesystem::path writeNode(const std::string& name, const std::string& lock) {
  const auto dir = test::writeShow(name, showManifest(lock));
  std::ofstream(dir / "token") << kToken << "\n";
  return dir / "show.toml";
}

std::string leaderLock(int port) {
  return "role = \"leader\"\nnode = \"leader\"\nlisten = \"127.0.0.1\"\nport = " + std::to_string(port) +
         "\nfollowers = 1\njoin_timeout_ms = 20000\ntimeout_ms = 500\n";
}

std::string followerLock(int port, int leaderTimeoutMs) {
  return "role = \"follower\"\nnode = \"north\"\nleader = \"127.0.0.1\"\nport = " + std::to_string(port) +
         "\nleader_timeout_ms = " + std::to_string(leaderTimeoutMs) + "\n";
}

/// Polls `show`'s /health until it contains every one of `needles`, at most `limit`.
bool healthSays(const test::RunningShow& show, const std::vector<std::string>& needles, std::chrono::milliseconds limit,
                std::string* last = nullptr) {
  const auto end = std::chrono::steady_clock::now() + limit;
  std::string body;
  while (std::chrono::steady_clock::now() < end) {
    body = show.get("/health").body;
    bool all = true;
    for (const std::string& n : needles) all = all && body.find(n) != std::string::npos;
    if (all) return true;
    std::this_thread::sleep_for(50ms);
  }
  if (last) *last = body;
  return false;
}

/// The frame in which a node's lock logged switching to item 2: "frame N: sends the programme:
/// active item 2 'second'" (leader) or "frame N: follows the programme: ..." (follower).
std::optional<long> switchFrame(const std::string& output, const std::string& verb) {
  const std::regex line("frame (\\d+): " + verb + " the programme: active item 2 'second'");
  std::smatch m;
  if (!std::regex_search(output, m, line)) return std::nullopt;
  return std::stol(m[1].str());
}

#define REQUIRE_EGL()                                                                  \
  do {                                                                                 \
    std::string why;                                                                   \
    if (!test::headlessEglWorks(why)) GTEST_SKIP() << "no headless EGL here: " << why; \
  } while (false)

TEST(LockedKiosk, NextOnTheLeaderSwitchesTheFollowerInTheSameFrame) {
  REQUIRE_EGL();
  const int port = lockPort(0);
  const auto leaderShow = writeNode("lock-kiosk-next-leader", leaderLock(port));
  const auto followerShow = writeNode("lock-kiosk-next-follower", followerLock(port, 3000));
  std::string why;
  auto leader = test::RunningShow::start({leaderShow.string(), "--realtime", "--no-resume"}, {}, why);
  ASSERT_TRUE(leader) << why;
  auto follower = test::RunningShow::start({followerShow.string(), "--realtime", "--no-resume"}, {}, why);
  ASSERT_TRUE(follower) << why;
  std::string last;
  ASSERT_TRUE(healthSays(*follower, {"\"item\": \"first\"", "\"leader_present\": true"}, 20s, &last)) << last;

  // A follower is not moved on its own: the leader decides for the group.
  const std::string bearer = std::string("Bearer ") + kToken;
  const auto refused = follower->post("/control/next", "", bearer);
  EXPECT_EQ(refused.status, 409) << refused.body;
  EXPECT_NE(refused.body.find("follows its frame-lock leader"), std::string::npos) << refused.body;

  const auto next = leader->post("/control/next", "", bearer);
  ASSERT_EQ(next.status, 200) << next.body;
  EXPECT_TRUE(healthSays(*follower, {"\"item\": \"second\"", "\"index\": 2"}, 5s, &last)) << last;
  EXPECT_TRUE(healthSays(*leader, {"\"item\": \"second\""}, 1s, &last)) << last;

  follower->process().signal(SIGTERM);
  leader->process().signal(SIGTERM);
  const auto fr = follower->process().wait(20s);
  const auto lr = leader->process().wait(20s);
  EXPECT_EQ(fr.exitCode, 0) << fr.output;
  EXPECT_EQ(lr.exitCode, 0) << lr.output;
  const auto sent = switchFrame(lr.output, "sends");
  const auto followed = switchFrame(fr.output, "follows");
  ASSERT_TRUE(sent) << lr.output;
  ASSERT_TRUE(followed) << fr.output;
  EXPECT_EQ(*followed, *sent) << "the follower switched in another frame than the leader";
  EXPECT_NE(fr.output.find("1 programme changes followed"), std::string::npos) << fr.output;
  EXPECT_NE(lr.output.find("1 programme changes sent"), std::string::npos) << lr.output;
}

using test::SocketDir;

/// systemd's notify socket, as a datagram socket the test reads, counting watchdog pings.
class NotifySocket : public test::DatagramSocket {
 public:
  using DatagramSocket::DatagramSocket;
  /// Counts WATCHDOG=1 pings for `span`; `seen` collects every datagram.
  int countPings(std::chrono::milliseconds span, std::string& seen) {
    int pings = 0;
    const auto end = std::chrono::steady_clock::now() + span;
    while (std::chrono::steady_clock::now() < end) {
      if (auto d = receive(50ms)) {
        seen += *d + "|";
        if (d->find("WATCHDOG=1") != std::string::npos) ++pings;
      }
    }
    return pings;
  }
};

TEST(LockedKiosk, AFollowerHoldingForALostLeaderKeepsPingingTheWatchdog) {
  REQUIRE_EGL();
  const int port = lockPort(1);
  const auto leaderShow = writeNode("lock-kiosk-hold-leader", leaderLock(port));
  const auto followerShow = writeNode("lock-kiosk-hold-follower", followerLock(port, 500));
  SocketDir sockets;
  NotifySocket notify(sockets.path() / "notify.sock");
  ASSERT_TRUE(notify.bound());
  std::string why;
  auto leader = test::RunningShow::start({leaderShow.string(), "--realtime", "--no-resume"}, {}, why);
  ASSERT_TRUE(leader) << why;
  // The watchdog wants a ping every 0.4 s (systemd's WatchdogSec=): Basalt pings every 0.2 s.
  auto follower =
      test::RunningShow::start({followerShow.string(), "--realtime", "--no-resume"},
                               {{"NOTIFY_SOCKET", notify.path().string()}, {"WATCHDOG_USEC", "400000"}}, why);
  ASSERT_TRUE(follower) << why;
  ASSERT_TRUE(notify.waitFor("READY=1", 20s)) << follower->process().outputSoFar();
  std::string last;
  ASSERT_TRUE(healthSays(*follower, {"\"leader_present\": true", "\"holding\": false"}, 10s, &last)) << last;

  leader->process().signal(SIGKILL);
  (void)leader->process().wait(5s);
  // Lost after 0.5 s of silence: the follower holds its picture and says so.
  EXPECT_TRUE(notify.waitFor("STATUS=holding frame", 5s)) << follower->process().outputSoFar();
  EXPECT_TRUE(
      healthSays(*follower, {"\"state\": \"degraded\"", "\"leader_present\": false", "\"holding\": true"}, 5s, &last))
      << last;
  // Three seconds of holding, far beyond the watchdog's 0.4 s: the pings go on (every 0.2 s).
  std::string seen;
  const int pings = notify.countPings(3s, seen);
  EXPECT_GE(pings, 10) << "about 15 expected in 3 s; got " << seen;
  EXPECT_EQ(::kill(follower->process().pid(), 0), 0) << "the follower is still running";
  const auto h = follower->get("/health").body;
  const std::regex holdingPings("\"watchdog_pings_holding\": (\\d+)");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(h, m, holdingPings)) << h;
  EXPECT_GE(std::stoi(m[1].str()), 5) << h;
  const auto metrics = follower->get("/metrics").body;
  EXPECT_EQ(test::metric(metrics, "basalt_lock_holding{node=\"north\",role=\"follower\"}"), 1.0) << metrics;

  // The leader comes back: the follower follows it again and says what plays.
  auto again = test::RunningShow::start({leaderShow.string(), "--realtime", "--no-resume"}, {}, why);
  ASSERT_TRUE(again) << why;
  EXPECT_TRUE(healthSays(
      *follower, {"\"leader_present\": true", "\"holding\": false", "\"leader_returned\": 1", "\"leader_lost\": 1"},
      20s, &last))
      << last;
  EXPECT_TRUE(notify.waitFor("STATUS=open, playing", 5s));
  follower->process().signal(SIGTERM);
  again->process().signal(SIGTERM);
  const auto fr = follower->process().wait(20s);
  EXPECT_NE(fr.output.find("the leader is back after"), std::string::npos) << fr.output;
  (void)again->process().wait(20s);
}

}  // namespace
}  // namespace basalt
