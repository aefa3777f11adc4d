#include "runtime/bindings.h"

#include <cmath>

namespace basalt::runtime {

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

bool Bindings::apply(const Event& event, Show& show) const {
  if (event.kind != EventKind::kDialDelta || event.index >= dials_.size()) return false;
  const DialBinding& b = dials_[event.index];
  const auto amount = static_cast<float>(event.value * b.gain);
  switch (b.action) {
    case Action::kNone: return false;
    case Action::kRotateX: show.rotateGlobal({amount, 0, 0}); return true;
    case Action::kRotateY: show.rotateGlobal({0, amount, 0}); return true;
    case Action::kRotateZ: show.rotateGlobal({0, 0, amount}); return true;
    case Action::kScale: show.scaleGlobal(std::exp2(amount)); return true;
    case Action::kTranslateX: show.translateGlobal({amount, 0, 0}); return true;
    case Action::kTranslateY: show.translateGlobal({0, amount, 0}); return true;
    case Action::kTranslateZ: show.translateGlobal({0, 0, amount}); return true;
  }
  return false;
}

}  // namespace basalt::runtime
