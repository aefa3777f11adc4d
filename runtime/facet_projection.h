#pragma once

/// \file
/// \brief The thesis' facet view (§4.4.3): the viewer turned so that the line of sight follows a
/// display facet's inward normal, the facet's base side (its longest side plus a side index)
/// along the bottom of the viewport, the near plane on the facet, and a frustum that shows the
/// whole facet as large as the viewport allows at its aspect ratio, scaled, flipped for rear
/// projection and skewed by the calibration values. Pure math: no GL, no allocation once the
/// border's storage has grown to the facet's corner count.

#include <cstdint>
#include <vector>

#include "runtime/error.h"
#include "runtime/formats/cave.h"
#include "runtime/math.h"
#include "runtime/show/show.h"

namespace basalt::runtime {

/// \brief What a facet view is computed from besides the facet itself.
struct FacetViewInput {
  /// Calibration (thesis §4.4.2, a `.cave` file's settings): `side`, the scales, skews and Z
  /// rotation are used here; `facet` picks the facet (the caller passes that facet).
  formats::CaveSettings calibration;
  /// The viewer in the display geometry's coordinates (head tracking moves it every frame).
  /// The thesis' default is the geometry's origin; stereo eyes are offset from it.
  Vec3 viewer{0, 0, 0};
  /// Where the display geometry sits in the world (thesis §4.4.4, the camera places the
  /// display): maps cave coordinates to world coordinates. Rigid (rotation and translation)
  /// plus an optional uniform scale.
  Mat4 worldFromCave;
  float aspect = 1.0f;          ///< viewport width / height
  float farDistance = 1000.0f;  ///< far clipping distance from the viewer, along the line of sight
  bool rearProjection = true;   ///< flip horizontally (thesis step 14: projectors behind the screens)
};

/// \brief A computed facet view. `view` and `projection` drop into a plain view's
/// ViewTransforms; the rest is for the border mask, the visual aids and the tests.
struct FacetProjection {
  bool visible = false;    ///< false when the viewer is on or behind the facet's plane
  Mat4 view;               ///< world to eye (the viewer turned towards the facet)
  Mat4 projection;         ///< eye to clip: frustum, scale, flip, skew
  Vec3 eye;                ///< the viewer in world coordinates
  float nearDistance = 0;  ///< viewer to facet plane along the normal (cave units)
  float farDistance = 0;
  /// Frustum on the near plane before scale, flip and skew (cave units).
  float frustumLeft = 0, frustumRight = 0, frustumBottom = 0, frustumTop = 0;
  std::uint32_t baseSide = 0;  ///< the longest side plus the side index, modulo the corner count
  /// The facet's corners in normalised device coordinates (x, y in -1..1 fill the viewport), in
  /// the facet's order: the border mask blackens everything outside this convex polygon.
  std::vector<Vec2> border;
  // The vectors of the thesis' update method, in cave coordinates (for the visual aids).
  Vec3 collision;  ///< collpos: where the ray from the viewer against the normal meets the facet plane
  Vec3 forward;    ///< line of sight (the negated facet normal)
  Vec3 up;         ///< upvector1: the viewport's up on the facet (after the Z rotation)
  Vec3 right;      ///< the viewport's right (before the rear-projection flip)
};

/// \brief Computes the view of `facet` into `out`, reusing `out.border`'s storage. An error
/// (not an assertion) for a degenerate facet (fewer than 3 corners, no area); a viewer on or
/// behind the facet plane gives `visible = false` and leaves the matrices unchanged.
[[nodiscard]] Result<void> computeFacetView(const formats::CaveFacet& facet, const FacetViewInput& input,
                                            FacetProjection& out);

/// \brief Where the show puts the display geometry (thesis §4.4.4: the camera places the
/// display, the viewer moves inside it). A scene drawn from its own camera (Framing::kScene)
/// places the geometry's origin at the camera, turned as the camera is (cameraTransform), in
/// scene units; otherwise the origin sits at LAVA's eye, `view().perspective` units out on +Z,
/// moved as the walking viewer moves the plain view's eye, so that the facet facing -Z shows
/// what the plain view shows.
Mat4 cavePlacement(const Show& show);

/// \brief Where a cave point lands on the facet's image, in normalised device coordinates
/// (x, y) and depth (z), through `projection` (for tests and the visual aids).
Vec3 projectCavePoint(const FacetProjection& projection, const Mat4& worldFromCave, const Vec3& cavePoint);

}  // namespace basalt::runtime
