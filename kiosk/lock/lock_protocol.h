#pragma once

/// \file
/// \brief The frame-lock wire format (thesis §4.5): what the leader of a group of display nodes
/// sends each frame, and what the followers answer. Plain encoding and decoding, no sockets:
/// `kiosk/lock/frame_lock.cpp` carries the bytes over ZeroMQ, and every message is one ZeroMQ frame.
///
/// Layout: every message starts with the 4 bytes "BLCK", a version byte (4), a kind byte and
/// two bytes of zero, then the kind's fixed fields, little-endian (integers two's complement,
/// floats IEEE 754). The size of each kind is fixed; a message of another size, another magic or
/// version, an unknown kind or a non-finite number is rejected with the reason. Version 2 added
/// the director's programme (LockedProgramme) to the `frame` message; version 3 the leader's
/// script commands (LockedCommand in `frame`, and the `resend` and `command` kinds that bring a
/// follower the commands it missed) and the movie frame each of its movies shows
/// (LockedMovieFrames in `frame`); version 4 the tracked viewer of the facet views (the
/// state's `head`, at the end of `frame`), so that every node draws its facets from one head.

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <span>
#include <string>

#include "runtime/error.h"
#include "runtime/head_tracking.h"
#include "runtime/math.h"
#include "runtime/show/attributes.h"

namespace basalt::runtime {
class Show;
}

