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
#include <ifaddrs.h>
#include <net/if.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <thread>

#include <nlohmann/json.hpp>

#include "kiosk/status/status_board.h"
#include "kiosk/status/status_server.h"
#include "support/process.h"
#include "support/test_paths.h"

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
std::string raw(std::uint16_t port, const std::string& bytes, std::chrono::milliseconds patience) {
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

/// The status line's code ("HTTP/1.1 200 OK" -> 200), or 0.
int statusOf(const std::string& answer) {
  return answer.starts_with("HTTP/1.1 ") && answer.size() >= 12 ? std::stoi(answer.substr(9, 3)) : 0;
}

// Makes sure a POST that announces no body (neither Content-Length nor Transfer-Encoding, as
// `curl -X POST` sends it) is taken at once as a POST with an empty body, on every path, while
// the client keeps its connection open. Example failure: 400 "malformed request" after httplib
// waited five seconds for the client to close.
TEST(StatusServerPost, APostWithoutABodyIsAPost) {
  StatusBoard board(WallTime{}, 30);
  FakeLoop loop(board);
  auto server = StatusServer::start(spec(0), board);
  ASSERT_TRUE(server) << server.error().describe();
  const std::uint16_t port = (*server)->port();
  const std::string auth = std::string("Authorization: Bearer ") + kToken + "\r\n";
  const auto began = std::chrono::steady_clock::now();
  const std::string next = raw(port, "POST /control/next HTTP/1.1\r\nHost: x\r\n" + auth + "\r\n", 3s);
  EXPECT_EQ(statusOf(next), 200) << next;
  EXPECT_TRUE(has(next, "did 0 with ''")) << next;
  EXPECT_LT(std::chrono::steady_clock::now() - began, 1s) << "answered without waiting for a body";
  EXPECT_EQ(loop.answered(), 1);
  // The device named in the query, no body.
  const std::string restart =
      raw(port, "POST /control/restart-device?device=knob HTTP/1.1\r\nHost: x\r\n" + auth + "\r\n", 3s);
  EXPECT_EQ(statusOf(restart), 200) << restart;
  EXPECT_TRUE(has(restart, "with 'knob'")) << restart;
  // A command needs its body: without one, a clear 400 at once.
  const std::string command = raw(port, "POST /control/command HTTP/1.1\r\nHost: x\r\n" + auth + "\r\n", 3s);
  EXPECT_EQ(statusOf(command), 400) << command;
  EXPECT_TRUE(has(command, "the body must be one LAVA script command")) << command;
  // Without the token, and on other paths: answered at once too.
  EXPECT_EQ(statusOf(raw(port, "POST /control/next HTTP/1.1\r\nHost: x\r\n\r\n", 3s)), 401);
  const std::string health = raw(port, "POST /health HTTP/1.1\r\nHost: x\r\n\r\n", 3s);
  EXPECT_EQ(statusOf(health), 405) << health;
  EXPECT_TRUE(has(health, "Allow: GET")) << health;
  const std::string nowhere = raw(port, "POST /nowhere HTTP/1.1\r\nHost: x\r\n\r\n", 3s);
  EXPECT_EQ(statusOf(nowhere), 404) << nowhere;
  EXPECT_TRUE(has(nowhere, "no such page: /nowhere")) << nowhere;
  EXPECT_EQ(statusOf(raw(port, "DELETE /control/next HTTP/1.1\r\nHost: x\r\n\r\n", 3s)), 405);
  EXPECT_LT(std::chrono::steady_clock::now() - began, 3s);
}

// The same with curl itself, the client a technician types: `curl -X POST` with the token, and
// `curl -d device=NAME` (a form). Example failure: 400 "malformed request".
TEST(StatusServerPost, CurlPostsWithAndWithoutABody) {
  if (::access("/usr/bin/curl", X_OK) != 0) GTEST_SKIP() << "curl is not installed (apt-get install curl)";
  StatusBoard board(WallTime{}, 30);
  FakeLoop loop(board);
  auto server = StatusServer::start(spec(0), board);
  ASSERT_TRUE(server) << server.error().describe();
  const std::string url = (*server)->url();
  const std::string bearer = std::string("Authorization: Bearer ") + kToken;
  const auto next = test::run({"/usr/bin/curl", "-sS", "--max-time", "4", "-w", "\n%{http_code}", "-X", "POST", "-H",
                               bearer, url + "control/next"});
  EXPECT_EQ(next.exitCode, 0) << next.output;
  EXPECT_TRUE(next.output.ends_with("\n200")) << next.output;
  EXPECT_TRUE(has(next.output, "did 0 with ''")) << next.output;
  const auto form = test::run({"/usr/bin/curl", "-sS", "--max-time", "4", "-w", "\n%{http_code}", "-H", bearer, "-d",
                               "device=dials", url + "control/restart-device"});
  EXPECT_TRUE(form.output.ends_with("\n200")) << form.output;
  EXPECT_TRUE(has(form.output, "with 'dials'")) << form.output;
  const auto command = test::run({"/usr/bin/curl", "-sS", "--max-time", "4", "-w", "\n%{http_code}", "-H", bearer,
                                  "--data-binary", "render.prim_type = wireframe", url + "control/command"});
  EXPECT_TRUE(command.output.ends_with("\n200")) << command.output;
  EXPECT_TRUE(has(command.output, "with 'render.prim_type = wireframe'")) << command.output;
}

// Makes sure a refused POST's body is still read, so that the next request on the same
// connection is read as a request. Example failure: the body's bytes taken for a request line,
// and the next GET answered 400.
TEST(StatusServerPost, ARefusedBodyDoesNotSpoilTheConnection) {
  StatusBoard board(WallTime{}, 30);
  auto server = StatusServer::start(spec(0), board);
  ASSERT_TRUE(server) << server.error().describe();
  httplib::Client client("127.0.0.1", (*server)->port());
  client.set_keep_alive(true);
  client.set_read_timeout(5, 0);
  const auto refused =
      client.Post("/control/command", {{"Authorization", "Bearer wrong"}}, "GET /x HTTP/1.1\r\n\r\n", "text/plain");
  ASSERT_TRUE(refused);
  EXPECT_EQ(refused->status, 403);
  const auto health = client.Get("/health");
  ASSERT_TRUE(health);
  EXPECT_EQ(health->status, 200);
  EXPECT_EQ((*server)->counters().requests, 2u);
}

/// An IPv4 address of this machine other than loopback, or "" when it has none.
std::string otherAddress() {
  ifaddrs* list = nullptr;
  if (::getifaddrs(&list) != 0) return {};
  std::string found;
  for (const ifaddrs* a = list; a && found.empty(); a = a->ifa_next) {
    if (!a->ifa_addr || a->ifa_addr->sa_family != AF_INET || (a->ifa_flags & IFF_LOOPBACK) ||
        !(a->ifa_flags & IFF_UP)) {
      continue;
    }
    char text[INET_ADDRSTRLEN] = {};
    ::inet_ntop(AF_INET, &reinterpret_cast<const sockaddr_in*>(a->ifa_addr)->sin_addr, text, sizeof text);
    found = text;
  }
  ::freeifaddrs(list);
  return found;
}

httplib::Result getFrom(const std::string& host, std::uint16_t port, const std::string& path,
                        const httplib::Headers& headers = {}) {
  httplib::Client client(host, port);
  client.set_connection_timeout(2, 0);
  client.set_read_timeout(5, 0);
  return client.Get(path, headers);
}

// Makes sure a read token keeps other machines from reading the status while this machine reads
// freely, and that a browser is asked for it (HTTP Basic, any user name, the token as password).
// Example failures: the page and snapshots open to the whole network; a local health check that
// suddenly needs a token; a wrong token let through.
TEST(StatusServerRead, OtherMachinesNeedTheReadToken) {
  const std::string address = otherAddress();
  if (address.empty()) GTEST_SKIP() << "this machine has no address but loopback to be reached from";
  StatusBoard board(WallTime{}, 30);
  StatusSpec s = spec(0);
  s.host = "0.0.0.0";
  s.readToken = "fedcba9876543210fedcba9876543210";
  auto server = StatusServer::start(s, board);
  ASSERT_TRUE(server) << server.error().describe();
  const std::uint16_t port = (*server)->port();
  EXPECT_EQ(getFrom("127.0.0.1", port, "/health")->status, 200) << "this machine reads without a token";
  for (const char* path : {"/health", "/metrics", "/", "/snapshot.png", "/nowhere"}) {
    const auto refused = getFrom(address, port, path);
    ASSERT_TRUE(refused) << path;
    EXPECT_EQ(refused->status, 401) << path << ": " << refused->body;
    EXPECT_EQ(refused->get_header_value("WWW-Authenticate"), "Basic realm=\"Basalt status\", charset=\"UTF-8\"");
    EXPECT_TRUE(has(refused->body, "needs the read token")) << refused->body;
  }
  const auto bearer = getFrom(address, port, "/health", {{"Authorization", "Bearer " + s.readToken}});
  EXPECT_EQ(bearer->status, 200) << bearer->body;
  // "any:fedcba9876543210fedcba9876543210" in base64, as a browser sends it.
  const auto basic =
      getFrom(address, port, "/metrics", {{"Authorization", "Basic YW55OmZlZGNiYTk4NzY1NDMyMTBmZWRjYmE5ODc2NTQzMjEw"}});
  EXPECT_EQ(basic->status, 200) << basic->body;
  const auto control = getFrom(address, port, "/health", {{"Authorization", std::string("Bearer ") + kToken}});
  EXPECT_EQ(control->status, 200) << "the control token reads too";
  const auto wrong = getFrom(address, port, "/health", {{"Authorization", "Bearer fedcba9876543210fedcba987654321X"}});
  EXPECT_EQ(wrong->status, 401);
  EXPECT_TRUE(has(wrong->body, "wrong read token")) << wrong->body;
  const auto health = nlohmann::json::parse(bearer->body);
  EXPECT_EQ(health["server"]["read_token"], true) << bearer->body;
  // curl's -u, the way a technician types it.
  if (::access("/usr/bin/curl", X_OK) == 0) {
    const auto curl =
        test::run({"/usr/bin/curl", "-sS", "--max-time", "4", "-o", "/dev/null", "-w", "%{http_code}", "-u",
                   "technician:" + s.readToken, "http://" + address + ":" + std::to_string(port) + "/health"});
    EXPECT_EQ(curl.output, "200") << curl.output;
  }
}

// Makes sure a read token file that is missing keeps other machines out (fail closed) and says
// why. Example failure: a typo in the file's name that opens the status to everyone.
TEST(StatusServerRead, AMissingReadTokenFileKeepsOthersOut) {
  const std::string address = otherAddress();
  if (address.empty()) GTEST_SKIP() << "this machine has no address but loopback to be reached from";
  StatusBoard board(WallTime{}, 30);
  StatusSpec s = spec(0);
  s.host = "0.0.0.0";
  s.readTokenFile = test::scratchDir("status-read-token") / "missing";
  auto server = StatusServer::start(s, board);
  ASSERT_TRUE(server) << server.error().describe();
  const auto refused = getFrom(address, (*server)->port(), "/health", {{"Authorization", "Bearer anything"}});
  ASSERT_TRUE(refused);
  EXPECT_EQ(refused->status, 403);
  EXPECT_TRUE(has(refused->body, "the read token file")) << refused->body;
  EXPECT_TRUE(has(refused->body, "missing")) << refused->body;
  EXPECT_EQ(getFrom("127.0.0.1", (*server)->port(), "/health")->status, 200);
}

// Makes sure a show can turn the snapshot off: a clear refusal, and /health tells the page to
// hide the thumbnail. Example failure: a camera show's visitors served to whoever asks.
TEST(StatusServerRead, TheSnapshotCanBeTurnedOff) {
  StatusBoard board(WallTime{}, 30);
  StatusSpec s = spec(0);
  s.snapshot = false;
  auto server = StatusServer::start(s, board);
  ASSERT_TRUE(server) << server.error().describe();
  std::string body;
  EXPECT_EQ(get((*server)->port(), "/snapshot.png?w=100", &body), 403);
  EXPECT_TRUE(has(body, "the snapshot is off in this show ([status] snapshot = false")) << body;
  EXPECT_EQ(board.snapshotRequests().size(), 0u) << "nothing asked of the frame loop";
  ASSERT_EQ(get((*server)->port(), "/health", &body), 200);
  const auto health = nlohmann::json::parse(body);
  EXPECT_EQ(health["server"]["snapshot"], false) << body;
  EXPECT_EQ(health["server"]["controls"], true) << body;
}

}  // namespace
}  // namespace basalt::kiosk
