// The visual aids of thesis §4.4.6 as geometry (runtime/cave_aids.h), on the thesis' displays:
// the wireframe holds every side of every facet, only the current facet is filled, the normal
// starts on that facet and points inwards, the viewer's cone has its apex at the viewer and opens
// along the line of sight, the line of sight ends at the collision point on the facet plane, up
// and right start there along the projection's vectors, and the outside camera sees the whole
// display, and a viewer behind the facet hides the vectors that only a visible facet has.
// Example failures: the normal drawn outwards (a display wound the other way); the cone pointing
// back at the viewer; every facet filled at once; a camera inside the display.

#include <gtest/gtest.h>

#include <cmath>

#include <fmt/format.h>

#include "runtime/cave_aids.h"
#include "runtime/facet_projection.h"
#include "runtime/formats/cave.h"
#include "support/polyhedra.h"

namespace basalt::runtime {
namespace {

std::shared_ptr<const formats::CaveGeometry> load(const std::string& obj) {
  std::vector<formats::Diagnostic> warnings;
  auto g = formats::parseCaveGeometry(obj, "display.obj", formats::LoadOptions{}, warnings);
  EXPECT_TRUE(g) << (g ? "" : g.error().describe());
  return std::make_shared<const formats::CaveGeometry>(g ? std::move(*g) : formats::CaveGeometry{});
}

const SceneNode& node(const Show& show, const char* name) {
  const auto id = show.findNode(name);
  EXPECT_TRUE(id) << name;
  return show.nodes()[id.value_or(0)];
}

bool selected(const Show& show, const char* part) {
  const auto id = show.findPart(part);
  EXPECT_TRUE(id) << part;
  return id && show.part(*id).selected;
}

Vec3 at(const Show& show, const char* name, const Vec3& local) {
  return show.worldTransform(*show.findNode(name)).transformPoint(local);
}

constexpr float kTol = 1e-4f;

void expectNear(const Vec3& a, const Vec3& b, float tol = kTol) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

TEST(CaveAids, EveryAidSitsWhereTheFacetViewPutsIt) {
  for (const std::string& obj : {test::cubeDisplayObj(), test::prismDisplayObj(), test::icositetrahedronDisplayObj()}) {
    const auto g = load(obj);
    auto aids = CaveAids::create(g);
    ASSERT_TRUE(aids) << aids.error().describe();
    const Show& show = aids->show();

    // The wireframe: one segment per side of every facet.
    std::size_t sides = 0;
    for (const auto& f : g->facets) sides += f.corners.size();
    EXPECT_EQ(node(show, "cave").mesh->lines.size(), 2 * sides);

    const Vec3 viewer{0.1f, -0.2f, 0.15f};  // a tracked head, off centre
    for (std::uint32_t k = 0; k < g->facets.size(); ++k) {
      SCOPED_TRACE(testing::Message() << g->facets.size() << " facets, facet " << k);
      const formats::CaveFacet& f = g->facets[k];
      FacetViewInput in;
      in.viewer = viewer;
      FacetProjection p;
      ASSERT_TRUE(computeFacetView(f, in, p));
      ASSERT_TRUE(p.visible);
      aids->update(k, p, viewer);
      EXPECT_EQ(aids->currentFacet(), k);
      for (std::uint32_t other = 0; other < g->facets.size(); ++other) {
        EXPECT_EQ(selected(show, fmt::format("facet {}", other).c_str()), other == k) << "facet part " << other;
      }
      // The normal starts at the facet's centroid, on its plane, and points into the display.
      const Vec3 base = at(show, "normal", {0, 0, 0});
      const Vec3 tip = at(show, "normal", {0, 0, 1});
      EXPECT_NEAR(dot(f.normal, base), f.planeOffset, kTol);
      EXPECT_GT(dot(tip - base, g->center - base), 0.0f) << "the normal points out of the display";
      EXPECT_NEAR(length(cross(normalize(tip - base), f.normal)), 0.0f, kTol);
      // The cone: apex at the viewer, opening along the line of sight (towards the facet).
      expectNear(at(show, "viewer", {0, 0, 0}), viewer);
      const Vec3 axis = at(show, "viewer", {0, 0, -1}) - viewer;
      EXPECT_GT(dot(normalize(axis), p.forward), 0.999f);
      // The line of sight runs from the viewer to the collision point, which is on the plane.
      expectNear(at(show, "line of sight", {0, 0, 0}), viewer);
      expectNear(at(show, "line of sight", {0, 0, 1}), p.collision);
      EXPECT_NEAR(dot(f.normal, p.collision), f.planeOffset, kTol);
      // Up and right start at the collision point along the projection's vectors.
      expectNear(at(show, "collision", {0, 0, 0}), p.collision);
      EXPECT_GT(dot(normalize(at(show, "up", {0, 0, 1}) - p.collision), p.up), 0.999f);
      EXPECT_GT(dot(normalize(at(show, "right", {0, 0, 1}) - p.collision), p.right), 0.999f);
      EXPECT_TRUE(selected(show, "line of sight"));
    }
  }
}

TEST(CaveAids, AViewerBehindTheFacetHidesTheVectors) {
  const auto g = load(test::cubeDisplayObj());
  auto aids = CaveAids::create(g);
  ASSERT_TRUE(aids);
  FacetViewInput in;
  in.viewer = {0, 0, -5};  // outside the cube, behind the back wall
  FacetProjection p;
  for (std::uint32_t k = 0; k < g->facets.size(); ++k) {
    ASSERT_TRUE(computeFacetView(g->facets[k], in, p));
    if (!p.visible) {
      aids->update(k, p, in.viewer);
      EXPECT_FALSE(selected(aids->show(), "line of sight"));
      EXPECT_FALSE(selected(aids->show(), "up"));
      EXPECT_FALSE(selected(aids->show(), "right"));
      EXPECT_FALSE(selected(aids->show(), "collision"));
      EXPECT_TRUE(selected(aids->show(), fmt::format("facet {}", k).c_str()));
      EXPECT_TRUE(selected(aids->show(), "viewer"));
      return;
    }
  }
  FAIL() << "no facet of the cube faces away from a viewer outside it";
}

TEST(CaveAids, TheOutsideCameraSeesTheWholeDisplay) {
  const auto g = load(test::icositetrahedronDisplayObj());
  auto aids = CaveAids::create(g);
  ASSERT_TRUE(aids);
  // Placed in the world turned, moved and scaled, seen from several directions and aspects.
  const Mat4 worldFromCave = Mat4::translation({3, -1, 2}) * Mat4::rotationY(30) * Mat4::scaling({2, 2, 2});
  for (const Vec3& from : {CaveAids::kDefaultFrom, Vec3{0, 1, 0}, Vec3{0, 0, -1}, Vec3{-2, -1, 0.5f}}) {
    for (const float aspect : {0.5f, 1.0f, 16.0f / 9.0f}) {
      const ViewTransforms t = aids->outsideView(worldFromCave, from, aspect);
      const Vec3 eyeCave = worldFromCave.inverted().transformPoint(t.eye);
      EXPECT_GT(length(eyeCave - g->center), aids->radius()) << "the camera is inside the display";
      for (const auto& f : g->facets) {
        for (const Vec3& c : f.corners) {
          const Vec3 world = worldFromCave.transformPoint(c);
          const Vec4 v = t.projection * (t.view * Vec4{world.x, world.y, world.z, 1});
          ASSERT_GT(v.w, 0.0f);
          EXPECT_LE(std::abs(v.x / v.w), 1.0f) << "a corner left of or right of the view";
          EXPECT_LE(std::abs(v.y / v.w), 1.0f) << "a corner above or below the view";
          EXPECT_LE(std::abs(v.z / v.w), 1.0f) << "a corner clipped by the near or far plane";
        }
      }
    }
  }
}

TEST(CaveAids, NeedsAGeometry) {
  EXPECT_FALSE(CaveAids::create(nullptr));
  EXPECT_FALSE(CaveAids::create(std::make_shared<const formats::CaveGeometry>()));
}

}  // namespace
}  // namespace basalt::runtime
