#pragma once

/// \file
/// \brief Bindings from input events to actions on the Show. The defaults are LAVA's dial
/// table (§4.1): dials 0-2 rotate about X, Y, Z; 3 scales; 4-6 translate along X, Y, Z; 7 idle.

#include <array>
#include <cstdint>

#include "runtime/event.h"
#include "runtime/show/show.h"

namespace basalt::runtime {

enum class Action : std::uint8_t { kNone, kRotateX, kRotateY, kRotateZ, kScale, kTranslateX, kTranslateY, kTranslateZ };

/// \brief What one dial does, and how much per turn: degrees for rotations, a factor of 2^gain
/// for scaling, window units for translations.
struct DialBinding {
  Action action = Action::kNone;
  double gain = 0;
};

inline constexpr std::size_t kMaxBoundDials = 32;

/// \brief Maps dial events to Show actions. Plain data: cheap to apply, nothing allocated.
class Bindings {
 public:
  /// \brief LAVA's dial table with Basalt's gains: 360 degrees, a factor of 2 and 1 window
  /// unit per full turn.
  static Bindings lavaDefaults();

  void setDial(std::size_t dial, DialBinding binding);
  [[nodiscard]] const DialBinding& dial(std::size_t index) const { return dials_[index]; }

  /// \brief Applies one event to the show; returns whether it changed anything.
  bool apply(const Event& event, Show& show) const;

 private:
  std::array<DialBinding, kMaxBoundDials> dials_{};
};

}  // namespace basalt::runtime
