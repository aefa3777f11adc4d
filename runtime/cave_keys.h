#pragma once

/// \file
/// \brief The thesis' cave adjustment keys (Appendix B) as a small state machine over keyboard
/// events (Linux key codes, as `EventKind::kKey` carries them): scales, skews, facet index,
/// base side, long side to the bottom or the top, and the stereo eye spacing. Outer keys make
/// large steps, inner keys small ones.

#include <cstdint>

#include "runtime/event.h"
#include "runtime/formats/cave.h"

namespace basalt::runtime {

/// \brief Step sizes of the adjustment keys.
struct CaveKeySteps {
  float scaleLarge = 0.1f, scaleSmall = 0.01f;
  float skewLarge = 5.0f, skewSmall = 0.5f;           ///< degrees
  float spacingLarge = 0.01f, spacingSmall = 0.001f;  ///< cave units
};

/// \brief What a key changed.
enum class CaveKeyEffect : std::uint8_t { kNone, kCalibration, kEyeSpacing };

/// \brief Applies Appendix B's keys:
///   M < > ?  Xscale      m , . /  Yscale      K L : "  Xskew      k l ; '  Yskew
///   PgUp/PgDown facet index (wrapping over the geometry's facets)   S  next base side (wrapping)
///   Home  long side to the bottom (Z rotation 0)   End  long side to the top (Z rotation 180)
///   { [ ] }  eye spacing
/// Shift is tracked from the shift keys' own events.
class CaveKeys {
 public:
  explicit CaveKeys(CaveKeySteps steps = {}) : steps_(steps) {}
  CaveKeyEffect apply(const Event& event, formats::CaveSettings& cave, const formats::CaveGeometry& geometry,
                      float& eyeSpacing);

 private:
  CaveKeySteps steps_;
  bool leftShift_ = false, rightShift_ = false;
};

}  // namespace basalt::runtime
