// The status server's limits over real sockets (the table in kiosk/status/README.md): bodies
// over the limit whatever their transfer encoding, heads with too many or too large fields, slow
// clients, connections per address, snapshots per period and long commands. The expected values
// are the documented limits, written here again.
// Example failures: a chunked body read to its end however large; a client that sends a header
// byte a second keeping a thread forever; one address taking every connection; every
// /snapshot.png costing the frame loop a read-back; a megabyte "command" parsed by the loop.

#include <gtest/gtest.h>
#include <httplib.h>

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <future>
#include <thread>
#include <vector>

#include "kiosk/status/status_board.h"
#include "kiosk/status/status_server.h"
#include "runtime/log.h"

namespace basalt::kiosk {
namespace {

using namespace std::chrono_literals;

// kiosk/status/README.md, "Limits".
constexpr std::size_t kBodyLimit = 16384;  // [status] max_request_bytes' default
constexpr std::size_t kHeaderFields = 64;  // header fields in one request
constexpr std::size_t kHeadBytes = 16384;  // request line and header fields
constexpr int kPerClient = 4;
constexpr std::size_t kReservedDescriptors =
    64;  // descriptors always left to the show                // connections open from one address
constexpr auto kRequestTimeout = 10s;        // a request from its first byte
constexpr auto kSnapshotPeriod = 1s;         // the frame loop reads back at most once per period
constexpr std::size_t kCommandBytes = 1024;  // POST /control/command
constexpr const char* kToken = "0123456789abcdef0123456789abcdef";

/// Plays the frame loop: answers controls and snapshot requests, counting the snapshots.
class FakeLoop {
 public:
  explicit FakeLoop(StatusBoard& board) : board_(board) {
    thread_ = std::thread([this] {
      while (!stop_.load()) {
        ControlRequest request;
        while (board_.controls().pop(request)) {
          ++controls_;
          request.reply->answer(200, "done");
        }
        std::shared_ptr<SnapshotRequest> snapshot;
        if (board_.snapshotRequests().pop(snapshot)) {
          ++snapshots_;  // one read-back serves every request waiting now, as the director does
          Image image;
          image.width = 4;
          image.height = 2;
          image.channels = 4;
          image.pixels.assign(4 * 2 * 4, 200);
          do {
            snapshot->answer(true, image, {});
          } while (board_.snapshotRequests().pop(snapshot));
        }
        std::this_thread::sleep_for(5ms);
      }
    });
  }
  ~FakeLoop() {
    stop_ = true;
    thread_.join();
  }
  [[nodiscard]] int controls() const { return controls_.load(); }
  [[nodiscard]] int snapshots() const { return snapshots_.load(); }

 private:
  StatusBoard& board_;
  std::atomic<bool> stop_{false};
  std::atomic<int> controls_{0};
  std::atomic<int> snapshots_{0};
  std::thread thread_;
};

StatusSpec spec() {
  StatusSpec s;
  s.enabled = true;
  s.host = "0.0.0.0";  // 127.0.0.2 reaches it too
  s.port = 0;
  s.token = kToken;
  s.requestsPerSecond = 1000;
  return s;
}

/// A connected socket from `source` (any 127.x address works on loopback); -1 when it fails.
int connectFrom(const char* source, std::uint16_t port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in from{};
  from.sin_family = AF_INET;
  ::inet_pton(AF_INET, source, &from.sin_addr);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(port);
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::bind(fd, reinterpret_cast<sockaddr*>(&from), sizeof from) != 0 ||
      ::connect(fd, reinterpret_cast<sockaddr*>(&to), sizeof to) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

/// Sends `bytes` (ignoring a reset: the server may refuse before all is sent).
void sendAll(int fd, std::string_view bytes) {
  while (!bytes.empty()) {
    const ssize_t n = ::send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL);
    if (n <= 0) return;
    bytes.remove_prefix(static_cast<std::size_t>(n));
  }
}

/// What comes back on `fd` until the server closes it or `patience` passes.
std::string readAnswer(int fd, std::chrono::milliseconds patience) {
  std::string answer;
  const auto until = std::chrono::steady_clock::now() + patience;
  char buffer[4096];
  while (std::chrono::steady_clock::now() < until) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 50) <= 0) continue;
    const ssize_t n = ::recv(fd, buffer, sizeof buffer, 0);
    if (n <= 0) break;
    answer.append(buffer, static_cast<std::size_t>(n));
  }
  return answer;
}

