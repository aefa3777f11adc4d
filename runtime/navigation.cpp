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
    const auto degrees = static_cast<float>(event.value) * show.viewer().rotationSpeed;
    // Moving the pointer right pans right; moving it forward (up the screen, negative y) tilts
    // the view down.
    if (event.index == 0) turnViewer(show, degrees, 0);
    if (event.index == 1) turnViewer(show, 0, degrees);
    return true;
  }
  return false;
}

void Navigator::advance(double seconds, Show& show) {
  const auto step = static_cast<float>(seconds) * show.viewer().positionSpeed;
  const float along = (forward_ ? 1.0f : 0.0f) - (back_ ? 1.0f : 0.0f);
  const float across = (right_ ? 1.0f : 0.0f) - (left_ ? 1.0f : 0.0f);
  const float vertical = (up_ ? 1.0f : 0.0f) - (down_ ? 1.0f : 0.0f);
  if (along == 0 && across == 0 && vertical == 0) return;
  moveViewer(show, along * step, across * step, vertical * step, eyeHeight_);
}

void moveViewer(Show& show, float forward, float right, float up, float eyeHeight) {
  Viewer& v = show.viewer();
  // Walking stays horizontal: the heading is the turn about Y; forward is -Z at heading 0.
  const float yaw = radians(v.rotation.y);
  const Vec3 ahead{-std::sin(yaw), 0, -std::cos(yaw)};
  const Vec3 side{std::cos(yaw), 0, -std::sin(yaw)};
  Vec3 p = v.position + ahead * forward + side * right;
  p.y += up;
  p.x = std::clamp(p.x, v.mapMin.x, v.mapMax.x);
  p.y = std::clamp(p.y, v.mapMin.y, v.mapMax.y);
  p.z = std::clamp(p.z, v.mapMin.z, v.mapMax.z);
  if (v.followTerrain && (forward != 0 || right != 0)) {
    if (auto ground = show.terrainHeightAt(p.x, p.z)) p.y = *ground + eyeHeight;
  }
  v.position = p;
  v.fromScene = true;
}

void turnViewer(Show& show, float heading, float pitch) {
  Viewer& v = show.viewer();
  // To the right is clockwise seen from above: negative about Y.
  v.rotation.y -= heading;
  v.rotation.x = std::clamp(v.rotation.x + pitch, -89.0f, 89.0f);
  v.fromScene = true;
}

}  // namespace basalt::runtime
