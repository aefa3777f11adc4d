#pragma once

/// \file
/// \brief Turning the kernel's evdev events (`struct input_event`) into Basalt `Event`s: what a
/// device is (keyboard, mouse, touchpad, or none of these) from its capability bits, and the
/// translation of its event frames. Pure logic, no file descriptors: the reader
/// (devices/evdev/evdev_input.cpp) and the tests feed it.
///
/// The kernel's `linux/input.h` is included here and in devices/evdev only (and by the tests).

#include <linux/input.h>

#include <array>
#include <bitset>
#include <cstddef>
#include <cstdint>
#include <span>

#include "runtime/event.h"

namespace basalt::devices {

/// \brief What a device can report: the kernel's capability bits (EVIOCGBIT, EVIOCGPROP) and
/// the resolution of its absolute X and Y axes (units per millimetre, 0 when unknown).
struct EvdevCapabilities {
  std::bitset<EV_CNT> types;
  std::bitset<KEY_CNT> keys;
  std::bitset<REL_CNT> relative;
  std::bitset<ABS_CNT> absolute;
  std::bitset<INPUT_PROP_CNT> properties;
  std::int32_t resolutionX = 0;
  std::int32_t resolutionY = 0;

  /// \brief Fills a bitset from the bytes an EVIOCGBIT/EVIOCGKEY ioctl wrote (bit n of the
  /// kernel's little-endian bit array is code n).
  template <std::size_t N>
  static std::bitset<N> fromBytes(std::span<const std::uint8_t> bytes) {
    std::bitset<N> bits;
    for (std::size_t i = 0; i < N && i / 8 < bytes.size(); ++i)
      bits[i] = ((static_cast<unsigned>(bytes[i / 8]) >> (i % 8)) & 1U) != 0;
    return bits;
  }
};

/// \brief The roles a device plays for the show. A device may be both (a keyboard with a
/// trackpoint reports as one node on some machines); a device that is neither (a power button,
/// a dial box, a touchscreen, a joystick, a tablet pen) is left alone.
struct EvdevRoles {
  bool keyboard = false;  ///< its keys become kKey events
  bool pointer = false;   ///< relative motion (REL_X/REL_Y) and buttons: a mouse, a trackball
  bool touchpad = false;  ///< absolute finger positions turned into motion while touched

  [[nodiscard]] bool any() const { return keyboard || pointer || touchpad; }
};

/// \brief Decides the roles from the capabilities:
/// - a keyboard has every letter key A-Z, or the four arrow keys, or the keypad's digits (a
///   numeric pad); a power button (KEY_POWER alone) or a remote's volume keys do not make one;
/// - a pointer has REL_X, REL_Y and BTN_LEFT (a HID dial box has relative axes too, but its
///   buttons are BTN_0 and up);
/// - a touchpad has ABS_X, ABS_Y and BTN_TOOL_FINGER and is not a direct-touch screen
///   (INPUT_PROP_DIRECT).
[[nodiscard]] EvdevRoles classifyEvdev(const EvdevCapabilities& caps);

/// \brief "keyboard", "pointer", "touchpad", "keyboard and pointer", ... or "not a keyboard or
/// pointer".
[[nodiscard]] const char* evdevRolesName(EvdevRoles roles);

/// \brief Translates one device's event frames into Events for the show.
///
/// The kernel groups events into frames ended by SYN_REPORT; the decoder holds a frame's events
/// and hands them out when its SYN_REPORT arrives, so that a frame is all or nothing. Keys:
/// `kKey` with the Linux key code, value 1 pressed, 0 released, 2 auto-repeat (as the kernel
/// says; the show treats a repeat as another press, as a window's repeated presses are). Mouse
/// motion: one `kPointerMotion` per axis and frame (index 0 x, 1 y), the frame's REL_X/REL_Y
/// summed, in counts taken as pixels. Buttons: `kPointerButton` 0 left, 1 middle, 2 right (the
/// window's numbering); other buttons (side, extra, the touchpad's touch and tool bits) are not
/// pointer buttons. Touchpads: the finger's movement between frames while it touches, scaled to
/// kTouchpadPixelsPerMm where the device states its resolution.
///
/// SYN_DROPPED (the kernel's buffer overflowed: events were lost): the frame being built and
/// every event up to and including the next SYN_REPORT are dropped, then needsResync() is true
/// until resync() has been given the kernel's key state (EVIOCGKEY): keys the show believes
/// held but that are up are released (so a walk started by an arrow key stops), keys down that
/// the show did not see pressed are pressed.
///
/// Threading: one decoder per device, used by one thread. Allocates nothing after construction.
class EvdevDecoder {
 public:
  /// \brief The most events one frame may produce; the rest of a larger frame is dropped
  /// (counted in framesTruncated()).
  static constexpr std::size_t kMaxFrameEvents = 64;
  /// \brief Touchpad motion: pixels per millimetre of finger travel.
  static constexpr double kTouchpadPixelsPerMm = 10.0;

  EvdevDecoder(EvdevRoles roles, DeviceId device, const EvdevCapabilities& caps = {});

  /// \brief Feeds one kernel event. Returns the events of the frame it completes (at a
  /// SYN_REPORT), or nothing; the span is valid until the next call.
  std::span<const Event> feed(const input_event& event);
  /// \brief True after a SYN_DROPPED once its frame has ended: call resync().
  [[nodiscard]] bool needsResync() const { return needsResync_; }
  /// \brief Reconciles the keys with the kernel's key state (the bytes EVIOCGKEY wrote) and
  /// returns the releases and presses that makes (pointer buttons included: they are in the
  /// same bits); clears needsResync() and forgets the touchpad's last position.
  std::span<const Event> resync(std::span<const std::uint8_t> keyState);
  /// \brief Releases of everything held: for a device that is going away.
  std::span<const Event> releaseAll();

  [[nodiscard]] std::uint64_t framesDropped() const { return framesDropped_; }
  [[nodiscard]] std::uint64_t framesTruncated() const { return framesTruncated_; }
  [[nodiscard]] DeviceId device() const { return device_; }
  [[nodiscard]] EvdevRoles roles() const { return roles_; }

 private:
  void add(EventKind kind, std::uint16_t index, double value);
  std::span<const Event> finishFrame();
  void setHeld(std::uint16_t code, bool down);

  EvdevRoles roles_;
  DeviceId device_;
  double touchpadScaleX_ = 1.0;
  double touchpadScaleY_ = 1.0;
  std::array<Event, kMaxFrameEvents> frame_{};
  std::size_t frameSize_ = 0;
  bool frameTruncated_ = false;
  std::array<Event, kMaxFrameEvents> out_{};
  std::size_t outSize_ = 0;
  std::bitset<KEY_CNT> held_;       // keys and buttons the show was told are down
  std::bitset<KEY_CNT> frameHeld_;  // the same with the frame being built applied
  bool dropping_ = false;           // after SYN_DROPPED, until the next SYN_REPORT
  bool needsResync_ = false;
  std::int32_t relX_ = 0, relY_ = 0;
  // Touchpad: the finger's position in this frame and the last frame.
  bool touching_ = false;
  bool touchKnown_ = false;
  bool positionChanged_ = false;
  std::int32_t absX_ = 0, absY_ = 0;
  std::int32_t lastX_ = 0, lastY_ = 0;
  double touchRestX_ = 0, touchRestY_ = 0;  // fractions of a pixel not sent yet
  std::uint64_t framesDropped_ = 0;
  std::uint64_t framesTruncated_ = 0;
};

}  // namespace basalt::devices