/// One whole answer on `fd` (head and Content-Length bytes of body), leaving the connection
/// open; what came when `patience` runs out otherwise.
std::string readOneAnswer(int fd, std::chrono::milliseconds patience) {
  std::string answer;
  const auto until = std::chrono::steady_clock::now() + patience;
  char buffer[4096];
  while (std::chrono::steady_clock::now() < until) {
    const std::size_t head = answer.find("\r\n\r\n");
    if (head != std::string::npos) {
      const std::size_t at = answer.find("Content-Length: ");
      const std::size_t length = at < head ? std::stoul(answer.substr(at + 16)) : 0;
      if (answer.size() >= head + 4 + length) break;
    }
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 50) <= 0) continue;
    const ssize_t n = ::recv(fd, buffer, sizeof buffer, 0);
    if (n <= 0) break;
    answer.append(buffer, static_cast<std::size_t>(n));
  }
  return answer;
}

int statusOf(const std::string& answer) {
  if (!answer.starts_with("HTTP/1.1 ")) return 0;
  return std::atoi(answer.c_str() + 9);
}

/// One exchange on a fresh connection from 127.0.0.1.
std::string exchange(std::uint16_t port, std::string_view request) {
  const int fd = connectFrom("127.0.0.1", port);
  if (fd < 0) return {};
  sendAll(fd, request);
  std::string answer = readAnswer(fd, 15s);
  ::close(fd);
  return answer;
}

struct Running {
  StatusBoard board{SystemClock().wallNow(), 60};
  std::unique_ptr<StatusServer> server;
  std::unique_ptr<FakeLoop> loop;
  explicit Running(const StatusSpec& s) {
    auto started = StatusServer::start(s, board);
    EXPECT_TRUE(started) << started.error().describe();
    server = std::move(*started);
    loop = std::make_unique<FakeLoop>(board);
  }
  [[nodiscard]] std::uint16_t port() const { return server->port(); }
};

std::string chunked(std::size_t total, std::size_t chunk) {
  std::string body;
  for (std::size_t sent = 0; sent < total; sent += chunk) {
    const std::size_t n = std::min(chunk, total - sent);
    body += fmt::format("{:x}\r\n{}\r\n", n, std::string(n, 'a'));
  }
  return body + "0\r\n\r\n";
}

// Makes sure the body limit holds for chunked bodies, which httplib reads to their end.
// Example failure: 200, or a body of any size held in memory.
TEST(StatusServerLimits, AChunkedBodyOverTheLimitIsRefused) {
  Running r(spec());
  const std::string head = fmt::format(
      "POST /control/next HTTP/1.1\r\nHost: x\r\nAuthorization: Bearer {}\r\nTransfer-Encoding: chunked\r\n\r\n",
      kToken);
  const std::string over = exchange(r.port(), head + chunked(kBodyLimit + 1000, 1000));
  EXPECT_EQ(statusOf(over), 413) << over;
  EXPECT_EQ(r.loop->controls(), 0);
  // Within the limit, the same request is a control.
  const std::string under =
      exchange(r.port(), std::string(head).insert(head.size() - 2, "Connection: close\r\n") + chunked(100, 50));
  EXPECT_EQ(statusOf(under), 200) << under;
  // A Content-Length over the limit is refused without reading the body.
  const std::string announced = exchange(
      r.port(), fmt::format("POST /control/next HTTP/1.1\r\nHost: x\r\nContent-Length: {}\r\n\r\n", kBodyLimit + 1));
  EXPECT_EQ(statusOf(announced), 413) << announced;
}

