// The frame loop's own watchdog: a participant that does not return (here one that sleeps) makes
// /health "degraded" with a problem that says the loop is stuck, over real HTTP, and the service
// manager's watchdog pings stop until the loop moves again (an emulated notify socket plays
// systemd's part, as in tests/kiosk/policy/supervision_gl_test.cpp).
// Example failures: /health "ok" while no frame is drawn; pings from a thread that keeps a stuck
// loop alive in systemd's eyes; the problem left behind once the loop moves again.

#include <gtest/gtest.h>
#include <httplib.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>

#include <nlohmann/json.hpp>

#include "kiosk/loop/frame_loop.h"
#include "kiosk/policy/supervisor.h"
#include "kiosk/status/status_board.h"
#include "kiosk/status/status_server.h"
#include "runtime/event_loop.h"
#include "support/datagram_socket.h"
#include "support/render_fixture.h"

namespace basalt::test {
namespace {

using namespace std::chrono_literals;

/// Sleeps in beforeDraw of frame `at` until released: a participant that does not return.
class Sleeper final : public kiosk::FrameParticipant {
 public:
  explicit Sleeper(std::int64_t at) : at_(at) {}
  Result<void> beforeDraw(const kiosk::FrameContext& frame) override {
    if (frame.frame != at_) return {};
    std::unique_lock lock(mutex_);
    asleep_ = true;
    wake_.notify_all();
    wake_.wait_for(lock, 60s, [this] { return released_; });
    asleep_ = false;
    return {};
  }
  void afterPresent(const kiosk::FrameContext& frame) override { last_ = frame.frame; }
  [[nodiscard]] bool wantsStop() const override { return stop_.load(); }

  bool waitAsleep(std::chrono::seconds limit) {
    std::unique_lock lock(mutex_);
    return wake_.wait_for(lock, limit, [this] { return asleep_; });
  }
  void release() {
    std::lock_guard lock(mutex_);
    released_ = true;
    wake_.notify_all();
  }
  void stop() { stop_ = true; }
  [[nodiscard]] std::int64_t lastPresented() const { return last_.load(); }

 private:
  std::int64_t at_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool asleep_ = false;    // guarded by mutex_
  bool released_ = false;  // guarded by mutex_
  std::atomic<bool> stop_{false};
  std::atomic<std::int64_t> last_{-1};
};

class FrameLoopWatchdog : public RenderTest {};

nlohmann::json health(std::uint16_t port) {
  httplib::Client client("127.0.0.1", port);
  client.set_read_timeout(10, 0);
  auto r = client.Get("/health");
  if (!r || r->status != 200) return {};
  return nlohmann::json::parse(r->body, nullptr, false);
}

bool saysStuck(const nlohmann::json& h) {
  if (!h.is_object() || h.value("state", "") != "degraded" || !h.contains("problems")) return false;
  for (const auto& p : h["problems"]) {
    if (p.is_string() && p.get<std::string>().find("frame loop has been stuck") != std::string::npos) return true;
  }
  return false;
}

TEST_F(FrameLoopWatchdog, AStuckParticipantDegradesHealthAndStopsThePings) {
  SocketDir sockets;
  DatagramSocket notify(sockets.path() / "notify.sock");
  ASSERT_TRUE(notify.bound());
  ::setenv("NOTIFY_SOCKET", notify.path().c_str(), 1);
  ::setenv("WATCHDOG_USEC", "200000", 1);  // a ping every 0.1 s while the loop runs
  // sd_notify reads $NOTIFY_SOCKET at each message: it stays set until the test ends.
  struct Unset {
    ~Unset() {
      ::unsetenv("NOTIFY_SOCKET");
      ::unsetenv("WATCHDOG_USEC");
    }
  } unset;
  auto supervisor = kiosk::Supervisor::fromEnvironment();
  ASSERT_TRUE(supervisor->watchdogTimeout());

  SystemClock clock;
  auto loop = runtime::EventLoop::create(clock);
  ASSERT_TRUE(loop);
  runtime::Show show = runtime::Show::makeDefault();
  kiosk::FrameLoop frameLoop({30, -1}, clock, nullptr, **loop, show, output(), renderer());
  kiosk::StatusBoard board(clock.wallNow(), 30);
  board.setFrameWatch(frameLoop.watch());
  kiosk::StatusSpec spec;
  spec.enabled = true;
  spec.host = "127.0.0.1";
  spec.port = 0;
  spec.requestsPerSecond = 1000;
  auto server = kiosk::StatusServer::start(spec, board);
  ASSERT_TRUE(server) << server.error().describe();

  Sleeper sleeper(30);  // one second into the show
  frameLoop.addParticipant(*supervisor);
  frameLoop.addParticipant(sleeper);

  // The observer: the loop runs on this thread, where the GL context is current.
  int pingsBefore = 0;
  bool okBefore = false;
  bool degraded = false;
  int pingsWhileStuck = -1;
  bool okAfter = false;
  int pingsAfter = 0;
  std::thread observer([&] {
    okBefore = health((*server)->port()).value("state", "") == "ok";
    const auto asleepBy = std::chrono::steady_clock::now() + 30s;
    while (!sleeper.waitAsleep(0s)) {
      if (std::chrono::steady_clock::now() > asleepBy) {
        sleeper.stop();
        return;
      }
      if (auto d = notify.receive(50ms); d && d->find("WATCHDOG=1") != std::string::npos) ++pingsBefore;
    }
    // Pings sent before the loop stuck are read while waiting for /health to say so.
    const auto giveUp = std::chrono::steady_clock::now() + 30s;
    while (!degraded && std::chrono::steady_clock::now() < giveUp) {
      while (notify.receive(0ms)) {
      }
      degraded = saysStuck(health((*server)->port()));
      if (!degraded) std::this_thread::sleep_for(200ms);
    }
    while (notify.receive(0ms)) {
    }
    // Five watchdog periods with the loop still stuck: systemd would have restarted it.
    pingsWhileStuck = 0;
    const auto quietUntil = std::chrono::steady_clock::now() + 1s;
    while (std::chrono::steady_clock::now() < quietUntil) {
      if (auto d = notify.receive(50ms); d && d->find("WATCHDOG=1") != std::string::npos) ++pingsWhileStuck;
    }
    sleeper.release();
    const auto resumed = std::chrono::steady_clock::now() + 30s;
    while (std::chrono::steady_clock::now() < resumed && (!okAfter || pingsAfter < 2)) {
      if (auto d = notify.receive(100ms); d && d->find("WATCHDOG=1") != std::string::npos) ++pingsAfter;
      if (!okAfter) okAfter = health((*server)->port()).value("state", "") == "ok";
    }
    sleeper.stop();
  });
  auto stats = frameLoop.run();
  observer.join();
  ASSERT_TRUE(stats) << stats.error().describe();
  EXPECT_TRUE(okBefore) << "the show was not ok before it stuck";
  EXPECT_GE(pingsBefore, 1) << "no pings while the loop ran: the notify socket is not heard";
  EXPECT_TRUE(degraded) << "/health never said the loop is stuck";
  EXPECT_EQ(pingsWhileStuck, 0) << "the watchdog was pinged while the loop was stuck";
  EXPECT_TRUE(okAfter) << "the problem stayed after the loop moved again";
  EXPECT_GE(pingsAfter, 2) << "the pings did not come back";
  EXPECT_GT(sleeper.lastPresented(), 30);
}

}  // namespace
}  // namespace basalt::test
