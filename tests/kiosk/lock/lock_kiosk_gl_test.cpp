// Frame-locked kiosks as real `basalt run` processes on loopback, each with its status and
// control server: one director for the group (a control request's `next` to the leader switches
// the follower's item in the same locked frame; a follower refuses to be moved on its own), and
// supervision of a follower whose leader is gone (it holds its picture, says so in its STATUS=
// and /health, and keeps pinging systemd's watchdog, emulated here through $NOTIFY_SOCKET, so
// that a long outage does not get it restarted; the leader's return shows in /health).
// Example failures: the follower switching a frame after the leader; a holding follower whose
// watchdog goes quiet (systemd would kill every follower while the leader is down); a lost
// leader the status page calls ok. A script command sent to the leader runs on the follower in
// the same frame, and the follower refuses one of its own. A movie that no director plays
// (`basalt run --movie`) shows the leader's movie frame on a follower that joined late, though its
// own timeline started later: no locked frame shows another movie frame than the leader's.

#include <gtest/gtest.h>

#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cstring>
#include <fstream>
#include <map>
#include <optional>
#include <regex>
#include <string>
#include <thread>

#include <fmt/format.h>

#include "media/image_io.h"
#include "support/datagram_socket.h"
#include "support/kiosk_process.h"
#include "support/numbered_clip.h"
#include "support/test_paths.h"

namespace basalt {
namespace {

using namespace std::chrono_literals;

constexpr const char* kToken = "0123456789abcdef0123456789abcdef";

// Four slots of four ports per process (a lock uses three), from the pid so that parallel test
// processes keep apart, below the ephemeral range (32768 on) and apart from the unit tests'
// ports (10000 to 26000) and the lock bench's (29200 on).
int lockPort(int slot) { return 26000 + static_cast<int>(::getpid() % 200) * 16 + slot * 4; }

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

/// A leader and a follower of the two-item show on loopback, in real time, started and waited
/// for until the follower hears the leader and plays the first item.
struct LockedPair {
  std::unique_ptr<test::RunningShow> leader;
  std::unique_ptr<test::RunningShow> follower;

