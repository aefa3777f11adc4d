// The facet view of thesis §4.4.3, checked numerically on the thesis' display geometries (a cube,
// a 10-facet prism, the 24-facet trapezoidal icositetrahedron), generated and read through the
// cave geometry loader: for every facet, seen from the centre and from a moved (tracked) viewer,
// the corners land inside the viewport with the extreme ones on its border, the image keeps the
// facet's aspect ratio, the near plane lies on the facet, and a point seen through the seam of
// two facets lands on both images at the same place along the shared side. Calibration (side,
// scales, skews, Z rotation, rear-projection flip) is checked against its definition.
// Example failures: a facet drawn stretched to the viewport (aspect lost); a near plane in front
// of the facet (the display geometry clips the world) or behind it (a gap at the seams); the
// image of one facet shifted against its neighbour at their common side; a side index that turns
// the wrong way; a viewer behind a facet producing NaN matrices.

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>
#include <utility>

#include "runtime/cave_keys.h"
#include "runtime/facet_projection.h"
#include "runtime/formats/cave.h"
#include "runtime/navigation.h"
#include "support/polyhedra.h"

namespace basalt::runtime {
namespace {

formats::CaveGeometry load(const std::string& obj, const char* name) {
  std::vector<formats::Diagnostic> warnings;
  formats::LoadOptions options;
  auto g = formats::parseCaveGeometry(obj, name, options, warnings);
  EXPECT_TRUE(g) << (g ? "" : g.error().describe());
  return g ? std::move(*g) : formats::CaveGeometry{};
}

struct Display {
  const char* name;
  std::string obj;
  std::size_t facets;
};

std::vector<Display> displays() {
  return {{"cube", test::cubeDisplayObj(), 6},
          {"prism", test::prismDisplayObj(), 10},
          {"icositetrahedron", test::icositetrahedronDisplayObj(), 24}};
}

// The facet's extent along the view's right and up directions (physical aspect ratio).
Vec2 extentInView(const formats::CaveFacet& f, const FacetProjection& p) {
  float minR = 1e9f, maxR = -1e9f, minU = 1e9f, maxU = -1e9f;
  for (const Vec3& c : f.corners) {
    minR = std::min(minR, dot(c, p.right)), maxR = std::max(maxR, dot(c, p.right));
    minU = std::min(minU, dot(c, p.up)), maxU = std::max(maxU, dot(c, p.up));
  }
  return {maxR - minR, maxU - minU};
}

void checkFacet(const formats::CaveFacet& f, const FacetViewInput& in, const std::string& what) {
  SCOPED_TRACE(what);
  FacetProjection p;
  ASSERT_TRUE(computeFacetView(f, in, p));
  ASSERT_TRUE(p.visible);
  ASSERT_EQ(p.border.size(), f.corners.size());
  float minX = 9, maxX = -9, minY = 9, maxY = -9;
  for (std::size_t i = 0; i < f.corners.size(); ++i) {
    const Vec3 ndc = projectCavePoint(p, in.worldFromCave, f.corners[i]);
    EXPECT_NEAR(ndc.x, p.border[i].x, 1e-5f);
    EXPECT_NEAR(ndc.y, p.border[i].y, 1e-5f);
    // The near plane lies on the facet: every corner is at NDC depth -1.
    EXPECT_NEAR(ndc.z, -1.0f, 2e-4f) << "corner " << i;
    minX = std::min(minX, ndc.x), maxX = std::max(maxX, ndc.x);
    minY = std::min(minY, ndc.y), maxY = std::max(maxY, ndc.y);
  }
  EXPECT_GE(minX, -1.0f - 1e-4f);
  EXPECT_LE(maxX, 1.0f + 1e-4f);
  EXPECT_GE(minY, -1.0f - 1e-4f);
  EXPECT_LE(maxY, 1.0f + 1e-4f);
  const bool fillsWidth = std::fabs(minX + 1) < 1e-4f && std::fabs(maxX - 1) < 1e-4f;
  const bool fillsHeight = std::fabs(minY + 1) < 1e-4f && std::fabs(maxY - 1) < 1e-4f;
  EXPECT_TRUE(fillsWidth || fillsHeight) << "x " << minX << ".." << maxX << " y " << minY << ".." << maxY;
  // Right aspect: the image's width : height in pixels is the facet's (seen square-on).
  const Vec2 extent = extentInView(f, p);
  const float imageAspect = (maxX - minX) * in.aspect / (maxY - minY);
  EXPECT_NEAR(imageAspect, extent.x / extent.y, 1e-3f * extent.x / extent.y);
  // The base side lies along the bottom of the viewport, left to right as the viewer sees it
  // (mirrored by the rear-projection flip).
  const Vec2 a = p.border[p.baseSide], b = p.border[(p.baseSide + 1) % f.corners.size()];
  EXPECT_NEAR(a.y, minY, 1e-4f);
  EXPECT_NEAR(b.y, minY, 1e-4f);
  // Points beyond the facet are drawn (depth inside -1..1), points between viewer and facet
  // are not (in front of the near plane).
  Vec3 centroid{};
  for (const Vec3& c : f.corners) centroid += c;
  centroid = centroid / static_cast<float>(f.corners.size());
  const Vec3 ray = centroid - in.viewer;
  EXPECT_GT(projectCavePoint(p, in.worldFromCave, in.viewer + ray * 1.5f).z, -1.0f);
  EXPECT_LT(projectCavePoint(p, in.worldFromCave, in.viewer + ray * 0.5f).z, -1.0f);
}

// Facets sharing a side, with the side's corners (as indices into each facet).
struct Seam {
  std::size_t f0, f1;
  Vec3 a, b;
};

std::vector<Seam> seams(const formats::CaveGeometry& g) {
  std::vector<Seam> out;
  for (std::size_t i = 0; i < g.facets.size(); ++i) {
    const auto& ci = g.facets[i].corners;
    for (std::size_t j = i + 1; j < g.facets.size(); ++j) {
      const auto& cj = g.facets[j].corners;
      std::vector<Vec3> shared;
      for (const Vec3& p : ci) {
        for (const Vec3& q : cj) {
          if (length(p - q) < 1e-4f) shared.push_back(p);
        }
      }
      if (shared.size() == 2) out.push_back({i, j, shared[0], shared[1]});
    }
  }
  return out;
}

// Where `p` lies along the projected segment a-b: the fraction and the distance off the line.
std::pair<float, float> alongSegment(Vec2 p, Vec2 a, Vec2 b) {
  const Vec2 d{b.x - a.x, b.y - a.y};
  const float len2 = d.x * d.x + d.y * d.y;
  const float t = ((p.x - a.x) * d.x + (p.y - a.y) * d.y) / len2;
  const float off = std::fabs((p.x - a.x) * d.y - (p.y - a.y) * d.x) / std::sqrt(len2);
  return {t, off};
}

FacetViewInput inputFor(const Vec3& viewer, float aspect) {
  FacetViewInput in;
  in.viewer = viewer;
  in.aspect = aspect;
  in.farDistance = 100;
  // The display placed somewhere in the world, turned: the view must not depend on it.
  in.worldFromCave = Mat4::translation({3, -2, 5}) * Mat4::rotationY(30) * Mat4::rotationX(-10);
  return in;
}

TEST(FacetProjection, EveryFacetOfTheThesisDisplaysFromTheCentreAndFromATrackedViewer) {
  for (const Display& d : displays()) {
    const formats::CaveGeometry g = load(d.obj, d.name);
    ASSERT_EQ(g.facets.size(), d.facets) << d.name;
    for (const auto& f : g.facets) EXPECT_TRUE(f.facesInward) << d.name << " line " << f.line;
    const Vec3 moved = g.center + Vec3{0.21f, -0.13f, 0.17f};
    for (const float aspect : {16.0f / 9.0f, 1.0f, 0.75f}) {
      for (std::size_t i = 0; i < g.facets.size(); ++i) {
        checkFacet(g.facets[i], inputFor(g.center, aspect), fmt::format("{} facet {} aspect {}", d.name, i, aspect));
        checkFacet(g.facets[i], inputFor(moved, aspect), fmt::format("{} facet {} moved viewer", d.name, i));
      }
    }
  }
}

TEST(FacetProjection, APointSeenThroughASeamLandsOnBothImagesAtTheSamePlace) {
  for (const Display& d : displays()) {
    const formats::CaveGeometry g = load(d.obj, d.name);
    const auto all = seams(g);
    ASSERT_GE(all.size(), d.facets) << d.name;  // every facet has neighbours
    for (const Vec3& viewer : {g.center, g.center + Vec3{-0.2f, 0.1f, 0.25f}}) {
      const FacetViewInput in = inputFor(viewer, 4.0f / 3.0f);
      for (const Seam& s : all) {
        FacetProjection p0, p1;
        ASSERT_TRUE(computeFacetView(g.facets[s.f0], in, p0));
        ASSERT_TRUE(computeFacetView(g.facets[s.f1], in, p1));
        // A world point far outside the display, seen exactly through the seam 30% along it.
        const Vec3 onSeam = s.a + (s.b - s.a) * 0.3f;
        const Vec3 world = viewer + (onSeam - viewer) * 7.0f;
        const Vec3 a0 = projectCavePoint(p0, in.worldFromCave, s.a), b0 = projectCavePoint(p0, in.worldFromCave, s.b);
        const Vec3 a1 = projectCavePoint(p1, in.worldFromCave, s.a), b1 = projectCavePoint(p1, in.worldFromCave, s.b);
        const Vec3 w0 = projectCavePoint(p0, in.worldFromCave, world),
                   w1 = projectCavePoint(p1, in.worldFromCave, world);
        const auto [t0, off0] = alongSegment({w0.x, w0.y}, {a0.x, a0.y}, {b0.x, b0.y});
        const auto [t1, off1] = alongSegment({w1.x, w1.y}, {a1.x, a1.y}, {b1.x, b1.y});
        SCOPED_TRACE(fmt::format("{} facets {} and {}", d.name, s.f0, s.f1));
        EXPECT_NEAR(t0, 0.3f, 1e-4f);
        EXPECT_NEAR(t1, 0.3f, 1e-4f);
        EXPECT_LT(off0, 1e-4f);
        EXPECT_LT(off1, 1e-4f);
        // Beyond the near plane in both views: drawn, not clipped.
        EXPECT_GT(w0.z, -1.0f);
        EXPECT_GT(w1.z, -1.0f);
      }
    }
  }
}

TEST(FacetProjection, CalibrationActsAsTheCaveFileSays) {
  const formats::CaveGeometry g = load(test::prismDisplayObj(), "prism");
  const formats::CaveFacet& f = g.facets[3];
  FacetViewInput in = inputFor(g.center, 1.0f);
  FacetProjection base;
  ASSERT_TRUE(computeFacetView(f, in, base));

  // side: the next side goes to the bottom.
  in.calibration.side = 1;
  FacetProjection side;
  ASSERT_TRUE(computeFacetView(f, in, side));
  EXPECT_EQ(side.baseSide, (base.baseSide + 1) % f.corners.size());
  EXPECT_GT(std::fabs(dot(side.up, base.up)), -1.0f);
  EXPECT_LT(dot(side.up, base.up), 0.5f);  // a rectangle's neighbour side: up turned 90 degrees
  in.calibration.side = 0;

  // Scale 2 horizontally: the image is half as wide about the same centre.
  in.calibration.xScale = 2;
  FacetProjection scaled;
  ASSERT_TRUE(computeFacetView(f, in, scaled));
  for (std::size_t i = 0; i < f.corners.size(); ++i) {
    EXPECT_NEAR(scaled.border[i].x, base.border[i].x * 0.5f, 1e-5f);
    EXPECT_NEAR(scaled.border[i].y, base.border[i].y, 1e-5f);
  }
  in.calibration.xScale = 1;

  // Front projection: the rear-projection flip undone mirrors x.
  in.rearProjection = false;
  FacetProjection front;
  ASSERT_TRUE(computeFacetView(f, in, front));
  for (std::size_t i = 0; i < f.corners.size(); ++i) EXPECT_NEAR(front.border[i].x, -base.border[i].x, 1e-5f);
  in.rearProjection = true;

  // Horizontal skew of 20 degrees: x moves by tan(20°) · y.
  in.calibration.xSkew = 20;
  FacetProjection skewed;
  ASSERT_TRUE(computeFacetView(f, in, skewed));
  for (std::size_t i = 0; i < f.corners.size(); ++i) {
    EXPECT_NEAR(skewed.border[i].x, base.border[i].x + std::tan(radians(20)) * base.border[i].y, 1e-5f);
  }
  in.calibration.xSkew = 0;

  // Z rotation of 90 degrees turns up onto the old right (or left) direction.
  in.calibration.zRotation = 90;
  FacetProjection turned;
  ASSERT_TRUE(computeFacetView(f, in, turned));
  EXPECT_NEAR(std::fabs(dot(turned.up, base.right)), 1.0f, 1e-5f);
  EXPECT_NEAR(turned.nearDistance, base.nearDistance, 1e-6f);
}

TEST(FacetProjection, AViewerBehindTheFacetIsNotVisibleAndGivesNoNaN) {
  const formats::CaveGeometry g = load(test::cubeDisplayObj(), "cube");
  FacetViewInput in = inputFor(g.center, 1.0f);
  for (const auto& f : g.facets) {
    in.viewer = f.corners[0] - f.normal * 0.5f;  // outside, behind the facet
    FacetProjection p;
    ASSERT_TRUE(computeFacetView(f, in, p));
    EXPECT_FALSE(p.visible);
    EXPECT_TRUE(p.border.empty());
  }
  formats::CaveFacet degenerate;
  degenerate.corners = {{0, 0, 0}, {1, 0, 0}};
  FacetProjection p;
  EXPECT_FALSE(computeFacetView(degenerate, in, p));
}

}  // namespace
}  // namespace basalt::runtime

