#pragma once

/// \file
/// \brief The thesis' walk-through navigation (§5.1, Appendix B, §4.6): arrow keys move the
/// viewer forward, back, left and right; the keypad's + and - move it up and down; pointer
/// motion pans (left and right) and tilts (forward and back). Speeds are the scene's
/// `positionchange` and `rotationchange`; the viewer stays inside `mapmin`..`mapmax`; with a
/// terrain loaded and `followTerrain` set, its height follows the ground, and a vertical move is
/// lost at the next horizontal one (as the thesis says). Acts on `Show::viewer()`, which places
/// the display geometry of facet views (`cavePlacement`).

#include "runtime/event.h"
#include "runtime/show/show.h"

namespace basalt::runtime {

/// \brief Moves the viewer `forward` along its heading, `right` across it and `up` (scene units),
/// within the map bounds; with `followTerrain` a horizontal move puts the eye `eyeHeight` above
/// the ground. What the arrow keys and the walk, strafe and rise dial actions do.
void moveViewer(Show& show, float forward, float right, float up, float eyeHeight = 1.7f);
/// \brief Turns the viewer: `heading` degrees to the right (a clockwise turn seen from above) and
/// `pitch` degrees down, the pitch kept within 89 degrees of level. What dragging the pointer and
/// the turn and tilt dial actions do.
void turnViewer(Show& show, float heading, float pitch);

/// \brief Turns key and pointer events into viewer motion. Plain state, no allocation.
class Navigator {
 public:
  /// \brief Height of the eye above the terrain when following it (scene units).
  explicit Navigator(float eyeHeight = 1.7f) : eyeHeight_(eyeHeight) {}
  /// \brief Takes a key (held state) or pointer event; true when it was a navigation event.
  bool apply(const Event& event, Show& show);
  /// \brief Moves the viewer for `seconds` of held keys and follows the terrain.
  void advance(double seconds, Show& show);

 private:
  float eyeHeight_;
  bool forward_ = false, back_ = false, left_ = false, right_ = false, up_ = false, down_ = false;
};

}  // namespace basalt::runtime
