// The plain view follows the walking viewer (thesis Appendix B: "arrow keys translate the
// viewer [...] mouse movement rotates viewer"; §4.6: "The viewer position is set based on this
// terrain height"), in a scene's own camera and in LAVA's fitted view. Expected positions are
// worked out here from a pinhole camera: a point at camera coordinates (x, y, z) lands at
// x / (-z) / (tan(fov / 2) aspect), y / (-z) / tan(fov / 2) in normalised device coordinates.
//
// Example failures: walking changes the viewer but not the picture (the plain view ignoring
// it); the strafe going left; the terrain height applied in window units; LAVA's view moved
// by a viewer that has not moved.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "runtime/navigation.h"
#include "runtime/show/show.h"

namespace basalt::runtime {
namespace {

Vec3 ndc(const ViewTransforms& t, const Vec3& world) {
  const Vec4 c = t.projection * (t.view * (t.model * Vec4{world.x, world.y, world.z, 1}));
  return {c.x / c.w, c.y / c.w, c.z / c.w};
}

Show sceneWithCube() {
  Show show = Show::makeDefault();
  show.resetTransforms();
  show.motion().globalFreeRun = false;
  show.viewer().framing = Framing::kScene;
  show.viewer().fieldOfView = 60;
  return show;
}

TEST(SceneView, WalkingInAPlainViewMovesThePictureAsThePinholeSays) {
  Show show = sceneWithCube();
  const double t = std::tan(30.0 * std::numbers::pi / 180.0);
  const Vec3 point{0, 0, -10};
  // At the origin the point is dead ahead.
  EXPECT_NEAR(ndc(computeView(show, 2.0f), point).x, 0.0f, 1e-5f);
  // One unit to the right (strafe): the point is 1 unit left at depth 10.
  moveViewer(show, 0, 1, 0);
  EXPECT_NEAR(ndc(computeView(show, 2.0f), point).x, -0.1 / (t * 2.0), 1e-5);
  // Four units forward: depth 6.
  moveViewer(show, 4, 0, 0);
  EXPECT_NEAR(ndc(computeView(show, 2.0f), point).x, -1.0 / 6.0 / (t * 2.0), 1e-5);
  // Half a unit up: the point is half a unit below the eye.
  moveViewer(show, 0, 0, 0.5f);
  EXPECT_NEAR(ndc(computeView(show, 2.0f), point).y, -0.5 / 6.0 / t, 1e-5);
  // Turned 10 degrees to the right: from (1, 0.5, -4) the point's heading is atan(1 / 6) to the
  // left of -Z; after the turn it is 10 degrees + atan(1 / 6) to the left.
  turnViewer(show, 10, 0);
  const double angle = 10.0 * std::numbers::pi / 180.0 + std::atan(1.0 / 6.0);
  const double depth = std::hypot(1.0, 6.0) * std::cos(angle), across = -std::hypot(1.0, 6.0) * std::sin(angle);
  EXPECT_NEAR(ndc(computeView(show, 2.0f), point).x, across / depth / (t * 2.0), 1e-4);
}

TEST(SceneView, WalkingOnATerrainKeepsTheEyeAboveTheGroundInSceneUnits) {
  Show show = sceneWithCube();
  auto field = std::make_shared<HeightField>();
  field->columns = 2, field->rows = 2, field->spacing = 10;
  field->origin = {-5, 0, -15};
  field->heights = {0, 4, 0, 4};  // rises from 0 at x = -5 to 4 at x = 5
  SceneNode ground;
  ground.name = "ground";
  show.addTerrain(std::move(ground), field);
  show.viewer().followTerrain = true;
  moveViewer(show, 5, 0, 0, 1.7f);  // to (0, ?, -5): ground 2 there
  const ViewTransforms v = computeView(show, 1.0f);
  EXPECT_NEAR(v.eye.y, 2.0f + 1.7f, 1e-5f);
  EXPECT_NEAR(v.eye.z, -5.0f, 1e-5f);
}

TEST(SceneView, LavasFittedViewMovesOnlyWhenTheViewerDoes) {
  Show show = Show::makeDefault();
  show.motion().globalFreeRun = false;
  const ViewTransforms before = computeView(show, 1.0f);
  EXPECT_NEAR(before.eye.z, show.view().perspective, 1e-6f) << "LAVA's eye";
  // The cube's radius is sqrt 3, so one scene unit is 1 / sqrt 3 window units: a step of
  // sqrt 3 scene units forward is one window unit.
  moveViewer(show, std::sqrt(3.0f), 0, 0);
  const ViewTransforms after = computeView(show, 1.0f);
  EXPECT_NEAR(after.eye.z, show.view().perspective - 1.0f, 1e-5f);
}

}  // namespace
}  // namespace basalt::runtime
