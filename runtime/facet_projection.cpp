#include "runtime/facet_projection.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace basalt::runtime {

// The thesis turns the viewer in two steps (rotation0 about rotaxis to face the facet, then
// rotation1 about the normal to put the base side at the bottom) and rotates the working
// vertices with the same angles. Both steps together are one orthonormal basis: the line of
// sight is the negated facet normal, up is the in-plane direction perpendicular to the base side
// pointing into the facet, turned by the Z rotation. Building that basis directly gives the
// same view without the thesis' special cases (a NaN rotaxis when the normal is parallel to
// -Z, the sign test of step 9).
Result<void> computeFacetView(const formats::CaveFacet& facet, const FacetViewInput& input, FacetProjection& out) {
  const std::size_t n = facet.corners.size();
  if (n < 3) return fail(Errc::kInvalidArgument, "a display facet needs at least 3 corners");
  if (!(facet.area > 0)) return fail(Errc::kInvalidArgument, "a display facet needs an area");

  const Vec3 normal = normalize(facet.normal);
  const float distance = dot(normal, input.viewer) - facet.planeOffset;
  out.forward = -normal;
  out.collision = input.viewer - normal * distance;
  out.baseSide = static_cast<std::uint32_t>((facet.longestSide + input.calibration.side) % n);
  if (!(distance > formats::kCaveViewerClearance)) {
    out.visible = false;
    out.border.clear();
    return {};
  }

  // Up: perpendicular to the base side in the facet's plane, towards the facet's inside.
  const Vec3& a = facet.corners[out.baseSide];
  const Vec3& b = facet.corners[(out.baseSide + 1) % n];
  Vec3 centroid{};
  for (const Vec3& c : facet.corners) centroid += c;
  centroid = centroid / static_cast<float>(n);
  Vec3 up = normalize(cross(normal, normalize(b - a)));
  if (dot(up, centroid - a) < 0) up = -up;
  if (input.calibration.zRotation != 0) {
    up = normalize(Mat4::rotation(input.calibration.zRotation, normal).transformDirection(up));
  }
  const Vec3 right = cross(up, normal);
  out.up = up;
  out.right = right;

  // Eye basis: rows right, up, back (the normal faces the viewer).
  Mat4 turn;
  turn(0, 0) = right.x, turn(0, 1) = right.y, turn(0, 2) = right.z;
  turn(1, 0) = up.x, turn(1, 1) = up.y, turn(1, 2) = up.z;
  turn(2, 0) = normal.x, turn(2, 1) = normal.y, turn(2, 2) = normal.z;
  const Mat4 eyeFromCave = turn * Mat4::translation(-input.viewer);
  out.view = eyeFromCave * input.worldFromCave.inverted();
  out.eye = input.worldFromCave.transformPoint(input.viewer);

  // The facet on the near plane (z = -distance in eye space), its bounding box grown to the
  // viewport's aspect ratio about its centre: the facet as large as the viewport allows.
  float minX = std::numeric_limits<float>::max(), maxX = -minX, minY = minX, maxY = -minX;
  for (const Vec3& c : facet.corners) {
    const Vec3 p = eyeFromCave.transformPoint(c);
    // Project onto the near plane: corners lie on it up to the facet's flatness tolerance.
    const float k = distance / std::max(-p.z, 1e-6f);
    minX = std::min(minX, p.x * k), maxX = std::max(maxX, p.x * k);
    minY = std::min(minY, p.y * k), maxY = std::max(maxY, p.y * k);
  }
  const float aspect = input.aspect > 0 ? input.aspect : 1.0f;
  const float cx = 0.5f * (minX + maxX), cy = 0.5f * (minY + maxY);
  float halfW = 0.5f * (maxX - minX), halfH = 0.5f * (maxY - minY);
  if (halfW > halfH * aspect) {
    halfH = halfW / aspect;
  } else {
    halfW = halfH * aspect;
  }
  out.frustumLeft = cx - halfW, out.frustumRight = cx + halfW, out.frustumBottom = cy - halfH,
  out.frustumTop = cy + halfH;
  // Field-of-view scale (C.1 Xscale/Yscale): the frustum grows about its centre.
  halfW *= input.calibration.xScale > 0 ? input.calibration.xScale : 1.0f;
  halfH *= input.calibration.yScale > 0 ? input.calibration.yScale : 1.0f;
  out.nearDistance = distance;
  out.farDistance = std::max(input.farDistance, distance * 1.001f);
  const Mat4 frustum = Mat4::frustum(cx - halfW, cx + halfW, cy - halfH, cy + halfH, distance, out.farDistance);
  Mat4 flip;
  if (input.rearProjection) flip(0, 0) = -1;
  Mat4 skew;
  skew(0, 1) = std::tan(radians(input.calibration.xSkew));
  skew(1, 0) = std::tan(radians(input.calibration.ySkew));
  out.projection = skew * flip * frustum;

  out.border.resize(n);
  const Mat4 clipFromCave = out.projection * eyeFromCave;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec4 c = clipFromCave * Vec4{facet.corners[i].x, facet.corners[i].y, facet.corners[i].z, 1};
    out.border[i] = {c.x / c.w, c.y / c.w};
  }
  out.visible = true;
  return {};
}

Mat4 cavePlacement(const Show& show) {
  const Viewer& v = show.viewer();
  if (v.framing == Framing::kScene) return cameraTransform(v.position, v.rotation);
  // LAVA's eye, moved by the walking viewer in window units (as computeView moves it).
  const float d = show.view().perspective > 0 ? show.view().perspective : 4.0f;
  const float scale = sceneScale(show);
  return Mat4::translation({0, 0, d}) *
         cameraTransform(v.position * (scale > 0 && std::isfinite(scale) ? scale : 1.0f), v.rotation);
}

Vec3 projectCavePoint(const FacetProjection& projection, const Mat4& worldFromCave, const Vec3& cavePoint) {
  const Vec3 world = worldFromCave.transformPoint(cavePoint);
  const Vec4 clip = projection.projection * (projection.view * Vec4{world.x, world.y, world.z, 1});
  return {clip.x / clip.w, clip.y / clip.w, clip.z / clip.w};
}

}  // namespace basalt::runtime
