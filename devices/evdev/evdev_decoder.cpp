// Translation of evdev event frames (keyboards, mice, touchpads) into Basalt events; see
// evdev_decoder.h. The kernel's protocol: Documentation/input/event-codes.rst (frames, SYN_DROPPED).

#include "devices/evdev/evdev_decoder.h"

#include <algorithm>
#include <cmath>
#include <initializer_list>

namespace basalt::devices {

namespace {

/// Codes of EV_KEY that are keys (not buttons of mice, joysticks, pads and tools).
bool isKeyCode(std::uint16_t code) {
  return (code > KEY_RESERVED && code < BTN_MISC) || (code >= KEY_OK && code < BTN_DPAD_UP) ||
         (code >= KEY_ALS_TOGGLE && code < BTN_TRIGGER_HAPPY);
}

/// The window's numbering of pointer buttons: 0 left, 1 middle, 2 right; -1 for the others.
int pointerButtonIndex(std::uint16_t code) {
  switch (code) {
    case BTN_LEFT: return 0;
    case BTN_MIDDLE: return 1;
    case BTN_RIGHT: return 2;
    default: return -1;
  }
}

bool hasAll(const std::bitset<KEY_CNT>& keys, std::initializer_list<int> codes) {
  for (const int c : codes) {
    if (!keys[static_cast<std::size_t>(c)]) return false;
  }
  return true;
}

}  // namespace

EvdevRoles classifyEvdev(const EvdevCapabilities& caps) {
  EvdevRoles roles;
  if (caps.types[EV_KEY]) {
    const auto& k = caps.keys;
    const bool letters =
        hasAll(k, {KEY_A, KEY_B, KEY_C, KEY_D, KEY_E, KEY_F, KEY_G, KEY_H, KEY_I, KEY_J, KEY_K, KEY_L, KEY_M,
                   KEY_N, KEY_O, KEY_P, KEY_Q, KEY_R, KEY_S, KEY_T, KEY_U, KEY_V, KEY_W, KEY_X, KEY_Y, KEY_Z});
    const bool arrows = hasAll(k, {KEY_UP, KEY_DOWN, KEY_LEFT, KEY_RIGHT});
    const bool keypad =
        hasAll(k, {KEY_KP0, KEY_KP1, KEY_KP2, KEY_KP3, KEY_KP4, KEY_KP5, KEY_KP6, KEY_KP7, KEY_KP8, KEY_KP9});
    roles.keyboard = letters || arrows || keypad;
  }
  roles.pointer =
      caps.types[EV_REL] && caps.types[EV_KEY] && caps.relative[REL_X] && caps.relative[REL_Y] && caps.keys[BTN_LEFT];
  roles.touchpad = caps.types[EV_ABS] && caps.types[EV_KEY] && caps.absolute[ABS_X] && caps.absolute[ABS_Y] &&
                   caps.keys[BTN_TOOL_FINGER] && !caps.properties[INPUT_PROP_DIRECT];
  return roles;
}

const char* evdevRolesName(EvdevRoles roles) {
  const bool pointing = roles.pointer || roles.touchpad;
  if (roles.keyboard && pointing) return roles.touchpad ? "keyboard and touchpad" : "keyboard and pointer";
  if (roles.keyboard) return "keyboard";
  if (roles.touchpad) return "touchpad";
  if (roles.pointer) return "pointer";
  return "not a keyboard or pointer";
}

EvdevDecoder::EvdevDecoder(EvdevRoles roles, DeviceId device, const EvdevCapabilities& caps)
    : roles_(roles), device_(device) {
  if (caps.resolutionX > 0) touchpadScaleX_ = kTouchpadPixelsPerMm / caps.resolutionX;
  if (caps.resolutionY > 0) touchpadScaleY_ = kTouchpadPixelsPerMm / caps.resolutionY;
}

void EvdevDecoder::add(EventKind kind, std::uint16_t index, double value) {
  if (frameSize_ == frame_.size()) {
    frameTruncated_ = true;
    return;
  }
  Event& e = frame_[frameSize_++];
  e = Event{};
  e.device = device_;
  e.kind = kind;
  e.index = index;
  e.value = value;
}

void EvdevDecoder::setHeld(std::uint16_t code, bool down) {
  if (code < frameHeld_.size()) frameHeld_[code] = down;
}

std::span<const Event> EvdevDecoder::finishFrame() {
  // Motion goes after the frame's buttons and keys: the kernel reports a button and the motion
  // that came with it in one frame, and a drag starts with the press.
  if (relX_ != 0) add(EventKind::kPointerMotion, 0, relX_);
  if (relY_ != 0) add(EventKind::kPointerMotion, 1, relY_);
  if (roles_.touchpad) {
    if (touching_ && touchKnown_ && positionChanged_) {
      // Whole pixels go out; the fractions add up, so that slow strokes move too.
      touchRestX_ += (absX_ - lastX_) * touchpadScaleX_;
      touchRestY_ += (absY_ - lastY_) * touchpadScaleY_;
      const double dx = std::trunc(touchRestX_);
      const double dy = std::trunc(touchRestY_);
      touchRestX_ -= dx;
      touchRestY_ -= dy;
      if (dx != 0) add(EventKind::kPointerMotion, 0, dx);
      if (dy != 0) add(EventKind::kPointerMotion, 1, dy);
    }
    if (!touching_) touchRestX_ = touchRestY_ = 0;
    lastX_ = absX_;
    lastY_ = absY_;
    touchKnown_ = touching_;
    positionChanged_ = false;
  }
  relX_ = relY_ = 0;
  held_ = frameHeld_;  // the frame is complete: what it pressed and released counts
  if (frameTruncated_) ++framesTruncated_;
  frameTruncated_ = false;
  std::copy_n(frame_.begin(), frameSize_, out_.begin());
  outSize_ = frameSize_;
  frameSize_ = 0;
  return {out_.data(), outSize_};
}

std::span<const Event> EvdevDecoder::feed(const input_event& event) {
  if (event.type == EV_SYN && event.code == SYN_DROPPED) {
    // Events were lost: this frame and the rest until the next SYN_REPORT are not to be trusted.
    if (!dropping_) ++framesDropped_;
    dropping_ = true;
    frameHeld_ = held_;  // the presses and releases of the lost frame never happened for the show
    frameSize_ = 0;
    frameTruncated_ = false;
    relX_ = relY_ = 0;
    return {};
  }
  if (dropping_) {
    if (event.type == EV_SYN && event.code == SYN_REPORT) {
      dropping_ = false;
      needsResync_ = true;
    }
    return {};
  }
  switch (event.type) {
    case EV_SYN:
      if (event.code == SYN_REPORT) return finishFrame();
      return {};
    case EV_KEY: {
      if (event.value < 0 || event.value > 2) return {};
      if (roles_.keyboard && isKeyCode(event.code)) {
        // A repeat of a key the show does not know is down (its press was lost) is a press.
        const bool down = event.value != 0;
        if (!down && !frameHeld_[event.code]) return {};  // a release of a key never reported down
        setHeld(event.code, down);
        add(EventKind::kKey, event.code, event.value);
        return {};
      }
      if (roles_.touchpad && event.code == BTN_TOUCH) {
        touching_ = event.value != 0;
        if (!touching_) touchKnown_ = false;
        return {};
      }
      const int button = pointerButtonIndex(event.code);
      if (button >= 0 && (roles_.pointer || roles_.touchpad) && event.value != 2) {
        const bool down = event.value == 1;
        if (down == frameHeld_[event.code]) return {};
        setHeld(event.code, down);
        add(EventKind::kPointerButton, static_cast<std::uint16_t>(button), down ? 1 : 0);
      }
      return {};
    }
    case EV_REL:
      if (!roles_.pointer) return {};
      if (event.code == REL_X) relX_ += event.value;
      if (event.code == REL_Y) relY_ += event.value;
      return {};
    case EV_ABS:
      if (!roles_.touchpad) return {};
      if (event.code == ABS_X) {
        absX_ = event.value;
        positionChanged_ = true;
      } else if (event.code == ABS_Y) {
        absY_ = event.value;
        positionChanged_ = true;
      }
      return {};
    default: return {};
  }
}

std::span<const Event> EvdevDecoder::resync(std::span<const std::uint8_t> keyState) {
  needsResync_ = false;
  touchKnown_ = false;
  touching_ = false;
  frameSize_ = 0;
  const std::bitset<KEY_CNT> now = EvdevCapabilities::fromBytes<KEY_CNT>(keyState);
  for (std::uint16_t code = 1; code < KEY_CNT; ++code) {
    const bool key = roles_.keyboard && isKeyCode(code);
    const int button = pointerButtonIndex(code);
    const bool pointerButton = button >= 0 && (roles_.pointer || roles_.touchpad);
    if ((!key && !pointerButton) || now[code] == held_[code]) continue;
    held_[code] = now[code];
    if (key) {
      add(EventKind::kKey, code, now[code] ? 1 : 0);
    } else {
      add(EventKind::kPointerButton, static_cast<std::uint16_t>(button), now[code] ? 1 : 0);
    }
  }
  relX_ = relY_ = 0;
  frameHeld_ = held_;
  frameTruncated_ = false;  // a resync is not a frame of the device's own
  std::copy_n(frame_.begin(), frameSize_, out_.begin());
  outSize_ = frameSize_;
  frameSize_ = 0;
  return {out_.data(), outSize_};
}

std::span<const Event> EvdevDecoder::releaseAll() {
  const std::array<std::uint8_t, (KEY_CNT + 7) / 8> none{};
  return resync(none);
}

}  // namespace basalt::devices
