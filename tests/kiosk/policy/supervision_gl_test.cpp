// Supervision: `basalt run` under a service manager. The test plays systemd's part through an
// emulated notify socket ($NOTIFY_SOCKET, $WATCHDOG_USEC, as systemd sets them for a
// Type=notify service with WatchdogSec=): READY=1 after the first frame, STATUS=, watchdog
// pings, RELOADING=1 on SIGHUP, STOPPING=1 on SIGTERM; a show hung on purpose misses its pings,
// is killed as systemd kills it and, restarted, comes back where it was; so does a show killed
// outright. Pings come from the frame loop itself. Logs reach the journal with their fields.
// Where a real systemd user manager exists, the same runs under `systemd-run --user`.
// Example failures: READY sent before anything is on screen; pings from a timer thread that
// keep a hung show alive; a restarted show starting from the beginning; a journal record
// without its priority.

#include <gtest/gtest.h>

#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <fstream>
#include <thread>

#include "kiosk/loop/frame_loop.h"
#include "kiosk/policy/supervisor.h"
#include "render/output.h"
#include "render/renderer.h"
#include "runtime/event_loop.h"
#include "runtime/log.h"
#include "runtime/show/show.h"
#include "support/datagram_socket.h"
#include "support/kiosk_process.h"
#include "support/test_paths.h"

namespace basalt {
namespace {

using namespace std::chrono_literals;

using test::DatagramSocket;
using test::SocketDir;

constexpr const char* kShow = R"(
[show]
name = "Supervised"
entry = "default"
fps = 30

[output]
kind = "headless"
size = "64x64"

[kiosk]
resume = true
)";

/// systemd's side of one service: environment, starting, and counting pings.
struct ServiceManager {
  std::filesystem::path dir =
      test::scratchDir(std::string("supervision-") + testing::UnitTest::GetInstance()->current_test_info()->name());
  SocketDir sockets;
  DatagramSocket notify{sockets.path() / "notify.sock"};
  std::filesystem::path show = [this] {
    std::ofstream(dir / "show.toml") << kShow;
    return dir / "show.toml";
  }();

