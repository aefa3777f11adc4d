#pragma once

/// \file
/// \brief The thesis' walk-through viewer (§4.3.1 camera, §4.6 terrain): where a `.sce` scene
/// puts the eye, how it projects, how fast it moves and where it may go, and the height fields
/// of terrains that keep a walking viewer on the ground. Plain data, owned by the Show.

#include <cstdint>
#include <optional>
#include <vector>

#include "runtime/math.h"

namespace basalt::runtime {

/// \brief How the world is framed in a view.
enum class Framing : std::uint8_t {
  /// LAVA's view (§6.1 "View"): the world centred and shrunk or grown into window units, seen
  /// from LAVA's eye; the viewer walks from that eye, its moves scaled into window units.
  kFit,
  /// The thesis' camera (§4.3.1, F.1): the world in its own units, seen from `position` turned
  /// by `rotation`, through `fieldOfView`, `nearClip`, `farClip` and the scene's viewport.
  kScene,
};

/// \brief The viewer a scene file sets (thesis C.3 and Appendix F.1). Defaults are the thesis'.
///
/// The camera's orientation (`rotation`, F.1 "Euler rotation angles (X, Y, Z)") is read as a
/// walking viewer's: the camera looks down -Z with +Y up, turned `rotation.y` degrees about the
/// world's Y axis (heading, positive to the left), then `rotation.x` about its own X axis
/// (positive looks up), then `rotation.z` about its line of sight: world-from-camera =
/// T(position) Ry Rx Rz (cameraTransform).
struct Viewer {
  bool fromScene = false;            ///< a scene or walking set this viewer
  Framing framing = Framing::kFit;   ///< a scene's own camera and units, or LAVA's fit to the window
  Vec3 position{0, 0, 0};            ///< `position[x,y,z]`: initial eye position
  Vec3 rotation{0, 0, 0};            ///< `rotation[x,y,z]`: Euler angles in degrees, X then Y then Z
  float fieldOfView = 60.0f;         ///< `projection fov[]`, degrees (unused on cave facets)
  float nearClip = 0.1f;             ///< `projection nearclip[]`
  float farClip = 1000.0f;           ///< `projection farclip[]`
  float eyeSpacing = 0.04f;          ///< `eyespacing[]`: distance between the stereo eyes
  Vec3 mapMin{-1000, -1000, -1000};  ///< `mapmin[]`: the viewer stays inside mapMin..mapMax
  Vec3 mapMax{1000, 1000, 1000};     ///< `mapmax[]`
  float positionSpeed = 25.0f;       ///< `positionchange[]`: movement speed factor
  float rotationSpeed = 0.25f;       ///< `rotationchange[]`: rotation speed factor
  /// `viewport position[x,y] resolution[w,h]`: the rectangle drawn into; 0 x 0 = the whole output
  std::int32_t viewportX = 0;
  std::int32_t viewportY = 0;
  std::int32_t viewportWidth = 0;
  std::int32_t viewportHeight = 0;
  bool followTerrain = false;  ///< keep the eye at terrain height (a scene with a terrain sets it)
  friend bool operator==(const Viewer&, const Viewer&) = default;
};

/// \brief Where the viewer's camera is and how it is turned: world-from-camera, T(position) Ry
/// Rx Rz (see Viewer). Rigid.
Mat4 cameraTransform(const Vec3& position, const Vec3& rotationDegrees);

/// \brief A terrain's heights on a regular grid in the XZ plane (thesis §4.6): sample (i, j) is
/// at x = origin.x + i * spacing, z = origin.z + j * spacing, height origin.y + heights[j*columns+i].
struct HeightField {
  std::uint32_t columns = 0;
  std::uint32_t rows = 0;
  float spacing = 1.0f;
  Vec3 origin{0, 0, 0};
  std::vector<float> heights;

  /// \brief The height at (x, z), interpolated between the four samples around it, or nothing
  /// when (x, z) is off the grid.
  [[nodiscard]] std::optional<float> heightAt(float x, float z) const;
};

}  // namespace basalt::runtime
