// Frame-locked nodes over ZeroMQ (libzmq's C API; Debian's libzmq3-dev). The leader binds a PUB
// socket on `port` (frames, presents, byes, join beacons) and a ROUTER socket on `port + 1`
// (followers' answers); a follower connects a SUB and a DEALER whose routing id is its node
// name. Nothing here blocks for longer than the spec's time-outs: the leader's barrier waits at
// most `timeout_ms` per frame, a follower's wait for "present" at most `leader_timeout_ms`.
// Over TCP a lost packet is a retransmission, so loss shows as delay: late answers, frames a
// follower skips and presents without the leader's word, all counted.
//
// With `lock.key_file` every socket speaks ZeroMQ's CURVE (libzmq is built with libsodium):
// the leader's sockets are CURVE servers, a follower's CURVE clients, and both key pairs are
// derived from the group's shared secret with libsodium (BLAKE2b, then X25519), so one file
// on every node is the whole configuration. A ZAP handler on the leader admits only clients
// with the group's public key; a socket monitor counts the handshakes that fail (no key, another
// key, a replayed capture). See docs/decisions/0060-frame-lock-curve.md.

#include "kiosk/lock/frame_lock.h"

#include <sodium.h>
#include <zmq.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <map>
#include <random>
#include <utility>

#include <fmt/format.h>

#include "kiosk/manifest/manifest.h"
#include "runtime/log.h"
#include "runtime/show/show.h"

namespace basalt::kiosk {

BASALT_LOG_CATEGORY(Lock, "lock");

namespace {

struct ZmqContextClose {
  void operator()(void* c) const {
    if (c) zmq_ctx_term(c);
  }
};
struct ZmqSocketClose {
  void operator()(void* s) const {
    if (s) zmq_close(s);
  }
};
using ZmqContext = std::unique_ptr<void, ZmqContextClose>;
using ZmqSocket = std::unique_ptr<void, ZmqSocketClose>;

Result<ZmqSocket> makeSocket(void* context, int type, std::string_view what) {
  ZmqSocket s(zmq_socket(context, type));
  if (!s)
    return failf(Errc::kUnavailable, "frame lock: cannot make the {} socket: {}", what, zmq_strerror(zmq_errno()));
  const int linger = 0;  // closing never waits for peers that are gone
  zmq_setsockopt(s.get(), ZMQ_LINGER, &linger, sizeof linger);
  const int hwm = 256;  // a few seconds of frames; beyond that a slow peer loses the oldest
  zmq_setsockopt(s.get(), ZMQ_SNDHWM, &hwm, sizeof hwm);
  zmq_setsockopt(s.get(), ZMQ_RCVHWM, &hwm, sizeof hwm);
  return s;
}

std::string endpoint(std::string_view host, int port) {
  // An IPv6 literal goes in brackets (ZeroMQ's tcp://[::1]:port).
  if (host.find(':') != std::string_view::npos) return fmt::format("tcp://[{}]:{}", host, port);
  return fmt::format("tcp://{}:{}", host, port);
}

/// The group's CURVE key pairs (Curve25519), derived from its shared secret.
struct LockKeys {
  using Key = std::array<unsigned char, 32>;
  Key leaderPublic{};
  Key leaderSecret{};
  Key followerPublic{};
  Key followerSecret{};
};

/// Derives both key pairs from the secret: a BLAKE2b hash of it, then one BLAKE2b keyed by that
/// hash per role (the role's name as the message) gives the secret key, and X25519's base point
/// multiplication its public key. Every node derives the same pairs from the same file.
Result<LockKeys> deriveKeys(std::string_view secret) {
  if (sodium_init() < 0) return fail(Errc::kUnavailable, "frame lock: libsodium does not start");
  static_assert(crypto_generichash_BYTES == 32 && crypto_scalarmult_BYTES == 32);
  LockKeys::Key master{};
  crypto_generichash(master.data(), master.size(), reinterpret_cast<const unsigned char*>(secret.data()), secret.size(),
                     nullptr, 0);
  LockKeys keys;
  const auto derive = [&master](std::string_view role, LockKeys::Key& secretKey, LockKeys::Key& publicKey) {
    crypto_generichash(secretKey.data(), secretKey.size(), reinterpret_cast<const unsigned char*>(role.data()),
                       role.size(), master.data(), master.size());
    return crypto_scalarmult_base(publicKey.data(), secretKey.data()) == 0;
  };
  const bool ok = derive("basalt frame lock v1: leader", keys.leaderSecret, keys.leaderPublic) &&
                  derive("basalt frame lock v1: follower", keys.followerSecret, keys.followerPublic);
  sodium_memzero(master.data(), master.size());
  if (!ok) return fail(Errc::kInternal, "frame lock: a derived key is not a usable Curve25519 key");
  return keys;
}

/// Makes `socket` a CURVE server (the leader's) or client (a follower's) of the group.
Result<void> secure(void* socket, bool server, const LockKeys& keys) {
  const auto set = [socket](int option, const void* value, std::size_t size) {
    return zmq_setsockopt(socket, option, value, size) == 0;
  };
  const int on = 1;
  constexpr std::string_view kDomain = "basalt-lock";
  const bool ok = server ? set(ZMQ_CURVE_SERVER, &on, sizeof on) &&
                               set(ZMQ_CURVE_SECRETKEY, keys.leaderSecret.data(), keys.leaderSecret.size()) &&
                               set(ZMQ_ZAP_DOMAIN, kDomain.data(), kDomain.size())
                         : set(ZMQ_CURVE_SERVERKEY, keys.leaderPublic.data(), keys.leaderPublic.size()) &&
                               set(ZMQ_CURVE_PUBLICKEY, keys.followerPublic.data(), keys.followerPublic.size()) &&
                               set(ZMQ_CURVE_SECRETKEY, keys.followerSecret.data(), keys.followerSecret.size());
  if (!ok) {
    return failf(Errc::kUnsupported, "frame lock: cannot use CURVE security: {} (is libzmq built with libsodium?)",
                 zmq_strerror(zmq_errno()));
  }
  return {};
}

/// One frame of a multi-part message, read whole whatever its size.
class ZmqMessage {
 public:
  ZmqMessage() { zmq_msg_init(&msg_); }
  ~ZmqMessage() { zmq_msg_close(&msg_); }
  ZmqMessage(const ZmqMessage&) = delete;
  ZmqMessage& operator=(const ZmqMessage&) = delete;
  ZmqMessage(ZmqMessage&&) = delete;
  ZmqMessage& operator=(ZmqMessage&&) = delete;
  bool receive(void* socket, int flags) { return zmq_msg_recv(&msg_, socket, flags) >= 0; }
  [[nodiscard]] std::string_view text() const {
    return {static_cast<const char*>(zmq_msg_data(&msg_)), zmq_msg_size(&msg_)};
  }
  [[nodiscard]] bool more() const { return zmq_msg_more(&msg_) != 0; }

