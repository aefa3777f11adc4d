// The status server's connections: cpp-httplib parses and routes requests, Basalt accepts and
// reads them. httplib 0.11 (Debian 12) serves each connection on a pool thread from its first
// byte to its last, with a read time-out per read() and no limit on header fields or chunked
// bodies, so one slow or endless client holds a thread for as long as it likes. Here a
// connection is admitted (per-client and total limits, a descriptor budget), its request is read
// whole by one reception thread that polls every waiting connection, and only a whole request
// reaches a worker. Decision: docs/decisions/0059-status-server-connections-handled-by-basalt.md.

#include "kiosk/status/guarded_http_server.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <optional>
#include <utility>

#include <fmt/format.h>

#include "runtime/log.h"

namespace basalt::kiosk {

namespace {

using SteadyClock = std::chrono::steady_clock;

BASALT_LOG_CATEGORY(Guard, "kiosk");

/// Answering takes CPU time from the show only when there is some to spare (nice 10).
void yieldToTheShow() { ::setpriority(PRIO_PROCESS, static_cast<id_t>(::gettid()), 10); }

bool equalsIgnoreCase(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
         });
}

std::string_view trimmed(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

/// The numeric address and port of a socket's peer (`peer`) or own end.
void addressOf(int fd, bool peer, std::string& address, int& port) {
  sockaddr_storage storage{};
  socklen_t length = sizeof storage;
  auto* sa = reinterpret_cast<sockaddr*>(&storage);
  if ((peer ? ::getpeername(fd, sa, &length) : ::getsockname(fd, sa, &length)) != 0) return;
  char text[INET6_ADDRSTRLEN] = {};
  if (storage.ss_family == AF_INET) {
    const auto* v4 = reinterpret_cast<const sockaddr_in*>(&storage);
    ::inet_ntop(AF_INET, &v4->sin_addr, text, sizeof text);
    port = ntohs(v4->sin_port);
  } else if (storage.ss_family == AF_INET6) {
    const auto* v6 = reinterpret_cast<const sockaddr_in6*>(&storage);
    ::inet_ntop(AF_INET6, &v6->sin6_addr, text, sizeof text);
    port = ntohs(v6->sin6_port);
  }
  address = text;
}

enum class Readiness : std::uint8_t { kIncomplete, kWhole, kHeadTooLarge, kBodyTooLarge };

/// Whether `bytes` hold a whole request under `limits`. A chunked body counts as whole at its
/// last chunk, or once it is larger than any body within the limit could be sent in reasonable
/// chunks: the worker then reads the rest and refuses what is over (413).
Readiness readiness(std::string_view bytes, const HttpLimits& limits) {
  std::size_t lines = 0;
  std::size_t headEnd = std::string_view::npos;
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    if (bytes[i] != '\n') continue;
    ++lines;
    if ((i >= 1 && bytes[i - 1] == '\n') || (i >= 2 && bytes[i - 1] == '\r' && bytes[i - 2] == '\n')) {
      headEnd = i + 1;
      break;
    }
  }
  if (headEnd == std::string_view::npos) {
    const std::size_t fields = lines > 0 ? lines - 1 : 0;
    if (bytes.size() > limits.maxHeadBytes || fields > limits.maxHeaderFields) return Readiness::kHeadTooLarge;
    return Readiness::kIncomplete;
  }
  if (headEnd > limits.maxHeadBytes || lines - 2 > limits.maxHeaderFields) return Readiness::kHeadTooLarge;

  bool chunked = false;
  bool expectContinue = false;
  std::optional<std::uint64_t> length;
  std::string_view head = bytes.substr(0, headEnd);
  head.remove_prefix(std::min(head.size(), head.find('\n') + 1));  // the request line
  while (!head.empty()) {
    const std::size_t eol = head.find('\n');
    const std::string_view line = head.substr(0, eol);
    head.remove_prefix(eol == std::string_view::npos ? head.size() : eol + 1);
    const std::size_t colon = line.find(':');
    if (colon == std::string_view::npos) continue;
    const std::string_view name = trimmed(line.substr(0, colon));
    const std::string_view value = trimmed(line.substr(colon + 1));
    if (equalsIgnoreCase(name, "Transfer-Encoding")) {
      chunked = true;
    } else if (equalsIgnoreCase(name, "Expect")) {
      expectContinue = true;
    } else if (equalsIgnoreCase(name, "Content-Length")) {
      std::uint64_t n = 0;
      const auto [end, ec] = std::from_chars(value.data(), value.data() + value.size(), n);
      // A malformed length reaches httplib, which answers 400.
      length = (ec == std::errc{} && end == value.data() + value.size()) ? n : 0;
    }
  }
  const std::string_view body = bytes.substr(headEnd);
  if (chunked) {
    if (expectContinue) return Readiness::kWhole;
    if (body.starts_with("0\r\n") || body.find("\r\n0\r\n") != std::string_view::npos) return Readiness::kWhole;
    return body.size() > 2 * limits.maxBodyBytes + 1024 ? Readiness::kWhole : Readiness::kIncomplete;
  }
  if (length) {
    if (*length > limits.maxBodyBytes) return Readiness::kBodyTooLarge;
    if (expectContinue || body.size() >= *length) return Readiness::kWhole;
    return Readiness::kIncomplete;
  }
  return Readiness::kWhole;
}

