// The status and control server on cpp-httplib (a maintained HTTP/1.1 library; used here and
// nowhere else).

#include "kiosk/status/status_server.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>

#include <fmt/format.h>
#include <fmt/std.h>
#include <nlohmann/json.hpp>

#include "kiosk/status/guarded_http_server.h"
#include "kiosk/status/rate_limiter.h"
#include "media/image_io.h"
#include "runtime/log.h"

namespace basalt::kiosk {

BASALT_LOG_CATEGORY(Status, "kiosk");

namespace {

constexpr auto kAnswerWait = std::chrono::seconds(3);
/// The frame loop reads a snapshot back at most once per period, however many clients ask.
constexpr auto kSnapshotPeriod = std::chrono::seconds(1);
/// A script command from the network is refused past this length before anything parses it.
constexpr std::size_t kMaxCommandBytes = 1024;

/// The limits of kiosk/status/README.md, with the show's body size.
HttpLimits limitsFor(const StatusSpec& spec) {
  HttpLimits limits;
  limits.maxBodyBytes = spec.maxRequestBytes;
  return limits;
}

std::string trim(std::string s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.pop_back();
  std::size_t start = 0;
  while (start < s.size() && std::isspace(static_cast<unsigned char>(s[start]))) ++start;
  return s.substr(start);
}

/// The token in `file` (surrounding white space trimmed), or "" when it cannot be read or is
/// shorter than 16 characters.
std::string tokenIn(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) return {};
  std::ostringstream text;
  text << in.rdbuf();
  std::string token = trim(text.str());
  return token.size() >= 16 ? token : std::string();
}

/// True for a loopback peer: 127.0.0.0/8, ::1, or 127.x mapped into IPv6.
bool loopbackPeer(const std::string& address) {
  in_addr v4{};
  if (::inet_pton(AF_INET, address.c_str(), &v4) == 1) return (ntohl(v4.s_addr) >> 24) == 127;
  in6_addr v6{};
  if (::inet_pton(AF_INET6, address.c_str(), &v6) != 1) return false;
  if (IN6_IS_ADDR_LOOPBACK(&v6)) return true;
  return IN6_IS_ADDR_V4MAPPED(&v6) && v6.s6_addr[12] == 127;
}

/// Standard base64 (RFC 4648, section 4), padding optional; empty when `text` is not base64.
std::optional<std::string> fromBase64(std::string_view text) {
  while (!text.empty() && text.back() == '=') text.remove_suffix(1);
  std::string out;
  std::uint32_t bits = 0;
  int count = 0;
  for (const char c : text) {
    int value = -1;
    if (c >= 'A' && c <= 'Z') value = c - 'A';
    if (c >= 'a' && c <= 'z') value = c - 'a' + 26;
    if (c >= '0' && c <= '9') value = c - '0' + 52;
    if (c == '+') value = 62;
    if (c == '/') value = 63;
    if (value < 0) return std::nullopt;
    bits = (bits << 6) | static_cast<std::uint32_t>(value);
    count += 6;
    if (count >= 8) {
      count -= 8;
      out += static_cast<char>((bits >> count) & 0xff);
    }
  }
  return out;
}

/// The secret a request gives: `Bearer SECRET`, or HTTP Basic with any user name and SECRET as
/// the password (what a browser sends after asking for it).
std::string credential(const httplib::Request& req) {
  const std::string auth = req.get_header_value("Authorization");
  if (auth.starts_with("Bearer ")) return auth.substr(7);
  if (auth.starts_with("Basic ")) {
    const auto pair = fromBase64(trim(auth.substr(6)));
    if (pair) {
      const auto colon = pair->find(':');
      if (colon != std::string::npos) return pair->substr(colon + 1);
    }
  }
  return {};
}

/// Compares in a time that does not depend on where the strings differ.
bool sameSecret(std::string_view expected, std::string_view given) {
  if (expected.empty() || expected.size() != given.size()) return false;
  unsigned char diff = 0;
  for (std::size_t i = 0; i < expected.size(); ++i) diff |= static_cast<unsigned char>(expected[i] ^ given[i]);
  return diff == 0;
}

void replyJson(httplib::Response& res, int status, bool ok, std::string_view message) {
  res.status = status;
  const nlohmann::ordered_json answer{{"ok", ok}, {"status", status}, {"message", message}};
  res.set_content(answer.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace) + "\n",
                  "application/json");
}

