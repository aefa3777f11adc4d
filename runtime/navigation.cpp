#include "runtime/navigation.h"

#include <algorithm>
#include <cmath>

namespace basalt::runtime {
namespace {
// Linux input key codes (linux/input-event-codes.h).
constexpr std::uint16_t kKeyUp = 103, kKeyDown = 108, kKeyLeft = 105, kKeyRight = 106;
constexpr std::uint16_t kKeyKpPlus = 78, kKeyKpMinus = 74;
}  // namespace

bool Navigator::apply(const Event& event, Show& show) {
  if (event.kind == EventKind::kKey) {
    const bool held = event.value != 0;
    switch (event.index) {
      case kKeyUp: forward_ = held; return true;
      case kKeyDown: back_ = held; return true;
      case kKeyLeft: left_ = held; return true;
      case kKeyRight: right_ = held; return true;
      case kKeyKpPlus: up_ = held; return true;
      case kKeyKpMinus: down_ = held; return true;
      default: return false;
    }
  }
  if (event.kind == EventKind::kPointerMotion) {
    Viewer& v = show.viewer();
    const auto degrees = static_cast<float>(event.value) * v.rotationSpeed;
    // Moving the pointer right pans right (a turn clockwise seen from above, negative about Y);
    // moving it forward (up the screen, negative y) tilts the view down.
    if (event.index == 0) v.rotation.y -= degrees;
    if (event.index == 1) v.rotation.x = std::clamp(v.rotation.x + degrees, -89.0f, 89.0f);
    v.fromScene = true;
    return true;
  }
  return false;
}

void Navigator::advance(double seconds, Show& show) {
  Viewer& v = show.viewer();
  const auto step = static_cast<float>(seconds) * v.positionSpeed;
  const float along = (forward_ ? 1.0f : 0.0f) - (back_ ? 1.0f : 0.0f);
  const float across = (right_ ? 1.0f : 0.0f) - (left_ ? 1.0f : 0.0f);
  const float vertical = (up_ ? 1.0f : 0.0f) - (down_ ? 1.0f : 0.0f);
  if (along == 0 && across == 0 && vertical == 0) return;
  // Walking stays horizontal: the heading is the turn about Y; forward is -Z at heading 0.
  const float yaw = radians(v.rotation.y);
  const Vec3 forward{-std::sin(yaw), 0, -std::cos(yaw)};
  const Vec3 right{std::cos(yaw), 0, -std::sin(yaw)};
  Vec3 p = v.position + forward * (along * step) + right * (across * step);
  p.y += vertical * step;
  p.x = std::clamp(p.x, v.mapMin.x, v.mapMax.x);
  p.y = std::clamp(p.y, v.mapMin.y, v.mapMax.y);
  p.z = std::clamp(p.z, v.mapMin.z, v.mapMax.z);
  if (v.followTerrain && (along != 0 || across != 0)) {
    if (auto ground = show.terrainHeightAt(p.x, p.z)) p.y = *ground + eyeHeight_;
  }
  v.position = p;
  v.fromScene = true;
}

}  // namespace basalt::runtime