/// Waits until `fd` is ready for `events` or `deadline` passes; true when ready.
bool waitFor(int fd, short events, SteadyClock::time_point deadline) {
  for (;;) {
    const auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - SteadyClock::now());
    if (left.count() <= 0) return false;
    pollfd p{fd, events, 0};
    const int n = ::poll(&p, 1, static_cast<int>(std::min<std::int64_t>(left.count(), 1000)));
    if (n > 0) return true;
    if (n < 0 && errno != EINTR) return false;
  }
}

std::string answerText(int status, std::string_view reason, std::string_view why) {
  const std::string body = fmt::format(R"({{"ok": false, "status": {}, "message": "{}"}})", status, why) + "\n";
  return fmt::format(
      "HTTP/1.1 {} {}\r\nContent-Type: application/json\r\nContent-Length: {}\r\nConnection: close\r\n{}\r\n{}", status,
      reason, body.size(), status == 503 ? "Retry-After: 1\r\n" : "", body);
}

/// httplib's task queue: runs each accepted socket's job at once on the acceptor thread, where
/// GuardedHttpServer admits it; the waiting happens in Basalt's own queue.
class InlineQueue final : public httplib::TaskQueue {
 public:
  void enqueue(std::function<void()> fn) override { fn(); }
  void shutdown() override {}
};

}  // namespace

struct GuardedHttpServer::Connection {
  int fd = -1;
  std::string peer;
  int peerPort = 0;
  std::string local;
  int localPort = 0;
  std::string buffer;               // read and not yet taken by httplib
  SteadyClock::time_point started;  // the request's first byte (or the accept)
  bool idle = false;                // kept alive, no byte of the next request yet
  bool lingering = false;           // answered and refused: reading what still comes, then closing
  SteadyClock::time_point lingerUntil;
  bool admitted = false;  // counted in perClient_ and open_
  std::size_t served = 0;

  [[nodiscard]] SteadyClock::time_point deadline(const HttpLimits& limits) const {
    if (lingering) return lingerUntil;
    return started + (idle ? limits.idleTimeout : limits.requestTimeout);
  }
};

namespace {

/// httplib's view of a connection on a worker: the bytes reception read first, then the socket
/// until the request's deadline; an answer must be written within the write time-out.
class ConnectionStream final : public httplib::Stream {
 public:
  ConnectionStream(GuardedHttpServer::Connection& c, SteadyClock::time_point readDeadline,
                   std::chrono::milliseconds writeTimeout)
      : c_(c), readDeadline_(readDeadline), writeTimeout_(writeTimeout) {}