 private:
  mutable zmq_msg_t msg_{};  // zmq_msg_data and zmq_msg_more take a non-const message and do not change it
};

/// A fixed ring of samples in milliseconds (no allocation per frame), medians on demand.
class Samples {
 public:
  void add(double ms) {
    ring_[next_ % ring_.size()] = ms;
    ++next_;
    max_ = std::max(max_, ms);
  }
  [[nodiscard]] double median() const {
    const std::size_t n = std::min<std::size_t>(next_, ring_.size());
    if (n == 0) return 0;
    std::vector<double> copy(ring_.begin(), ring_.begin() + static_cast<std::ptrdiff_t>(n));
    std::nth_element(copy.begin(), copy.begin() + static_cast<std::ptrdiff_t>(n / 2), copy.end());
    return copy[n / 2];
  }
  [[nodiscard]] double max() const { return max_; }

 private:
  std::array<double, 600> ring_{};
  std::size_t next_ = 0;
  double max_ = 0;
};

double millis(Nanos t) { return std::chrono::duration<double, std::milli>(t).count(); }

struct Follower {
  std::int64_t lastReady = -2;
  std::int64_t missed = 0;
  bool inBarrier = true;
  std::int64_t clockOffsetNs = 0;
  std::int64_t skipped = 0;
};

}  // namespace

struct FrameLock::Impl {
  LockSpec spec;
  const Clock& clock;
  runtime::Show& show;
  const LockClockProbe* probe = nullptr;
  std::function<void(const FrameLockFigures&)> publish;
  LockedDirector* director = nullptr;
  std::vector<LockedMovies*> movies;             // borrowed (addMovies): a script's VCR, --movie streams
  std::optional<LockedProgramme> lastProgramme;  // the programme last sent (leader) or followed (follower)
  Nanos lostAt{-1};                              // wall time the leader was reported lost
  Nanos lastPublished{-1};
  bool publishNow = false;
  SystemClock ownClock;
  const Clock* shared = &ownClock;  // the clock every node reads alike (send and receive times)
  ZmqContext context;
  ZmqSocket pub;                       // leader: PUB; follower: SUB
  ZmqSocket answers;                   // leader: ROUTER; follower: DEALER
  std::optional<LockKeys> keys;        // the group's (lock.key_file); none: unauthenticated
  ZmqSocket zap;                       // leader with a key: the ZAP handler (REP) admitting followers
  std::array<ZmqSocket, 2> monitors;   // PAIR: handshake failures of `pub` and `answers`
  std::array<bool, 6> reasonLogged{};  // a refusal's reason logged once (LockRejections' order)
  std::int64_t sentFrame = -1;         // leader: the newest frame published
  bool sequenceReported = false;       // an out-of-sequence burst is logged once
  bool fullReported = false;           // refused followers are logged once per burst
  LockBuffer buffer{};
  FrameLockFigures figures;
  Samples barrierWait;
  Samples delay;
  // Leader.
  std::map<std::string, Follower, std::less<>> followers;
  std::optional<std::pair<std::uint32_t, std::uint32_t>> announced;  // (epoch, newest) of the last frame
  std::uint32_t session = drawSession();  // this run, in every frame (a follower sees a restart by it)
  // Follower.
  std::optional<FrameMessage> pending;  // the newest frame received and not drawn yet
  std::int64_t current = -1;            // the frame being drawn
  std::int64_t newestFrame = -1;        // the newest frame accepted from the leader
  bool jumpReported = false;            // a burst of refused frame jumps is logged once
  std::int64_t newestPresented = -1;
  Nanos lastHeard{-1};
  bool byeSeen = false;
  bool joined = false;
  bool waitingReported = false;
  Nanos lastHello{-1};
  std::optional<std::uint32_t> leaderSession;  // the leader's run whose frames this node draws
  // Follower: the leader's script commands.
  std::optional<std::uint32_t> commandEpoch;          // the leader's log being followed
  std::uint32_t lastCommandRun = 0;                   // the last of its commands run on this show
  std::uint32_t commandsAnnounced = 0;                // the newest the leader announced
  std::uint32_t commandBase = 0;                      // commands up to here no longer act
  std::optional<std::uint64_t> commandsForShow;       // the director's showLoads() they were run on
  std::map<std::uint32_t, std::string> commandsHeld;  // received, not run yet (by number)
  std::uint32_t resendFrom = 0;                       // the last re-send asked, and when
  Nanos resendAt{-1};

  Impl(const LockSpec& s, const Clock& c, runtime::Show& sh) : spec(s), clock(c), show(sh) {}

  [[nodiscard]] bool isLeader() const { return spec.role == LockRole::kLeader; }

  /// A number for this run, never 0 (a frame's session 0 is one from before sessions).
  static std::uint32_t drawSession() {
    std::random_device entropy;
    std::uint32_t n = 0;
    while (n == 0) n = entropy();
    return n;
  }

  void send(void* socket, std::size_t n) {
    // Never blocks: a peer whose queue is full loses the message (PUB drops; DEALER with no
    // connection yet returns EAGAIN), which the protocol survives.
    (void)zmq_send(socket, buffer.data(), n, ZMQ_DONTWAIT);
  }

  // ---- Security: both roles ----

  /// Counts a refusal and logs the first of each reason.
  void refuse(std::int64_t LockRejections::* counter, std::size_t reason, std::string_view why) {
    ++(figures.rejected.*counter);
    if (reason < reasonLogged.size() && !std::exchange(reasonLogged.at(reason), true)) {
      log::warn(kLogLock, "{} (refused and counted; /metrics basalt_lock_messages_rejected_total)", why);
    }
  }

  /// Watches `socket`'s handshakes on a PAIR socket: the ones that fail are counted by reason.
  Result<void> watch(std::size_t index, void* socket) {
    const std::string at = fmt::format("inproc://basalt-lock-monitor-{}", index);
    if (zmq_socket_monitor(socket, at.c_str(),
                           ZMQ_EVENT_HANDSHAKE_FAILED_NO_DETAIL | ZMQ_EVENT_HANDSHAKE_FAILED_PROTOCOL |
                               ZMQ_EVENT_HANDSHAKE_FAILED_AUTH) != 0) {
      return failf(Errc::kUnavailable, "frame lock: cannot watch the handshakes: {}", zmq_strerror(zmq_errno()));
    }
    ZmqSocket pair(zmq_socket(context.get(), ZMQ_PAIR));
    const int linger = 0;
    if (pair) zmq_setsockopt(pair.get(), ZMQ_LINGER, &linger, sizeof linger);
    if (!pair || zmq_connect(pair.get(), at.c_str()) != 0) {
      return failf(Errc::kUnavailable, "frame lock: cannot watch the handshakes: {}", zmq_strerror(zmq_errno()));
    }
    monitors.at(index) = std::move(pair);
    return {};
  }

