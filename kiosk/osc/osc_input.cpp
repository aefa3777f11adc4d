// The OSC input. Basalt owns the sockets rather than liblo's servers: liblo 0.31 (Debian 12)
// binds its servers to every interface whatever address is asked for, and `[osc] listen` must be
// able to keep the port on loopback (docs/decisions/0065-osc-with-liblo.md). liblo takes each
// message apart (osc_message.cpp) and matches address patterns (osc_router.cpp).
//
// UDP: one datagram is one packet. TCP: each packet is preceded by its size (a 32-bit big-endian
// integer), as OSC 1.0 streams and liblo's own TCP clients (oscsend osc.tcp://...) frame them.
// Limits: packets of at most kOscMaxPacketBytes, kOscMaxConnections connections, a connection
// quiet for 60 s is closed; the rate limit and command length are the HTTP controls'.

#include "kiosk/osc/osc_input.h"

#include <arpa/inet.h>
#include <netdb.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "runtime/log.h"

namespace basalt::kiosk {

namespace {

// The frame loop answers a control within a frame; past this, the loop may be hung (as HTTP).
constexpr std::chrono::seconds kAnswerWait{3};
constexpr std::chrono::seconds kConnectionIdle{60};
constexpr int kPollMs = 50;
constexpr std::size_t kMaxPending = 64;

std::string numericHost(const sockaddr_storage& a) {
  std::array<char, NI_MAXHOST> host{};
  if (::getnameinfo(reinterpret_cast<const sockaddr*>(&a), sizeof a, host.data(), host.size(), nullptr, 0,
                    NI_NUMERICHOST) != 0) {
    return "?";
  }
  return host.data();
}

std::uint16_t boundPort(int fd) {
  sockaddr_storage a{};
  socklen_t len = sizeof a;
  if (::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len) != 0) return 0;
  if (a.ss_family == AF_INET6) return ntohs(reinterpret_cast<const sockaddr_in6*>(&a)->sin6_port);
  return ntohs(reinterpret_cast<const sockaddr_in*>(&a)->sin_port);
}

Result<UniqueFd> openSocket(const std::string& host, std::uint16_t port, bool tcp) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = tcp ? SOCK_STREAM : SOCK_DGRAM;
  hints.ai_flags = AI_PASSIVE | AI_NUMERICHOST | AI_NUMERICSERV;
  addrinfo* found = nullptr;
  const std::string service = std::to_string(port);
  const std::string name = host == "localhost" ? "127.0.0.1" : host;
  if (const int rc = ::getaddrinfo(name.c_str(), service.c_str(), &hints, &found); rc != 0) {
    return fail(Errc::kInvalidArgument, fmt::format("OSC: '{}' is not an address: {}", host, ::gai_strerror(rc)));
  }
  std::unique_ptr<addrinfo, decltype(&::freeaddrinfo)> list(found, &::freeaddrinfo);
  UniqueFd fd(::socket(found->ai_family, found->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC, 0));
  if (!fd) return fail(Errc::kIo, fmt::format("OSC: cannot make a socket: {}", std::strerror(errno)));
  const int one = 1;
  if (tcp) (void)::setsockopt(fd.get(), SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  if (::bind(fd.get(), found->ai_addr, found->ai_addrlen) != 0) {
    return fail(Errc::kIo, fmt::format("OSC: cannot listen on {} {}:{}: {} (another program, or another Basalt, may "
                                       "use the port; change [osc] listen)",
                                       tcp ? "tcp" : "udp", host, port, std::strerror(errno)));
  }
  if (tcp && ::listen(fd.get(), 8) != 0) {
    return fail(Errc::kIo, fmt::format("OSC: cannot listen on tcp {}:{}: {}", host, port, std::strerror(errno)));
  }
  return fd;
}

}  // namespace

struct OscInput::Connection {
  UniqueFd fd;
  std::string sender;
  std::vector<std::byte> buffer;  // bytes read, not yet a whole packet
  Nanos lastHeard{0};
};

struct OscInput::Pending {
  std::shared_ptr<ControlReply> reply;
  std::string address;
  std::string sender;
  Nanos deadline{0};
};

OscInput::OscInput(const OscSpec& spec, StatusBoard& board) : spec_(spec), board_(board), router_(spec) {}

Result<std::unique_ptr<OscInput>> OscInput::start(const OscSpec& spec, StatusBoard& board, OscTrackerSink* tracker) {
  std::unique_ptr<OscInput> input(new OscInput(spec, board));
  input->router_.setTrackerSink(tracker);
  if (auto bound = input->bind(); !bound) return std::unexpected(bound.error());
  input->stop_ = UniqueFd(::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC));
  if (!input->stop_) return fail(Errc::kIo, fmt::format("OSC: cannot make an eventfd: {}", std::strerror(errno)));
  input->publish();
  input->thread_ = std::thread([self = input.get()] { self->run(); });
  return input;
}