  bool is_readable() const override { return offset_ < c_.buffer.size() || waitFor(c_.fd, POLLIN, readDeadline_); }
  bool is_writable() const override {
    return waitFor(c_.fd, POLLOUT, writeDeadline_.value_or(SteadyClock::now() + writeTimeout_));
  }
  ssize_t read(char* ptr, size_t size) override {
    if (offset_ < c_.buffer.size()) {
      const std::size_t n = std::min(size, c_.buffer.size() - offset_);
      std::memcpy(ptr, c_.buffer.data() + offset_, n);
      offset_ += n;
      return static_cast<ssize_t>(n);
    }
    for (;;) {
      if (!waitFor(c_.fd, POLLIN, readDeadline_)) {
        timedOut_ = SteadyClock::now() >= readDeadline_;
        return -1;
      }
      const ssize_t n = ::recv(c_.fd, ptr, size, MSG_DONTWAIT);
      if (n >= 0 || (errno != EAGAIN && errno != EINTR)) return n;
    }
  }
  ssize_t write(const char* ptr, size_t size) override {
    if (!writeDeadline_) writeDeadline_ = SteadyClock::now() + writeTimeout_;
    for (;;) {
      if (!waitFor(c_.fd, POLLOUT, *writeDeadline_)) return -1;
      const ssize_t n = ::send(c_.fd, ptr, size, MSG_DONTWAIT | MSG_NOSIGNAL);
      if (n >= 0 || (errno != EAGAIN && errno != EINTR)) return n;
    }
  }
  void get_remote_ip_and_port(std::string& ip, int& port) const override {
    ip = c_.peer;
    port = c_.peerPort;
  }
  void get_local_ip_and_port(std::string& ip, int& port) const override {
    ip = c_.local;
    port = c_.localPort;
  }
  socket_t socket() const override { return c_.fd; }

  [[nodiscard]] bool timedOut() const { return timedOut_; }
  [[nodiscard]] bool closing() const { return closing_; }
  void closeAfterAnswer() { closing_ = true; }
  /// Drops the bytes httplib took from the buffer.
  void consume() { c_.buffer.erase(0, offset_); }

 private:
  GuardedHttpServer::Connection& c_;
  std::size_t offset_ = 0;
  SteadyClock::time_point readDeadline_;
  std::chrono::milliseconds writeTimeout_;
  std::optional<SteadyClock::time_point> writeDeadline_;
  bool timedOut_ = false;
  bool closing_ = false;
};

thread_local ConnectionStream* tCurrentStream = nullptr;

}  // namespace

GuardedHttpServer::GuardedHttpServer(HttpLimits limits) : limits_(limits) {
  wakeFd_ = ::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
  new_task_queue = [] { return new InlineQueue; };
  reception_ = std::thread([this] { receive(); });
  for (std::size_t i = 0; i < limits_.workers; ++i) workers_.emplace_back([this] { work(); });
}

GuardedHttpServer::~GuardedHttpServer() {
  stopping_.store(true, std::memory_order_release);
  wakeReception();
  {
    std::lock_guard lock(mutex_);
    workWake_.notify_all();
  }
  if (reception_.joinable()) reception_.join();
  for (std::thread& t : workers_) t.join();
  std::vector<std::unique_ptr<Connection>> left;
  {
    std::lock_guard lock(mutex_);
    for (auto& c : inbox_) left.push_back(std::move(c));
    for (auto& c : work_) left.push_back(std::move(c));
    inbox_.clear();
    work_.clear();
  }
  for (auto& c : left) close(std::move(c));
  if (wakeFd_ >= 0) ::close(wakeFd_);
}

GuardCounters GuardedHttpServer::guardCounters() const {
  return {refusedPerClient_.load(), refusedTotal_.load(), refusedDescriptors_.load(),
          timedOut_.load(),         headTooLarge_.load(), bodyTooLarge_.load(),
          evicted_.load()};
}

void GuardedHttpServer::noteRefusal(std::string_view kind, std::string_view what) {
  const auto now = SteadyClock::now();
  std::uint64_t before = 0;
  {
    std::lock_guard lock(notedMutex_);
    auto it = noted_.find(kind);
    if (it == noted_.end()) {
      noted_.emplace(std::string(kind), Noted{now, 0});
    } else if (now - it->second.logged < std::chrono::minutes(1)) {
      ++it->second.since;
      return;
    } else {
      before = it->second.since;
      it->second = Noted{now, 0};
    }
  }
  if (before > 0) {
    log::warn(kLogGuard, "status server: {} ({} more since the last line like it)", what, before);
  } else {
    log::warn(kLogGuard, "status server: {}", what);
  }
}