namespace basalt::kiosk {

/// \brief What a follower needs to draw the leader's frame exactly: LAVA's placement, motion and
/// view menu, and the thesis' walking viewer (where it stands and where it looks). Everything
/// else a frame shows follows from the same manifest and the frame's show time.
struct LockedShowState {
  Mat4 global;
  Mat4 local;
  Mat4 view;
  Vec3 globalRotate;
  Vec3 localRotate;
  float globalScale = 1;
  float localScale = 1;
  bool globalFreeRun = false;
  bool localFreeRun = false;
  std::int32_t motionFramesLeft = -1;
  Vec3 viewCenter;
  float viewScale = 1;
  float zClipScale = 2;
  float perspective = 4;
  Vec3 viewerPosition;
  Vec3 viewerRotation;
  float eyeSpacing = 0.04f;
  /// The tracked head of the facet views (Show::head()): the leader's, smoothed, so that every
  /// node's frusta follow the same viewer on the same frame. Encoded after the movie frames.
  runtime::HeadPose head;
  friend bool operator==(const LockedShowState&, const LockedShowState&) = default;
};

/// \brief Takes the state a follower needs from the leader's Show.
LockedShowState captureLockedState(const runtime::Show& show);
/// \brief Puts the leader's state into a follower's Show.
void applyLockedState(const LockedShowState& state, runtime::Show& show);

/// How many of a show's movie streams the frame lock carries (their pass and shown frame), in
/// the manifest's texture order; later ones keep their own timeline.
inline constexpr std::size_t kLockedMovieStreams = 16;

/// \brief The leader's programme (thesis §4.5: one director for the group): what its kiosk
/// policy plays, since when, and when its show's media streams started, so that followers play
/// the same item from the same point and their movies show the same video frame.
struct LockedProgramme {
  bool present = false;           ///< false: the leader has no director (a script run)
  bool hasItem = false;           ///< an item plays (not black, not off)
  std::uint8_t mode = 2;          ///< KioskMode: 0 closed, 1 attract, 2 active
  std::uint8_t display = 0;       ///< DisplayState: 0 on, 1 black, 2 off
  std::uint32_t index = 0;        ///< the item's place in its list
  std::int64_t itemStartNs = 0;   ///< show time the item started
  std::int64_t mediaStartNs = 0;  ///< show time the show's [media] streams started (their frame 0)
  std::uint32_t reloads = 0;      ///< reloads the leader applied: a follower reloads when it grows
  std::array<char, 32> item{};    ///< the item's name, NUL-padded (checked against the follower's list)
  /// One pass of each of the show's first looping movie streams on the leader's timeline (0:
  /// not looped yet), in the manifest's texture order: where a follower joining late places
  /// the current loop.
  std::array<std::int64_t, kLockedMovieStreams> moviePassNs{};
  friend bool operator==(const LockedProgramme&, const LockedProgramme&) = default;
  [[nodiscard]] std::string itemName() const;
  void setItemName(std::string_view name);
};

/// The longest command text a `frame` message carries; a longer one comes by `command` message.
constexpr std::size_t kFrameCommandBytes = 200;
/// The longest script command a frame-locked leader runs (what a `command` message carries).
constexpr std::size_t kCommandTextBytes = 1024;

/// \brief The leader's script commands as a frame announces them (thesis §4.5: a control
/// request's command acts on every node). The leader numbers the commands it ran since its show
/// was (re)loaded from 1; a follower runs them in that order.
struct LockedCommand {
  std::uint32_t epoch = 0;   ///< the leader's reload count: its log starts again with each reload
  std::uint32_t newest = 0;  ///< the newest command's number (0: none since the show loaded)
  /// Commands up to this number no longer act: the leader's show was reset after them (an item
  /// switch starts the item's own Show), so a follower catching up skips them.
  std::uint32_t base = 0;
  bool carried = false;  ///< `text` is command `newest`, new in this frame
  std::string text;      ///< at most kFrameCommandBytes, one line
  friend bool operator==(const LockedCommand&, const LockedCommand&) = default;
};

/// \brief The movie frame each of the leader's movies shows in a frame (thesis §4.5: every node
/// shows the same video frame): its number in its clip, -1 for none (no such movie, nothing on
/// screen yet). A follower shows exactly these frames, whatever its own decoder's timestamps add
/// up to (MoviePlayer::frameNumbered).
/// \brief -1 (no frame) in every stream's place.
constexpr std::array<std::int32_t, kLockedMovieStreams> noMovieFrames() {
  std::array<std::int32_t, kLockedMovieStreams> none{};
  none.fill(-1);
  return none;
}

struct LockedMovieFrames {
  std::int32_t item = -1;  ///< the movie item of the playlist
  /// The show's first movie streams, in the manifest's texture order (as LockedProgramme::moviePassNs).
  std::array<std::int32_t, kLockedMovieStreams> textures = noMovieFrames();
  friend bool operator==(const LockedMovieFrames&, const LockedMovieFrames&) = default;
};

enum class LockMessageKind : std::uint8_t {
  kFrame = 1,    ///< leader -> all: draw frame N with this state
  kPresent = 2,  ///< leader -> all: present frame N now
  kReady = 3,    ///< follower -> leader: frame N is drawn (or -1: I am here, send me frames)
  kBye = 4,      ///< leader -> all: the leader is ending the show
  kResend = 5,   ///< follower -> leader: send me your commands from number N on
  kCommand = 6,  ///< leader -> one follower: command N of the log
};

/// \brief Leader -> followers, published before the leader draws the frame.
struct FrameMessage {
  std::int64_t frame = 0;
  std::int64_t showTimeNs = 0;  ///< the frame's time on the shared clock
  std::int64_t sentNs = 0;      ///< when the leader sent it, on the shared clock (delay figures)
  LockedShowState state;
  LockedProgramme programme;
  LockedCommand command;     ///< since version 3
  LockedMovieFrames movies;  ///< since version 3
  /// The leader's run: a number it draws when it starts (since version 3). A follower that sees
  /// it change knows the leader restarted (its show, and the commands run on it, are new).
  std::uint32_t session = 0;
  friend bool operator==(const FrameMessage&, const FrameMessage&) = default;
};

/// \brief Leader -> followers: every node presents `frame` now.
struct PresentMessage {
  std::int64_t frame = 0;
  friend bool operator==(const PresentMessage&, const PresentMessage&) = default;
};

/// \brief Follower -> leader: `frame` is drawn and waits to be presented (-1: joining).
struct ReadyMessage {
  std::int64_t frame = -1;
  std::int64_t skipped = 0;        ///< frames this follower passed over so far
  std::int64_t clockOffsetNs = 0;  ///< shared clock minus this node's own clock
  std::array<char, 32> node{};     ///< the follower's name, NUL-padded
  friend bool operator==(const ReadyMessage&, const ReadyMessage&) = default;
  [[nodiscard]] std::string nodeName() const;
  void setNodeName(std::string_view name);
};

/// \brief Leader -> followers: the show ends after `frame`.
struct ByeMessage {
  std::int64_t frame = 0;
  friend bool operator==(const ByeMessage&, const ByeMessage&) = default;
};

/// \brief Follower -> leader (DEALER -> ROUTER): the commands of log `epoch` from `from` on.
struct ResendMessage {
  std::uint32_t epoch = 0;
  std::uint32_t from = 1;
  friend bool operator==(const ResendMessage&, const ResendMessage&) = default;
};

/// \brief Leader -> the follower that asked (ROUTER -> DEALER): command `seq` of log `epoch`.
struct CommandMessage {
  std::uint32_t epoch = 0;
  std::uint32_t seq = 1;
  /// The commands before `seq` that the follower asked for are gone from the leader's log (it
  /// keeps the newest LockCommandLog::kKept).
  bool earlierGone = false;
  std::string text;  ///< 1 to kCommandTextBytes bytes, one line
  friend bool operator==(const CommandMessage&, const CommandMessage&) = default;
};

constexpr std::size_t kLockHeaderBytes = 8;
/// Three matrices, two rotations, two scales, the motion flags and frame count, the view's
/// centre and three numbers, the viewer's position and rotation, the eye spacing.
constexpr std::size_t kLockedStateBytes = 284;
/// Flags, mode, display, a reserved byte, the index, two times, the reload count, four reserved
/// bytes, the item's name and the movie streams' passes.
constexpr std::size_t kLockedProgrammeBytes = 64 + 8 * kLockedMovieStreams;
/// The epoch, the newest and base numbers, the text's length, flags, a reserved byte and the
/// text, NUL-padded.
constexpr std::size_t kLockedCommandBytes = 16 + kFrameCommandBytes;
/// The item's and the movie streams' frames, the leader's session.
constexpr std::size_t kLockedMovieFramesBytes = 8 + 4 * kLockedMovieStreams;
/// The tracked head: flags, position, right vector, the newest sample's time (since version 4).
constexpr std::size_t kLockedHeadBytes = 4 + 12 + 12 + 8;
constexpr std::size_t kFrameMessageBytes = kLockHeaderBytes + 24 + kLockedStateBytes + kLockedProgrammeBytes +
                                           kLockedCommandBytes + kLockedMovieFramesBytes + kLockedHeadBytes;
constexpr std::size_t kPresentMessageBytes = kLockHeaderBytes + 8;
constexpr std::size_t kReadyMessageBytes = kLockHeaderBytes + 24 + 32;
constexpr std::size_t kByeMessageBytes = kLockHeaderBytes + 8;
constexpr std::size_t kResendMessageBytes = kLockHeaderBytes + 8;
/// The epoch, the number, the text's length, flags, a reserved byte and the text, NUL-padded.
constexpr std::size_t kCommandMessageBytes = kLockHeaderBytes + 12 + kCommandTextBytes;
constexpr std::size_t kMaxLockMessageBytes = std::max(kFrameMessageBytes, kCommandMessageBytes);

/// \brief A buffer big enough for any message; encode* return the bytes used.
using LockBuffer = std::array<std::byte, kMaxLockMessageBytes>;

std::size_t encode(const FrameMessage& m, LockBuffer& out);
std::size_t encode(const PresentMessage& m, LockBuffer& out);
std::size_t encode(const ReadyMessage& m, LockBuffer& out);
std::size_t encode(const ByeMessage& m, LockBuffer& out);
std::size_t encode(const ResendMessage& m, LockBuffer& out);
/// \brief `m.text` must fit kCommandTextBytes (the leader refuses longer commands).
std::size_t encode(const CommandMessage& m, LockBuffer& out);

/// \brief The kind of a message whose header is valid (magic, version, known kind, the kind's
/// size), or why it is not.
Result<LockMessageKind> peekKind(std::span<const std::byte> bytes);
Result<FrameMessage> decodeFrame(std::span<const std::byte> bytes);
Result<PresentMessage> decodePresent(std::span<const std::byte> bytes);
Result<ReadyMessage> decodeReady(std::span<const std::byte> bytes);
Result<ByeMessage> decodeBye(std::span<const std::byte> bytes);
Result<ResendMessage> decodeResend(std::span<const std::byte> bytes);
Result<CommandMessage> decodeCommand(std::span<const std::byte> bytes);

/// \brief The leader's log of the script commands it ran since its show was (re)loaded,
/// numbered from 1, the newest kKept of them kept for followers that missed some.
class LockCommandLog {
 public:
  static constexpr std::uint32_t kKept = 1024;
  /// \brief The show was (re)loaded: numbering starts again at 1 under `epoch`.
  void restart(std::uint32_t epoch);
  /// \brief Records a command that ran; returns its number.
  std::uint32_t add(std::string text);
  /// \brief The show was reset (an item started): the commands so far no longer act.
  void markShowReset() { base_ = newest_; }
  [[nodiscard]] std::uint32_t epoch() const { return epoch_; }
  [[nodiscard]] std::uint32_t newest() const { return newest_; }
  [[nodiscard]] std::uint32_t base() const { return base_; }
  /// \brief The oldest number still kept (newest() + 1 when none is).
  [[nodiscard]] std::uint32_t oldest() const { return newest_ + 1 - static_cast<std::uint32_t>(kept_.size()); }
  /// \brief Command `seq`, or null when it is not kept (or not run yet).
  [[nodiscard]] const std::string* at(std::uint32_t seq) const;

 private:
  std::uint32_t epoch_ = 0;
  std::uint32_t newest_ = 0;
  std::uint32_t base_ = 0;
  std::deque<std::string> kept_;
};

}  // namespace basalt::kiosk
