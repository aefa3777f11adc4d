// The frame loop under attack: what the status server's limits (decision 0059), the frame lock's
// CURVE (decision 0060) and the watch on content (decision 0062) cost a show while someone tries
// to break it. A real `basalt run` plays in real time at 60 fps on loopback with its status
// server, a control token and a `[lock]` leader with a key file, and goes through phases of
// BASALT_ATTACK_SECONDS each (default 10 s), one after the other:
//  - idle: nobody asks (the baseline the phases are set beside);
//  - chunked: 100 MB POSTs to /control/command in 64 KiB chunks, with the token, again and again;
//  - headers: requests of a million header fields each, again and again;
//  - slowloris: 64 connections from 16 addresses, each sending one byte of its head a second;
//  - idle connections: 2 000 connections from 250 addresses that send nothing (reopened when
//    the server closes them);
//  - snapshots: /snapshot.png asked for in a loop on four connections;
//  - lock: connections to the lock's ports speaking ZeroMQ without the key; garbage; a
//    follower's captured conversation replayed (captured through a relay from a follower with
//    the key, before the idle phase), each a phase of its own;
//  - empty manifest: show.toml emptied, then SIGHUP.
// A second run plays a show with a movie texture (the video-wall example at 60 fps) with its own
// idle phase, then the movie's file cut to 0 bytes while it plays.
//
// Each phase: late frames (basalt_frames_late_total), intervals over 17.5 ms (the histogram's
// buckets), the frame interval p50/p99/max from /health (its window is the last 600 frames, so
// a phase shorter than 10 s shares it with the phase before), the process's CPU per frame,
// resident memory and open descriptors (/proc/PID) at the phase's start and end, how the server
// or the lock counted the attack in /metrics, the log lines Basalt wrote, what the attacker was
// answered, and how often a bystander (another address asking /health once a second) was served.
// Targets, printed against the measured figures and never asserted: no late frame (snapshots: at
// most one per read-back, one a second), memory within 16 MB of the phase's start, descriptors
// within the server's 32 connections and 8 more of the idle phase's.
//
// The attackers run in this process at nice 19, on threads of their own: they stand for
// machines elsewhere, so what the show loses is what refusing them costs it, not their own work.
// Figures are read from 127.0.0.2 after each attack has stopped (the attacks use 127.0.0.1 and
// 127.0.1.0/16), with a few retries while the server closes the attackers' connections.

#include <benchmark/benchmark.h>

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "bench_main.h"
#include "kiosk/lock/frame_lock.h"
#include "kiosk/manifest/manifest.h"
#include "render/output.h"
#include "runtime/clock.h"
#include "runtime/event_loop.h"
#include "runtime/show/show.h"
#include "support/process.h"

namespace {

using namespace std::chrono_literals;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr std::uint32_t kBystander = 0x7f000002;  // 127.0.0.2: the bench's own reads
constexpr std::uint32_t kAttacker = 0x7f000001;   // 127.0.0.1
constexpr const char* kToken = "attack-bench-control-token-0123456789";
constexpr const char* kLockKey = "9f3c1a7e5b2d4f608e1c3a5b7d9f1e2c4a6b8d0f2e4c6a8b0d2f4e6a8c0b2d4f";

std::string basalt() { return std::string(BASALT_BINARY_DIR) + "/basalt"; }

/// Seconds each phase lasts: BASALT_ATTACK_SECONDS, default 10.
int phaseSeconds() {
  const char* value = std::getenv("BASALT_ATTACK_SECONDS");
  const int seconds = value != nullptr ? std::atoi(value) : 10;
  return seconds >= 1 ? seconds : 10;
}

fs::path scratch() {
  static const fs::path dir = [] {
    const fs::path d = fs::temp_directory_path() / ("basalt-attack-bench-" + std::to_string(::getpid()));
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
  }();
  return dir;
}

/// Frame-lock ports from the pid, apart from the lock tests' (10000 to 29200) and the lock
/// bench's (29200 to 30800), below the ephemeral range: the leader's three and two relayed.
int lockPort() { return 30800 + static_cast<int>(::getpid() % 200) * 8; }

// ---- sockets ----------------------------------------------------------------------------------

sockaddr_in address(std::uint32_t host, std::uint16_t port) {
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(port);
  a.sin_addr.s_addr = htonl(host);
  return a;
}

/// A TCP connection from `from` (a loopback address) to 127.0.0.1:`port`; -1 when it fails.
int connectFrom(std::uint32_t from, std::uint16_t port, bool nonBlocking = false) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC | (nonBlocking ? SOCK_NONBLOCK : 0), 0);
  if (fd < 0) return -1;
  const sockaddr_in local = address(from, 0);
  // An attacker's address of its own, or none: from another address it would be another attack.
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&local), sizeof local) != 0) {
    ::close(fd);
    return -1;
  }
  const sockaddr_in to = address(INADDR_LOOPBACK, port);
  if (::connect(fd, reinterpret_cast<const sockaddr*>(&to), sizeof to) != 0 && errno != EINPROGRESS) {
    ::close(fd);
    return -1;
  }
  const timeval limit{2, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &limit, sizeof limit);
  return fd;
}