Result<void> OscInput::bind() {
  // Port 0 picks a free port for the first protocol, and the other takes the same one (a few
  // tries, in case another program took it meanwhile).
  for (int attempt = 0; attempt < 8; ++attempt) {
    std::uint16_t port = spec_.port;
    UniqueFd udp;
    UniqueFd tcp;
    if (spec_.udp) {
      auto made = openSocket(spec_.host, port, false);
      if (!made) return std::unexpected(made.error());
      udp = std::move(*made);
      port = boundPort(udp.get());
    }
    if (spec_.tcp) {
      auto made = openSocket(spec_.host, port, true);
      if (!made) {
        if (spec_.port == 0 && spec_.udp) continue;
        return std::unexpected(made.error());
      }
      tcp = std::move(*made);
      port = boundPort(tcp.get());
    }
    udp_ = std::move(udp);
    tcp_ = std::move(tcp);
    port_ = port;
    return {};
  }
  return fail(Errc::kIo, "OSC: found no port free for both UDP and TCP");
}

OscInput::~OscInput() {
  if (thread_.joinable()) {
    const std::uint64_t one = 1;
    (void)!::write(stop_.get(), &one, sizeof one);
    thread_.join();
  }
}

std::string OscInput::describe() const {
  const char* protocols = spec_.udp && spec_.tcp ? "udp+tcp" : spec_.udp ? "udp" : "tcp";
  const bool v6 = spec_.host.find(':') != std::string::npos;
  return fmt::format("{} {}{}{}:{}", protocols, v6 ? "[" : "", spec_.host, v6 ? "]" : "", port_);
}

void OscInput::run() {
  // Answering OSC takes CPU from the show only when there is some to spare, as the status
  // server's workers do.
  (void)::setpriority(PRIO_PROCESS, static_cast<id_t>(::syscall(SYS_gettid)), 10);
  log::info(kLogOsc, "OSC on {} ({} bindings{})", describe(), spec_.bindings.size(),
            spec_.allow.empty() ? "" : fmt::format(", senders {}", fmt::join(spec_.allow, ", ")));
  std::vector<pollfd> fds;
  for (;;) {
    fds.clear();
    fds.push_back({stop_.get(), POLLIN, 0});
    if (udp_) fds.push_back({udp_.get(), POLLIN, 0});
    if (tcp_) fds.push_back({tcp_.get(), POLLIN, 0});
    const std::size_t firstConnection = fds.size();
    for (const auto& c : connections_) fds.push_back({c->fd.get(), POLLIN, 0});
    const int ready = ::poll(fds.data(), fds.size(), kPollMs);
    if (ready < 0 && errno != EINTR) {
      log::error(kLogOsc, "OSC: poll failed: {}; the OSC input stops", std::strerror(errno));
      break;
    }
    if (fds[0].revents != 0) break;
    std::size_t at = 1;
    if (udp_ && (fds[at++].revents & POLLIN) != 0) readUdp();
    if (tcp_ && (fds[at++].revents & POLLIN) != 0) acceptTcp();
    const Nanos now = clock_.now();
    // Connections: read the ready ones; close those that ended, broke a limit or went quiet.
    std::vector<bool> close(connections_.size(), false);
    for (std::size_t i = 0; i < connections_.size() && firstConnection + i < fds.size(); ++i) {
      const short revents = fds[firstConnection + i].revents;
      if ((revents & (POLLIN | POLLHUP | POLLERR)) != 0) {
        close[i] = !readTcp(*connections_[i]);
      } else if (now - connections_[i]->lastHeard > kConnectionIdle) {
        close[i] = true;
      }
    }
    for (std::size_t i = connections_.size(); i-- > 0;) {
      if (close[i]) connections_.erase(connections_.begin() + static_cast<std::ptrdiff_t>(i));
    }
    sweepReplies(false);
    publish();
  }
  sweepReplies(true);
  publish();
}

void OscInput::readUdp() {
  alignas(4) std::array<std::byte, kOscMaxPacketBytes> buffer{};
  // At most 256 datagrams a turn, so that TCP and the stop signal get their turn in a flood.
  for (int i = 0; i < 256; ++i) {
    sockaddr_storage from{};
    socklen_t fromLen = sizeof from;
    const ssize_t n =
        ::recvfrom(udp_.get(), buffer.data(), buffer.size(), MSG_TRUNC, reinterpret_cast<sockaddr*>(&from), &fromLen);
    if (n < 0) return;  // EAGAIN: read all there was
    const std::string sender = numericHost(from);
    if (static_cast<std::size_t>(n) > buffer.size()) {
      router_.countMalformed(1);  // too large: dropped unread
      continue;
    }
    handle(std::span(buffer.data(), static_cast<std::size_t>(n)), sender);
  }
}

