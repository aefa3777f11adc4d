#pragma once

/// \file
/// \brief Frame-locked display nodes (thesis §4.5): one leader and any number of followers, each
/// a `basalt` process drawing one or more facets, all presenting the same frame number.
///
/// Each frame the leader publishes the frame's number, show time and the state a follower needs
/// to draw it (`kiosk/lock/lock_protocol.h`) on a ZeroMQ PUB socket, draws its own picture, then
/// waits (bounded) on a ROUTER socket for every follower in the barrier to say that frame is
/// drawn, and publishes "present N". A follower draws exactly the leader's frames (the newest one
/// when it fell behind, counting the frames it skipped), answers "ready N" on a DEALER socket and
/// presents when told. A follower that misses `drop_after` deadlines in a row leaves the barrier
/// (reported), and is back in it with its next answer; a follower that dies or restarts never
/// stops the others. A follower that hears nothing for `leader_timeout_ms` reports the leader
/// lost and holds its last picture until the leader is back.

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "kiosk/lock/lock_figures.h"
#include "kiosk/lock/lock_protocol.h"
#include "kiosk/loop/frame_loop.h"
#include "runtime/clock.h"
#include "runtime/error.h"

namespace basalt::kiosk {

struct LockSpec;  // kiosk/manifest/manifest.h

/// \brief Where the lock's shared clock reads (the network clock on followers), for the offset.
class LockClockProbe {
 public:
  virtual ~LockClockProbe() = default;
  /// \brief Shared clock minus this node's own clock.
  [[nodiscard]] virtual Nanos offset() const = 0;
};

/// \brief Follower: what its movies did with the leader's movie frames (MoviePlayer::frameNumbered).
struct LockedMovieCounts {
  std::int64_t corrected = 0;  ///< shown by number, though this node's own timeline would have shown another
  std::int64_t late = 0;       ///< not decoded in time: the frame before stayed
};

/// \brief The kiosk's director as the lock sees it (kiosk/show/show_director.h): the leader sends its
/// programme with every frame; a follower takes the leader's before each frame is drawn, so that
/// an item switched on the leader is switched on every node in the same frame.
class LockedDirector {
 public:
  virtual ~LockedDirector() = default;
  /// \brief Leader: what plays now (called in the lock's beforeDraw, after the director's).
  [[nodiscard]] virtual LockedProgramme lockedProgramme() const = 0;
  /// \brief Follower: plays the leader's programme from the frame at `showTime` on (called
  /// before any participant's beforeDraw). True when what plays changed.
  virtual bool followProgramme(const LockedProgramme& programme, Nanos showTime) = 0;
  /// \brief Follower: the leader restarted (its frames come from a new run): the show it
  /// plays, and the commands run on it, start anew; this node's should too (called before the
  /// new run's programme is followed).
  virtual void leaderRestarted() {}
  /// \brief Leader: the movie frame each of its movies shows in this frame (called in the lock's
  /// beforeDraw, after the director's).
  [[nodiscard]] virtual LockedMovieFrames lockedMovieFrames() const { return {}; }
  /// \brief Follower: the leader's movie frames for the frame about to be drawn (called by the
  /// gate after followProgramme): its movies show exactly these.
  virtual void followMovieFrames(const LockedMovieFrames& frames) { (void)frames; }
  /// \brief Follower: its movies' frames shown by the leader's number so far.
  [[nodiscard]] virtual LockedMovieCounts movieFrameCounts() const { return {}; }
  /// \brief Leader: the script commands it ran since its show was (re)loaded, which the lock
  /// announces in each frame and re-sends to followers that missed some; null: none are run.
  [[nodiscard]] virtual const LockCommandLog* commandLog() const { return nullptr; }
  /// \brief Follower: how many times this node's show was (re)loaded. The leader's commands
  /// applied to an earlier show went with it: the lock applies them again from the first.
  [[nodiscard]] virtual std::uint64_t showLoads() const { return 0; }
  /// \brief Follower: true while this node loads a show (the leader's commands wait for it).
  [[nodiscard]] virtual bool loadingShow() const { return false; }
  /// \brief Follower: runs one of the leader's script commands on this node's show (called by
  /// the gate before any participant's beforeDraw, after followProgramme).
  virtual Result<std::string> runLeaderCommand(std::string_view command) {
    (void)command;
    return fail(Errc::kUnsupported, "this director runs no script commands");
  }
};

/// \brief Movies of a run that no director plays (a LAVA script's VCR, `basalt run --movie`
/// streams), shown by the leader's frame number on followers as the director's are. Each uses
/// fixed slots of LockedMovieFrames (the same on every node: the same show and command line).
class LockedMovies {
 public:
  virtual ~LockedMovies() = default;
  /// \brief Leader: writes the movie frame each of its movies shows in this frame into every slot
  /// it uses, -1 for none (called in the lock's beforeDraw, after the director's). Also called
  /// on a follower, to learn which slots these movies use.
  virtual void lockedMovieFrames(LockedMovieFrames& frames) const = 0;
  /// \brief Follower: the leader's movie frames for the frame about to be drawn (called by the
  /// gate before any participant's beforeDraw): its movies show exactly these.
  virtual void followMovieFrames(const LockedMovieFrames& frames) = 0;
  /// \brief Follower: its movies' frames shown by the leader's number so far.
  [[nodiscard]] virtual LockedMovieCounts movieFrameCounts() const = 0;
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
  /// \brief Called on the frame loop's thread with the figures after the first frame and then
  /// about once a second (the kiosk hands them to the StatusBoard).
  void setPublisher(std::function<void(const FrameLockFigures&)> publish);
  /// \brief The director whose programme the leader sends and a follower follows; borrowed, null
  /// for none (a script run: followers then keep their own).
  void setDirector(LockedDirector* director);
  /// \brief Movies besides the director's whose frames the leader sends and a follower shows by
  /// number (a script's VCR, `--movie` streams); borrowed, must outlive the lock. Their slots
  /// take precedence over the director's, which a follower then gives -1 there.
  void addMovies(LockedMovies& movies);

  Result<void> beforeDraw(const FrameContext& frame) override;
  Result<void> afterDraw(const FrameContext& frame, render::Output& output) override;
  [[nodiscard]] bool wantsStop() const override;
  void afterPresent(const FrameContext& frame) override;

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
