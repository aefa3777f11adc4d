#include "runtime/bindings.h"

#include <cmath>

#include "runtime/navigation.h"

namespace basalt::runtime {

namespace {

constexpr struct {
  Action action;
  std::string_view name;
} kActionNames[] = {
    {Action::kNone, "none"},
    {Action::kRotateX, "rotate_x"},
    {Action::kRotateY, "rotate_y"},
    {Action::kRotateZ, "rotate_z"},
    {Action::kScale, "scale"},
    {Action::kTranslateX, "translate_x"},
    {Action::kTranslateY, "translate_y"},
    {Action::kTranslateZ, "translate_z"},
    {Action::kMoveZoomX, "move_zoom_x"},
    {Action::kMoveZoomY, "move_zoom_y"},
    {Action::kWalk, "walk"},
    {Action::kStrafe, "strafe"},
    {Action::kRise, "rise"},
    {Action::kTurn, "turn"},
    {Action::kTilt, "tilt"},
};

// Turns further apart than this count as a fresh, slow turn for acceleration.
constexpr double kSlowGapSeconds = 0.25;

}  // namespace

std::string_view actionName(Action action) {
  for (const auto& a : kActionNames) {
    if (a.action == action) return a.name;
  }
  return "none";
}

std::optional<Action> actionByName(std::string_view name) {
  for (const auto& a : kActionNames) {
    if (a.name == name) return a.action;
  }
  return std::nullopt;
}

bool applyAction(Action action, float amount, Show& show) {
  switch (action) {
    case Action::kNone:
    case Action::kMoveZoomX:
    case Action::kMoveZoomY: return false;
    case Action::kRotateX: show.rotateGlobal({amount, 0, 0}); return true;
    case Action::kRotateY: show.rotateGlobal({0, amount, 0}); return true;
    case Action::kRotateZ: show.rotateGlobal({0, 0, amount}); return true;
    case Action::kScale: show.scaleGlobal(std::exp2(amount)); return true;
    case Action::kTranslateX: show.translateGlobal({amount, 0, 0}); return true;
    case Action::kTranslateY: show.translateGlobal({0, amount, 0}); return true;
    case Action::kTranslateZ: show.translateGlobal({0, 0, amount}); return true;
    case Action::kWalk: moveViewer(show, amount, 0, 0); return true;
    case Action::kStrafe: moveViewer(show, 0, amount, 0); return true;
    case Action::kRise: moveViewer(show, 0, 0, amount); return true;
    case Action::kTurn: turnViewer(show, amount, 0); return true;
    case Action::kTilt: turnViewer(show, 0, amount); return true;
  }
  return false;
}

Bindings Bindings::lavaDefaults() {
  Bindings b;
  b.setDial(0, {Action::kRotateX, 360});
  b.setDial(1, {Action::kRotateY, 360});
  b.setDial(2, {Action::kRotateZ, 360});
  b.setDial(3, {Action::kScale, 1});
  b.setDial(4, {Action::kTranslateX, 1});
  b.setDial(5, {Action::kTranslateY, 1});
  b.setDial(6, {Action::kTranslateZ, 1});
  b.setDial(7, {Action::kNone, 0});
  return b;
}

void Bindings::setDial(std::size_t dial, DialBinding binding) {
  if (dial < dials_.size()) dials_[dial] = binding;
}

void Bindings::setAcceleration(double acceleration) {
  for (DialBinding& d : dials_) d.acceleration = acceleration;
}

void Bindings::reset() {
  state_.fill(DialState{});
  zoomMove_ = {};
}

bool Bindings::turn(std::size_t dial, double turns, Nanos time, Show& show, bool accelerate) {
  const DialBinding& b = dials_[dial];
  if (b.action == Action::kNone || turns == 0) return false;
  double factor = 1;
  if (accelerate && b.acceleration != 0) {
    DialState& s = state_[dial];
    const double gap =
        s.lastTime.count() < 0 ? kSlowGapSeconds : std::min(kSlowGapSeconds, toSeconds(time - s.lastTime));
    const double speed = std::abs(turns) / std::max(gap, 1e-3);
    factor = 1 + b.acceleration * speed;
    s.lastTime = time;
  }
  const auto amount = static_cast<float>(turns * b.gain * gain_ * factor * (b.invert ? -1 : 1));
  switch (b.action) {
    case Action::kMoveZoomX: zoomMove_.dx += amount; return true;
    case Action::kMoveZoomY: zoomMove_.dy += amount; return true;
    default: return applyAction(b.action, amount, show);
  }
}

bool Bindings::apply(const Event& event, Show& show) {
  if (event.kind == EventKind::kDeviceState) {
    // A device that is not live any more holds no shuttle open.
    if (event.value == 0) {
      for (DialState& s : state_) {
        if (s.shuttleDevice == event.device) s.shuttle = 0;
        s.haveAbsolute = false;
      }
    }
    return false;
  }
  if (event.index >= dials_.size()) return false;
  DialState& s = state_[event.index];
  switch (event.kind) {
    case EventKind::kDialDelta: return turn(event.index, event.value, event.time, show, true);
    case EventKind::kDialAbsolute: {
      const bool had = s.haveAbsolute;
      const double delta = event.value - s.lastAbsolute;
      s.lastAbsolute = event.value;
      s.haveAbsolute = true;
      return had && turn(event.index, delta, event.time, show, true);
    }
    case EventKind::kShuttle:
      s.shuttle = event.value;
      s.shuttleDevice = event.device;
      return false;
    default: return false;
  }
}

bool Bindings::advance(Nanos elapsed, Show& show) {
  bool changed = false;
  const double seconds = toSeconds(elapsed);
  for (std::size_t i = 0; i < state_.size(); ++i) {
    if (state_[i].shuttle != 0) changed |= turn(i, state_[i].shuttle * shuttleRate_ * seconds, Nanos{0}, show, false);
  }
  return changed;
}

}  // namespace basalt::runtime