// The thesis' adjustment keys (Appendix B) on Linux key codes, shift from the shift keys' own
// events. Example failure: shift stuck after its release (m changes Xscale); a side index past
// the facet's corners saved into the cave file (which then no longer loads).
namespace basalt::runtime {
namespace {

Event key(std::uint16_t code, double value = 1) {
  Event e;
  e.kind = EventKind::kKey;
  e.index = code;
  e.value = value;
  return e;
}

TEST(CaveKeys, AppendixBKeysAdjustTheCalibration) {
  std::vector<formats::Diagnostic> warnings;
  auto g = formats::parseCaveGeometry(test::prismDisplayObj(), "prism.obj", {}, warnings);
  ASSERT_TRUE(g);
  CaveKeys keys;
  formats::CaveSettings cave;
  float spacing = 0.06f;
  EXPECT_EQ(keys.apply(key(50), cave, *g, spacing), CaveKeyEffect::kCalibration);  // m: Yscale large down
  EXPECT_FLOAT_EQ(cave.yScale, 0.9f);
  EXPECT_FLOAT_EQ(cave.xScale, 1.0f);
  keys.apply(key(42), cave, *g, spacing);  // left shift down
  keys.apply(key(53), cave, *g, spacing);  // ?: Xscale large up
  EXPECT_FLOAT_EQ(cave.xScale, 1.1f);
  keys.apply(key(39), cave, *g, spacing);  // ':' Xskew small up
  EXPECT_FLOAT_EQ(cave.xSkew, 0.5f);
  keys.apply(key(27), cave, *g, spacing);  // '}' eye spacing large up
  EXPECT_FLOAT_EQ(spacing, 0.07f);
  for (int i = 0; i < 5; ++i) keys.apply(key(31), cave, *g, spacing);  // S five times on a 4-sided wall
  EXPECT_EQ(cave.side, 1u);
  keys.apply(key(42, 0), cave, *g, spacing);  // shift released
  keys.apply(key(38), cave, *g, spacing);     // l: Yskew small down
  EXPECT_FLOAT_EQ(cave.ySkew, -0.5f);
  EXPECT_FLOAT_EQ(cave.xSkew, 0.5f);
  EXPECT_EQ(keys.apply(key(31), cave, *g, spacing), CaveKeyEffect::kNone);  // plain s is not S
  keys.apply(key(109), cave, *g, spacing);                                  // PgDown from 0 wraps
  EXPECT_EQ(cave.facet, 9u);
  EXPECT_EQ(cave.side, 0u);
  keys.apply(key(107), cave, *g, spacing);  // End: long side to the top
  EXPECT_FLOAT_EQ(cave.zRotation, 180.0f);
  EXPECT_EQ(keys.apply(key(50, 0), cave, *g, spacing), CaveKeyEffect::kNone);  // releases change nothing
}

}  // namespace
}  // namespace basalt::runtime