/// The request's body. A request with neither Content-Length nor Transfer-Encoding has none (RFC
/// 9112, section 6.3), as `curl -X POST` sends it; httplib would instead read until the client
/// closes, and answer 400 when its read time-out came first. So POST handlers take a
/// ContentReader and read only an announced body; an announced one is read whole, so that its
/// bytes are not taken for the next request on the connection. Empty when it could not be read:
/// `res.status` then says why (413, 400) and the error handler words the answer.
///
/// At most `limit` bytes, whatever the transfer encoding: httplib checks a Content-Length against
/// its payload limit but reads a chunked body to its end, so the receiver stops at the limit.
std::optional<std::string> requestBody(const httplib::Request& req, httplib::Response& res,
                                       const httplib::ContentReader& reader, std::size_t limit) {
  std::string body;
  if (!req.has_header("Content-Length") && !req.has_header("Transfer-Encoding")) return body;
  bool tooLarge = false;
  const bool read = reader([&body, &tooLarge, limit](const char* data, std::size_t length) {
    if (body.size() + length > limit) {
      tooLarge = true;
      return false;
    }
    body.append(data, length);
    return true;
  });
  if (tooLarge) res.status = 413;
  if (!read) {
    // The rest of the body was not read: the connection cannot carry another request.
    res.set_header("Connection", "close");
    GuardedHttpServer::closeAfterAnswer();
    return std::nullopt;
  }
  return body;
}

/// The server's threads run at a lower priority than the frame loop (nice 10), so that answering
/// requests takes CPU time from the show only when there is some to spare.
void yieldToTheShow() {
  thread_local bool done = false;
  if (done) return;
  done = true;
  ::setpriority(PRIO_PROCESS, static_cast<id_t>(::gettid()), 10);
}

}  // namespace

/// The frame on screen, read back by the frame loop at most once per kSnapshotPeriod: requests
/// within a period share the last picture, and while one request waits for the loop the others
/// wait for its answer rather than asking again. A failure is kept for the period too, so a hung
/// loop is not asked again by every client.
class StatusServer::SnapshotCache {
 public:
  struct Taken {
    int status = 200;  // 200, or 500/503 with `error`
    std::shared_ptr<const Image> image;
    std::string error;
  };

  Taken get(StatusBoard& board) {
    std::unique_lock lock(mutex_);
    for (;;) {
      if (last_ && std::chrono::steady_clock::now() - takenAt_ < kSnapshotPeriod) return *last_;
      if (!asking_) break;
      answered_.wait(lock);  // the asker waits kAnswerWait at most
    }
    asking_ = true;
    lock.unlock();
    Taken taken = ask(board);
    lock.lock();
    asking_ = false;
    last_ = taken;
    takenAt_ = std::chrono::steady_clock::now();
    answered_.notify_all();
    return taken;
  }

 private:
  static Taken ask(StatusBoard& board) {
    auto request = std::make_shared<SnapshotRequest>();
    if (!board.snapshotRequests().push(request)) return {503, nullptr, "too many snapshots asked at once; try again"};
    board.wake();
    if (!request->wait(kAnswerWait)) {
      return {503, nullptr, "the frame loop did not draw a frame within 3 s; it may be hung"};
    }
    std::lock_guard lock(request->mutex);
    if (!request->ok) return {500, nullptr, request->error};
    return {200, std::make_shared<const Image>(std::move(request->image)), {}};
  }

