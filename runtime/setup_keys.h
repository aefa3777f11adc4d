#pragma once

/// \file
/// \brief The thesis' display set-up toggles (Appendix B, "general runtime commands"), from a
/// keyboard (Linux key codes, as `EventKind::kKey` carries them) or by name (a control request):
///   Ctrl-c control mode   c cave mode   t stereo   F fog   s smooth shading   Ctrl-l lighting
///   f filled   P points   w wireframe   n normals   Ctrl-d light tokens   p pause   Esc exit
/// While control mode is off (Ctrl-c) only Ctrl-c itself is taken, so the keys reach the show.
/// Acts on the Show's global style, fog, stereo and motion; cave mode, exit and the two aids
/// Basalt does not draw (normals, light tokens) are returned for the caller to act on or report.

#include <cstdint>
#include <optional>
#include <string_view>

#include "runtime/event.h"
#include "runtime/show/show.h"

namespace basalt::runtime {

enum class SetupToggle : std::uint8_t {
  kControlMode,
  kCaveMode,
  kStereo,
  kFog,
  kSmoothShading,
  kLighting,
  kFilled,
  kPoints,
  kWireframe,
  kNormals,
  kLightTokens,
  kPause,
  kExit,
};

/// \brief The toggle's name in control requests: "control", "cave", "stereo", "fog", "smooth",
/// "lighting", "filled", "points", "wireframe", "normals", "light-tokens", "pause", "exit".
std::string_view setupToggleName(SetupToggle toggle);
/// \brief The toggle a name stands for, if any.
std::optional<SetupToggle> parseSetupToggle(std::string_view name);

/// \brief Keeps what a toggle switched off, so the next press brings it back.
///
/// Threading: the frame loop's thread, with the Show.
class SetupToggles {
 public:
  /// \brief The toggle a key press names (tracks Shift and Ctrl from their own events); none for
  /// other keys, releases, and every key but Ctrl-c while control mode is off.
  std::optional<SetupToggle> key(const Event& event);
  /// \brief Applies `toggle` to `show`; returns a line saying what it is now ("fog off").
  /// kCaveMode and kExit change nothing here (the caller owns the views and the run).
  std::string apply(SetupToggle toggle, Show& show);
  [[nodiscard]] bool controlMode() const { return controlMode_; }
  [[nodiscard]] bool normals() const { return normals_; }
  [[nodiscard]] bool lightTokens() const { return lightTokens_; }
  [[nodiscard]] bool paused() const { return paused_.has_value(); }

 private:
  bool leftShift_ = false, rightShift_ = false, leftCtrl_ = false, rightCtrl_ = false;
  bool controlMode_ = true;  ///< Appendix B: "It is on/true by default"
  bool normals_ = false, lightTokens_ = false;
  FogMode fogWas_ = FogMode::kExp;                      ///< the fog mode to bring back
  Illumination lightingWas_ = Illumination::kPerFacet;  ///< the illumination to bring back
  std::optional<Motion> paused_;                        ///< the motion a pause stopped
};

}  // namespace basalt::runtime
