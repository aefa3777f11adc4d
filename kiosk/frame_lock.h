#pragma once

/// \file
/// \brief Frame-locked display nodes (thesis §4.5): one leader and any number of followers, each
/// a `basalt` process drawing one or more facets, all presenting the same frame number.
///
/// Each frame the leader publishes the frame's number, show time and the state a follower needs
/// to draw it (`kiosk/lock_protocol.h`) on a ZeroMQ PUB socket, draws its own picture, then
/// waits (bounded) on a ROUTER socket for every follower in the barrier to say that frame is
/// drawn, and publishes "present N". A follower draws exactly the leader's frames (the newest one
/// when it fell behind, counting the frames it skipped), answers "ready N" on a DEALER socket and
/// presents when told. A follower that misses `drop_after` deadlines in a row leaves the barrier
/// (reported), and is back in it with its next answer; a follower that dies or restarts never
/// stops the others. A follower that hears nothing for `leader_timeout_ms` reports the leader
/// lost and holds its last picture until the leader is back.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "kiosk/frame_loop.h"
#include "kiosk/lock_protocol.h"
#include "runtime/clock.h"
#include "runtime/error.h"

namespace basalt::kiosk {

struct LockSpec;  // kiosk/manifest.h

/// \brief The lock's figures, for the summary line, /health and /metrics.
struct FrameLockFigures {
  bool leader = false;
  std::string node;
  // Leader.
  std::int64_t followers = 0;          ///< followers in the barrier now
  std::int64_t followersKnown = 0;     ///< followers ever heard from
  std::int64_t barrierTimeouts = 0;    ///< frames presented without every follower's answer
  std::int64_t followersDropped = 0;   ///< times a follower left the barrier
  std::int64_t followersRejoined = 0;  ///< times a dropped follower came back
  std::int64_t lateAnswers = 0;        ///< answers for a frame already presented
  double barrierWaitP50Ms = 0;         ///< time the leader waited for answers (median, max)
  double barrierWaitMaxMs = 0;
  std::int64_t maxClockOffsetUs = 0;  ///< largest |clock offset| a follower reported
  // Follower.
  std::int64_t framesDrawn = 0;
  std::int64_t firstFrame = -1;  ///< the first and last leader frame this node drew
  std::int64_t lastFrame = -1;
  std::int64_t skipped = 0;         ///< leader frames passed over (fell behind, joined late)
  std::int64_t presentsMissed = 0;  ///< frames presented without the leader's "present"
  std::int64_t maxSkewFrames = 0;   ///< newest frame the leader presented minus this node's, largest
  std::int64_t leaderLost = 0;      ///< times the leader went quiet
  bool leaderPresent = false;
  std::int64_t clockOffsetUs = 0;  ///< shared clock minus own clock at the last frame
  std::int64_t maxClockOffsetUsSeen = 0;
  std::uint64_t frameChecksum = 0;  ///< FNV-1a over the frame numbers drawn, in order
  // Both.
  std::int64_t malformed = 0;  ///< messages rejected (bad size, magic, version)
  double delayP50Ms = 0;       ///< leader send -> follower receipt on the shared clock (followers)
  double delayMaxMs = 0;
};

/// \brief Where the lock's shared clock reads (the network clock on followers), for the offset.
class LockClockProbe {
 public:
  virtual ~LockClockProbe() = default;
  /// \brief Shared clock minus this node's own clock.
  [[nodiscard]] virtual Nanos offset() const = 0;
};

/// \brief One node of a frame-locked group: a FrameParticipant on both roles (add it last, so
/// that it sees the frame's final state), and the FrameGate of a follower's loop.
///
/// Threading: everything on the frame loop's thread; figures() may be called from it only (the
/// kiosk copies them to the StatusBoard).
class FrameLock final : public FrameParticipant, public FrameGate {
 public:
  /// \brief Binds (leader) or connects (follower) the sockets. `clock` is the show's clock (the
  /// shared one); `show` the Show a follower puts the leader's state into.
  [[nodiscard]] static Result<std::unique_ptr<FrameLock>> create(const LockSpec& spec, const Clock& clock,
                                                                 runtime::Show& show);
  ~FrameLock() override;
  FrameLock(const FrameLock&) = delete;
  FrameLock& operator=(const FrameLock&) = delete;

  [[nodiscard]] bool leader() const;
  /// \brief Leader: waits up to the spec's join time-out for the expected followers, serving
  /// `loop` meanwhile. Returns how many joined.
  std::int64_t awaitFollowers(runtime::EventLoop& loop);
  /// \brief Leader: tells the followers the show ends after `frame`.
  void sayBye(std::int64_t frame);
  void setClockProbe(const LockClockProbe* probe);
  /// \brief The clock every node reads alike, for the messages' send and receive times: the
  /// leader's own monotonic clock (the default, what the leader serves), a follower's network
  /// clock. Borrowed.
  void setSharedClock(const Clock& clock);

  Result<void> beforeDraw(const FrameContext& frame) override;
  Result<void> afterDraw(const FrameContext& frame, render::Output& output) override;
  [[nodiscard]] bool wantsStop() const override;

  Result<std::optional<GatedFrame>> nextFrame(runtime::EventLoop& loop, Nanos patience) override;

  [[nodiscard]] FrameLockFigures figures() const;
  /// \brief One line for the run's summary.
  [[nodiscard]] std::string describe() const;

  struct Impl;

 private:
  explicit FrameLock(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace basalt::kiosk