  /// Counts the handshakes that failed since the last call: none of those peers reached the lock.
  void takeHandshakeFailures() {
    for (const ZmqSocket& monitor : monitors) {
      if (!monitor) continue;
      for (;;) {
        ZmqMessage event;
        if (!event.receive(monitor.get(), ZMQ_DONTWAIT)) break;
        ZmqMessage address;  // the second part always follows the first
        (void)address.receive(monitor.get(), 0);
        const std::string_view head = event.text();
        if (head.size() < 6) continue;
        std::uint16_t kind = 0;
        std::uint32_t value = 0;
        std::memcpy(&kind, head.data(), sizeof kind);
        std::memcpy(&value, head.data() + 2, sizeof value);
        const std::string_view peer = address.text();
        if (kind == ZMQ_EVENT_HANDSHAKE_FAILED_PROTOCOL && value == ZMQ_PROTOCOL_ERROR_ZMTP_MECHANISM_MISMATCH) {
          refuse(&LockRejections::noKey, 0,
                 fmt::format("frame lock: a peer on {} speaks {} the group's key", peer,
                             keys ? "without" : "with a key, but this node has no lock.key_file; it is not"));
        } else if ((kind == ZMQ_EVENT_HANDSHAKE_FAILED_PROTOCOL && value == ZMQ_PROTOCOL_ERROR_ZMTP_CRYPTOGRAPHIC) ||
                   kind == ZMQ_EVENT_HANDSHAKE_FAILED_AUTH) {
          refuse(&LockRejections::wrongKey, 1,
                 fmt::format("frame lock: a peer on {} did not prove the group's key (another key_file, or a "
                             "replayed capture)",
                             peer));
        } else {
          refuse(&LockRejections::handshake, 2,
                 fmt::format("frame lock: a handshake on {} broke off (not a frame-lock peer, or cut short; "
                             "ZeroMQ event {:#x}, {:#x})",
                             peer, kind, value));
        }
      }
    }
  }

  /// Leader: answers the ZAP requests waiting (RFC 27): a CURVE client with the group's
  /// follower key is admitted, any other refused (the monitor counts the refusal).
  void serveZap() {
    if (!zap) return;
    for (;;) {
      std::array<std::string, 7> part;
      std::size_t parts = 0;
      bool more = true;
      while (more) {
        ZmqMessage m;
        if (!m.receive(zap.get(), parts == 0 ? ZMQ_DONTWAIT : 0)) return;
        if (parts < part.size()) part.at(parts) = std::string(m.text());
        ++parts;
        more = m.more();
      }
      const std::string_view want(reinterpret_cast<const char*>(keys->followerPublic.data()),
                                  keys->followerPublic.size());
      const bool ok = parts >= 7 && part[0] == "1.0" && part[5] == "CURVE" && part[6] == want;
      const std::array<std::string_view, 6> reply{
          "1.0", part[1], ok ? "200" : "400", ok ? "OK" : "not the frame-lock group's key", "", ""};
      for (std::size_t i = 0; i < reply.size(); ++i) {
        (void)zmq_send(zap.get(), reply.at(i).data(), reply.at(i).size(), i + 1 < reply.size() ? ZMQ_SNDMORE : 0);
      }
    }
  }

  /// Everything a leader's wait serves: answers, ZAP requests and handshake failures.
  void pollLeader(long ms) {
    std::array<zmq_pollitem_t, 2> items{zmq_pollitem_t{answers.get(), 0, ZMQ_POLLIN, 0},
                                        zmq_pollitem_t{zap.get(), 0, ZMQ_POLLIN, 0}};
    (void)zmq_poll(items.data(), zap ? 2 : 1, ms);
  }

  // ---- Leader ----

  /// Reads every answer waiting; returns true when one for `frame` completed the barrier.
  void takeAnswers(std::int64_t presenting) {
    serveZap();
    takeHandshakeFailures();
    for (;;) {
      std::array<char, 64> id{};
      const int idBytes = zmq_recv(answers.get(), id.data(), id.size(), ZMQ_DONTWAIT);
      if (idBytes < 0) return;
      int more = 0;
      std::size_t moreSize = sizeof more;
      zmq_getsockopt(answers.get(), ZMQ_RCVMORE, &more, &moreSize);
      if (!more) {
        ++figures.malformed;
        continue;
      }
      std::array<std::byte, kMaxLockMessageBytes + 1> bytes{};
      const int n = zmq_recv(answers.get(), bytes.data(), bytes.size(), ZMQ_DONTWAIT);
      if (n < 0) continue;
      // Drop any further parts of a message with more than two.
      zmq_getsockopt(answers.get(), ZMQ_RCVMORE, &more, &moreSize);
      while (more) {
        std::array<char, 16> rest{};
        (void)zmq_recv(answers.get(), rest.data(), rest.size(), ZMQ_DONTWAIT);
        zmq_getsockopt(answers.get(), ZMQ_RCVMORE, &more, &moreSize);
        ++figures.malformed;
      }
      const auto size = std::min<std::size_t>(static_cast<std::size_t>(n), bytes.size());
      const std::span<const std::byte> message(bytes.data(), size);
      if (auto kind = peekKind(message); kind && *kind == LockMessageKind::kResend) {
        auto resend = decodeResend(message);
        if (!resend) {
          if (figures.malformed++ == 0) log::warn(kLogLock, "{}", resend.error().message());
          continue;
        }
        const std::string_view from(id.data(), std::min(static_cast<std::size_t>(idBytes), id.size()));
        if (!followers.contains(from)) {
          refuse(&LockRejections::outOfSequence, 4,
                 fmt::format("frame lock: a 'resend' from '{}', which is not an admitted follower", from));
          continue;
        }
        resendCommands(from, *resend);
        continue;
      }
      auto ready = decodeReady(message);
      if (!ready) {
        if (figures.malformed++ == 0) log::warn(kLogLock, "{}", ready.error().message());
        continue;
      }
      if (ready->frame > sentFrame) {
        // A follower cannot have drawn a frame this leader has not sent: taking it would let
        // the barrier go on without it.
        ++figures.rejected.outOfSequence;
        if (!std::exchange(sequenceReported, true)) {
          log::warn(kLogLock,
                    "frame lock: follower '{}' says it drew frame {}, but the newest frame sent is {}; "
                    "refused (counted as out_of_sequence)",
                    ready->nodeName(), ready->frame, sentFrame);
        }
        continue;
      }
      sequenceReported = false;
      const std::string name = ready->nodeName();
      if (!followers.contains(name) && std::cmp_greater_equal(followers.size(), spec.maxFollowers)) {
        ++figures.rejected.followersFull;
        if (!std::exchange(fullReported, true)) {
          log::warn(kLogLock, "frame lock: follower '{}' refused: this leader admits {} followers (lock.max_followers)",
                    name, spec.maxFollowers);
        }
        continue;
      }
      auto [it, isNew] = followers.try_emplace(name);
      if (isNew) fullReported = false;
      Follower& f = it->second;
      if (isNew) {
        log::info(kLogLock, "follower '{}' joined at frame {}", name, ready->frame);
        ++figures.followersKnown;
      } else if (!f.inBarrier) {
        log::info(kLogLock, "follower '{}' is back in the barrier at frame {}", name, ready->frame);
        ++figures.followersRejoined;
      }
      f.inBarrier = true;
      f.missed = 0;
      f.clockOffsetNs = ready->clockOffsetNs;
      f.skipped = ready->skipped;
      if (ready->frame >= 0 && ready->frame < presenting) ++figures.lateAnswers;
      f.lastReady = std::max(f.lastReady, ready->frame);
      figures.maxClockOffsetUs = std::max(figures.maxClockOffsetUs, std::abs(ready->clockOffsetNs) / 1000);
    }
  }