// Makes sure a head with too many fields, or one too large, is refused (431) before httplib
// keeps it. Example failure: 200 after storing 100 000 header fields.
TEST(StatusServerLimits, TooManyOrTooLargeHeadersAreRefused) {
  Running r(spec());
  std::string many = "GET /health HTTP/1.1\r\nHost: x\r\n";
  for (std::size_t i = 0; i < kHeaderFields; ++i) many += fmt::format("X-Field-{}: {}\r\n", i, i);
  many += "\r\n";
  const std::string tooMany = exchange(r.port(), many);
  EXPECT_EQ(statusOf(tooMany), 431) << tooMany;

  const std::string large =
      fmt::format("GET /health HTTP/1.1\r\nHost: x\r\nX-Large: {}\r\n\r\n", std::string(kHeadBytes, 'b'));
  const std::string tooLarge = exchange(r.port(), large);
  EXPECT_EQ(statusOf(tooLarge), 431) << tooLarge;

  // Within both limits: answered.
  std::string fine = "GET /health HTTP/1.1\r\nHost: x\r\nConnection: close\r\n";
  for (std::size_t i = 0; i + 2 < kHeaderFields; ++i) fine += fmt::format("X-Field-{}: {}\r\n", i, i);
  fine += "\r\n";
  EXPECT_EQ(statusOf(exchange(r.port(), fine)), 200);
}

// Makes sure a client that sends its head a byte a second is dropped after the request
// time-out, and that others are answered meanwhile. Example failure: the slow client holds a
// worker until it stops, or everyone else waits behind it.
TEST(StatusServerLimits, ASlowClientIsDroppedWhileOthersAreServed) {
  Running r(spec());
  const int slow = connectFrom("127.0.0.1", r.port());
  ASSERT_GE(slow, 0);
  const auto began = std::chrono::steady_clock::now();
  std::atomic<bool> dropped{false};
  std::string slowAnswer;
  std::thread slowClient([&] {
    const std::string head = "GET /health HTTP/1.1\r\nHost: x\r\nX-Slow: " + std::string(200, 's');
    for (const char c : head) {
      if (::send(slow, &c, 1, MSG_NOSIGNAL) != 1) break;
      pollfd p{slow, POLLIN, 0};
      if (::poll(&p, 1, 1000) > 0) break;  // the server answered (and closes)
    }
    slowAnswer = readAnswer(slow, 5s);
    dropped = true;
  });
  // Another client, while the slow one is still sending.
  std::this_thread::sleep_for(2s);
  const std::string other = exchange(r.port(), "GET /health HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n");
  const bool otherBeforeDrop = !dropped.load();
  EXPECT_EQ(statusOf(other), 200) << other;
  EXPECT_TRUE(otherBeforeDrop) << "the other client was answered only after the slow one was dropped";
  slowClient.join();
  const auto took = std::chrono::steady_clock::now() - began;
  ::close(slow);
  EXPECT_EQ(statusOf(slowAnswer), 408) << slowAnswer;
  EXPECT_GE(took, kRequestTimeout) << "dropped before its time-out";
  EXPECT_LT(took, kRequestTimeout + 60s) << "the slow client was never dropped";
}

// Makes sure one address cannot hold every connection: past the per-client limit it is refused
// (503) while another address is still served. Example failure: the fifth connection waits or
// is served; 127.0.0.2 is refused as well.
TEST(StatusServerLimits, ConnectionsPastThePerClientLimitAreRefused) {
  Running r(spec());
  std::vector<int> held;
  for (int i = 0; i < kPerClient; ++i) {
    const int fd = connectFrom("127.0.0.1", r.port());
    ASSERT_GE(fd, 0);
    held.push_back(fd);
  }
  // The server admits connections in the order it accepts them; let it take the held ones.
  std::this_thread::sleep_for(500ms);
  const int extra = connectFrom("127.0.0.1", r.port());
  ASSERT_GE(extra, 0);
  sendAll(extra, "GET /health HTTP/1.1\r\nHost: x\r\n\r\n");
  const std::string refused = readAnswer(extra, 10s);
  ::close(extra);
  EXPECT_EQ(statusOf(refused), 503) << refused;

  const int other = connectFrom("127.0.0.2", r.port());
  ASSERT_GE(other, 0) << "127.0.0.2 should be a loopback address";
  sendAll(other, "GET /health HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n");
  const std::string served = readAnswer(other, 10s);
  ::close(other);
  EXPECT_EQ(statusOf(served), 200) << served;

  // Closing one held connection makes room for the address again.
  ::close(held.back());
  held.pop_back();
  std::string again;
  for (int attempt = 0; attempt < 50 && statusOf(again) != 200; ++attempt) {
    std::this_thread::sleep_for(100ms);
    again = exchange(r.port(), "GET /health HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n");
  }
  EXPECT_EQ(statusOf(again), 200) << again;
  for (const int fd : held) ::close(fd);
}

