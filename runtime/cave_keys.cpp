#include "runtime/cave_keys.h"

#include <algorithm>

namespace basalt::runtime {
namespace {
// Linux input key codes (linux/input-event-codes.h), the values kKey events carry.
enum Key : std::uint32_t {
  kKeyLeftBrace = 26,
  kKeyRightBrace = 27,
  kKeyS = 31,
  kKeyK = 37,
  kKeyL = 38,
  kKeySemicolon = 39,
  kKeyApostrophe = 40,
  kKeyLeftShift = 42,
  kKeyM = 50,
  kKeyComma = 51,
  kKeyDot = 52,
  kKeySlash = 53,
  kKeyRightShift = 54,
  kKeyHome = 102,
  kKeyPageUp = 104,
  kKeyEnd = 107,
  kKeyPageDown = 109,
};
}  // namespace

CaveKeyEffect CaveKeys::apply(const Event& event, formats::CaveSettings& cave, const formats::CaveGeometry& geometry,
                              float& eyeSpacing) {
  const auto facetCount = static_cast<std::uint32_t>(geometry.facets.size());
  if (event.kind != EventKind::kKey) return CaveKeyEffect::kNone;
  const bool down = event.value != 0;  // press or auto-repeat
  if (event.index == kKeyLeftShift) leftShift_ = down;
  if (event.index == kKeyRightShift) rightShift_ = down;
  if (!down) return CaveKeyEffect::kNone;
  const bool shift = leftShift_ || rightShift_;
  // The four keys of a row: large decrement, small decrement, small increment, large increment.
  auto row = [&](std::uint32_t k0, std::uint32_t k1, std::uint32_t k2, std::uint32_t k3, float small, float large,
                 float& value) {
    const std::uint32_t k = event.index;
    if (k == k0)
      value -= large;
    else if (k == k1)
      value -= small;
    else if (k == k2)
      value += small;
    else if (k == k3)
      value += large;
    else
      return false;
    return true;
  };
  const CaveKeySteps& s = steps_;
  if (shift ? row(kKeyM, kKeyComma, kKeyDot, kKeySlash, s.scaleSmall, s.scaleLarge, cave.xScale)
            : row(kKeyM, kKeyComma, kKeyDot, kKeySlash, s.scaleSmall, s.scaleLarge, cave.yScale)) {
    cave.xScale = std::max(cave.xScale, s.scaleSmall);
    cave.yScale = std::max(cave.yScale, s.scaleSmall);
    return CaveKeyEffect::kCalibration;
  }
  if (shift ? row(kKeyK, kKeyL, kKeySemicolon, kKeyApostrophe, s.skewSmall, s.skewLarge, cave.xSkew)
            : row(kKeyK, kKeyL, kKeySemicolon, kKeyApostrophe, s.skewSmall, s.skewLarge, cave.ySkew)) {
    cave.xSkew = std::clamp(cave.xSkew, -80.0f, 80.0f);
    cave.ySkew = std::clamp(cave.ySkew, -80.0f, 80.0f);
    return CaveKeyEffect::kCalibration;
  }
  // { and } are the shifted [ and ]: the outer (large) eye-spacing keys.
  if (event.index == kKeyLeftBrace || event.index == kKeyRightBrace) {
    const float step = shift ? s.spacingLarge : s.spacingSmall;
    eyeSpacing = std::max(0.0f, eyeSpacing + (event.index == kKeyRightBrace ? step : -step));
    return CaveKeyEffect::kEyeSpacing;
  }
  switch (event.index) {
    case kKeyPageUp:
    case kKeyPageDown:
      if (facetCount == 0) return CaveKeyEffect::kNone;
      cave.facet =
          event.index == kKeyPageUp ? (cave.facet + 1) % facetCount : (cave.facet + facetCount - 1) % facetCount;
      cave.side = 0;
      return CaveKeyEffect::kCalibration;
    case kKeyS:
      if (!shift) return CaveKeyEffect::kNone;
      if (cave.facet >= facetCount) return CaveKeyEffect::kNone;
      // The side stays an index the cave file can hold (loading checks it against the facet).
      cave.side = (cave.side + 1) % static_cast<std::uint32_t>(geometry.facets[cave.facet].corners.size());
      return CaveKeyEffect::kCalibration;
    case kKeyHome: cave.zRotation = 0; return CaveKeyEffect::kCalibration;
    case kKeyEnd: cave.zRotation = 180; return CaveKeyEffect::kCalibration;
    default: return CaveKeyEffect::kNone;
  }
}

}  // namespace basalt::runtime
