#pragma once

/// \file
/// \brief What a frame-locked node (kiosk/lock/frame_lock.h) counts, as plain data: the run's summary
/// line, the status server's /health and /metrics.

#include <cstdint>
#include <string>

namespace basalt::kiosk {

/// \brief What the lock refused, by reason (`basalt_lock_messages_rejected_total{reason}`): nothing
/// it refuses changes the show.
struct LockRejections {
  std::int64_t noKey = 0;      ///< `no_key`: a peer that speaks without the CURVE handshake
  std::int64_t wrongKey = 0;   ///< `wrong_key`: a handshake that proves no key of the group (another key, or replayed)
  std::int64_t handshake = 0;  ///< `handshake`: a handshake that broke off otherwise (garbage, cut short)
  std::int64_t frameJump = 0;  ///< `frame_jump`: a frame further ahead of the last drawn than lock.max_frame_jump
  std::int64_t outOfSequence = 0;  ///< `out_of_sequence`: a number its sender cannot have reached yet
  std::int64_t followersFull = 0;  ///< `followers_full`: a follower beyond lock.max_followers
  [[nodiscard]] std::int64_t total() const {
    return noKey + wrongKey + handshake + frameJump + outOfSequence + followersFull;
  }
};

/// \brief The lock's figures, for the summary line, /health and /metrics.
struct FrameLockFigures {
  bool leader = false;
  std::string node;
  bool authenticated = false;  ///< every connection proves the group's key (lock.key_file)
  LockRejections rejected;
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
  bool holding = false;               ///< the leader is lost and this node holds its last picture
  double holdingSeconds = 0;          ///< how long it has held it (0 when not holding)
  std::int64_t leaderReturned = 0;    ///< times a lost leader came back
  std::int64_t leaderRestarts = 0;    ///< times the leader's frames came from a new run of it
  std::int64_t heldFrame = -1;        ///< the frame held while holding
  std::int64_t programmeChanges = 0;  ///< times the programme changed (leader: sent; follower: followed)
  std::int64_t commandsApplied = 0;   ///< script commands run (leader: its own, logged; follower: the leader's)
  std::int64_t commandsResent = 0;    ///< commands re-sent (leader: to followers that asked; follower: received)
  std::int64_t commandsLost = 0;      ///< follower: the leader's commands gone from its log before this node had them
  /// Follower: movie frames shown by the leader's number that this node's own timeline would not
  /// have picked (its decoder's timestamps came out a hair off the leader's), and those not
  /// decoded in time (the frame before stayed).
  std::int64_t movieFramesCorrected = 0;
  std::int64_t movieFramesLate = 0;
  std::uint64_t watchdogPingsHolding = 0;  ///< systemd watchdog pings sent while holding (run_command fills it)
  std::int64_t clockOffsetUs = 0;          ///< shared clock minus own clock at the last frame
  std::int64_t maxClockOffsetUsSeen = 0;
  std::uint64_t frameChecksum = 0;  ///< FNV-1a over the frame numbers drawn, in order
  // Both.
  std::int64_t malformed = 0;  ///< messages rejected (bad size, magic, version)
  double delayP50Ms = 0;       ///< leader send -> follower receipt on the shared clock (followers)
  double delayMaxMs = 0;
};

}  // namespace basalt::kiosk
