// Polygon geometry shared by the loaders: triangulation always gives n - 2 triangles that cover
// the polygon and keep its winding, in any orientation in space; the shape measures that cave
// validation relies on (normal, area, flatness, convexity, longest side).
// Example failures: a concave polygon triangulated across its notch; a polygon facing -X
// triangulated with flipped triangles; a slightly bent facet called flat.

#include <gtest/gtest.h>

#include <cmath>

#include "runtime/formats/polygon.h"

namespace basalt::formats {
namespace {

double area(const std::vector<Vec3>& p, const std::vector<std::uint32_t>& tris, const Vec3& normal, bool& flipped) {
  double sum = 0;
  flipped = false;
  for (std::size_t i = 0; i < tris.size(); i += 3) {
    const Vec3 c = cross(p[tris[i + 1]] - p[tris[i]], p[tris[i + 2]] - p[tris[i]]);
    if (dot(c, normal) < -1e-6f) flipped = true;
    sum += 0.5 * static_cast<double>(length(c));
  }
  return sum;
}

TEST(Polygon, ConcaveShapesInEveryOrientation) {
  // A "comb" with three notches: area 5 x 3 minus two 1 x 2 notches = 11.
  const std::vector<Vec3> flat = {{0, 0, 0}, {5, 0, 0}, {5, 3, 0}, {4, 3, 0}, {4, 1, 0}, {3, 1, 0},
                                  {3, 3, 0}, {2, 3, 0}, {2, 1, 0}, {1, 1, 0}, {1, 3, 0}, {0, 3, 0}};
  const Mat4 turns[] = {Mat4{},
                        Mat4::rotationY(90),
                        Mat4::rotationY(-90),
                        Mat4::rotationX(90),
                        Mat4::rotationX(180),
                        Mat4::rotation(37, normalize(Vec3{1, 2, 3}))};
  for (const Mat4& turn : turns) {
    std::vector<Vec3> p(flat.size());
    for (std::size_t i = 0; i < flat.size(); ++i) p[i] = turn.transformPoint(flat[i]);
    std::vector<std::uint32_t> tris;
    ASSERT_TRUE(triangulatePolygon(p, tris, 1'000'000));
    ASSERT_EQ(tris.size(), 3 * (p.size() - 2));
    bool flipped = false;
    EXPECT_NEAR(area(p, tris, turn.transformDirection({0, 0, 1}), flipped), 11.0, 1e-4);
    EXPECT_FALSE(flipped);
  }
}

TEST(Polygon, TheBudgetBoundsTheWorkAndStillGivesNMinusTwo) {
  std::vector<Vec3> zigzag(400);
  for (std::size_t i = 0; i < 400; ++i) zigzag[i] = {static_cast<float>(i), (i % 2) ? 1.0f : 0.0f, 0};
  zigzag.push_back({399, -5, 0});
  zigzag.push_back({0, -5, 0});
  std::vector<std::uint32_t> tris;
  EXPECT_FALSE(triangulatePolygon(zigzag, tris, 1000)) << "the budget runs out";
  EXPECT_EQ(tris.size(), 3 * (zigzag.size() - 2));
  tris.clear();
  EXPECT_TRUE(triangulatePolygon(zigzag, tris, 100'000'000));
  bool flipped = false;
  const double expected = 399 * 5 + 399 * 0.5;  // the band under the zigzag plus its teeth
  EXPECT_NEAR(area(zigzag, tris, {0, 0, -1}, flipped), expected, 1e-2) << "(the zigzag runs clockwise)";
  EXPECT_FALSE(flipped);
}

TEST(Polygon, ShapeMeasures) {
  const PolygonShape square = measurePolygon(std::vector<Vec3>{{0, 0, 2}, {2, 0, 2}, {2, 1, 2}, {0, 1, 2}});
  EXPECT_EQ(square.normal, (Vec3{0, 0, 1}));
  EXPECT_FLOAT_EQ(square.planeOffset, 2.0f);
  EXPECT_FLOAT_EQ(square.area, 2.0f);
  EXPECT_EQ(square.reflexCorner, -1);
  EXPECT_EQ(square.longestSide, 0u);
  EXPECT_FALSE(square.degenerate);
  EXPECT_FLOAT_EQ(square.maxPlaneDistance, 0.0f);
  const PolygonShape bent = measurePolygon(std::vector<Vec3>{{0, 0, 0}, {1, 0, 0}, {1, 1, 0.1f}, {0, 1, 0}});
  EXPECT_GT(bent.maxPlaneDistance, 0.01f);
  const PolygonShape dart = measurePolygon(std::vector<Vec3>{{0, 0, 0}, {2, 1, 0}, {0, 2, 0}, {0.5f, 1, 0}});
  EXPECT_EQ(dart.reflexCorner, 3);
  EXPECT_TRUE(measurePolygon(std::vector<Vec3>{{0, 0, 0}, {1, 1, 1}, {2, 2, 2}}).degenerate);
  // Collinear corners along a side keep a polygon convex.
  EXPECT_EQ(measurePolygon(std::vector<Vec3>{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {2, 2, 0}, {0, 2, 0}}).reflexCorner, -1);
}

}  // namespace
}  // namespace basalt::formats
