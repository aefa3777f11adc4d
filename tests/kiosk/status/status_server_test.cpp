// The status server on its own, without a show: a StatusBoard, the server, and a thread that
// plays the frame loop's part for controls. Over real HTTP (cpp-httplib's client, raw sockets
// and curl where installed): the port is the server's alone and a taken one is retried; a POST
// without a body is a POST.
// Example failures: a second server that binds the same port through SO_REUSEPORT and answers
// half the requests; a taken port that ends the server for good, or that the log does not name;
// `curl -X POST` refused as "malformed" after five seconds.

#include <gtest/gtest.h>
#include <httplib.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "kiosk/status/status_board.h"
#include "kiosk/status/status_server.h"
#include "support/process.h"

namespace basalt::kiosk {
namespace {

using namespace std::chrono_literals;

constexpr const char* kToken = "0123456789abcdef0123456789abcdef";

bool has(const std::string& text, const std::string& needle) { return text.find(needle) != std::string::npos; }

/// Answers the board's controls as the frame loop would: "did KIND with 'ARGUMENT'".
class FakeLoop {
 public:
  explicit FakeLoop(StatusBoard& board) : board_(board) {
    thread_ = std::thread([this] {
      while (!stop_.load()) {
        ControlRequest request;
        while (board_.controls().pop(request)) {
          ++answered_;
          request.reply->answer(200, fmt::format("did {} with '{}'", static_cast<int>(request.kind), request.argument));
        }
        std::this_thread::sleep_for(5ms);
      }
    });
  }
  ~FakeLoop() {
    stop_ = true;
    thread_.join();
  }
  [[nodiscard]] int answered() const { return answered_.load(); }

 private:
  StatusBoard& board_;
  std::atomic<bool> stop_{false};
  std::atomic<int> answered_{0};
  std::thread thread_;
};

StatusSpec spec(std::uint16_t port) {
  StatusSpec s;
  s.enabled = true;
  s.host = "127.0.0.1";
  s.port = port;
  s.token = kToken;
  s.requestsPerSecond = 1000;
  return s;
}

int get(std::uint16_t port, const std::string& path, std::string* body = nullptr) {
  httplib::Client client("127.0.0.1", port);
  client.set_connection_timeout(2, 0);
  client.set_read_timeout(10, 0);
  auto r = client.Get(path);
  if (!r) return 0;
  if (body) *body = r->body;
  return r->status;
}

/// Sends `bytes` on a fresh connection and returns what comes back within `patience`.
[[maybe_unused]] std::string raw(std::uint16_t port, const std::string& bytes, std::chrono::milliseconds patience) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(port);
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  std::string answer;
  if (::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) == 0) {
    (void)::send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL);
    // The connection stays open for writing, as curl's does: the server must not wait for more.
    const auto until = std::chrono::steady_clock::now() + patience;
    char buffer[4096];
    while (std::chrono::steady_clock::now() < until) {
      pollfd p{fd, POLLIN, 0};
      if (::poll(&p, 1, 50) <= 0) continue;
      const ssize_t n = ::recv(fd, buffer, sizeof buffer, 0);
      if (n <= 0) break;
      answer.append(buffer, static_cast<std::size_t>(n));
      if (answer.find("\r\n\r\n") != std::string::npos && answer.find('}') != std::string::npos) break;
    }
  }
  ::close(fd);
  return answer;
}

std::string logged(const StatusBoard& board) {
  std::string all;
  for (const log::Record& r : board.snapshot(WallTime{}).logTail) all += r.message + "\n";
  return all;
}

// Makes sure no second socket can share the server's port, the way httplib's default
// SO_REUSEPORT allowed: a socket asking for SO_REUSEPORT is refused with EADDRINUSE.
// Example failure: bind() succeeds and the kernel splits the connections between the two.
TEST(StatusServerPort, NoOtherSocketSharesThePort) {
  StatusBoard board(WallTime{}, 30);
  auto server = StatusServer::start(spec(0), board);
  ASSERT_TRUE(server) << server.error().describe();
  ASSERT_TRUE((*server)->listening());
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  const int yes = 1;
  ASSERT_EQ(::setsockopt(fd, SOL_SOCKET, SO_REUSEPORT, &yes, sizeof yes), 0);
  ASSERT_EQ(::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes), 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons((*server)->port());
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  const int bound = ::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address);
  const int error = errno;
  ::close(fd);
  EXPECT_EQ(bound, -1) << "a socket with SO_REUSEPORT bound the status server's port";
  EXPECT_EQ(error, EADDRINUSE);
}

// Makes sure a second server on a taken port says so, keeps trying, and takes the port once the
// first one is gone; meanwhile every request reaches the first. Example failures: the second
// server gives up (no status page until a restart); a message that does not name the port.
TEST(StatusServerPort, ATakenPortIsRetriedUntilItIsFree) {
  StatusBoard board(WallTime{}, 30);
  auto first = StatusServer::start(spec(0), board);
  ASSERT_TRUE(first) << first.error().describe();
  const std::uint16_t port = (*first)->port();
  const auto began = std::chrono::steady_clock::now();
  auto second = StatusServer::start(spec(port), board);
  ASSERT_TRUE(second) << "a taken port is not the end of the server: " << second.error().describe();
  EXPECT_FALSE((*second)->listening());
  EXPECT_EQ((*second)->port(), port);
  const std::string why = (*second)->notUpBecause();
  EXPECT_TRUE(has(why, "port " + std::to_string(port) + " on 127.0.0.1 is taken")) << why;
  EXPECT_TRUE(has(why, "another Basalt may be running")) << why;
  const std::string log = logged(board);
  EXPECT_TRUE(has(log, "the status server is not up yet: port " + std::to_string(port))) << log;
  EXPECT_TRUE(has(log, "the show plays on")) << log;
  // Every request is the first server's: count them on each.
  for (int i = 0; i < 10; ++i) EXPECT_EQ(get(port, "/health"), 200);
  EXPECT_EQ((*first)->counters().requests, 10u);
  EXPECT_EQ((*second)->counters().requests, 0u);

  first->reset();  // the port is free: the second takes it at its next try (1 s, then 3 s)
  while (!(*second)->listening() && std::chrono::steady_clock::now() - began < 8s) std::this_thread::sleep_for(20ms);
  ASSERT_TRUE((*second)->listening()) << logged(board);
  EXPECT_EQ((*second)->notUpBecause(), "");
  EXPECT_EQ(get(port, "/health"), 200);
  EXPECT_EQ((*second)->counters().requests, 1u);
  EXPECT_TRUE(
      has(logged(board), "status server on http://127.0.0.1:" + std::to_string(port) + "/ (the port was free after"))
      << logged(board);
}

// Makes sure a server still waiting for its port stops at once. Example failure: the process
// hangs at exit for the rest of a 30 s back-off.
TEST(StatusServerPort, AWaitingServerStopsAtOnce) {
  StatusBoard board(WallTime{}, 30);
  auto first = StatusServer::start(spec(0), board);
  ASSERT_TRUE(first);
  auto second = StatusServer::start(spec((*first)->port()), board);
  ASSERT_TRUE(second);
  ASSERT_FALSE((*second)->listening());
  const auto began = std::chrono::steady_clock::now();
  second->reset();
  EXPECT_LT(std::chrono::steady_clock::now() - began, 500ms);
}

}  // namespace
}  // namespace basalt::kiosk