  [[nodiscard]] bool allReady(std::int64_t frame) const {
    return std::all_of(followers.begin(), followers.end(),
                       [frame](const auto& f) { return !f.second.inBarrier || f.second.lastReady >= frame; });
  }

  void publishFrame(const FrameContext& frame) {
    FrameMessage m;
    m.frame = frame.frame;
    m.showTimeNs = frame.time.count();
    m.sentNs = shared->now().count();
    m.state = captureLockedState(show);
    if (director) {
      m.programme = director->lockedProgramme();
      m.programme.present = true;
      m.movies = director->lockedMovieFrames();
      noteProgramme(m.frame, m.programme, "sends");
      if (const LockCommandLog* commands = director->commandLog()) announceCommands(*commands, m.command);
    }
    // The run's other movies write their own slots (after the director's: theirs win).
    for (const LockedMovies* other : movies) other->lockedMovieFrames(m.movies);
    m.session = session;
    sentFrame = m.frame;
    send(pub.get(), encode(m, buffer));
  }

  /// The frame announces the newest command, with its text when it is new in this frame and
  /// fits; a follower without it asks for it (resendCommands).
  void announceCommands(const LockCommandLog& commands, LockedCommand& c) {
    c.epoch = commands.epoch();
    c.newest = commands.newest();
    c.base = commands.base();
    const std::pair<std::uint32_t, std::uint32_t> now{c.epoch, c.newest};
    const bool isNew = c.newest > 0 && (!announced || *announced != now);
    if (announced && announced->first == c.epoch && c.newest > announced->second)
      figures.commandsApplied += c.newest - announced->second;
    else if (c.newest > 0 && (!announced || announced->first != c.epoch))
      figures.commandsApplied += c.newest;
    announced = now;
    const std::string* text = isNew ? commands.at(c.newest) : nullptr;
    if (text && text->size() <= kFrameCommandBytes) {
      c.carried = true;
      c.text = *text;
    }
  }

  /// Sends the follower `id` the commands it asked for, a batch at a time (it asks again for
  /// the rest once it has them), directly over ROUTER; never blocks.
  void resendCommands(std::string_view id, const ResendMessage& ask) {
    const LockCommandLog* commands = director ? director->commandLog() : nullptr;
    // Another epoch: the follower asks for a log this leader's reload ended; the next frame
    // tells it the new one.
    if (!commands || ask.epoch != commands->epoch() || ask.from > commands->newest()) return;
    constexpr std::uint32_t kBatch = 64;  // well under the sockets' high-water mark of 256
    CommandMessage m;
    m.epoch = commands->epoch();
    m.seq = ask.from;
    if (ask.from < commands->oldest()) {
      log::warn(kLogLock,
                "follower '{}' asks for command {}, but this leader keeps only its last {} commands (from {} on): "
                "it misses {}; reload the show on the leader (POST /control/reload) to bring every node to the "
                "same state",
                id, ask.from, LockCommandLog::kKept, commands->oldest(), commands->oldest() - ask.from);
      m.seq = commands->oldest();
      m.earlierGone = true;
    }
    const std::uint32_t last = std::min(commands->newest(), m.seq + kBatch - 1);
    for (; m.seq <= last; ++m.seq) {
      const std::string* text = commands->at(m.seq);
      if (!text) break;
      m.text = *text;
      const std::size_t n = encode(m, buffer);
      if (zmq_send(answers.get(), id.data(), id.size(), ZMQ_SNDMORE | ZMQ_DONTWAIT) < 0) break;
      (void)zmq_send(answers.get(), buffer.data(), n, ZMQ_DONTWAIT);
      ++figures.commandsResent;
      m.earlierGone = false;
    }
  }

  /// Counts and logs a change of programme (item, mode, display, start or media start).
  void noteProgramme(std::int64_t frame, const LockedProgramme& p, std::string_view verb) {
    if (lastProgramme && *lastProgramme == p) return;
    const bool first = !lastProgramme;
    lastProgramme = p;
    if (first) return;
    ++figures.programmeChanges;
    log::info(kLogLock, "frame {}: {} the programme: {} item {} '{}' since show time {:.3f} s (media from {:.3f} s)",
              frame, verb,
              p.mode == 0   ? "closed"
              : p.mode == 1 ? "attract"
                            : "active",
              p.index + 1, p.itemName(), toSeconds(Nanos{p.itemStartNs}), toSeconds(Nanos{p.mediaStartNs}));
  }

  void barrier(std::int64_t frame) {
    const SystemClock wall;
    const Nanos start = wall.now();
    const Nanos deadline = start + std::chrono::milliseconds(spec.timeoutMs);
    takeAnswers(frame);
    while (!allReady(frame)) {
      const Nanos left = deadline - wall.now();
      if (left <= Nanos{0}) break;
      const auto ms = std::max<long>(1, static_cast<long>(std::chrono::ceil<std::chrono::milliseconds>(left).count()));
      pollLeader(ms);
      takeAnswers(frame);
    }
    barrierWait.add(millis(wall.now() - start));
    bool complete = true;
    for (auto& [name, f] : followers) {
      if (!f.inBarrier || f.lastReady >= frame) continue;
      complete = false;
      if (++f.missed >= spec.dropAfter) {
        f.inBarrier = false;
        ++figures.followersDropped;
        log::warn(kLogLock, "follower '{}' left the barrier: no answer for {} frames (last frame {}); the others go on",
                  name, f.missed, f.lastReady);
      }
    }
    if (!complete) ++figures.barrierTimeouts;
    PresentMessage present{frame};
    send(pub.get(), encode(present, buffer));
  }

  // ---- Follower ----

  void sayReady(std::int64_t frame) {
    ReadyMessage m;
    m.frame = frame;
    m.skipped = figures.skipped;
    m.clockOffsetNs = probe ? probe->offset().count() : 0;
    m.setNodeName(spec.node);
    figures.clockOffsetUs = m.clockOffsetNs / 1000;
    figures.maxClockOffsetUsSeen = std::max(figures.maxClockOffsetUsSeen, std::abs(figures.clockOffsetUs));
    send(answers.get(), encode(m, buffer));
  }