bool sendAll(int fd, std::string_view bytes) {
  while (!bytes.empty()) {
    const ssize_t n = ::send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL);
    if (n <= 0) return false;
    bytes.remove_prefix(static_cast<std::size_t>(n));
  }
  return true;
}

/// What the peer sends within `timeoutMs` of silence, until it closes.
std::string readAll(int fd, int timeoutMs) {
  std::string answer;
  std::array<char, 8192> buffer{};
  for (;;) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, timeoutMs) <= 0) break;
    const ssize_t n = ::recv(fd, buffer.data(), buffer.size(), MSG_DONTWAIT);
    if (n <= 0) break;
    answer.append(buffer.data(), static_cast<std::size_t>(n));
  }
  return answer;
}

/// True when the peer has sent something (or closed) already.
bool answered(int fd) {
  pollfd p{fd, POLLIN, 0};
  return ::poll(&p, 1, 0) > 0;
}

/// The status code of an HTTP answer; 0 for none (closed or reset without one).
int statusCode(const std::string& answer) {
  if (!answer.starts_with("HTTP/1.1 ") || answer.size() < 12) return 0;
  return std::atoi(answer.substr(9, 3).c_str());
}

/// GET `path` from 127.0.0.2; the body of a 200 answer, or empty.
std::string probe(std::uint16_t port, const std::string& path) {
  const int fd = connectFrom(kBystander, port);
  if (fd < 0) return {};
  std::string answer;
  if (sendAll(fd, "GET " + path + " HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n")) {
    answer = readAll(fd, 5000);
  }
  ::close(fd);
  const auto body = answer.find("\r\n\r\n");
  if (statusCode(answer) != 200 || body == std::string::npos) return {};
  return answer.substr(body + 4);
}

/// `probe`, tried again a few times while the server is busy closing the attackers' connections.
std::string probeHard(std::uint16_t port, const std::string& path) {
  for (int i = 0; i < 20; ++i) {
    std::string body = probe(port, path);
    if (!body.empty()) return body;
    std::this_thread::sleep_for(250ms);
  }
  return {};
}

/// Lowers the calling thread's priority to the least (Linux: nice is per thread).
void lowestPriority() { (void)::setpriority(PRIO_PROCESS, static_cast<id_t>(::gettid()), 19); }

// ---- figures ----------------------------------------------------------------------------------

/// The sum of every series of metric `name` (with or without labels) whose line contains `has`.
double metric(const std::string& text, const std::string& name, const std::string& has = {}) {
  std::istringstream in(text);
  double sum = 0;
  bool found = false;
  for (std::string line; std::getline(in, line);) {
    if (!line.starts_with(name) || line.size() <= name.size()) continue;
    const char next = line[name.size()];
    if (next != ' ' && next != '{') continue;
    if (!has.empty() && line.find(has) == std::string::npos) continue;
    const auto space = line.rfind(' ');
    sum += std::stod(line.substr(space + 1));
    found = true;
  }
  return found ? sum : -1;
}

double procStatusKb(pid_t pid, const std::string& key) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(in, line);) {
    if (line.starts_with(key + ":")) return std::stod(line.substr(key.size() + 1));
  }
  return -1;
}

double openDescriptors(pid_t pid) {
  std::error_code ec;
  double n = 0;
  for (fs::directory_iterator it("/proc/" + std::to_string(pid) + "/fd", ec), end; !ec && it != end; it.increment(ec)) {
    ++n;
  }
  return n;
}

/// User and system CPU time of the process in seconds (/proc/PID/stat, fields 14 and 15).
double processCpuSeconds(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string text;
  std::getline(in, text);
  const auto close = text.rfind(')');
  if (close == std::string::npos) return -1;
  std::istringstream fields(text.substr(close + 2));
  std::vector<std::string> f;
  for (std::string s; fields >> s;) f.push_back(s);
  if (f.size() < 13) return -1;
  return (std::stod(f[11]) + std::stod(f[12])) / static_cast<double>(::sysconf(_SC_CLK_TCK));
}

struct Reading {
  std::string metrics;
  double frames = -1;
  double late = 0;
  double slow = 0;  ///< intervals over 17.5 ms
  double cpu = 0;
  double rssKb = 0;
  double fds = 0;
};

Reading read(std::uint16_t port, pid_t pid) {
  Reading r;
  r.metrics = probeHard(port, "/metrics");
  r.cpu = processCpuSeconds(pid);
  r.rssKb = procStatusKb(pid, "VmRSS");
  r.fds = openDescriptors(pid);
  if (r.metrics.empty()) return r;
  r.frames = metric(r.metrics, "basalt_frame_work_seconds_count");
  r.late = metric(r.metrics, "basalt_frames_late_total");
  r.slow = metric(r.metrics, "basalt_frame_interval_seconds_count") -
           metric(r.metrics, "basalt_frame_interval_seconds_bucket", "le=\"0.0175\"");
  return r;
}