// Makes sure connections that send nothing cannot lock the technician out: 32 silent
// connections from eight addresses (four each, the per-address most) fill the server, and a
// ninth address still gets its answer, because the connection that has sent the least for
// longest is dropped (503) to make room. Each kind of refusal is counted in /metrics and said
// in the log, once for a flood. Example failures: the ninth address refused 503 while the
// silent ones hold every slot for their 10 s (a slowloris lock-out); refusals in neither the
// metrics nor the log.
TEST(StatusServerLimits, SilentConnectionsCannotLockOutAClient) {
  auto sink = std::make_shared<log::RingSink>(256);
  log::addSink(sink);
  Running r(spec());
  constexpr std::size_t kTotal = 32;  // [status]'s connection most
  std::vector<int> silent;
  for (std::size_t i = 0; i < kTotal; ++i) {
    const std::string from = fmt::format("127.0.0.{}", 10 + i / kPerClient);
    const int fd = connectFrom(from.c_str(), r.port());
    ASSERT_GE(fd, 0) << from;
    silent.push_back(fd);
    std::this_thread::sleep_for(5ms);  // admitted in this order: the first is the oldest
  }
  std::this_thread::sleep_for(300ms);
  const auto began = std::chrono::steady_clock::now();
  const int late = connectFrom("127.0.0.99", r.port());
  ASSERT_GE(late, 0);
  sendAll(late, "GET /health HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n");
  const std::string answer = readAnswer(late, 5s);
  ::close(late);
  EXPECT_EQ(statusOf(answer), 200) << answer;
  EXPECT_LT(std::chrono::steady_clock::now() - began, kRequestTimeout / 2) << "answered without waiting out a slot";
  // The oldest silent connection was the one dropped, with a 503 that says why.
  const std::string dropped = readAnswer(silent.front(), 2s);
  EXPECT_EQ(statusOf(dropped), 503) << dropped;
  EXPECT_NE(dropped.find("slowest"), std::string::npos) << dropped;
  const ServerCounters counters = r.server->counters();
  EXPECT_GE(counters.evicted, 1u);
  // A fifth connection from an address that has four open is still refused, and counted.
  const int fifth = connectFrom("127.0.0.11", r.port());
  ASSERT_GE(fifth, 0);
  const std::string refused = readAnswer(fifth, 3s);
  ::close(fifth);
  EXPECT_EQ(statusOf(refused), 503) << refused;
  EXPECT_GE(r.server->counters().rejectedConnections, 1u);
  for (const int fd : silent) ::close(fd);
  std::size_t said = 0;
  for (const auto& record : sink->snapshot(log::Level::kWarn)) {
    said += record.message.find("status server: dropped a connection from 127.0.0.10") != std::string::npos;
  }
  log::removeSink(sink);
  EXPECT_EQ(said, 1u) << "the first drop is said at once, in one line";
}

std::size_t openDescriptors() {
  std::size_t n = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator("/proc/self/fd")) ++n;
  return n;
}