// Navigation (thesis §5.1, Appendix B, §4.6): held arrow keys move the viewer at the scene's
// speed along its heading, pointer motion pans and tilts, the map bounds hold, and on a terrain
// the eye follows the ground. Example failures: forward moving along +Z; a tilt past vertical;
// the viewer walking through a hill at its old height.
namespace basalt::runtime {
namespace {

TEST(Navigation, ArrowKeysWalkThePointerTurnsAndTheTerrainCarries) {
  Show show;
  Viewer& v = show.viewer();
  v.positionSpeed = 2.0f;
  v.rotationSpeed = 0.5f;
  Navigator nav(1.5f);
  EXPECT_TRUE(nav.apply(key(103), show));  // up arrow held
  nav.advance(0.5, show);
  EXPECT_NEAR(v.position.z, -1.0f, 1e-6f);
  EXPECT_NEAR(v.position.x, 0.0f, 1e-6f);
  nav.apply(key(103, 0), show);
  Event pan;
  pan.kind = EventKind::kPointerMotion;
  pan.index = 0;
  pan.value = -180;  // pointer 180 px left: turn left by 90 degrees
  EXPECT_TRUE(nav.apply(pan, show));
  EXPECT_NEAR(v.rotation.y, 90.0f, 1e-4f);
  nav.apply(key(103), show);
  nav.advance(0.5, show);  // heading +90: forward is -X
  EXPECT_NEAR(v.position.x, -1.0f, 1e-5f);
  pan.index = 1;
  pan.value = -1000;
  nav.apply(pan, show);
  EXPECT_FLOAT_EQ(v.rotation.x, -89.0f);  // pointer forward tilts down, clamped short of vertical
  v.mapMin = {-1.5f, -10, -10};
  nav.advance(10, show);
  EXPECT_FLOAT_EQ(v.position.x, -1.5f);  // held at the map's edge

  // A ramp rising along X; the eye stays 1.5 above it.
  auto ramp = std::make_shared<HeightField>();
  ramp->columns = 11, ramp->rows = 11, ramp->spacing = 1, ramp->origin = {-5, 0, -5};
  for (std::uint32_t j = 0; j < 11; ++j) {
    for (std::uint32_t i = 0; i < 11; ++i) ramp->heights.push_back(static_cast<float>(i) * 0.5f);
  }
  SceneNode ground;
  ground.name = "ground";
  show.addTerrain(ground, ramp);
  v.followTerrain = true;
  v.mapMin = {-1000, -1000, -1000};
  v.position = {0, 0, 0};
  v.rotation = {0, -90, 0};  // heading -90: forward is +X
  nav.advance(1, show);
  EXPECT_NEAR(v.position.x, 2.0f, 1e-4f);
  EXPECT_NEAR(v.position.y, (2.0f + 5.0f) * 0.5f + 1.5f, 1e-4f);
  nav.apply(key(103, 0), show);
  nav.apply(key(78), show);  // keypad +: up, lost at the next horizontal move
  nav.advance(1, show);
  EXPECT_NEAR(v.position.y, 5.0f + 2.0f, 1e-4f);
}

}  // namespace
}  // namespace basalt::runtime