/// What an attack was answered: status codes (0: closed without an answer) and a note.
struct Tally {
  std::mutex mutex;
  std::map<int, int> codes;  // guarded by mutex
  std::atomic<long long> attempts{0};
  std::atomic<long long> bytes{0};
  void answer(int code) {
    const std::lock_guard lock(mutex);
    ++codes[code];
  }
  std::string describe() {
    const std::lock_guard lock(mutex);
    const long long sent = bytes.load();
    std::string out = std::to_string(attempts.load()) + " attempts, " +
                      (sent < 10240 ? std::to_string(sent) + " bytes" : std::to_string(sent / 1024) + " KiB") +
                      " sent; answers";
    for (const auto& [code, n] : codes)
      out += " " + (code == 0 ? std::string("none") : std::to_string(code)) + " x" + std::to_string(n);
    return codes.empty() ? out + " none" : out;
  }
};

/// One phase's figures.
struct Phase {
  std::string name;
  std::string why;  ///< why there are none; empty when measured
  double frames = 0;
  double late = 0;
  double lateAllowed = 0;
  double slow = 0;
  double p50Ms = 0;
  double p99Ms = 0;
  double maxMs = 0;
  double cpuMs = 0;
  double rssStartKb = 0;
  double rssEndKb = 0;
  double fdsStart = 0;
  double fdsEnd = 0;
  std::string counted;
  std::string logged;
  std::string attack;
  int bystanderServed = 0;
  int bystanderAsked = 0;
};

std::vector<Phase> phases;  // every phase of both runs, in order

// ---- the attacks ------------------------------------------------------------------------------

struct Target {
  std::uint16_t port = 0;  ///< the status server's
  int lock = 0;            ///< the frame lock's first port
  std::string lockReplay;  ///< a follower's captured conversation on the answer port
};
using Attack = std::function<void(const Target&, const std::atomic<bool>& stop, Tally&)>;

void chunkedPosts(const Target& t, const std::atomic<bool>& stop, Tally& tally) {
  const std::string chunk = "10000\r\n" + std::string(0x10000, 'a') + "\r\n";
  constexpr long long kTotal = 100LL * 1000 * 1000;
  while (!stop) {
    const int fd = connectFrom(kAttacker, t.port);
    if (fd < 0) {
      std::this_thread::sleep_for(50ms);
      continue;
    }
    ++tally.attempts;
    bool ok = sendAll(fd, std::string("POST /control/command HTTP/1.1\r\nHost: 127.0.0.1\r\nAuthorization: Bearer ") +
                              kToken + "\r\nContent-Type: text/plain\r\nTransfer-Encoding: chunked\r\n\r\n");
    for (long long sent = 0; ok && sent < kTotal && !stop && !answered(fd); sent += 0x10000) {
      ok = sendAll(fd, chunk);
      if (ok) tally.bytes += static_cast<long long>(chunk.size());
    }
    if (ok && !answered(fd)) (void)sendAll(fd, "0\r\n\r\n");
    tally.answer(statusCode(readAll(fd, 2000)));
    ::close(fd);
  }
}

void millionHeaders(const Target& t, const std::atomic<bool>& stop, Tally& tally) {
  std::string batch;
  for (int i = 0; i < 1000; ++i) batch += "X-Field-" + std::to_string(i) + ": value\r\n";
  while (!stop) {
    const int fd = connectFrom(kAttacker, t.port);
    if (fd < 0) {
      std::this_thread::sleep_for(50ms);
      continue;
    }
    ++tally.attempts;
    bool ok = sendAll(fd, "GET /health HTTP/1.1\r\nHost: 127.0.0.1\r\n");
    for (int sent = 0; ok && sent < 1000 * 1000 && !stop && !answered(fd); sent += 1000) {
      ok = sendAll(fd, batch);
      if (ok) tally.bytes += static_cast<long long>(batch.size());
    }
    if (ok && !answered(fd)) (void)sendAll(fd, "\r\n");
    tally.answer(statusCode(readAll(fd, 2000)));
    ::close(fd);
  }
}