  /// Reads everything the leader sent; returns the newest "present" number seen (or -1).
  std::int64_t takeLeaderMessages() {
    takeHandshakeFailures();
    std::int64_t presented = -1;
    for (;;) {
      std::array<std::byte, kMaxLockMessageBytes + 1> bytes{};
      const int n = zmq_recv(pub.get(), bytes.data(), bytes.size(), ZMQ_DONTWAIT);
      if (n < 0) break;
      const std::span<const std::byte> message(bytes.data(),
                                               std::min<std::size_t>(static_cast<std::size_t>(n), bytes.size()));
      auto kind = peekKind(message);
      if (!kind) {
        if (figures.malformed++ == 0) log::warn(kLogLock, "{}", kind.error().message());
        continue;
      }
      switch (*kind) {
        case LockMessageKind::kFrame:
          if (auto f = decodeFrame(message)) {
            if (newestFrame >= 0 && f->frame > newestFrame + spec.maxFrameJump) {
              // Refused, and not heard: a leader that only sends such frames is lost after
              // leader_timeout_ms, and its frames are taken from their new numbers when it is back.
              ++figures.rejected.frameJump;
              if (!std::exchange(jumpReported, true)) {
                log::warn(kLogLock,
                          "frame lock: frame {} is {} frames past the newest ({}), more than lock.max_frame_jump "
                          "({}); refused until the leader is heard again",
                          f->frame, f->frame - newestFrame, newestFrame, spec.maxFrameJump);
              }
              break;
            }
            heard();
            jumpReported = false;
            newestFrame = std::max(newestFrame, f->frame);
            delay.add(millis(shared->now() - Nanos{f->sentNs}));
            // A newer frame replaces one not drawn yet: nextFrame() counts the gap as skipped.
            if (f->frame > current && (!pending || f->frame > pending->frame)) {
              if (pending) keepCommand(pending->command);
              pending = *f;
            }
          } else {
            heard();
            ++figures.malformed;
          }
          break;
        case LockMessageKind::kPresent: {
          auto p = decodePresent(message);
          if (p && newestFrame >= 0 && p->frame > newestFrame) {
            // The leader presents only frames it sent before, on this socket, in order.
            refuse(&LockRejections::outOfSequence, 4,
                   fmt::format("frame lock: 'present {}' before that frame (newest {})", p->frame, newestFrame));
            break;
          }
          // A present, the join beacon (present -1, which does not decode), or a present heard
          // before any frame (joined between a frame and its present: not ours to present).
          heard();
          if (p && newestFrame >= 0) {
            presented = std::max(presented, p->frame);
            newestPresented = std::max(newestPresented, p->frame);
          }
          break;
        }
        case LockMessageKind::kBye:
          heard();
          byeSeen = true;
          break;
        case LockMessageKind::kReady:
        case LockMessageKind::kResend:
        case LockMessageKind::kCommand:
          heard();
          ++figures.malformed;  // followers do not talk to each other; commands come on DEALER
          break;
      }
    }
    return presented;
  }

  void heard() {
    const SystemClock wall;
    lastHeard = wall.now();
    if (!figures.leaderPresent) {
      if (figures.leaderLost > 0) {
        // A restarted leader counts from its own start: take its frames from here on.
        log::info(kLogLock, "the leader is back after {:.1f} s; following its frames again",
                  toSeconds(wall.now() - lostAt));
        ++figures.leaderReturned;
        current = -1;
        newestFrame = -1;
        newestPresented = -1;
        publishNow = true;
      }
      figures.leaderPresent = true;
      figures.holding = false;
      figures.holdingSeconds = 0;
      figures.heldFrame = -1;
    }
  }

  void checkLeader() {
    const SystemClock wall;
    const Nanos now = wall.now();
    if (lastHeard.count() < 0) lastHeard = now;  // counting from the start
    if (!figures.leaderPresent && figures.leaderLost == 0 && !waitingReported &&
        now - lastHeard > std::chrono::milliseconds(spec.leaderTimeoutMs)) {
      waitingReported = true;
      log::warn(kLogLock, "no leader at {} port {} yet; waiting for it", spec.leader, spec.port);
    }
    if (figures.leaderPresent && now - lastHeard > std::chrono::milliseconds(spec.leaderTimeoutMs)) {
      figures.leaderPresent = false;
      figures.holding = true;
      figures.heldFrame = current;
      lostAt = now;
      ++figures.leaderLost;
      joined = false;     // say hello again, so that a restarted leader counts this follower
      publishNow = true;  // the status page says so while the picture holds
      log::warn(kLogLock, "the leader at {} is lost: nothing for {} ms; holding frame {} until it is back", spec.leader,
                spec.leaderTimeoutMs, current);
    }
    if (figures.holding) figures.holdingSeconds = toSeconds(now - lostAt);
    // Until the first frame, say hello every 100 ms: the leader counts who is here before it
    // starts, and knows our SUB socket is connected once we heard its beacon.
    if (!joined && figures.leaderPresent &&
        (lastHello.count() < 0 || now - lastHello > std::chrono::milliseconds(100))) {
      lastHello = now;
      sayReady(-1);
    }
  }

  Result<std::optional<GatedFrame>> nextFrame(runtime::EventLoop& loop, Nanos patience) {
    const SystemClock wall;
    const Nanos deadline = wall.now() + patience;
    for (;;) {
      (void)takeLeaderMessages();
      checkLeader();
      if (byeSeen && !pending) return GatedFrame{current, Nanos{0}, true};
      if (pending) {
        const FrameMessage& f = *pending;
        if (current >= 0 && f.frame > current + 1) figures.skipped += f.frame - current - 1;
        current = f.frame;
        joined = true;
        noteSession(f);
        // The leader's programme before any participant runs: the director plays the item the
        // leader plays in this very frame.
        if (director && f.programme.present) {
          if (director->followProgramme(f.programme, Nanos{f.showTimeNs}))
            noteProgramme(f.frame, f.programme, "follows");
          // The movie frames the leader shows in this frame: the follower's movies show them
          // (the director's, less the slots the run's other movies use).
          director->followMovieFrames(directorMovies(f.movies));
        }
        for (LockedMovies* other : movies) other->followMovieFrames(f.movies);
        // Then the leader's script commands, in order: those it ran in this frame act in it on
        // every node (after the programme, which may have reset the show, as on the leader).
        if (director && f.programme.present) {
          noteCommands(f.command);
          takeResentCommands();
          runCommands(f.frame);
        }
        return GatedFrame{f.frame, Nanos{f.showTimeNs}, false};
      }
      const Nanos left = deadline - wall.now();
      if (left <= Nanos{0}) return std::optional<GatedFrame>{};
      // Poll the SUB socket in short slices and serve the event loop between them (signals,
      // wake-ups), so a follower waiting for its leader still stops when told to.
      zmq_pollitem_t item{pub.get(), 0, ZMQ_POLLIN, 0};
      (void)zmq_poll(&item, 1, std::min<long>(5, std::max<long>(1, static_cast<long>(left.count() / 1'000'000))));
      if (auto r = loop.dispatch(Nanos{0}); !r) return std::unexpected(r.error());
    }
  }

