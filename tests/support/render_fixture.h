#pragma once

/// \file
/// \brief Shared set-up for render tests: one headless output and one renderer per test binary
/// (shader variants compile once), geometry makers, a camera whose pixels the tests can map back
/// to world points, and read-back helpers.

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "render/output.h"
#include "render/renderer.h"
#include "runtime/image.h"
#include "runtime/show/show.h"

namespace basalt::test {

inline constexpr std::uint32_t kRenderSize = 256;

/// \brief The output and renderer every render test in a binary shares.
struct RenderContext {
  std::unique_ptr<render::Output> output;
  std::unique_ptr<render::Renderer> renderer;
  std::string unavailable;  ///< why there is no EGL here (tests skip with it)
};
RenderContext& renderContext();

/// \brief A fixture that skips with the reason when EGL is missing.
class RenderTest : public ::testing::Test {
 protected:
  void SetUp() override;
  render::Renderer& renderer() { return *renderContext().renderer; }
  render::Output& output() { return *renderContext().output; }
  /// \brief Draws `show` through `view` into the whole output and reads it back.
  Image render(const runtime::Show& show, const runtime::ViewTransforms& view);
  /// \brief Draws `show` the way the frame loop does (LAVA's view, stereo as set) and reads back.
  Image renderShow(const runtime::Show& show);
};

/// \brief A camera on +Z looking at the origin: model identity, eye at (0, 0, distance), a
/// symmetric frustum of `halfWidth` at z = 0, near and far planes as given.
runtime::ViewTransforms testCamera(float distance = 3.0f, float halfWidth = 1.0f, float zNear = 1.0f,
                                   float zFar = 5.0f);

/// \brief The world point on the plane z = `planeZ` that pixel (x, y) of a read-back image
/// (top row first) shows through `view`, for an image of kRenderSize squared.
Vec3 pixelOnPlane(const runtime::ViewTransforms& view, std::uint32_t x, std::uint32_t y, float planeZ);
/// \brief The first point of the sphere (centre, radius) pixel (x, y) shows; false if none.
bool pixelOnSphere(const runtime::ViewTransforms& view, std::uint32_t x, std::uint32_t y, const Vec3& centre,
                   float radius, Vec3& hit);
/// \brief Where a world point lands in a read-back image (top row first), pixel coordinates.
Vec2 worldToPixel(const runtime::ViewTransforms& view, const Vec3& world);

/// \brief A square in the plane z = `z`, from -half to half, facing +Z, cut into n x n squares,
/// with polygon edges for each small square and texture coordinates 0..1.
std::shared_ptr<runtime::Mesh> makeQuad(float half = 1.0f, float z = 0.0f, int n = 1, const std::string& part = "quad");
/// \brief A UV sphere with smooth normals.
std::shared_ptr<runtime::Mesh> makeSphere(float radius, int rings, int segments, const std::string& part = "sphere");
/// \brief One mesh holding the parts of all `meshes` (index ranges moved along).
std::shared_ptr<runtime::Mesh> combine(const std::vector<std::shared_ptr<runtime::Mesh>>& meshes);
/// \brief A polyline through `points` (consecutive segments sharing vertices), as mesh lines.
std::shared_ptr<runtime::Mesh> makePolyline(const std::vector<Vec3>& points, const std::string& part);
/// \brief Loose points, as mesh points.
std::shared_ptr<runtime::Mesh> makePoints(const std::vector<Vec3>& points, const std::string& part);
/// \brief A show holding `mesh` at its original size (no normalisation), lights as LAVA sets them.
runtime::Show showOf(std::shared_ptr<const runtime::Mesh> mesh);
/// \brief Switches every light off.
void lightsOff(runtime::Show& show);

/// \brief Channel `c` of pixel (x, y) as 0..1.
inline double channel(const Image& image, std::uint32_t x, std::uint32_t y, std::uint32_t c) {
  return static_cast<double>(image.at(x, y, c)) / 255.0;
}
/// \brief A float widened on purpose (the tests compute references in double).
inline double wide(float v) { return static_cast<double>(v); }

/// \brief Compares with the golden image NAME under tests/render/golden ("" when it matches).
std::string matchesGolden(const Image& image, const std::string& name);

}  // namespace basalt::test
