#pragma once

/// \file
/// \brief Bindings from input events to actions on the Show. The defaults are LAVA's dial
/// table (§4.1): dials 0-2 rotate about X, Y, Z; 3 scales; 4-6 translate along X, Y, Z; 7 idle.
/// A show may change the gain of every dial, add acceleration (faster turns go further), and
/// override any dial's action, gain, acceleration and direction.

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>
#include <utility>

#include "runtime/clock.h"
#include "runtime/event.h"
#include "runtime/show/show.h"

namespace basalt::runtime {

/// The move_zoom actions move LAVA's Zoom picture (a movie drawn flat over the scene, LAVA §4.3
/// "Shift + drag") by `gain` output pixels per turn; they leave the Show alone and are collected
/// for the movie streams (Bindings::takeZoomMove()).
enum class Action : std::uint8_t {
  kNone,
  kRotateX,
  kRotateY,
  kRotateZ,
  kScale,
  kTranslateX,
  kTranslateY,
  kTranslateZ,
  kMoveZoomX,
  kMoveZoomY,
  // The walk-through viewer (thesis §4.6, Appendix B), for scenes and facet views: `gain` scene
  // units per turn for walk, strafe and rise, degrees per turn for turn and tilt.
  kWalk,
  kStrafe,
  kRise,
  kTurn,
  kTilt,
};

/// \brief "rotate_x", "scale", "none", ... (the names a show manifest uses).
std::string_view actionName(Action action);
/// \brief The action named `name`, or nullopt.
std::optional<Action> actionByName(std::string_view name);

/// \brief Applies `amount` of `action` to the show at once, in the units a dial's gain gives
/// per turn (degrees for rotations and turns, a factor of 2^amount for scaling, window or scene
/// units for moves). The Zoom moves and kNone change nothing here (false); everything else
/// returns true. Controls that are not dials (OSC) act through this, as the dials do.
bool applyAction(Action action, float amount, Show& show);

/// \brief What one dial does, and how much per turn: degrees for rotations, a factor of 2^gain
/// for scaling, window units for translations.
struct DialBinding {
  Action action = Action::kNone;
  double gain = 0;
  /// Extra gain with speed: a turn at `s` turns per second moves `1 + acceleration * s` times as
  /// far (0: linear, like LAVA).
  double acceleration = 0;
  bool invert = false;
  friend bool operator==(const DialBinding&, const DialBinding&) = default;
};

inline constexpr std::size_t kMaxBoundDials = 32;

/// \brief Maps dial events to Show actions. Plain data plus a little state per dial (speed for
/// acceleration, the last absolute position, shuttle rings held off-centre): nothing allocated.
///
/// Events of kind kDialDelta and kDialAbsolute move dial `index`; kShuttle holds dial `index`
/// turning at `value * shuttleTurnsPerSecond` until it returns to 0 (advance() applies it each
/// frame); kDeviceState with a lost device stops that device's shuttles, so a dial box pulled
/// out mid-turn leaves nothing spinning. Threading: the frame loop's thread only.
class Bindings {
 public:
  /// \brief LAVA's dial table with Basalt's gains: 360 degrees, a factor of 2 and 1 window
  /// unit per full turn; no acceleration.
  static Bindings lavaDefaults();

  void setDial(std::size_t dial, DialBinding binding);
  [[nodiscard]] const DialBinding& dial(std::size_t index) const { return dials_[index]; }
  /// \brief Multiplies every dial's gain (the manifest's `gain`, default 1).
  void setGain(double gain) { gain_ = gain; }
  [[nodiscard]] double gain() const { return gain_; }
  /// \brief Sets the acceleration of every dial (per-dial overrides come after, with setDial).
  void setAcceleration(double acceleration);
  /// \brief Turns per second of a shuttle ring at full deflection (default 1).
  void setShuttleTurnsPerSecond(double rate) { shuttleRate_ = rate; }

  /// \brief Applies one event to the show; returns whether it changed anything.
  bool apply(const Event& event, Show& show);
  /// \brief Applies continuous motion (shuttle rings) for `elapsed` show time.
  bool advance(Nanos elapsed, Show& show);
  /// \brief Forgets speeds, positions and shuttles (a new show, a replay from the start).
  void reset();

  /// \brief Output pixels the move_zoom dials turned since the last call (right and down are
  /// positive), and zero from then on.
  struct ZoomMove {
    float dx = 0;
    float dy = 0;
  };
  [[nodiscard]] ZoomMove takeZoomMove() { return std::exchange(zoomMove_, ZoomMove{}); }

 private:
  bool turn(std::size_t dial, double turns, Nanos time, Show& show, bool accelerate);

  struct DialState {
    Nanos lastTime{-1};
    double lastAbsolute = 0;
    bool haveAbsolute = false;
    double shuttle = 0;
    DeviceId shuttleDevice = 0;
  };

  std::array<DialBinding, kMaxBoundDials> dials_{};
  std::array<DialState, kMaxBoundDials> state_{};
  double gain_ = 1;
  double shuttleRate_ = 1;
  ZoomMove zoomMove_;
};

}  // namespace basalt::runtime