  test::Process start(std::chrono::milliseconds watchdog) {
    return test::Process::start(
        {(test::binaryDir() / "basalt").string(), "run", show.string(), "--realtime", "--state-dir",
         (dir / "state").string()},
        {{"NOTIFY_SOCKET", notify.path().string()},
         {"WATCHDOG_USEC", std::to_string(std::chrono::duration_cast<std::chrono::microseconds>(watchdog).count())}});
  }
};

#define REQUIRE_EGL()                                                                  \
  do {                                                                                 \
    std::string why;                                                                   \
    if (!test::headlessEglWorks(why)) GTEST_SKIP() << "no headless EGL here: " << why; \
  } while (false)

TEST(Supervision, ReadyStatusWatchdogReloadAndStop) {
  REQUIRE_EGL();
  ServiceManager manager;
  ASSERT_TRUE(manager.notify.bound());
  test::Process p = manager.start(400ms);
  std::vector<std::string> seen;
  ASSERT_TRUE(manager.notify.waitFor("READY=1", 20s, &seen)) << p.outputWithin(1s);
  std::string status;
  for (const auto& d : seen) status += d + "|";
  EXPECT_NE(status.find("STATUS=open, playing: 'Supervised' (1/1)"), std::string::npos) << status;

  // Pings every half timeout (0.2 s) while the show runs.
  int pings = 0;
  const auto end = std::chrono::steady_clock::now() + 1200ms;
  while (std::chrono::steady_clock::now() < end) {
    if (auto d = manager.notify.receive(100ms); d && *d == "WATCHDOG=1") ++pings;
  }
  EXPECT_GE(pings, 4) << "about 6 expected in 1.2 s";

  p.signal(SIGHUP);
  EXPECT_TRUE(manager.notify.waitFor("RELOADING=1", 5s)) << p.outputSoFar();
  EXPECT_TRUE(manager.notify.waitFor("READY=1", 10s)) << p.outputWithin(1s);

  p.signal(SIGTERM);
  EXPECT_TRUE(manager.notify.waitFor("STOPPING=1", 5s)) << p.outputSoFar();
  const auto r = p.wait(20s);
  EXPECT_EQ(r.exitCode, 0) << r.output;
}

/// Waits until `p` has been quiet on the watchdog for `timeout`: what systemd then does.
bool watchdogExpires(DatagramSocket& notify, std::chrono::milliseconds timeout) {
  auto lastPing = std::chrono::steady_clock::now();
  const auto giveUp = lastPing + 20s;
  while (std::chrono::steady_clock::now() < giveUp) {
    if (auto d = notify.receive(50ms); d && d->find("WATCHDOG=1") != std::string::npos) {
      lastPing = std::chrono::steady_clock::now();
    }
    if (std::chrono::steady_clock::now() - lastPing > timeout) return true;
  }
  return false;
}

TEST(Supervision, AHungShowIsKilledAndComesBackWhereItWas) {
  REQUIRE_EGL();
  ServiceManager manager;
  ASSERT_TRUE(manager.notify.bound());
  test::Process first = manager.start(500ms);
  ASSERT_TRUE(manager.notify.waitFor("READY=1", 20s)) << first.outputWithin(1s);
  std::this_thread::sleep_for(3s);  // the state is saved every 2 s of show time

  // Hung on purpose: nothing of the process runs, so no ping comes.
  first.signal(SIGSTOP);
  ASSERT_TRUE(watchdogExpires(manager.notify, 500ms)) << "a stopped show must miss its pings";
  // systemd's WatchdogSignal (SIGABRT), then SIGKILL after TimeoutAbortSec.
  first.signal(SIGABRT);
  first.signal(SIGKILL);
  const auto killed = first.wait(10s);
  EXPECT_EQ(killed.exitCode, 128 + SIGKILL);

  // Restart=always.
  test::Process second = manager.start(500ms);
  ASSERT_TRUE(manager.notify.waitFor("READY=1", 20s)) << second.outputWithin(1s);
  ASSERT_TRUE(second.waitForOutput("resuming 'Supervised' at ", 5s)) << second.outputSoFar();
  const std::string& out = second.outputSoFar();
  const auto at = out.find("resuming 'Supervised' at ") + 25;
  const double position = std::stod(out.substr(at));
  EXPECT_GE(position, 1.5) << "it ran about 3 s before it hung: " << out;
  EXPECT_LE(position, 4.0) << out;

  // Killed outright (a crash): back again, further on.
  std::this_thread::sleep_for(2500ms);
  second.signal(SIGKILL);
  second.wait(10s);
  test::Process third = manager.start(500ms);
  ASSERT_TRUE(manager.notify.waitFor("READY=1", 20s)) << third.outputWithin(1s);
  ASSERT_TRUE(third.waitForOutput("resuming 'Supervised' at ", 5s)) << third.outputSoFar();
  const std::string& out3 = third.outputSoFar();
  const double later = std::stod(out3.substr(out3.find("resuming 'Supervised' at ") + 25));
  EXPECT_GT(later, position) << out3;
  third.signal(SIGTERM);
  EXPECT_EQ(third.wait(20s).exitCode, 0);
}

TEST(Supervision, ACorruptStateFileIsIgnoredWithAWarning) {
  REQUIRE_EGL();
  ServiceManager manager;
  std::filesystem::create_directories(manager.dir / "state");
  {
    test::Process p = manager.start(2s);
    ASSERT_TRUE(manager.notify.waitFor("READY=1", 20s)) << p.outputWithin(1s);
    p.signal(SIGTERM);
    p.wait(20s);
  }
  // Damage every state file the way a torn write or an editor would.
  int damaged = 0;
  for (const auto& entry : std::filesystem::directory_iterator(manager.dir / "state")) {
    if (!entry.is_regular_file()) continue;  // the show's last good copy (last-good/)
    std::ofstream(entry.path(), std::ios::app) << "position_ns=999999999999\n";
    ++damaged;
  }
  ASSERT_EQ(damaged, 1);
  test::Process p = manager.start(2s);
  ASSERT_TRUE(manager.notify.waitFor("READY=1", 20s)) << p.outputWithin(1s);
  EXPECT_TRUE(p.waitForOutput("ignoring the saved state", 5s)) << p.outputSoFar();
  EXPECT_NE(p.outputSoFar().find("the show starts from the beginning"), std::string::npos) << p.outputSoFar();
  EXPECT_EQ(p.outputSoFar().find("resuming"), std::string::npos) << p.outputSoFar();
  p.signal(SIGTERM);
  EXPECT_EQ(p.wait(20s).exitCode, 0);
}

TEST(Supervision, ANotifySocketThatCannotBeReachedIsOneWarningAndTheShowGoesOn) {
  REQUIRE_EGL();
  const std::filesystem::path dir = test::scratchDir("supervision-unreachable");
  std::ofstream(dir / "show.toml") << kShow;
  const std::string tooLong = "/tmp/" + std::string(120, 'n');
  for (const std::string& socket : {tooLong, std::string("/tmp/basalt-no-such-notify-socket")}) {
    const auto r = test::run({(test::binaryDir() / "basalt").string(), "run", (dir / "show.toml").string(), "--frames",
                              "20", "--state-dir", (dir / "state").string()},
                             {{"NOTIFY_SOCKET", socket}, {"WATCHDOG_USEC", "100000"}}, 60s);
    EXPECT_EQ(r.exitCode, 0) << r.output;
    const std::string warning = "cannot notify the service manager at $NOTIFY_SOCKET=" + socket;
    const auto first = r.output.find(warning);
    ASSERT_NE(first, std::string::npos) << r.output;
    EXPECT_EQ(r.output.find(warning, first + 1), std::string::npos) << "one warning, not one a frame: " << r.output;
    EXPECT_EQ(r.output.find("107 bytes") != std::string::npos, socket == tooLong) << r.output;
  }
}

TEST(Supervision, UnderARealSystemdUserManager) {
  REQUIRE_EGL();
  if (::access("/usr/bin/systemd-run", X_OK) != 0) GTEST_SKIP() << "systemd-run is not installed";
  const auto probe = test::run({"/usr/bin/systemd-run", "--user", "--quiet", "--wait", "/bin/true"}, {}, 20s);
  if (probe.exitCode != 0) {
    GTEST_SKIP() << "no systemd user manager here (systemd-run --user: " << probe.output
                 << "); the emulated notify socket tests above cover supervision";
  }
  ServiceManager manager;
  const std::string unit = "basalt-test-" + std::to_string(::getpid());
  const auto r = test::run({"/usr/bin/systemd-run",
                            "--user",
                            "--quiet",
                            "--wait",
                            "--collect",
                            "--unit",
                            unit,
                            "-p",
                            "Type=notify",
                            "-p",
                            "WatchdogSec=5",
                            "-p",
                            "NotifyAccess=main",
                            (test::binaryDir() / "basalt").string(),
                            "run",
                            manager.show.string(),
                            "--seconds",
                            "2",
                            "--realtime",
                            "--no-resume",
                            "--output-dir",
                            (manager.dir / "out").string()},
                           {}, 60s);
  EXPECT_EQ(r.exitCode, 0) << "systemd-run --wait reports the service's result: " << r.output;
}

// ---- In process: the pings come from the frame loop ----------------------------------------

/// Stalls the frame loop for `stall` at frame `at`, as a hung script or driver would.
class Staller final : public kiosk::FrameParticipant {
 public:
  Staller(std::int64_t at, std::chrono::milliseconds stall) : at_(at), stall_(stall) {}
  Result<void> beforeDraw(const kiosk::FrameContext& frame) override {
    if (frame.frame == at_) std::this_thread::sleep_for(stall_);
    return {};
  }