std::size_t GuardedHttpServer::openConnections() const {
  std::lock_guard lock(mutex_);
  return open_;
}

bool GuardedHttpServer::currentRequestTimedOut() { return tCurrentStream && tCurrentStream->timedOut(); }

void GuardedHttpServer::closeAfterAnswer() {
  if (tCurrentStream) tCurrentStream->closeAfterAnswer();
}

void GuardedHttpServer::wakeReception() const {
  const std::uint64_t one = 1;
  if (wakeFd_ >= 0) (void)!::write(wakeFd_, &one, sizeof one);
}

bool GuardedHttpServer::process_and_close_socket(socket_t sock) {
  auto c = std::make_unique<Connection>();
  c->fd = sock;
  c->started = SteadyClock::now();
  addressOf(sock, true, c->peer, c->peerPort);
  addressOf(sock, false, c->local, c->localPort);
  if (stopping_.load(std::memory_order_acquire)) {
    close(std::move(c));
    return true;
  }
  // Descriptors are given lowest first, so every one below this socket's is in use: when even
  // that leaves fewer than the reserve free, the show's own files come first.
  rlimit files{};
  if (::getrlimit(RLIMIT_NOFILE, &files) == 0 && files.rlim_cur != RLIM_INFINITY &&
      static_cast<rlim_t>(sock) + 1 + static_cast<rlim_t>(limits_.reservedDescriptors) > files.rlim_cur) {
    refusedDescriptors_.fetch_add(1, std::memory_order_relaxed);
    const std::string answer =
        answerText(503, "Service Unavailable", "the show needs its file descriptors; try again later");
    (void)::send(sock, answer.data(), answer.size(), MSG_DONTWAIT | MSG_NOSIGNAL);
    noteRefusal("descriptors", fmt::format("refused a connection from {}: the show needs its file descriptors "
                                           "(a limit of {}, {} kept for the show)",
                                           c->peer, files.rlim_cur, limits_.reservedDescriptors));
    close(std::move(c));  // no lingering: the descriptor is what is short
    return true;
  }
  std::string refusal;
  std::string_view kind;
  {
    std::lock_guard lock(mutex_);
    std::size_t& fromClient = perClient_[c->peer];
    if (fromClient >= limits_.maxPerClient) {
      refusedPerClient_.fetch_add(1, std::memory_order_relaxed);
      kind = "per-client";
      refusal = fmt::format("{} has {} connections open, the most one address may have; close one or try again",
                            c->peer, fromClient);
    } else if (open_ >= limits_.maxConnections && evictWanted_ >= evictable_.load(std::memory_order_relaxed)) {
      // Full, and every connection is at work (none reading a request or idle): refused.
      refusedTotal_.fetch_add(1, std::memory_order_relaxed);
      kind = "total";
      refusal = fmt::format("the status server has {} connections open, its most, all at work; try again", open_);
    } else {
      // Full of connections that send slowly or nothing (a slow-client attack, or idle
      // kept-alive ones): this one comes in, and reception drops the slowest to make room.
      if (open_ >= limits_.maxConnections) ++evictWanted_;
      ++fromClient;
      ++open_;
      c->admitted = true;
    }
    if (fromClient == 0) perClient_.erase(c->peer);
  }
  if (!refusal.empty()) {
    noteRefusal(kind, fmt::format("refused a connection with 503: {}", refusal));
    refuse(std::move(c), 503, refusal);
    return true;
  }
  toReception(std::move(c));
  return true;
}

void GuardedHttpServer::refuse(std::unique_ptr<Connection> c, int status, std::string_view why) {
  const std::string_view reason = status == 408   ? "Request Timeout"
                                  : status == 413 ? "Payload Too Large"
                                  : status == 431 ? "Request Header Fields Too Large"
                                                  : "Service Unavailable";
  const std::string answer = answerText(status, reason, why);
  (void)::send(c->fd, answer.data(), answer.size(), MSG_DONTWAIT | MSG_NOSIGNAL);
  ::shutdown(c->fd, SHUT_WR);
  // Read what the client still sends for a moment before closing, so that closing on unread
  // bytes (a reset) does not destroy the answer before the client reads it.
  c->lingering = true;
  c->lingerUntil = SteadyClock::now() + limits_.linger;
  c->buffer.clear();
  toReception(std::move(c));
}