void OscInput::acceptTcp() {
  for (;;) {
    sockaddr_storage from{};
    socklen_t fromLen = sizeof from;
    UniqueFd fd(::accept4(tcp_.get(), reinterpret_cast<sockaddr*>(&from), &fromLen, SOCK_NONBLOCK | SOCK_CLOEXEC));
    if (!fd) return;
    if (connections_.size() >= kOscMaxConnections) {
      if (static log::Once full; full.first()) {
        log::warn(kLogOsc, "OSC: more than {} TCP connections at once; further ones are closed (said once)",
                  kOscMaxConnections);
      }
      continue;  // closed as fd goes
    }
    auto c = std::make_unique<Connection>();
    c->fd = std::move(fd);
    c->sender = numericHost(from);
    c->lastHeard = clock_.now();
    connections_.push_back(std::move(c));
  }
}

bool OscInput::readTcp(Connection& c) {
  std::array<std::byte, 4096> chunk{};
  for (;;) {
    const ssize_t n = ::read(c.fd.get(), chunk.data(), chunk.size());
    if (n == 0) return false;  // the sender closed
    if (n < 0) return errno == EAGAIN || errno == EINTR;
    c.lastHeard = clock_.now();
    c.buffer.insert(c.buffer.end(), chunk.begin(), chunk.begin() + n);
    // Whole packets out of the buffer.
    std::size_t at = 0;
    while (c.buffer.size() - at >= 4) {
      const std::byte* p = c.buffer.data() + at;
      const std::uint32_t size = (std::to_integer<std::uint32_t>(p[0]) << 24) |
                                 (std::to_integer<std::uint32_t>(p[1]) << 16) |
                                 (std::to_integer<std::uint32_t>(p[2]) << 8) | std::to_integer<std::uint32_t>(p[3]);
      if (size == 0 || size > kOscMaxPacketBytes) {
        // Not OSC's framing, or a packet past the limit: nothing after it can be read in step.
        router_.countMalformed(1);
        return false;
      }
      if (c.buffer.size() - at - 4 < size) break;
      handle(std::span<const std::byte>(p + 4, size), c.sender);
      at += 4 + size;
    }
    c.buffer.erase(c.buffer.begin(), c.buffer.begin() + static_cast<std::ptrdiff_t>(at));
  }
}

void OscInput::handle(std::span<const std::byte> bytes, const std::string& sender) {
  OscPacket packet = parseOscPacket(bytes);
  router_.countMalformed(packet.malformed);
  if (packet.malformed > 0) {
    if (static log::Once said; said.first()) {
      log::warn(kLogOsc,
                "OSC: a packet from {} could not be read as OSC; such packets are counted (malformed), "
                "not logged again",
                sender);
    }
  }
  const Nanos now = clock_.now();
  bool woke = false;
  for (OscMessage& m : packet.messages) {
    m.sender = sender;
    OscRouted routed = router_.route(m, now);
    std::size_t pushed = 0;
    for (std::size_t i = 0; i < routed.controls.size(); ++i) {
      ControlRequest& request = routed.controls[i];
      auto reply = std::make_shared<ControlReply>();
      request.reply = reply;
      if (pending_.size() >= kMaxPending || !board_.controls().push(std::move(request))) {
        router_.countQueueFull(pushed == 0 && i + 1 == routed.controls.size());
        static log::Once full;
        if (full.first()) {
          log::warn(kLogOsc,
                    "OSC: the controls' queue is full; OSC controls are dropped while it is (counted queue_full, "
                    "said once)");
        }
        continue;
      }
      ++pushed;
      pending_.push_back({std::move(reply), m.address, sender, now + kAnswerWait});
      woke = true;
    }
  }
  if (woke) board_.wake();
}

void OscInput::sweepReplies(bool all) {
  const Nanos now = clock_.now();
  std::erase_if(pending_, [&](Pending& p) {
    std::lock_guard lock(p.reply->mutex);
    if (p.reply->answered) {
      // As the HTTP controls are logged: what ran, from whom, and the frame loop's answer.
      log::info(kLogOsc, "control OSC {} from {}: {}", p.address, p.sender, p.reply->message);
      return true;
    }
    if (all || now > p.deadline) {
      log::warn(kLogOsc, "control OSC {} from {}: the frame loop did not answer within 3 s; it may be hung", p.address,
                p.sender);
      return true;
    }
    return false;
  });
}

void OscInput::publish() {
  const OscFigures& f = router_.figures();
  const std::uint64_t stamp = f.received + f.malformed + f.queueFull;
  if (stamp == published_) return;
  published_ = stamp;
  OscFigures copy = f;
  copy.listen = describe();
  board_.publishOsc(copy);
}

}  // namespace basalt::kiosk
