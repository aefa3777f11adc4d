#pragma once

/// \file
/// \brief The frame-lock wire format (thesis §4.5): what the leader of a group of display nodes
/// sends each frame, and what the followers answer. Plain encoding and decoding, no sockets:
/// `kiosk/frame_lock.cpp` carries the bytes over ZeroMQ, and every message is one ZeroMQ frame.
///
/// Layout: every message starts with the 4 bytes "BLCK", a version byte (2), a kind byte and
/// two bytes of zero, then the kind's fixed fields, little-endian (integers two's complement,
/// floats IEEE 754). The size of each kind is fixed; a message of another size, another magic or
/// version, an unknown kind or a non-finite number is rejected with the reason. Version 2 added
/// the director's programme (LockedProgramme) to the `frame` message.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "runtime/error.h"
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
  friend bool operator==(const LockedShowState&, const LockedShowState&) = default;
};

/// \brief Takes the state a follower needs from the leader's Show.
LockedShowState captureLockedState(const runtime::Show& show);
/// \brief Puts the leader's state into a follower's Show.
void applyLockedState(const LockedShowState& state, runtime::Show& show);

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
  std::array<std::int64_t, 4> moviePassNs{};
  friend bool operator==(const LockedProgramme&, const LockedProgramme&) = default;
  [[nodiscard]] std::string itemName() const;
  void setItemName(std::string_view name);
};

enum class LockMessageKind : std::uint8_t {
  kFrame = 1,    ///< leader -> all: draw frame N with this state
  kPresent = 2,  ///< leader -> all: present frame N now
  kReady = 3,    ///< follower -> leader: frame N is drawn (or -1: I am here, send me frames)
  kBye = 4,      ///< leader -> all: the leader is ending the show
};

/// \brief Leader -> followers, published before the leader draws the frame.
struct FrameMessage {
  std::int64_t frame = 0;
  std::int64_t showTimeNs = 0;  ///< the frame's time on the shared clock
  std::int64_t sentNs = 0;      ///< when the leader sent it, on the shared clock (delay figures)
  LockedShowState state;
  LockedProgramme programme;
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

constexpr std::size_t kLockHeaderBytes = 8;
/// Three matrices, two rotations, two scales, the motion flags and frame count, the view's
/// centre and three numbers, the viewer's position and rotation, the eye spacing.
constexpr std::size_t kLockedStateBytes = 284;
/// Flags, mode, display, a reserved byte, the index, two times, the reload count, four reserved
/// bytes, the item's name and four movie passes.
constexpr std::size_t kLockedProgrammeBytes = 96;
constexpr std::size_t kFrameMessageBytes = kLockHeaderBytes + 24 + kLockedStateBytes + kLockedProgrammeBytes;
constexpr std::size_t kPresentMessageBytes = kLockHeaderBytes + 8;
constexpr std::size_t kReadyMessageBytes = kLockHeaderBytes + 24 + 32;
constexpr std::size_t kByeMessageBytes = kLockHeaderBytes + 8;
constexpr std::size_t kMaxLockMessageBytes = kFrameMessageBytes;

/// \brief A buffer big enough for any message; encode* return the bytes used.
using LockBuffer = std::array<std::byte, kMaxLockMessageBytes>;

std::size_t encode(const FrameMessage& m, LockBuffer& out);
std::size_t encode(const PresentMessage& m, LockBuffer& out);
std::size_t encode(const ReadyMessage& m, LockBuffer& out);
std::size_t encode(const ByeMessage& m, LockBuffer& out);

/// \brief The kind of a message whose header is valid (magic, version, known kind, the kind's
/// size), or why it is not.
Result<LockMessageKind> peekKind(std::span<const std::byte> bytes);
Result<FrameMessage> decodeFrame(std::span<const std::byte> bytes);
Result<PresentMessage> decodePresent(std::span<const std::byte> bytes);
Result<ReadyMessage> decodeReady(std::span<const std::byte> bytes);
Result<ByeMessage> decodeBye(std::span<const std::byte> bytes);

}  // namespace basalt::kiosk