  /// A frame from another run of the leader than the last: the leader restarted. Its show is
  /// new, and the commands run on the old one are gone with it: the director loads this node's
  /// show again (it then takes the new leader's commands from the first).
  void noteSession(const FrameMessage& f) {
    if (leaderSession && *leaderSession != f.session) {
      log::warn(kLogLock, "frame {}: the leader restarted; this node loads its show again to start where it starts",
                f.frame);
      ++figures.leaderRestarts;
      commandEpoch.reset();
      lastCommandRun = 0;
      commandsHeld.clear();
      resendFrom = 0;
      if (director) director->leaderRestarted();
    }
    leaderSession = f.session;
  }

  /// What a frame says of the leader's commands: a new log (the leader reloaded), the newest
  /// number, and the newest's text when it came in this frame.
  void noteCommands(const LockedCommand& c) {
    if (!commandEpoch || *commandEpoch != c.epoch) {
      if (commandEpoch) {
        log::info(kLogLock, "the leader's command log starts again (its show was reloaded, reload {})", c.epoch);
      }
      commandEpoch = c.epoch;
      lastCommandRun = 0;
      commandsHeld.clear();
      resendFrom = 0;
    } else if (c.newest < lastCommandRun) {
      log::warn(kLogLock,
                "the leader's command log starts again at {} though this node ran {} of its commands (a restarted "
                "leader?); this node's show keeps them: reload the show on the leader (POST /control/reload) to "
                "bring every node to the same state",
                c.newest, lastCommandRun);
      lastCommandRun = 0;
      commandsHeld.clear();
      resendFrom = 0;
    }
    commandsAnnounced = c.newest;
    commandBase = c.base;
    if (c.carried && c.newest > lastCommandRun) commandsHeld.insert_or_assign(c.newest, c.text);
  }

  /// The command a frame passed over carried, so that it need not be asked for again.
  void keepCommand(const LockedCommand& c) {
    if (c.carried && commandEpoch && c.epoch == *commandEpoch && c.newest > lastCommandRun)
      commandsHeld.insert_or_assign(c.newest, c.text);
  }

  /// Commands the leader re-sent on the DEALER socket (this follower asked for them).
  void takeResentCommands() {
    for (;;) {
      std::array<std::byte, kMaxLockMessageBytes + 1> bytes{};
      const int n = zmq_recv(answers.get(), bytes.data(), bytes.size(), ZMQ_DONTWAIT);
      if (n < 0) return;
      const auto size = std::min<std::size_t>(static_cast<std::size_t>(n), bytes.size());
      auto m = decodeCommand(std::span<const std::byte>(bytes.data(), size));
      if (!m) {
        if (figures.malformed++ == 0) log::warn(kLogLock, "{}", m.error().message());
        continue;
      }
      if (!commandEpoch || m->epoch != *commandEpoch) continue;  // for a log the leader has ended
      if (m->seq > commandsAnnounced) {
        refuse(
            &LockRejections::outOfSequence, 4,
            fmt::format("frame lock: command {} re-sent, but the leader announced only {}", m->seq, commandsAnnounced));
        continue;
      }
      ++figures.commandsResent;
      if (m->earlierGone && m->seq > lastCommandRun + 1 && m->seq - 1 > commandBase) {
        const std::uint32_t from = std::max(lastCommandRun, commandBase) + 1;
        figures.commandsLost += m->seq - from;
        log::warn(kLogLock,
                  "the leader's commands {}..{} are gone from its log: this node's show misses them; reload the "
                  "show on the leader (POST /control/reload) to bring every node to the same state",
                  from, m->seq - 1);
        lastCommandRun = m->seq - 1;
      }
      if (m->seq > lastCommandRun) commandsHeld.insert_or_assign(m->seq, std::move(m->text));
    }
  }

  /// Runs the commands held in order, from the one after the last run; asks the leader for
  /// those missing.
  void runCommands(std::int64_t frame) {
    if (!commandEpoch) return;
    const std::uint64_t loads = director->showLoads();
    if (commandsForShow && *commandsForShow != loads) {
      // This node's show was (re)loaded: what ran on the old one went with it.
      lastCommandRun = 0;
      resendFrom = 0;
    }
    commandsForShow = loads;
    if (director->loadingShow()) return;  // they run on the show being loaded, once it is on
    // Commands before the leader's last show reset no longer act there; this node's show was
    // reset at the same point (the programme it follows).
    lastCommandRun = std::max(lastCommandRun, std::min(commandBase, commandsAnnounced));
    for (auto it = commandsHeld.begin(); it != commandsHeld.end();) {
      if (it->first <= lastCommandRun) {
        it = commandsHeld.erase(it);
        continue;
      }
      if (it->first != lastCommandRun + 1) break;
      auto out = director->runLeaderCommand(it->second);
      if (out) {
        log::info(kLogLock, "frame {}: runs the leader's command {}: {}", frame, it->first, it->second);
      } else {
        log::warn(kLogLock, "frame {}: the leader's command {} '{}' failed on this node: {}", frame, it->first,
                  it->second, out.error().describe());
      }
      ++figures.commandsApplied;
      lastCommandRun = it->first;
      it = commandsHeld.erase(it);
    }
    if (lastCommandRun < commandsAnnounced) askForCommands();
  }

  /// Asks the leader for its commands after the last run here: at once for a new gap, again
  /// after 250 ms without an answer. Never blocks.
  void askForCommands() {
    const std::uint32_t from = lastCommandRun + 1;
    const SystemClock wall;
    const Nanos now = wall.now();
    if (from == resendFrom && now - resendAt < std::chrono::milliseconds(250)) return;
    resendFrom = from;
    resendAt = now;
    log::debug(kLogLock, "asks the leader for its commands {}..{}", from, commandsAnnounced);
    send(answers.get(), encode(ResendMessage{*commandEpoch, from}, buffer));
  }

  /// The leader's movie frames without the slots the run's other movies use (-1 there), which
  /// the director must not take for its own movies.
  [[nodiscard]] LockedMovieFrames directorMovies(const LockedMovieFrames& frames) const {
    if (movies.empty()) return frames;
    constexpr std::int32_t kUnused = -2;  // no movie writes it: a slot still holding it is free
    LockedMovieFrames used{kUnused, {kUnused, kUnused, kUnused, kUnused}};
    for (const LockedMovies* other : movies) other->lockedMovieFrames(used);
    LockedMovieFrames mine = frames;
    if (used.item != kUnused) mine.item = -1;
    for (std::size_t i = 0; i < mine.textures.size(); ++i) {
      if (used.textures[i] != kUnused) mine.textures[i] = -1;
    }
    return mine;
  }