  void start(const std::string& name, int port) {
    const auto leaderShow = writeNode(name + "-leader", leaderLock(port));
    const auto followerShow = writeNode(name + "-follower", followerLock(port, 3000));
    std::string why;
    leader = test::RunningShow::start({leaderShow.string(), "--realtime", "--no-resume"}, {}, why);
    ASSERT_TRUE(leader) << why;
    follower = test::RunningShow::start({followerShow.string(), "--realtime", "--no-resume"}, {}, why);
    ASSERT_TRUE(follower) << why;
    std::string last;
    ASSERT_TRUE(healthSays(*follower, {"\"item\": \"first\"", "\"leader_present\": true"}, 20s, &last)) << last;
  }
};

TEST(LockedKiosk, NextOnTheLeaderSwitchesTheFollowerInTheSameFrame) {
  REQUIRE_EGL();
  LockedPair pair;
  ASSERT_NO_FATAL_FAILURE(pair.start("lock-kiosk-next", lockPort(0)));
  auto& leader = pair.leader;
  auto& follower = pair.follower;
  std::string last;

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

/// The frame in which a node's log says it ran script command `seq` of the group: "frame N:
/// runs command 1 for the frame-locked group: ..." (leader) or "frame N: runs the leader's
/// command 1: ..." (follower).
std::optional<long> commandFrame(const std::string& output, const std::string& what, int seq) {
  const std::regex line("frame (\\d+): runs " + what + " " + std::to_string(seq) + "[ :]");
  std::smatch m;
  if (!std::regex_search(output, m, line)) return std::nullopt;
  return std::stol(m[1].str());
}

/// The red, green and blue of the top-left pixel of `show`'s /snapshot.png (the background
/// around the default cube), or nothing when there is no snapshot.
std::optional<std::array<int, 3>> cornerColour(const test::RunningShow& show, const std::string& name) {
  const auto s = show.get("/snapshot.png");
  if (s.status != 200) return std::nullopt;
  const auto file = test::scratchDir(name) / "snapshot.png";
  std::ofstream(file, std::ios::binary) << s.body;
  auto image = media::readImage(file);
  if (!image || image->width == 0) return std::nullopt;
  return std::array<int, 3>{image->at(0, 0, 0), image->at(0, 0, 1), image->at(0, 0, 2)};
}

/// Polls `show`'s snapshot until its corner is red, at most `limit`.
bool cornerTurnsRed(const test::RunningShow& show, const std::string& name, std::chrono::milliseconds limit,
                    std::string& last) {
  const auto end = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < end) {
    if (const auto c = cornerColour(show, name)) {
      last = fmt::format("{} {} {}", (*c)[0], (*c)[1], (*c)[2]);
      if ((*c)[0] > 200 && (*c)[1] < 50 && (*c)[2] < 50) return true;
    }
    std::this_thread::sleep_for(100ms);
  }
  return false;
}

// Makes sure a script command sent to the leader's control server runs on the follower too, in
// the leader's frame, and shows there (the follower's snapshot turns red), while the follower
// refuses a command of its own. Example failure: the leader's background turns red and the
// follower's facets stay black, or the follower runs a command that parts it from the group.
TEST(LockedKiosk, ACommandOnTheLeaderRunsOnTheFollowerInTheSameFrame) {
  REQUIRE_EGL();
  LockedPair pair;
  ASSERT_NO_FATAL_FAILURE(pair.start("lock-kiosk-command", lockPort(2)));
  auto& leader = pair.leader;
  auto& follower = pair.follower;
  std::string last;
  const auto before = cornerColour(*follower, "lock-kiosk-command-before");
  ASSERT_TRUE(before);
  EXPECT_LT((*before)[0], 200) << "the default background is not red";

  const std::string bearer = std::string("Bearer ") + kToken;
  const std::string red = "global.background_color = 1 0 0";
  const auto refused = follower->post("/control/command", red, bearer);
  EXPECT_EQ(refused.status, 409) << refused.body;
  EXPECT_NE(refused.body.find("send the command to the leader's control server"), std::string::npos) << refused.body;

  const auto ran = leader->post("/control/command", red, bearer);
  ASSERT_EQ(ran.status, 200) << ran.body;
  EXPECT_TRUE(healthSays(*follower, {"\"commands_applied\": 1"}, 5s, &last)) << last;
  EXPECT_TRUE(cornerTurnsRed(*follower, "lock-kiosk-command-after", 5s, last)) << "corner " << last;
  EXPECT_TRUE(cornerTurnsRed(*leader, "lock-kiosk-command-leader", 1s, last)) << "corner " << last;
  const auto metrics = follower->get("/metrics").body;
  EXPECT_EQ(test::metric(metrics, "basalt_lock_commands_applied_total{node=\"north\",role=\"follower\"}"), 1.0)
      << metrics;

  follower->process().signal(SIGTERM);
  leader->process().signal(SIGTERM);
  const auto fr = follower->process().wait(20s);
  const auto lr = leader->process().wait(20s);
  EXPECT_EQ(fr.exitCode, 0) << fr.output;
  EXPECT_EQ(lr.exitCode, 0) << lr.output;
  const auto sent = commandFrame(lr.output, "command", 1);
  const auto followed = commandFrame(fr.output, "the leader's command", 1);
  ASSERT_TRUE(sent) << lr.output;
  ASSERT_TRUE(followed) << fr.output;
  EXPECT_EQ(*followed, *sent) << "the follower ran the command in another frame than the leader";
  EXPECT_NE(fr.output.find("1 of the leader's commands run"), std::string::npos) << fr.output;
  EXPECT_NE(lr.output.find("1 commands sent"), std::string::npos) << lr.output;
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

/// {locked frame: movie frame} that texture `texture` showed, from a node's debug output
/// ("frame N: texture 'T' shows movie 'M' frame K", BASALT_LOG=kiosk=debug).
std::map<long, long> movieFrames(const std::string& output, const std::string& texture) {
  const std::regex line("frame (\\d+): texture '" + texture + "' shows movie '[^']*' frame (\\d+)");
  std::map<long, long> frames;
  for (auto it = std::sregex_iterator(output.begin(), output.end(), line); it != std::sregex_iterator(); ++it) {
    frames[std::stol((*it)[1].str())] = std::stol((*it)[2].str());
  }
  return frames;
}

std::string movieManifest(const std::string& lock) {
  return R"(
[show]
name = "Locked movies"
fps = 60

[output]
kind = "headless"
size = "64x48"

[status]
listen = "127.0.0.1:0"

[lock]
)" + lock;
}

// Makes sure the movies `basalt run --movie` adds (VideoStreams, no director's) are frame-locked
// by number: the leader sends the frame each shows, and a follower that joined 1.5 s late, whose
// own movie timeline starts at its first frame, shows the leader's frame in every locked frame.
// Example failure: the follower's stream plays on its own timestamps (about 20 movie frames
// behind the leader's here, in every frame).
TEST(LockedKiosk, AFollowerShowsTheLeadersMovieFramesOfAMovieOption) {
  REQUIRE_EGL();
  const int port = lockPort(3);
  const auto leaderDir = test::writeShow(
      "lock-kiosk-movie-leader", movieManifest("role = \"leader\"\nnode = \"leader\"\nlisten = \"127.0.0.1\"\nport = " +
                                               std::to_string(port) + "\nfollowers = 0\ntimeout_ms = 500\n"));
  const auto followerDir = test::writeShow("lock-kiosk-movie-follower", movieManifest(followerLock(port, 3000)));
  auto clip = test::makeNumberedClip(leaderDir / "numbers.mkv", 30, 30, media::VideoCodec::kH264);
  ASSERT_TRUE(clip) << clip.error().describe();
  const std::string movie = "screen=" + clip->string();
  const std::map<std::string, std::string> debug{{"BASALT_LOG", "kiosk=debug"}};
  std::string why;
  // 600 frames at 60 Hz: 10 s, the follower in for the last 8 or so.
  auto leader = test::RunningShow::start(
      {(leaderDir / "show.toml").string(), "--movie", movie, "--frames", "600", "--realtime", "--no-resume"}, debug,
      why);
  ASSERT_TRUE(leader) << why;
  ASSERT_TRUE(leader->process().waitForOutput("shows movie", 20s)) << leader->process().outputSoFar();
  std::this_thread::sleep_for(1500ms);
  auto follower =
      test::RunningShow::start({(followerDir / "show.toml").string(), "--movie", movie, "--no-resume"}, debug, why);
  ASSERT_TRUE(follower) << why;
  const auto lr = leader->process().wait(60s);
  const auto fr = follower->process().wait(30s);
  ASSERT_EQ(lr.exitCode, 0) << lr.output;
  ASSERT_EQ(fr.exitCode, 0) << fr.output;

  const std::map<long, long> lead = movieFrames(lr.output, "screen");
  const std::map<long, long> mine = movieFrames(fr.output, "screen");
  ASSERT_FALSE(lead.empty()) << lr.output.substr(0, 3000);
  ASSERT_GE(mine.size(), 120u) << "the follower showed the movie in too few frames:\n" << fr.output.substr(0, 3000);
  EXPECT_GT(mine.begin()->first, lead.begin()->first + 30) << "the follower was meant to join late";
  std::size_t common = 0;
  std::vector<std::string> differ;
  for (const auto& [frame, shown] : mine) {
    const auto it = lead.find(frame);
    if (it == lead.end()) continue;
    ++common;
    if (it->second != shown) differ.push_back(fmt::format("{}: {} vs {}", frame, it->second, shown));
  }
  EXPECT_GE(common, mine.size() * 95 / 100) << "the follower's locked frames are the leader's";
  EXPECT_TRUE(differ.empty()) << differ.size() << " of " << common
                              << " locked frames showed another movie frame than the leader's (frame: leader vs "
                                 "follower), first: "
                              << differ.front();
  const std::regex counts("(\\d+) movie frames corrected to the leader's, (\\d+) late");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(fr.output, m, counts))
      << fr.output.substr(fr.output.size() > 3000 ? fr.output.size() - 3000 : 0);
  // Its own timeline started later than the leader's: the leader's number corrected it.
  EXPECT_GT(std::stol(m[1].str()), 0) << m[0].str();
}

}  // namespace
}  // namespace basalt
