#pragma once

/// \file
/// \brief Polygon geometry the loaders share: the Newell normal, triangulation of any simple
/// polygon (convex or concave) by ear clipping, and the planarity and convexity checks that cave
/// facets must pass.

#include <cstdint>
#include <span>
#include <vector>

#include "runtime/math.h"

namespace basalt::formats {

/// \brief The polygon's Newell normal: its direction is the normal of the best-fit plane (counter-
/// clockwise corners give a normal towards the viewer), its length twice the projected area.
Vec3 newellNormal(std::span<const Vec3> corners);

/// \brief Triangulates a polygon. Appends exactly `corners.size() - 2` triangles to `out` as
/// triples of corner numbers (0-based), keeping the corners' winding: convex polygons become a
/// fan, concave ones are ear-clipped in the polygon's plane. Degenerate polygons (collinear,
/// self-overlapping) still give n - 2 triangles, some of them without area. `budget` is the
/// number of point-in-triangle tests allowed; past it the rest is fanned and false is returned.
bool triangulatePolygon(std::span<const Vec3> corners, std::vector<std::uint32_t>& out, std::uint64_t budget);

/// \brief How far a polygon is from a flat convex one (cave facets must be both).
struct PolygonShape {
  Vec3 normal{0, 0, 1};            ///< unit normal (counter-clockwise corners face it)
  float planeOffset = 0;           ///< the plane: dot(normal, p) == planeOffset
  float area = 0;                  ///< area of the polygon projected onto its plane
  float maxPlaneDistance = 0;      ///< largest distance of a corner from the plane
  float diameter = 0;              ///< largest distance between two corners
  bool degenerate = false;         ///< fewer than 3 corners, or no area
  std::int32_t reflexCorner = -1;  ///< a corner where the outline turns the wrong way (-1: convex)
  std::uint32_t longestSide = 0;   ///< side i runs from corner i to corner i+1
};

/// \brief Measures a polygon: plane, area, planarity, convexity and its longest side.
PolygonShape measurePolygon(std::span<const Vec3> corners);

}  // namespace basalt::formats