/// Connections that the attack keeps open: each gets `trickle` (or nothing) once a second; one
/// the server closed is tallied with its answer and opened again.
void holdConnections(const Target& t, const std::atomic<bool>& stop, Tally& tally, int count, int addresses,
                     std::uint32_t base, bool trickle) {
  struct Held {
    int fd = -1;
    std::uint32_t from = 0;
    std::size_t sent = 0;
    std::string answer;
  };
  const std::string head = "GET /health HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Slow: " + std::string(4096, 'z');
  std::vector<Held> held(static_cast<std::size_t>(count));
  for (std::size_t i = 0; i < held.size(); ++i)
    held[i].from = base + static_cast<std::uint32_t>(i % static_cast<std::size_t>(addresses)) + 1;
  const auto open = [&](Held& h) {
    h.fd = connectFrom(h.from, t.port, true);
    h.sent = 0;
    h.answer.clear();
    if (h.fd >= 0) ++tally.attempts;
  };
  for (Held& h : held) open(h);
  std::array<char, 4096> buffer{};
  while (!stop) {
    const auto tick = Clock::now();
    for (Held& h : held) {
      if (h.fd < 0) {
        open(h);
        continue;
      }
      for (;;) {
        const ssize_t n = ::recv(h.fd, buffer.data(), buffer.size(), MSG_DONTWAIT);
        if (n > 0) {
          h.answer.append(buffer.data(), static_cast<std::size_t>(n));
          continue;
        }
        if (n == 0 || (errno != EAGAIN && errno != ENOTCONN && errno != EINPROGRESS)) {
          tally.answer(statusCode(h.answer));
          ::close(h.fd);
          h.fd = -1;
        }
        break;
      }
      if (h.fd >= 0 && trickle && h.sent < head.size()) {
        if (::send(h.fd, head.data() + h.sent, 1, MSG_NOSIGNAL | MSG_DONTWAIT) == 1) {
          ++h.sent;
          ++tally.bytes;
        }
      }
    }
    while (!stop && Clock::now() - tick < 1s) std::this_thread::sleep_for(20ms);
  }
  for (Held& h : held) {
    if (h.fd >= 0) ::close(h.fd);
  }
}

void slowloris(const Target& t, const std::atomic<bool>& stop, Tally& tally) {
  holdConnections(t, stop, tally, 64, 16, 0x7f010100, true);  // 127.0.1.1 to 127.0.1.16
}

void idleConnections(const Target& t, const std::atomic<bool>& stop, Tally& tally) {
  holdConnections(t, stop, tally, 2000, 250, 0x7f010200, false);  // 127.0.2.1 to 127.0.2.250
}

void snapshots(const Target& t, const std::atomic<bool>& stop, Tally& tally) {
  std::vector<std::thread> clients;
  clients.reserve(4);
  for (int c = 0; c < 4; ++c) {
    clients.emplace_back([&] {
      lowestPriority();
      while (!stop) {
        const int fd = connectFrom(kAttacker, t.port);
        if (fd < 0) continue;
        ++tally.attempts;
        std::string answer;
        if (sendAll(fd, "GET /snapshot.png HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n")) {
          answer = readAll(fd, 5000);
        }
        tally.bytes += static_cast<long long>(answer.size());
        tally.answer(statusCode(answer));
        ::close(fd);
      }
    });
  }
  for (std::thread& c : clients) c.join();
}

/// ZeroMQ's greeting (ZMTP 3.0) with the NULL mechanism, the READY of a DEALER, and one message
/// frame holding a `ready` for frame 1 as the wire format lays it out: what a peer without the
/// key sends.
std::string forgedReady() {
  std::string g(64, '\0');
  g[0] = static_cast<char>(0xff);
  g[9] = 0x7f;
  g[10] = 3;
  g.replace(12, 4, "NULL");
  std::string ready = std::string("\x05READY", 6) + "\x0bSocket-Type" + std::string("\0\0\0\x06", 4) + "DEALER";
  g += std::string(1, '\x04') + static_cast<char>(ready.size()) + ready;
  std::string message = std::string("BLCK\x03\x03\0\0", 8) + std::string(24, '\0');
  message[8] = 1;  // frame 1
  g += std::string(1, '\0') + static_cast<char>(message.size()) + message;
  return g;
}

enum class LockAttack : std::uint8_t { kNoKey, kGarbage, kReplay };

/// Connections to the lock's ports, one every 20 ms: ZeroMQ without the key (on the answer port
/// and the frame port in turn), 512 random bytes, or the captured follower's conversation.
Attack lockAttack(LockAttack kind) {
  return [kind](const Target& t, const std::atomic<bool>& stop, Tally& tally) {
    std::mt19937 random(7);
    std::string garbage(512, '\0');
    for (char& c : garbage) c = static_cast<char>(random() & 0xff);
    const std::string forged = forgedReady();
    const std::string& bytes = kind == LockAttack::kNoKey     ? forged
                               : kind == LockAttack::kGarbage ? garbage
                                                              : t.lockReplay;
    for (int i = 0; !stop && !bytes.empty(); ++i) {
      const bool framePort = kind == LockAttack::kNoKey && i % 2 == 1;
      const int fd = connectFrom(kAttacker, static_cast<std::uint16_t>(framePort ? t.lock : t.lock + 1));
      if (fd < 0) {
        std::this_thread::sleep_for(50ms);
        continue;
      }
      ++tally.attempts;
      if (sendAll(fd, bytes)) tally.bytes += static_cast<long long>(bytes.size());
      (void)readAll(fd, 100);
      tally.answer(0);
      ::close(fd);
      std::this_thread::sleep_for(20ms);
    }
  };
}