 private:
  std::int64_t at_;
  std::chrono::milliseconds stall_;
};

TEST(Supervision, PingsComeFromTheFrameLoop) {
  auto output = render::createHeadlessOutput({32, 32});
  if (!output) GTEST_SKIP() << "no headless EGL here: " << output.error().describe();
  auto renderer = render::Renderer::create();
  ASSERT_TRUE(renderer);
  SocketDir sockets;
  DatagramSocket notify(sockets.path() / "notify.sock");
  ASSERT_TRUE(notify.bound());
  ::setenv("NOTIFY_SOCKET", notify.path().c_str(), 1);
  ::setenv("WATCHDOG_USEC", "200000", 1);
  auto supervisor = kiosk::Supervisor::fromEnvironment();
  ASSERT_TRUE(supervisor->notifying());
  ASSERT_EQ(supervisor->watchdogTimeout(), std::chrono::milliseconds(200));

  SystemClock clock;
  auto loop = runtime::EventLoop::create(clock);
  ASSERT_TRUE(loop);
  runtime::Show show = runtime::Show::makeDefault();
  kiosk::FrameLoop frameLoop({50, 60}, clock, nullptr, **loop, show, **output, **renderer);
  Staller staller(20, 700ms);
  frameLoop.addParticipant(staller);
  frameLoop.addParticipant(*supervisor);

  std::vector<std::chrono::steady_clock::time_point> pings;
  std::atomic<bool> done{false};
  std::thread listener([&] {
    while (!done) {
      if (auto d = notify.receive(50ms)) {
        if (*d == "WATCHDOG=1") pings.push_back(std::chrono::steady_clock::now());
      }
    }
  });
  auto stats = frameLoop.run();
  done = true;
  listener.join();
  ::unsetenv("NOTIFY_SOCKET");
  ::unsetenv("WATCHDOG_USEC");
  ASSERT_TRUE(stats) << stats.error().describe();
  ASSERT_GE(pings.size(), 4u);
  // While the loop stalled for 700 ms, no ping came: the gap spans the stall.
  std::chrono::milliseconds longest{0};
  for (std::size_t i = 1; i < pings.size(); ++i) {
    longest = std::max(longest, std::chrono::duration_cast<std::chrono::milliseconds>(pings[i] - pings[i - 1]));
  }
  EXPECT_GE(longest, 650ms) << "a ping arrived while the frame loop was stuck";
}

// ---- The journal ---------------------------------------------------------------------------

BASALT_LOG_CATEGORY(JournalTest, "kiosk");

TEST(Journal, RecordsCarryTheirFieldsWhenStderrIsTheJournal) {
  const std::filesystem::path socket = "/run/systemd/journal/socket";
  if (std::filesystem::exists(socket)) {
    GTEST_SKIP() << "a journal runs on this machine; this test emulates one at " << socket
                 << " and will not replace it";
  }
  std::error_code ec;
  const bool madeRun = !std::filesystem::exists("/run/systemd");
  const bool madeJournal = !std::filesystem::exists("/run/systemd/journal");
  std::filesystem::create_directories(socket.parent_path(), ec);
  if (ec) GTEST_SKIP() << "cannot create " << socket.parent_path() << ": " << ec.message();
  {
    DatagramSocket journal(socket);
    ASSERT_TRUE(journal.bound());
    // Not the journal: JOURNAL_STREAM names another file.
    ::setenv("JOURNAL_STREAM", "1:1", 1);
    EXPECT_FALSE(kiosk::stderrIsJournal());
    struct stat st{};
    ASSERT_EQ(::fstat(STDERR_FILENO, &st), 0);
    ::setenv("JOURNAL_STREAM", (std::to_string(st.st_dev) + ":" + std::to_string(st.st_ino)).c_str(), 1);
    EXPECT_TRUE(kiosk::stderrIsJournal());
    ::unsetenv("JOURNAL_STREAM");

    kiosk::logToJournal("Journal test");
    log::warn(kLogJournalTest, "the dial box went away");
    const auto record = journal.receive(5000ms);
    ASSERT_TRUE(record) << "nothing reached the journal socket";
    EXPECT_NE(record->find("MESSAGE=kiosk: the dial box went away\n"), std::string::npos) << *record;
    EXPECT_NE(record->find("PRIORITY=4\n"), std::string::npos) << *record;
    EXPECT_NE(record->find("SYSLOG_IDENTIFIER=basalt\n"), std::string::npos) << *record;
    EXPECT_NE(record->find("BASALT_CATEGORY=kiosk\n"), std::string::npos) << *record;
    EXPECT_NE(record->find("BASALT_LEVEL=warning\n"), std::string::npos) << *record;
    EXPECT_NE(record->find("BASALT_SHOW=Journal test\n"), std::string::npos) << *record;
    EXPECT_NE(record->find("CODE_FILE="), std::string::npos) << *record;
  }
  if (madeJournal) std::filesystem::remove("/run/systemd/journal", ec);
  if (madeRun) std::filesystem::remove("/run/systemd", ec);
}

}  // namespace
}  // namespace basalt