void GuardedHttpServer::close(std::unique_ptr<Connection> c) {
  if (c->admitted) {
    std::lock_guard lock(mutex_);
    --open_;
    if (auto it = perClient_.find(c->peer); it != perClient_.end() && --it->second == 0) perClient_.erase(it);
  }
  ::shutdown(c->fd, SHUT_RDWR);
  ::close(c->fd);
}

void GuardedHttpServer::toReception(std::unique_ptr<Connection> c) {
  {
    std::lock_guard lock(mutex_);
    inbox_.push_back(std::move(c));
  }
  wakeReception();
}

void GuardedHttpServer::receive() {
  yieldToTheShow();
  std::vector<std::unique_ptr<Connection>> waiting;
  std::vector<pollfd> polled;
  std::size_t lingering = 0;
  std::vector<char> chunk(4096);
  // Takes a whole request to a worker, refuses one over a limit; false when `c` stays here.
  const auto examine = [this](std::unique_ptr<Connection>& c) {
    switch (readiness(c->buffer, limits_)) {
      case Readiness::kIncomplete: return;
      case Readiness::kWhole: {
        std::lock_guard lock(mutex_);
        work_.push_back(std::move(c));
        workWake_.notify_one();
        return;
      }
      case Readiness::kHeadTooLarge:
        headTooLarge_.fetch_add(1, std::memory_order_relaxed);
        noteRefusal("head", fmt::format("refused a request from {} with 431: its head is over {} bytes or {} fields",
                                        c->peer, limits_.maxHeadBytes, limits_.maxHeaderFields));
        refuse(std::move(c), 431,
               fmt::format("request head too large: at most {} bytes and {} header fields", limits_.maxHeadBytes,
                           limits_.maxHeaderFields));
        return;
      case Readiness::kBodyTooLarge:
        bodyTooLarge_.fetch_add(1, std::memory_order_relaxed);
        noteRefusal("body", fmt::format("refused a request from {} with 413: its body is over {} bytes", c->peer,
                                        limits_.maxBodyBytes));
        refuse(std::move(c), 413, fmt::format("request too large: at most {} bytes", limits_.maxBodyBytes));
        return;
    }
  };
  while (!stopping_.load(std::memory_order_acquire)) {
    {
      std::vector<std::unique_ptr<Connection>> arrived;
      {
        std::lock_guard lock(mutex_);
        arrived.swap(inbox_);
      }
      for (auto& c : arrived) {
        if (c->lingering) {
          // Refused connections that were never admitted hold descriptors too: a bounded few linger.
          if (!c->admitted && lingering >= limits_.maxConnections) {
            close(std::move(c));
            continue;
          }
          if (!c->admitted) ++lingering;
        } else if (!c->buffer.empty()) {
          examine(c);  // a kept-alive connection with the next request read already
          if (!c) continue;
        }
        waiting.push_back(std::move(c));
      }
    }
    evictSlowest(waiting);
    polled.assign(1, pollfd{wakeFd_, POLLIN, 0});
    auto next = SteadyClock::now() + std::chrono::seconds(1);
    for (const auto& c : waiting) {
      polled.push_back(pollfd{c->fd, POLLIN, 0});
      next = std::min(next, c->deadline(limits_));
    }
    const auto wait = std::chrono::ceil<std::chrono::milliseconds>(next - SteadyClock::now());
    if (::poll(polled.data(), polled.size(), static_cast<int>(std::max<std::int64_t>(wait.count(), 0))) < 0 &&
        errno != EINTR) {
      continue;
    }
    if (polled[0].revents != 0) {
      std::uint64_t count = 0;
      (void)!::read(wakeFd_, &count, sizeof count);
    }
    const auto now = SteadyClock::now();
    for (std::size_t i = 0; i < waiting.size(); ++i) {
      auto& c = waiting[i];
      const auto finish = [&] {
        if (c->lingering && !c->admitted) --lingering;
        close(std::move(c));
      };
      if (polled[i + 1].revents != 0) {
        const ssize_t n = ::recv(c->fd, chunk.data(), chunk.size(), MSG_DONTWAIT);
        if (n == 0 || (n < 0 && errno != EAGAIN && errno != EINTR)) {
          finish();  // the client closed (or reset) the connection
          continue;
        }
        if (n > 0 && !c->lingering) {
          if (c->idle) {
            c->idle = false;
            c->started = now;
          }
          c->buffer.append(chunk.data(), static_cast<std::size_t>(n));
          examine(c);
          if (!c) continue;
        }
      }
      if (c && now >= c->deadline(limits_)) {
        if (c->lingering || c->idle) {
          finish();
        } else {
          timedOut_.fetch_add(1, std::memory_order_relaxed);
          noteRefusal("timeout", fmt::format("dropped a connection from {} with 408: its request was not all there "
                                             "within {} s",
                                             c->peer, std::chrono::duration<double>(limits_.requestTimeout).count()));
          refuse(std::move(c), 408,
                 fmt::format("the request was not all there within {} s",
                             std::chrono::duration<double>(limits_.requestTimeout).count()));
        }
      }
    }
    std::erase_if(waiting, [](const auto& c) { return !c; });
    evictable_.store(static_cast<std::size_t>(std::count_if(
                         waiting.begin(), waiting.end(), [](const auto& c) { return c->admitted && !c->lingering; })),
                     std::memory_order_relaxed);
  }
  for (auto& c : waiting) close(std::move(c));
}