// ---- the follower whose conversation is replayed ----------------------------------------------

class NullOutput final : public basalt::render::Output {
 public:
  [[nodiscard]] std::string_view kind() const override { return "null"; }
  [[nodiscard]] basalt::render::Size size() const override { return {4, 4}; }
  [[nodiscard]] std::string describe() const override { return "null"; }
  [[nodiscard]] basalt::Result<void> beginFrame() override { return {}; }
  [[nodiscard]] basalt::Result<void> present() override { return {}; }
};

/// A TCP relay on loopback from `listenPort` to `targetPort` for one client, keeping what the
/// client sent.
class Relay {
 public:
  Relay(int listenPort, int targetPort) : target_(targetPort) {
    listener_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    const int on = 1;
    ::setsockopt(listener_, SOL_SOCKET, SO_REUSEADDR, &on, sizeof on);
    const sockaddr_in at = address(INADDR_LOOPBACK, static_cast<std::uint16_t>(listenPort));
    if (::bind(listener_, reinterpret_cast<const sockaddr*>(&at), sizeof at) == 0 && ::listen(listener_, 4) == 0) {
      thread_ = std::thread([this] { run(); });
    }
  }
  ~Relay() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
    ::close(listener_);
  }
  Relay(const Relay&) = delete;
  Relay& operator=(const Relay&) = delete;
  Relay(Relay&&) = delete;
  Relay& operator=(Relay&&) = delete;

  [[nodiscard]] std::string fromClient() {
    const std::lock_guard lock(mutex_);
    return fromClient_;
  }

 private:
  void run() {
    int client = -1;
    int server = -1;
    std::array<char, 4096> chunk{};
    while (!stop_) {
      std::vector<pollfd> fds{{listener_, POLLIN, 0}};
      if (client >= 0) fds.push_back({client, POLLIN, 0});
      if (server >= 0) fds.push_back({server, POLLIN, 0});
      if (::poll(fds.data(), fds.size(), 20) <= 0) continue;
      if ((fds[0].revents & POLLIN) != 0) {
        const int s = ::accept4(listener_, nullptr, nullptr, SOCK_CLOEXEC);
        if (client >= 0 || s < 0) {
          if (s >= 0) ::close(s);
          continue;
        }
        client = s;
        server = connectFrom(INADDR_LOOPBACK, static_cast<std::uint16_t>(target_));
        if (server < 0) break;
        continue;
      }
      for (std::size_t i = 1; i < fds.size() && !stop_; ++i) {
        if ((fds[i].revents & (POLLIN | POLLHUP | POLLERR)) == 0) continue;
        const ssize_t n = ::read(fds[i].fd, chunk.data(), chunk.size());
        if (n <= 0) {
          stop_ = true;
          break;
        }
        const bool client2server = fds[i].fd == client;
        if (client2server) {
          const std::lock_guard lock(mutex_);
          fromClient_.append(chunk.data(), static_cast<std::size_t>(n));
        }
        (void)sendAll(client2server ? server : client, std::string_view(chunk.data(), static_cast<std::size_t>(n)));
      }
    }
    if (client >= 0) ::close(client);
    if (server >= 0) ::close(server);
  }

  int target_;
  int listener_ = -1;
  std::atomic<bool> stop_{false};
  std::mutex mutex_;
  std::string fromClient_;  // guarded by mutex_
  std::thread thread_;
};

/// A follower with the key joins the leader on `port` through relays for 30 frames; what it
/// sent on the answer port (its CURVE handshake and answers) is returned for the replay.
std::string captureFollower(int port, const fs::path& key) {
  const int relayed = port + 4;
  Relay frames(relayed, port);
  Relay answers(relayed + 1, port + 1);
  {
    basalt::SystemClock clock;
    auto loop = basalt::runtime::EventLoop::create(clock);
    basalt::runtime::Show show;
    basalt::kiosk::LockSpec spec;
    spec.role = basalt::kiosk::LockRole::kFollower;
    spec.node = "captured";
    spec.leader = "127.0.0.1";
    spec.port = relayed;
    spec.keyFile = key;
    spec.clock = false;
    auto lock = basalt::kiosk::FrameLock::create(spec, clock, show);
    if (!loop || !lock) return {};
    NullOutput out;
    int drawn = 0;
    for (const auto begin = Clock::now(); drawn < 30 && Clock::now() - begin < 10s;) {
      auto next = (*lock)->nextFrame(**loop, 20ms);
      if (!next || !*next) continue;
      if ((*next)->end) break;
      basalt::kiosk::FrameContext c{(*next)->frame, (*next)->time, false};
      if (!(*lock)->beforeDraw(c) || !(*lock)->afterDraw(c, out)) break;
      ++drawn;
    }
    if (drawn < 30) return {};
  }
  return answers.fromClient();
}