  void beforeDrawFollower() {
    // The movies were drawn before this (the lock is the last participant).
    LockedMovieCounts counts;
    if (director) counts = director->movieFrameCounts();
    for (const LockedMovies* other : movies) {
      const LockedMovieCounts c = other->movieFrameCounts();
      counts.corrected += c.corrected;
      counts.late += c.late;
    }
    figures.movieFramesCorrected = counts.corrected;
    figures.movieFramesLate = counts.late;
    if (!pending) return;
    applyLockedState(pending->state, show);
    pending.reset();
  }

  void afterDrawFollower(std::int64_t frame) {
    sayReady(frame);
    ++figures.framesDrawn;
    if (figures.firstFrame < 0) figures.firstFrame = frame;
    figures.lastFrame = frame;
    // FNV-1a over the frame numbers in order: two nodes that drew the same frames agree.
    std::uint64_t h = figures.frameChecksum == 0 ? 1469598103934665603ULL : figures.frameChecksum;
    for (int i = 0; i < 8; ++i) {
      h ^= static_cast<std::uint64_t>(frame >> (8 * i)) & 0xffU;
      h *= 1099511628211ULL;
    }
    figures.frameChecksum = h;
    const SystemClock wall;
    const Nanos deadline = wall.now() + std::chrono::milliseconds(spec.leaderTimeoutMs);
    for (;;) {
      const std::int64_t presented = takeLeaderMessages();
      if (presented >= frame) break;
      if (byeSeen || (pending && pending->frame > frame)) {
        // The leader went on without our answer (it was late, or its "present" is lost).
        ++figures.presentsMissed;
        break;
      }
      const Nanos left = deadline - wall.now();
      if (left <= Nanos{0}) {
        ++figures.presentsMissed;
        break;
      }
      zmq_pollitem_t item{pub.get(), 0, ZMQ_POLLIN, 0};
      (void)zmq_poll(&item, 1, std::max<long>(1, static_cast<long>(left.count() / 1'000'000)));
    }
    // Skew: the newest frame the leader presented minus the one this node presents (0 in step).
    figures.maxSkewFrames = std::max(figures.maxSkewFrames, newestPresented - frame);
  }
};

FrameLock::FrameLock(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
FrameLock::~FrameLock() = default;

Result<std::unique_ptr<FrameLock>> FrameLock::create(const LockSpec& spec, const Clock& clock, runtime::Show& show) {
  if (spec.role == LockRole::kOff) return fail(Errc::kInvalidArgument, "frame lock: the role is off");
  auto impl = std::make_unique<Impl>(spec, clock, show);
  impl->figures.leader = impl->isLeader();
  impl->figures.node = spec.node;
  impl->context.reset(zmq_ctx_new());
  if (!impl->context) return fail(Errc::kUnavailable, "frame lock: cannot start ZeroMQ");
  const bool leader = impl->isLeader();
  auto pub = makeSocket(impl->context.get(), leader ? ZMQ_PUB : ZMQ_SUB, leader ? "publishing" : "subscribing");
  if (!pub) return std::unexpected(pub.error());
  auto answers = makeSocket(impl->context.get(), leader ? ZMQ_ROUTER : ZMQ_DEALER, "answer");
  if (!answers) return std::unexpected(answers.error());
  impl->pub = std::move(*pub);
  impl->answers = std::move(*answers);
  if (!spec.keyFile.empty()) {
    auto secret = readLockKey(spec.keyFile);
    if (!secret) return failf(Errc::kPermissionDenied, "frame lock: {}", secret.error().message());
    auto keys = deriveKeys(*secret);
    sodium_memzero(secret->data(), secret->size());
    if (!keys) return std::unexpected(keys.error());
    impl->keys = *keys;
    impl->figures.authenticated = true;
    for (void* socket : {impl->pub.get(), impl->answers.get()}) {
      if (auto r = secure(socket, leader, *impl->keys); !r) return std::unexpected(r.error());
    }
    if (leader) {
      // The ZAP handler must be bound before the sockets take connections (RFC 27).
      impl->zap.reset(zmq_socket(impl->context.get(), ZMQ_REP));
      const int linger = 0;
      if (impl->zap) zmq_setsockopt(impl->zap.get(), ZMQ_LINGER, &linger, sizeof linger);
      if (!impl->zap || zmq_bind(impl->zap.get(), "inproc://zeromq.zap.01") != 0) {
        return failf(Errc::kUnavailable, "frame lock: cannot start the ZAP handler: {}", zmq_strerror(zmq_errno()));
      }
    }
  } else if (!spec.loopbackOnly()) {
    log::warn(kLogLock,
              "frame lock: unauthenticated: {} {} port {} without lock.key_file; anything that reaches the port can "
              "freeze or steer the show (give every node the same key_file)",
              leader ? "listening on" : "following the leader at", leader ? spec.listen : spec.leader, spec.port);
  }
  for (std::size_t i = 0; i < 2; ++i) {
    if (auto r = impl->watch(i, i == 0 ? impl->pub.get() : impl->answers.get()); !r) return std::unexpected(r.error());
  }
  if (leader) {
    const int handover = 1;  // a restarted follower with the same name takes its place over
    zmq_setsockopt(impl->answers.get(), ZMQ_ROUTER_HANDOVER, &handover, sizeof handover);
    for (auto [socket, port] : {std::pair{impl->pub.get(), spec.port}, std::pair{impl->answers.get(), spec.port + 1}}) {
      const std::string at = endpoint(spec.listen, port);
      if (zmq_bind(socket, at.c_str()) != 0) {
        return failf(Errc::kUnavailable, "frame lock: cannot listen on {}: {} (another leader on this node?)", at,
                     zmq_strerror(zmq_errno()));
      }
    }
  } else {
    zmq_setsockopt(impl->pub.get(), ZMQ_SUBSCRIBE, "", 0);
    zmq_setsockopt(impl->answers.get(), ZMQ_ROUTING_ID, spec.node.data(), spec.node.size());
    const int reconnect = 100;  // ms: a restarted leader is found again quickly
    zmq_setsockopt(impl->pub.get(), ZMQ_RECONNECT_IVL, &reconnect, sizeof reconnect);
    zmq_setsockopt(impl->answers.get(), ZMQ_RECONNECT_IVL, &reconnect, sizeof reconnect);
    for (auto [socket, port] : {std::pair{impl->pub.get(), spec.port}, std::pair{impl->answers.get(), spec.port + 1}}) {
      const std::string at = endpoint(spec.leader, port);
      if (zmq_connect(socket, at.c_str()) != 0) {
        return failf(Errc::kInvalidArgument, "frame lock: cannot connect to {}: {}", at, zmq_strerror(zmq_errno()));
      }
    }
  }
  return std::unique_ptr<FrameLock>(new FrameLock(std::move(impl)));
}

bool FrameLock::leader() const { return impl_->isLeader(); }

void FrameLock::setClockProbe(const LockClockProbe* probe) { impl_->probe = probe; }

void FrameLock::setSharedClock(const Clock& clock) { impl_->shared = &clock; }

void FrameLock::setPublisher(std::function<void(const FrameLockFigures&)> publish) {
  impl_->publish = std::move(publish);
}

void FrameLock::setDirector(LockedDirector* director) { impl_->director = director; }

void FrameLock::addMovies(LockedMovies& movies) { impl_->movies.push_back(&movies); }

void FrameLock::afterPresent(const FrameContext& frame) {
  (void)frame;
  Impl& d = *impl_;
  if (!d.publish) return;
  const Nanos now = d.ownClock.now();
  if (d.lastPublished.count() >= 0 && now - d.lastPublished < std::chrono::seconds(1)) return;
  d.lastPublished = now;
  d.publish(figures());
}

std::int64_t FrameLock::awaitFollowers(runtime::EventLoop& loop) {
  Impl& d = *impl_;
  const SystemClock wall;
  const Nanos deadline = wall.now() + std::chrono::milliseconds(d.spec.joinTimeoutMs);
  Nanos lastBeacon{-1};
  while (static_cast<std::int64_t>(d.followers.size()) < d.spec.followers && wall.now() < deadline) {
    if (lastBeacon.count() < 0 || wall.now() - lastBeacon > std::chrono::milliseconds(50)) {
      // A beacon (present -1): a follower that hears it knows its SUB socket is connected.
      lastBeacon = wall.now();
      d.send(d.pub.get(), encode(PresentMessage{-1}, d.buffer));
    }
    d.pollLeader(10);
    d.takeAnswers(0);
    if (!loop.dispatch(Nanos{0})) break;
  }
  const auto joined = static_cast<std::int64_t>(d.followers.size());
  if (joined < d.spec.followers) {
    log::warn(kLogLock,
              "{} of {} followers joined within {} ms; starting without the others (they join when they come)", joined,
              d.spec.followers, d.spec.joinTimeoutMs);
  }
  return joined;
}

void FrameLock::sayBye(std::int64_t frame) {
  Impl& d = *impl_;
  if (!d.isLeader()) return;
  d.send(d.pub.get(), encode(ByeMessage{frame}, d.buffer));
}

Result<void> FrameLock::beforeDraw(const FrameContext& frame) {
  if (impl_->isLeader()) {
    impl_->publishFrame(frame);
  } else {
    impl_->beforeDrawFollower();
  }
  return {};
}

Result<void> FrameLock::afterDraw(const FrameContext& frame, render::Output& output) {
  (void)output;
  if (impl_->isLeader()) {
    impl_->barrier(frame.frame);
    if (frame.last) sayBye(frame.frame);
  } else {
    impl_->afterDrawFollower(frame.frame);
  }
  return {};
}

bool FrameLock::wantsStop() const { return !impl_->isLeader() && impl_->byeSeen && !impl_->pending; }

Result<std::optional<GatedFrame>> FrameLock::nextFrame(runtime::EventLoop& loop, Nanos patience) {
  if (impl_->isLeader()) return fail(Errc::kInternal, "frame lock: the leader paces itself; it has no gate");
  auto next = impl_->nextFrame(loop, patience);
  Impl& d = *impl_;
  // While the picture holds no frame is presented (afterPresent publishes then): the status
  // page still hears about the hold once a second, and at once when it starts or ends.
  const Nanos now = d.ownClock.now();
  const bool due =
      d.figures.holding && (d.lastPublished.count() < 0 || now - d.lastPublished >= std::chrono::seconds(1));
  if ((d.publishNow || due) && d.publish) {
    d.publishNow = false;
    d.lastPublished = now;
    d.publish(figures());
  }
  return next;
}

FrameLockFigures FrameLock::figures() const {
  FrameLockFigures f = impl_->figures;
  f.followers = static_cast<std::int64_t>(std::count_if(impl_->followers.begin(), impl_->followers.end(),
                                                        [](const auto& x) { return x.second.inBarrier; }));
  f.barrierWaitP50Ms = impl_->barrierWait.median();
  f.barrierWaitMaxMs = impl_->barrierWait.max();
  f.delayP50Ms = impl_->delay.median();
  f.delayMaxMs = impl_->delay.max();
  return f;
}

std::string FrameLock::describe() const {
  const FrameLockFigures f = figures();
  const LockRejections& r = f.rejected;
  const std::string refused = fmt::format(
      "; {}, {} refused (no key {}, wrong key {}, handshake {}, frame jump {}, out of sequence {}, followers full {})",
      f.authenticated ? "authenticated" : "unauthenticated", r.total(), r.noKey, r.wrongKey, r.handshake, r.frameJump,
      r.outOfSequence, r.followersFull);
  if (f.leader) {
    return fmt::format(
               "frame lock: leader '{}': {} followers in the barrier ({} known), {} frames presented without every "
               "answer, "
               "{} dropped, {} rejoined, {} late answers, barrier wait median {:.3f} ms max {:.3f} ms, largest "
               "follower "
               "clock offset {} us, {} malformed messages, {} programme changes sent, {} commands sent, {} re-sent",
               f.node, f.followers, f.followersKnown, f.barrierTimeouts, f.followersDropped, f.followersRejoined,
               f.lateAnswers, f.barrierWaitP50Ms, f.barrierWaitMaxMs, f.maxClockOffsetUs, f.malformed,
               f.programmeChanges, f.commandsApplied, f.commandsResent) +
           refused;
  }
  return fmt::format(
             "frame lock: follower '{}': drew {} frames, {}..{}, checksum {:016x}, {} skipped, {} presented without "
             "the "
             "leader's word, skew at most {} frames, leader lost {} times, clock offset {} us (largest {} us), delay "
             "median "
             "{:.3f} ms max {:.3f} ms, {} malformed messages, leader back {} times (restarted {}), {} programme "
             "changes "
             "followed, {} of "
             "the leader's commands run ({} re-sent, {} lost), {} movie frames corrected to the leader's, {} late",
             f.node, f.framesDrawn, f.firstFrame, f.lastFrame, f.frameChecksum, f.skipped, f.presentsMissed,
             f.maxSkewFrames, f.leaderLost, f.clockOffsetUs, f.maxClockOffsetUsSeen, f.delayP50Ms, f.delayMaxMs,
             f.malformed, f.leaderReturned, f.leaderRestarts, f.programmeChanges, f.commandsApplied, f.commandsResent,
             f.commandsLost, f.movieFramesCorrected, f.movieFramesLate) +
         refused;
}

}  // namespace basalt::kiosk