// Makes sure HTTP clients cannot take the descriptors the show needs: with the process's limit
// a little above what is open, connections (from distinct addresses, so that the per-client
// limit plays no part) are refused once one more would leave fewer than the reserve, and the
// show can still open files then. Example failure: every connection admitted until open()
// fails with EMFILE, and saving the state with it.
TEST(StatusServerLimits, TheShowKeepsItsDescriptors) {
  Running r(spec());
  rlimit saved{};
  ASSERT_EQ(::getrlimit(RLIMIT_NOFILE, &saved), 0);
  rlimit tight = saved;
  tight.rlim_cur = openDescriptors() + kReservedDescriptors + 16;
  ASSERT_LE(tight.rlim_cur, saved.rlim_max);
  ASSERT_EQ(::setrlimit(RLIMIT_NOFILE, &tight), 0);
  std::vector<int> held;
  int admitted = 0;
  bool refused = false;
  for (int i = 1; i <= 16 && !refused; ++i) {
    const int fd = connectFrom(fmt::format("127.0.0.{}", i + 10).c_str(), r.port());
    if (fd < 0) break;
    held.push_back(fd);
    sendAll(fd, "GET /health HTTP/1.1\r\nHost: x\r\n\r\n");
    const std::string answer = readOneAnswer(fd, 10s);
    if (statusOf(answer) == 503) {
      refused = true;
    } else if (statusOf(answer) == 200) {
      ++admitted;
    }
  }
  // What the show still has: it can open files up to the reserve (less this test's own sockets).
  const std::size_t free = tight.rlim_cur - openDescriptors();
  std::vector<int> files;
  for (std::size_t i = 0; i + 8 < kReservedDescriptors; ++i) {
    const int fd = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
    if (fd < 0) break;
    files.push_back(fd);
  }
  const std::size_t opened = files.size();
  for (const int fd : files) ::close(fd);
  for (const int fd : held) ::close(fd);
  ::setrlimit(RLIMIT_NOFILE, &saved);
  EXPECT_TRUE(refused) << admitted << " connections admitted, none refused";
  EXPECT_GE(admitted, 1);
  EXPECT_GE(free + 2 * held.size(), kReservedDescriptors) << "HTTP left the show fewer than the reserve";
  EXPECT_EQ(opened, kReservedDescriptors - 8) << "the show could not open its files";
}

// Makes sure many clients asking for /snapshot.png cost the frame loop at most one read-back
// per period. Example failure: one read-back per request.
TEST(StatusServerLimits, SnapshotsCostTheLoopOnePerPeriod) {
  Running r(spec());
  constexpr int kClients = kPerClient;
  constexpr int kEach = 10;
  const auto began = std::chrono::steady_clock::now();
  std::vector<std::future<int>> answered;
  for (int c = 0; c < kClients; ++c) {
    answered.push_back(std::async(std::launch::async, [&] {
      httplib::Client client("127.0.0.1", r.port());
      client.set_read_timeout(10, 0);
      // One connection each: a client that closes and reconnects at once may briefly have one
      // more open than the per-client limit, as the server sees it.
      client.set_keep_alive(true);
      int ok = 0;
      for (int i = 0; i < kEach; ++i) {
        auto res = client.Get("/snapshot.png");
        if (res && res->status == 200 && res->body.starts_with("\x89PNG")) ++ok;
      }
      return ok;
    }));
  }
  int ok = 0;
  for (auto& a : answered) ok += a.get();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count();
  EXPECT_EQ(ok, kClients * kEach);
  const double periods = seconds / std::chrono::duration<double>(kSnapshotPeriod).count();
  EXPECT_GE(r.loop->snapshots(), 1);
  EXPECT_LE(r.loop->snapshots(), static_cast<int>(periods) + 1) << ok << " snapshots served in " << seconds << " s";
}

// Makes sure a long command is refused before the frame loop sees it. Example failure: the
// loop parses a megabyte, or the answer is 200.
TEST(StatusServerLimits, ALongCommandIsRefusedBeforeParsing) {
  Running r(spec());
  httplib::Client client("127.0.0.1", r.port());
  client.set_bearer_token_auth(kToken);
  auto longOne = client.Post("/control/command", "echo " + std::string(kCommandBytes, 'x'), "text/plain");
  ASSERT_TRUE(longOne);
  EXPECT_EQ(longOne->status, 413) << longOne->body;
  EXPECT_EQ(r.loop->controls(), 0) << "the command reached the frame loop";
  auto shortOne = client.Post("/control/command", "echo " + std::string(kCommandBytes - 10, 'x'), "text/plain");
  ASSERT_TRUE(shortOne);
  EXPECT_EQ(shortOne->status, 200) << shortOne->body;
  EXPECT_EQ(r.loop->controls(), 1);
}

}  // namespace
}  // namespace basalt::kiosk