// ---- the run ----------------------------------------------------------------------------------

const std::regex& intervalPattern() {
  static const std::regex pattern(
      R"re("frame_time_ms": \{\s*"p50": ([0-9.]+),\s*"p90": [0-9.]+,\s*"p99": ([0-9.]+),\s*"max": ([0-9.]+)\s*\})re");
  return pattern;
}

struct Step {
  std::string name;
  Attack attack;  ///< empty: idle
  std::function<std::string(const Reading& before, const Reading& after)> counted;
  std::function<void(basalt::test::Process&)> start;  ///< at the phase's start, after the attack began
  double lateAllowedPerSecond = 0;
};

/// Runs `steps` on a running show, each phaseSeconds() long; appends them to `phases`.
void runPhases(basalt::test::Process& show, const Target& target, const std::vector<Step>& steps) {
  const int seconds = phaseSeconds();
  for (const Step& step : steps) {
    Phase p;
    p.name = step.name;
    p.lateAllowed = step.lateAllowedPerSecond * seconds;
    const Reading before = read(target.port, show.pid());
    if (before.frames < 0) {
      p.why = "no /metrics before the phase";
      phases.push_back(p);
      continue;
    }
    const std::size_t logFrom = show.outputSoFar().size();
    std::atomic<bool> stop{false};
    Tally tally;
    std::atomic<int> served{0};
    std::atomic<int> asked{0};
    std::thread attacker;
    if (step.attack) {
      attacker = std::thread([&] {
        lowestPriority();
        step.attack(target, stop, tally);
      });
    }
    // A bystander asks /health once a second.
    std::thread bystander([&] {
      lowestPriority();
      while (!stop) {
        const auto tick = Clock::now();
        ++asked;
        if (!probe(target.port, "/health").empty()) ++served;
        while (!stop && Clock::now() - tick < 1s) std::this_thread::sleep_for(20ms);
      }
    });
    if (step.start) step.start(show);
    const auto begin = Clock::now();
    while (Clock::now() - begin < std::chrono::seconds(seconds)) {
      (void)show.outputWithin(std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::seconds(seconds) -
                                                                                    (Clock::now() - begin)));
    }
    stop = true;
    if (attacker.joinable()) attacker.join();
    bystander.join();
    const Reading after = read(target.port, show.pid());
    const std::string health = probeHard(target.port, "/health");
    std::smatch m;
    if (after.frames < 0 || !std::regex_search(health, m, intervalPattern())) {
      p.why = "no /metrics or /health after the phase";
      phases.push_back(p);
      continue;
    }
    p.frames = after.frames - before.frames;
    p.late = after.late - before.late;
    p.slow = after.slow - before.slow;
    p.p50Ms = std::stod(m[1].str());
    p.p99Ms = std::stod(m[2].str());
    p.maxMs = std::stod(m[3].str());
    p.cpuMs = p.frames > 0 ? (after.cpu - before.cpu) / p.frames * 1e3 : 0;
    p.rssStartKb = before.rssKb;
    p.rssEndKb = after.rssKb;
    p.fdsStart = before.fds;
    p.fdsEnd = after.fds;
    p.counted = step.counted ? step.counted(before, after) : "";
    p.attack = step.attack ? tally.describe() : "";
    p.bystanderServed = served;
    p.bystanderAsked = asked;
    // The log lines written during the phase: how many, and the first.
    const std::string log = show.outputSoFar().substr(logFrom);
    const auto lines = std::count(log.begin(), log.end(), '\n');
    const std::string first = log.substr(0, std::min<std::size_t>(log.find('\n'), 160));
    p.logged = std::to_string(lines) + " lines" + (lines > 0 ? ", first: " + first : "");
    phases.push_back(p);
  }
}

/// A counter's growth as "name +N".
std::function<std::string(const Reading&, const Reading&)> grew(const std::string& name, const std::string& has = {},
                                                                const std::string& label = {}) {
  return [=](const Reading& before, const Reading& after) {
    const double b = metric(before.metrics, name, has);
    const double a = metric(after.metrics, name, has);
    char text[64];
    std::snprintf(text, sizeof text, " %+.0f", a < 0 ? 0 : a - std::max(b, 0.0));
    return (label.empty() ? name : label) + (a < 0 ? " (absent)" : text);
  };
}

std::optional<basalt::test::Process> startShow(const fs::path& manifest, std::string& why, std::uint16_t& port) {
  basalt::test::Process show = basalt::test::Process::start(
      {basalt(), "run", manifest.string(), "--output", "headless", "--realtime", "--fps", "60", "--no-resume",
       "--status", "127.0.0.1:0", "--state-dir", (manifest.parent_path() / "state").string(), "--output-dir",
       manifest.parent_path().string()});
  const std::string marker = "status server: http://127.0.0.1:";
  if (!show.started() || !show.waitForOutput(marker, 30s) || !show.waitForOutput("first frame on", 30s)) {
    why = "the show did not start (is EGL available?): " + show.outputSoFar();
    return std::nullopt;
  }
  const std::string& text = show.outputSoFar();
  port = static_cast<std::uint16_t>(std::stoi(text.substr(text.find(marker) + marker.size())));
  (void)show.outputWithin(2s);  // past the start's allocations
  return show;
}