void GuardedHttpServer::evictSlowest(std::vector<std::unique_ptr<Connection>>& waiting) {
  std::size_t wanted = 0;
  {
    std::lock_guard lock(mutex_);
    wanted = std::exchange(evictWanted_, 0);
  }
  for (; wanted > 0; --wanted) {
    // The connection whose request (or idle wait) began longest ago: a slow client's, or one
    // kept alive doing nothing. A real request is whole within milliseconds of its first byte.
    auto slowest = waiting.end();
    for (auto it = waiting.begin(); it != waiting.end(); ++it) {
      if (!*it || !(*it)->admitted || (*it)->lingering) continue;
      if (slowest == waiting.end() || (*it)->started < (*slowest)->started) slowest = it;
    }
    if (slowest == waiting.end()) break;
    std::unique_ptr<Connection> c = std::move(*slowest);
    evicted_.fetch_add(1, std::memory_order_relaxed);
    noteRefusal("evicted", fmt::format("dropped a connection from {} with 503 to make room: {} connections were "
                                       "open, the most, and it had sent the least for longest",
                                       c->peer, limits_.maxConnections));
    const std::string answer =
        answerText(503, "Service Unavailable", "the status server is full and this connection was the slowest");
    (void)::send(c->fd, answer.data(), answer.size(), MSG_DONTWAIT | MSG_NOSIGNAL);
    close(std::move(c));  // at once: its slot is what the new connection needs
  }
  std::erase_if(waiting, [](const auto& c) { return !c; });
}

void GuardedHttpServer::work() {
  yieldToTheShow();
  for (;;) {
    std::unique_ptr<Connection> c;
    {
      std::unique_lock lock(mutex_);
      workWake_.wait(lock, [this] { return !work_.empty() || stopping_.load(std::memory_order_acquire); });
      if (work_.empty()) return;
      c = std::move(work_.front());
      work_.pop_front();
    }
    serve(std::move(c));
  }
}

void GuardedHttpServer::serve(std::unique_ptr<Connection> c) {
  for (;;) {
    ConnectionStream stream(*c, c->started + limits_.requestTimeout, limits_.writeTimeout);
    const bool last = c->served + 1 >= limits_.keepAliveRequests || stopping_.load(std::memory_order_acquire);
    bool closed = false;
    tCurrentStream = &stream;
    const bool ok = process_request(stream, last, closed, {});
    tCurrentStream = nullptr;
    stream.consume();
    ++c->served;
    if (!ok || closed || last || stream.timedOut() || stream.closing()) {
      close(std::move(c));
      return;
    }
    c->started = SteadyClock::now();
    c->idle = c->buffer.empty();
    if (c->idle || readiness(c->buffer, limits_) != Readiness::kWhole) {
      toReception(std::move(c));
      return;
    }
  }
}

}  // namespace basalt::kiosk