  std::mutex mutex_;  // guards everything below
  std::condition_variable answered_;
  bool asking_ = false;
  std::optional<Taken> last_;
  std::chrono::steady_clock::time_point takenAt_;
};

/// Token buckets per client address (RateLimiter, shared with the OSC input), on the system clock.
class StatusServer::Limiter {
 public:
  explicit Limiter(double rate) : buckets_(rate) {}
  bool allow(const std::string& client) { return buckets_.allow(client, clock_.now()); }

 private:
  SystemClock clock_;
  RateLimiter buckets_;
};

StatusServer::StatusServer(const StatusSpec& spec, StatusBoard& board, std::string token)
    : spec_(spec),
      board_(board),
      token_(std::move(token)),
      server_(std::make_unique<GuardedHttpServer>(limitsFor(spec))),
      limiter_(std::make_unique<Limiter>(spec.requestsPerSecond)),
      snapshots_(std::make_unique<SnapshotCache>()) {}

StatusServer::~StatusServer() {
  {
    std::lock_guard lock(bindMutex_);
    stopping_ = true;
  }
  stopWake_.notify_all();
  if (!thread_.joinable()) return;
  // Once bound, the thread goes on to serve: stop() ends that, but only once it runs.
  while (bound_.load(std::memory_order_acquire) && !served_.load(std::memory_order_acquire)) {
    if (server_->is_running()) {
      server_->stop();
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  thread_.join();
  // The workers run handlers that use the limiter and the snapshot cache: they end first.
  server_.reset();
}

std::string StatusServer::notUpBecause() const {
  std::lock_guard lock(bindMutex_);
  return notUpBecause_;
}

bool StatusServer::bind() {
  httplib::Server& http = *server_;
  errno = 0;
  int port = spec_.port;
  if (port == 0) {
    port = http.bind_to_any_port(spec_.host);
  } else if (!http.bind_to_port(spec_.host, port)) {
    port = -1;
  }
  const int error = errno;
  if (port > 0) {
    port_.store(static_cast<std::uint16_t>(port), std::memory_order_release);
    std::lock_guard lock(bindMutex_);
    notUpBecause_.clear();
    return true;
  }
  std::lock_guard lock(bindMutex_);
  if (error == EADDRINUSE) {
    notUpBecause_ = fmt::format(
        "port {} on {} is taken: another Basalt may be running (systemctl status basalt; ss -ltnp 'sport = :{}'), "
        "or another program uses it (change [status] listen in show.toml)",
        spec_.port, spec_.host, spec_.port);
  } else {
    notUpBecause_ = fmt::format("cannot listen on {}:{}: {}; check [status] listen in show.toml", spec_.host,
                                spec_.port, error != 0 ? std::strerror(error) : "no such address");
  }
  return false;
}

void StatusServer::serve() {
  yieldToTheShow();
  if (!bound_.load(std::memory_order_acquire)) {
    auto wait = std::chrono::seconds(1);
    const auto began = std::chrono::steady_clock::now();
    int tries = 1;
    for (;;) {
      {
        std::unique_lock lock(bindMutex_);
        if (stopWake_.wait_for(lock, wait, [this] { return stopping_; })) break;
      }
      ++tries;
      if (bind()) {
        std::lock_guard lock(bindMutex_);
        if (stopping_) break;  // stopped while binding: the process is on its way out
        bound_.store(true, std::memory_order_release);
        const auto after = std::chrono::duration_cast<std::chrono::seconds>(std::chrono::steady_clock::now() - began);
        log::info(kLogStatus, "status server on {} (the port was free after {} s and {} tries; controls {})", url(),
                  after.count(), tries, controlsEnabled() ? "on, with the token" : "off: no token");
        break;
      }
      // Said once more when the back-off reaches its longest, so that a long wait does not
      // fill the log.
      if (wait == std::chrono::seconds(16)) {
        log::warn(kLogStatus, "the status server is still not up: {}; trying every 30 s", notUpBecause());
      }
      wait = std::min<std::chrono::seconds>(wait * 2, std::chrono::seconds(30));
    }
  }
  if (bound_.load(std::memory_order_acquire)) server_->listen_after_bind();
  served_.store(true, std::memory_order_release);
}

std::string StatusServer::url() const {
  const bool v6 = spec_.host.find(':') != std::string::npos;
  return fmt::format("http://{}{}{}:{}/", v6 ? "[" : "", spec_.host, v6 ? "]" : "", port());
}

MachineFacts StatusServer::machineFacts(const std::string& manifest) {
  const Nanos now = SystemClock().now();
  std::lock_guard lock(machineMutex_);
  // Read at most once a second, however often the page and the scrapers ask.
  if (!machine_ || now - machineRead_ >= std::chrono::seconds(1)) {
    std::vector<FolderToWatch> folders;
    if (!manifest.empty()) folders.push_back({"show", std::filesystem::path(manifest).parent_path()});
    for (const FolderToWatch& f : board_.watchedFolders()) folders.push_back(f);
    machine_ = readMachineFacts(folders);
    machineRead_ = now;
  }
  return *machine_;
}

ServerCounters StatusServer::counters() const {
  ServerCounters c{requests_.load(), rejectedRate_.load(), rejectedAuth_.load(), rejectedSize_.load()};
  if (server_) {
    // What the connection guard refused before a request reached httplib.
    const GuardCounters g = server_->guardCounters();
    c.rejectedSize += g.bodyTooLarge;
    c.rejectedConnections = g.refusedPerClient + g.refusedTotal + g.refusedDescriptors;
    c.rejectedTimeout = g.timedOut;
    c.rejectedHead = g.headTooLarge;
    c.evicted = g.evicted;
  }
  return c;
}

Result<std::unique_ptr<StatusServer>> StatusServer::start(const StatusSpec& spec, StatusBoard& board) {
  std::string token = spec.token;
  if (token.empty() && !spec.tokenFile.empty()) {
    token = tokenIn(spec.tokenFile);
    if (token.empty()) {
      log::warn(kLogStatus, "the token file {} is missing or shorter than 16 characters; controls are off",
                spec.tokenFile);
    }
  }
  auto server = std::unique_ptr<StatusServer>(new StatusServer(spec, board, std::move(token)));
  if (!spec.readToken.empty() || !spec.readTokenFile.empty()) {
    server->readGuarded_ = true;
    server->readToken_ = spec.readToken.empty() ? tokenIn(spec.readTokenFile) : spec.readToken;
    if (server->readToken_.empty()) {
      // Fail closed: a missing read token keeps other machines out rather than letting them in.
      server->readTokenProblem_ = fmt::format(
          "the read token file {} is missing or shorter than 16 characters; only this machine can read the status "
          "until it is there (then restart Basalt)",
          spec.readTokenFile);
      log::warn(kLogStatus, "{}", server->readTokenProblem_);
    }
  }
  server->routes();
  httplib::Server& http = *server->server_;
  // Threads, time-outs and keep-alive are GuardedHttpServer's (HttpLimits); httplib still
  // checks a Content-Length against the body limit.
  http.set_payload_max_length(spec.maxRequestBytes);
  // httplib's default sets SO_REUSEPORT, with which a second process binds the same port and
  // the kernel hands it half the connections. SO_REUSEADDR alone lets a restart bind at once
  // past connections in TIME_WAIT, and a port in use stays refused.
  http.set_socket_options([](int socket) {
    const int yes = 1;
    ::setsockopt(socket, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  });
  server->port_.store(spec.port, std::memory_order_release);
  if (server->bind()) {
    server->bound_.store(true, std::memory_order_release);
    log::info(kLogStatus, "status server on {} (controls {})", server->url(),
              server->controlsEnabled() ? "on, with the token" : "off: no token");
  } else {
    // The show matters more than its status page: it plays on while the server waits.
    log::error(kLogStatus,
               "the status server is not up yet: {}; the show plays on, and the server tries again in "
               "1 s, then less often",
               server->notUpBecause());
  }
  server->thread_ = std::thread([s = server.get()] { s->serve(); });
  return server;
}

void StatusServer::routes() {
  GuardedHttpServer& http = *server_;
  http.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
    yieldToTheShow();
    requests_.fetch_add(1, std::memory_order_relaxed);
    if (!limiter_->allow(req.remote_addr)) {
      rejectedRate_.fetch_add(1, std::memory_order_relaxed);
      res.set_header("Retry-After", "1");
      replyJson(res, 429, false, fmt::format("too many requests: at most {} a second", spec_.requestsPerSecond));
      return httplib::Server::HandlerResponse::Handled;
    }
    // Reading from another machine may need the read token (controls check theirs).
    if (readGuarded_ && (req.method == "GET" || req.method == "HEAD") && !loopbackPeer(req.remote_addr)) {
      if (readToken_.empty()) {
        rejectedAuth_.fetch_add(1, std::memory_order_relaxed);
        replyJson(res, 403, false, readTokenProblem_);
        return httplib::Server::HandlerResponse::Handled;
      }
      const std::string given = credential(req);
      if (!sameSecret(readToken_, given) && !sameSecret(token_, given)) {
        rejectedAuth_.fetch_add(1, std::memory_order_relaxed);
        // Basic, so that a browser asks for it: any user name, the read token as the password.
        res.set_header("WWW-Authenticate", "Basic realm=\"Basalt status\", charset=\"UTF-8\"");
        replyJson(res, 401, false,
                  given.empty() ? "reading the status from another machine needs the read token: 'Authorization: "
                                  "Bearer TOKEN', or any user name with the token as the password"
                                : "wrong read token");
        return httplib::Server::HandlerResponse::Handled;
      }
    }
    return httplib::Server::HandlerResponse::Unhandled;
  });
  http.set_error_handler([this](const httplib::Request& req, httplib::Response& res) {
    // A request that was not all there in time reaches httplib as a failed read (400).
    if (res.status == 400 && GuardedHttpServer::currentRequestTimedOut()) res.status = 408;
    if (res.status == 400 || res.status == 408 || res.status == 413) {
      // What is left of the request is not a request: close after answering.
      res.set_header("Connection", "close");
      GuardedHttpServer::closeAfterAnswer();
    }
    if (res.status == 413) rejectedSize_.fetch_add(1, std::memory_order_relaxed);
    if (!res.body.empty()) return;
    switch (res.status) {
      case 404: replyJson(res, 404, false, fmt::format("no such page: {}; see / for the status page", req.path)); break;
      case 413:
        replyJson(res, 413, false, fmt::format("request too large: at most {} bytes", spec_.maxRequestBytes));
        break;
      case 400: replyJson(res, 400, false, "malformed request"); break;
      case 414: replyJson(res, 414, false, "request line too long"); break;
      case 408:
        replyJson(res, 408, false,
                  fmt::format("the request was not all there within {} s",
                              std::chrono::duration<double>(server_->limits().requestTimeout).count()));
        break;
      default: replyJson(res, res.status, false, fmt::format("HTTP status {}", res.status)); break;
    }
  });

  const auto now = [] { return SystemClock().wallNow(); };
  http.Get("/health", [this, now](const httplib::Request&, httplib::Response& res) {
    res.set_header("Cache-Control", "no-store");
    StatusSnapshot snapshot = board_.snapshot(now());
    snapshot.server = facts();
    snapshot.process = readProcessFigures();
    snapshot.machine = machineFacts(snapshot.show.manifest);
    res.set_content(healthJson(snapshot), "application/json");
  });
  http.Get("/log.txt", [this](const httplib::Request&, httplib::Response& res) {
    res.set_header("Cache-Control", "no-store");
    res.set_header("Content-Disposition", "inline; filename=\"basalt.log\"");
    res.set_content(logText(board_.logRecords()), "text/plain; charset=utf-8");
  });
  http.Get("/metrics", [this, now](const httplib::Request&, httplib::Response& res) {
    StatusSnapshot snapshot = board_.snapshot(now());
    snapshot.process = readProcessFigures();
    res.set_content(metricsText(snapshot, counters()), "text/plain; version=0.0.4; charset=utf-8");
  });
  http.Get("/", [](const httplib::Request&, httplib::Response& res) {
    res.set_header("Cache-Control", "no-store");
    res.set_content(std::string(statusPageHtml()), "text/html; charset=utf-8");
  });
  http.Get("/snapshot.png", [this](const httplib::Request& req, httplib::Response& res) {
    if (!spec_.snapshot) {
      // A camera show may not want its visitors seen by whoever reaches the port.
      replyJson(res, 403, false, "the snapshot is off in this show ([status] snapshot = false in show.toml)");
      return;
    }
    std::uint32_t width = 0;
    if (req.has_param("w")) {
      const std::string w = req.get_param_value("w");
      unsigned value = 0;
      const auto [end, ec] = std::from_chars(w.data(), w.data() + w.size(), value);
      if (ec != std::errc{} || end != w.data() + w.size() || value == 0 || value > 16384) {
        replyJson(res, 400, false, "w must be a width in pixels, 1 to 16384");
        return;
      }
      width = value;
    }
    const SnapshotCache::Taken taken = snapshots_->get(board_);
    if (taken.status != 200) {
      replyJson(res, taken.status, false, taken.error);
      return;
    }
    auto png = media::encodePng(width ? scaleDown(*taken.image, width) : *taken.image);
    if (!png) {
      replyJson(res, 500, false, png.error().describe());
      return;
    }
    res.set_header("Cache-Control", "no-store");
    res.set_content(reinterpret_cast<const char*>(png->data()), png->size(), "image/png");
  });

  const auto control = [this](ControlKind kind, bool needsArgument) {
    return [this, kind, needsArgument](const httplib::Request& req, httplib::Response& res,
                                       const httplib::ContentReader& reader) {
      const std::optional<std::string> body = requestBody(req, res, reader, spec_.maxRequestBytes);
      if (!body) return;
      if (token_.empty()) {
        rejectedAuth_.fetch_add(1, std::memory_order_relaxed);
        replyJson(res, 403, false, "controls are off: this show has no token (set status.token_file in show.toml)");
        return;
      }
      const std::string auth = req.get_header_value("Authorization");
      if (auth.empty()) {
        rejectedAuth_.fetch_add(1, std::memory_order_relaxed);
        res.set_header("WWW-Authenticate", "Bearer realm=\"basalt\"");
        replyJson(res, 401, false, "controls need the header 'Authorization: Bearer TOKEN'");
        return;
      }
      if (!auth.starts_with("Bearer ") || !sameSecret(token_, std::string_view(auth).substr(7))) {
        rejectedAuth_.fetch_add(1, std::memory_order_relaxed);
        replyJson(res, 403, false, "wrong token");
        return;
      }
      if (kind == ControlKind::kRunCommand && body->size() > kMaxCommandBytes) {
        // Refused before anything parses it: a command is one line of a script.
        rejectedSize_.fetch_add(1, std::memory_order_relaxed);
        replyJson(res, 413, false, fmt::format("a command is at most {} bytes", kMaxCommandBytes));
        return;
      }
      ControlRequest request;
      request.kind = kind;
      // A form (curl -d device=NAME) names the device as the query does.
      httplib::Params form;
      if (req.get_header_value("Content-Type").starts_with("application/x-www-form-urlencoded")) {
        httplib::detail::parse_query_text(*body, form);
      }
      const auto device = form.find("device");
      request.argument = req.has_param("device") ? req.get_param_value("device")
                         : device != form.end()  ? device->second
                                                 : trim(*body);
      request.view = req.has_param("view") ? req.get_param_value("view") : std::string();
      request.save = req.has_param("save") && req.get_param_value("save") != "0";
      // Calibration statements may come one per line, as in a cave file.
      if (kind == ControlKind::kCalibrate) std::replace(request.argument.begin(), request.argument.end(), '\n', ';');
      if (needsArgument && request.argument.empty()) {
        replyJson(res, 400, false,
                  kind == ControlKind::kRunCommand ? "the body must be one LAVA script command"
                  : kind == ControlKind::kSetup
                      ? "name the set-up toggle in the body: cave, stereo, fog, smooth, lighting, filled, points, "
                        "wireframe, normals, light-tokens, pause, control or exit"
                      : "name the device: ?device=NAME or the body");
        return;
      }
      if (request.argument.find('\n') != std::string::npos || request.argument.find('\0') != std::string::npos) {
        replyJson(res, 400, false, "one line only");
        return;
      }
      request.reply = std::make_shared<ControlReply>();
      auto reply = request.reply;
      if (!board_.controls().push(std::move(request))) {
        replyJson(res, 503, false, "too many controls waiting; try again");
        return;
      }
      board_.wake();
      if (!reply->wait(kAnswerWait)) {
        replyJson(res, 503, false, "the frame loop did not answer within 3 s; it may be hung");
        return;
      }
      std::lock_guard lock(reply->mutex);
      log::info(kLogStatus, "control {} from {}: {}", req.path, req.remote_addr, reply->message);
      replyJson(res, reply->status, reply->status < 300, reply->message);
    };
  };
  http.Post("/control/next", control(ControlKind::kNext, false));
  http.Post("/control/previous", control(ControlKind::kPrevious, false));
  http.Post("/control/reload", control(ControlKind::kReload, false));
  http.Post("/control/command", control(ControlKind::kRunCommand, true));
  http.Post("/control/restart-device", control(ControlKind::kRestartDevice, true));
  http.Post("/control/calibrate", control(ControlKind::kCalibrate, false));
  http.Post("/control/setup", control(ControlKind::kSetup, true));

  // Wrong methods on known paths say which method they take; unknown paths are 404 whatever the
  // method. Requests that may carry a body are answered at once when they announce none.
  const auto methodNotAllowed = [](std::string_view allowed) {
    return [allowed](const httplib::Request&, httplib::Response& res) {
      res.set_header("Allow", std::string(allowed));
      replyJson(res, 405, false, fmt::format("use {}", allowed));
    };
  };
  const auto withBody = [this, methodNotAllowed](std::string_view allowed) {
    return [this, answer = methodNotAllowed(allowed)](const httplib::Request& req, httplib::Response& res,
                                                      const httplib::ContentReader& reader) {
      if (requestBody(req, res, reader, spec_.maxRequestBytes)) answer(req, res);
    };
  };
  for (const char* path : {"/health", "/metrics", "/snapshot.png", "/log.txt", "/"}) {
    http.Post(path, withBody("GET"));
    http.Put(path, withBody("GET"));
    http.Patch(path, withBody("GET"));
    http.Delete(path, withBody("GET"));
  }
  for (const char* path : {"/control/next", "/control/previous", "/control/reload", "/control/command",
                           "/control/restart-device", "/control/calibrate", "/control/setup"}) {
    http.Get(path, methodNotAllowed("POST"));
    http.Put(path, withBody("POST"));
    http.Patch(path, withBody("POST"));
    http.Delete(path, withBody("POST"));
  }
  const auto noSuchPage = [this](const httplib::Request& req, httplib::Response& res,
                                 const httplib::ContentReader& reader) {
    if (requestBody(req, res, reader, spec_.maxRequestBytes)) {
      replyJson(res, 404, false, fmt::format("no such page: {}; see / for the status page", req.path));
    }
  };
  http.Post(".*", noSuchPage);
  http.Put(".*", noSuchPage);
  http.Patch(".*", noSuchPage);
  http.Delete(".*", noSuchPage);
}

}  // namespace basalt::kiosk
