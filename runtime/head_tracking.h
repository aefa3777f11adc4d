#pragma once

/// \file
/// \brief Head tracking for immersive displays (thesis §4.4.3: the facet frusta follow the
/// viewer): a tracker's samples, the head pose the display views draw from, and the smoothing
/// between the two. Pure math, no devices, no allocation.

#include <cstdint>

#include "runtime/clock.h"
#include "runtime/math.h"

namespace basalt::runtime {

/// \brief One measurement of a tracked head or object, in the tracker's own units and axes.
/// Trivially copyable.
struct TrackerSample {
  Nanos time{0};               ///< when it was measured, on the show's Clock
  Vec3 position;               ///< tracker units (a HID tracker's physical unit, a trace's metres, ...)
  Vec3 rotation;               ///< Euler angles in degrees, applied X, then Y, then Z (as a scene's viewer)
  std::uint32_t sequence = 0;  ///< counts the device's samples, for drops and tests
  friend bool operator==(const TrackerSample&, const TrackerSample&) = default;
};

/// \brief The head's right vector for a rotation: +X turned by X, then Y, then Z.
Vec3 headRight(const Vec3& rotationDegrees);

/// \brief Where the display's viewer is this frame, in the display geometry's units (a cave's
/// coordinates: the display centre is the origin). Owned by the Show; carried by the frame lock.
struct HeadPose {
  bool tracked = false;  ///< a tracker drives it; otherwise the display views use their fixed viewer
  Vec3 position;         ///< the point between the eyes
  Vec3 right{1, 0, 0};   ///< unit: the stereo eyes sit along it, eye spacing apart
  Nanos sampleTime{0};   ///< the newest tracker sample it includes (latency is measured from it)
  friend bool operator==(const HeadPose&, const HeadPose&) = default;
};

/// \brief How tracker samples are smoothed before the frusta follow them.
struct HeadSmoothing {
  enum class Kind : std::uint8_t {
    kOff,          ///< the newest sample as it is
    kExponential,  ///< first-order low pass with time constant `timeConstant`
    kOneEuro,      ///< the 1€ filter (Casiez, Roussel, Vogel 2012): steady at rest, quick when moving
  };
  Kind kind = Kind::kOneEuro;
  /// kExponential: the time constant (63 % of a step after this long).
  Nanos timeConstant = std::chrono::milliseconds(50);
  /// kOneEuro: the cut-off at rest, Hz (time constant 1 / (2 pi minCutoff)).
  double minCutoff = 1.0;
  /// kOneEuro: how fast the cut-off rises with speed, per display unit per second.
  double beta = 0.5;
  /// kOneEuro: the cut-off of the speed estimate, Hz.
  double derivativeCutoff = 1.0;
};

/// \brief Smooths a head's position and right vector sample by sample, with each step's
/// weight from the time between samples (so the result does not depend on the sample rate).
/// Exact for a given sequence of samples: replays repeat it bit for bit.
class HeadSmoother {
 public:
  explicit HeadSmoother(HeadSmoothing config = {}) : config_(config) {}
  /// \brief Adds one sample (already in display units); returns the smoothed pose.
  const HeadPose& add(Nanos time, const Vec3& position, const Vec3& right);
  /// \brief Forgets the history: the next sample is taken as it is.
  void reset() { primed_ = false; }
  [[nodiscard]] const HeadPose& pose() const { return pose_; }
  [[nodiscard]] const HeadSmoothing& config() const { return config_; }

 private:
  /// One low-pass step's weight of the new value for a cut-off (Hz) over `dt` seconds.
  static double alpha(double cutoffHz, double dt);

  HeadSmoothing config_;
  bool primed_ = false;
  HeadPose pose_;
  Vec3 speed_;  ///< 1€: the filtered speed of the position, units per second
  Nanos last_{0};
};

/// \brief How a tracker's space maps onto the display's: display = offset + scale * tracker
/// (no rotation: mount the tracker's axes along the display's).
struct TrackerPlacement {
  Vec3 offset;         ///< where the tracker's origin is, in display units
  float scale = 1.0f;  ///< display units per tracker unit
  [[nodiscard]] Vec3 toDisplay(const Vec3& trackerPosition) const { return offset + trackerPosition * scale; }
};

}  // namespace basalt::runtime