std::string slurp(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

/// The default demo with a control token, the most requests a second, and a keyed lock leader.
std::string attackStatusAndLock() {
  const fs::path dir = scratch() / "default";
  fs::create_directories(dir);
  std::ofstream(dir / "control.token", std::ios::trunc) << kToken << "\n";
  const fs::path key = scratch() / "lock.key";
  std::ofstream(key, std::ios::trunc) << kLockKey << "\n";
  fs::permissions(key, fs::perms::owner_read | fs::perms::owner_write);
  std::string manifest = slurp(fs::path(BASALT_SOURCE_DIR) / "configs/shows/default/show.toml");
  const auto at = manifest.find("[status]\n");
  if (at == std::string::npos) return "the default show has no [status]";
  manifest.insert(at + 9, "requests_per_second = 1000\ntoken_file = \"control.token\"\n");
  manifest += "\n[lock]\nrole = \"leader\"\nnode = \"attacked\"\nport = " + std::to_string(lockPort()) +
              "\nkey_file = \"" + key.string() + "\"\n";
  const fs::path file = dir / "show.toml";
  std::ofstream(file, std::ios::trunc) << manifest;

  std::string why;
  Target target;
  auto show = startShow(file, why, target.port);
  if (!show) return why;
  target.lock = lockPort();
  target.lockReplay = captureFollower(target.lock, key);
  if (target.lockReplay.empty()) return "no follower conversation to replay: " + show->outputSoFar();
  (void)show->outputWithin(2s);  // the leader has dropped the captured follower

  const std::string rejected = "basalt_http_rejected_total";
  const auto lockCounted = [](const Reading& b, const Reading& a) {
    std::string out;
    for (const char* reason : {"no_key", "wrong_key", "handshake"}) {
      out += grew("basalt_lock_messages_rejected_total", std::string("reason=\"") + reason + "\"", reason)(b, a) + ", ";
    }
    return out + grew("basalt_lock_malformed_total", {}, "malformed")(b, a) + ", authenticated " +
           std::to_string(static_cast<int>(metric(a.metrics, "basalt_lock_authenticated")));
  };
  runPhases(*show, target,
            {
                {"idle (baseline)", {}, grew("basalt_http_requests_total", {}, "requests"), {}, 0},
                {"chunked 100 MB POST /control/command",
                 chunkedPosts,
                 grew(rejected, "reason=\"size\"", "basalt_http_rejected_total{size}"),
                 {},
                 0},
                {"a million header fields", millionHeaders, grew("basalt_http_requests_total", {}, "requests"), {}, 0},
                {"slowloris (64 connections, a byte a second)",
                 slowloris,
                 grew("basalt_http_requests_total", {}, "requests"),
                 {},
                 0},
                {"2000 idle connections", idleConnections, grew("basalt_http_requests_total", {}, "requests"), {}, 0},
                {"/snapshot.png in a loop", snapshots, grew("basalt_http_requests_total", {}, "requests"), {}, 1},
                {"lock: ZeroMQ without the key (both ports)", lockAttack(LockAttack::kNoKey), lockCounted, {}, 0},
                {"lock: garbage", lockAttack(LockAttack::kGarbage), lockCounted, {}, 0},
                {"lock: a follower's conversation replayed", lockAttack(LockAttack::kReplay), lockCounted, {}, 0},
                {"empty manifest, SIGHUP",
                 {},
                 [](const Reading& b, const Reading& a) {
                   return grew("basalt_reload_failures_total", {}, "reload failures")(b, a) + ", " +
                          grew("basalt_errors_logged_total", {}, "errors logged")(b, a);
                 },
                 [file](basalt::test::Process& p) {
                   std::ofstream(file, std::ios::trunc).close();
                   p.signal(SIGHUP);
                 },
                 0},
            });
  show->signal(SIGTERM);
  (void)show->wait(20s);
  return {};
}

/// The video-wall example at 60 fps: a movie texture whose file is cut to 0 bytes while it plays.
std::string attackMovie() {
  const fs::path dir = scratch() / "video-wall";
  fs::copy(fs::path(BASALT_SOURCE_DIR) / "configs/shows/video-wall", dir,
           fs::copy_options::recursive | fs::copy_options::overwrite_existing);
  std::string manifest = slurp(dir / "show.toml");
  const auto fps = manifest.find("fps = 30");
  if (fps == std::string::npos) return "the video-wall show has no `fps = 30`";
  manifest.replace(fps, 8, "fps = 60");
  // Smaller than the example's 1280 x 720, so that a software renderer keeps 60 fps.
  const auto size = manifest.find("size = \"1280x720\"");
  if (size != std::string::npos) manifest.replace(size, 17, "size = \"640x360\"");
  std::ofstream(dir / "show.toml", std::ios::trunc) << manifest;
  std::string why;
  Target target;
  auto show = startShow(dir / "show.toml", why, target.port);
  if (!show) return why;
  const fs::path clip = dir / "clips/loop.webm";
  const auto counted = [](const Reading& b, const Reading& a) {
    return "stream_state " + std::to_string(static_cast<int>(metric(a.metrics, "basalt_stream_state"))) +
           " (4: degraded), " + grew("basalt_errors_logged_total", {}, "errors logged")(b, a);
  };
  runPhases(*show, target,
            {
                {"movie: idle (baseline)", {}, counted, {}, 0},
                {"movie: its file cut to 0 bytes",
                 {},
                 counted,
                 [clip](basalt::test::Process&) {
                   fs::resize_file(clip, 0);
                   std::ofstream(clip, std::ios::app).close();  // the writer's close
                 },
                 0},
            });
  show->signal(SIGTERM);
  (void)show->wait(20s);
  return {};
}

void attacks(benchmark::State& state, bool movie) {
  for (auto _ : state) {
    const std::string why = movie ? attackMovie() : attackStatusAndLock();
    if (!why.empty()) {
      state.SkipWithError(why.c_str());
      return;
    }
    state.SetIterationTime(1);
  }
}

BENCHMARK_CAPTURE(attacks, status_and_lock, false)->UseManualTime()->Iterations(1)->Repetitions(1);
BENCHMARK_CAPTURE(attacks, movie, true)->UseManualTime()->Iterations(1)->Repetitions(1);

void printPhase(const Phase& p, const Phase& base) {
  if (!p.why.empty()) {
    std::printf("attack, %s: no figures (%s)\n", p.name.c_str(), p.why.c_str());
    return;
  }
  const double rssGrowth = p.rssEndKb - p.rssStartKb;
  const bool lateMet = p.late <= p.lateAllowed;
  const bool memoryMet = rssGrowth <= 16 * 1024;
  const bool fdsMet = p.fdsEnd <= base.fdsStart + 40 && p.fdsStart <= base.fdsStart + 40;
  std::printf(
      "attack, %s: %.0f frames; late %.0f (idle %.0f; target <= %.0f: %s); intervals over 17.5 ms %.0f; /health "
      "interval p50 "
      "%.2f ms, p99 %.2f ms, max %.2f ms; process CPU %.3f ms per frame (idle %.3f, %+.0f%%); resident %.1f -> %.1f "
      "MB (%+.0f kB; target within 16 MB: %s); descriptors %.0f -> %.0f (target <= idle's %.0f + 40: %s)\n",
      p.name.c_str(), p.frames, p.late, base.late, p.lateAllowed, lateMet ? "met" : "NOT MET", p.slow, p.p50Ms, p.p99Ms,
      p.maxMs, p.cpuMs, base.cpuMs, base.cpuMs > 0 ? (p.cpuMs / base.cpuMs - 1) * 100 : 0, p.rssStartKb / 1024,
      p.rssEndKb / 1024, rssGrowth, memoryMet ? "met" : "NOT MET", p.fdsStart, p.fdsEnd, base.fdsStart,
      fdsMet ? "met" : "NOT MET");
  std::printf("attack, %s: counted: %s; logged: %s\n", p.name.c_str(), p.counted.c_str(), p.logged.c_str());
  if (!p.attack.empty()) std::printf("attack, %s: the attacker: %s\n", p.name.c_str(), p.attack.c_str());
  std::printf("attack, %s: a bystander's /health served %d of %d\n", p.name.c_str(), p.bystanderServed,
              p.bystanderAsked);
}

}  // namespace

int main(int argc, char** argv) {
  // 2 000 idle connections and the rest need more descriptors than the usual soft limit.
  rlimit files{};
  if (::getrlimit(RLIMIT_NOFILE, &files) == 0) {
    files.rlim_cur = files.rlim_max;
    (void)::setrlimit(RLIMIT_NOFILE, &files);
  }
  const int result = basalt::bench::runBenchmarks(argc, argv, [](const basalt::bench::Medians&) {
    std::printf(
        "attack: %d s a phase; the default demo at 60 fps with a control token and a keyed lock leader, "
        "then the video-wall example at 60 fps\n",
        phaseSeconds());
    const Phase* base = nullptr;
    for (const Phase& p : phases) {
      if (p.name.find("idle (baseline)") != std::string::npos) base = &p;
      if (base != nullptr) printPhase(p, *base);
    }
    if (phases.empty()) std::printf("attack: no figures (a run failed)\n");
  });
  fs::remove_all(scratch());
  return result;
}
