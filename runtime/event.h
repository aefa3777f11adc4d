#pragma once

/// \file
/// \brief Input events: what devices push up to the frame loop.

#include <cstdint>

#include "runtime/clock.h"

namespace basalt {

/// \brief Identifies a device for the life of the process (assigned by the DeviceManager).
using DeviceId = std::uint32_t;

enum class EventKind : std::uint8_t {
  kNone,
  kDialDelta,      ///< relative turn of dial `index`; value in turns (1.0 = one full turn)
  kDialAbsolute,   ///< absolute position of dial `index` in turns (devices without wrap)
  kButton,         ///< button `index`; value 1 pressed, 0 released
  kShuttle,        ///< spring-loaded ring `index`; value -1..1 (position, not motion)
  kKey,            ///< keyboard key `index` (Linux input key code); value 1 down, 0 up, 2 repeat
  kPointerMotion,  ///< pointer moved; `index` 0 = x, 1 = y; value in pixels (relative)
  kPointerButton,  ///< pointer button `index` (0 left, 1 middle, 2 right); value 1 down, 0 up
  kDeviceState,    ///< the device became live (value 1) or was lost (value 0); its bindings go quiet
};

/// \brief A timestamped value from one input of one device. Trivially copyable, so queues of
/// events never allocate.
struct Event {
  Nanos time{0};        ///< when the device produced it, on the show's Clock
  DeviceId device = 0;  ///< source device
  EventKind kind = EventKind::kNone;
  std::uint16_t index = 0;  ///< which dial, button, key or axis
  double value = 0;         ///< meaning depends on `kind` (see EventKind)
};

}  // namespace basalt
