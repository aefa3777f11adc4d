// Cave files (thesis C.1) and cave geometry: every statement in both its forms, the thesis'
// rules (Zrotation only after a model; several cave files in succession), facets validated as
// flat convex polygons with the failing facet named, and the written file reading back the same.
// Example failures: a twisted facet accepted (the projection would be wrong on site); a concave
// facet reported without saying which; a second cave file that forgets the first's model; a
// facet index past the geometry's end accepted.

#include <gtest/gtest.h>

#include <fstream>

#include "formats_test_util.h"
#include "runtime/formats/cave.h"
#include "support/test_paths.h"

namespace basalt::formats {
namespace {

// A unit cube seen from inside: every facet's corners run counter-clockwise from the inside.
constexpr const char* kCube =
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
    "f 1 5 6 2\nf 4 3 7 8\nf 1 2 3 4\nf 5 8 7 6\nf 1 4 8 5\nf 2 6 7 3\n";

Result<CaveGeometry> geometry(std::string_view text, std::vector<Diagnostic>& warnings) {
  return parseCaveGeometry(text, "cave.obj", test::quiet(), warnings);
}

TEST(Cave, EveryStatementInBracketAndPlainForm) {
  auto parsed = parseCaveText(
      "# a cave\nmodel room.obj\nfacet[3]\nside 2\nXscale[1.5]\nYscale 0.5\nXskew[-10]\nYskew [20]\nZrotation[90]\n",
      "a.cave", {}, false);
  ASSERT_TRUE(parsed) << parsed.error().describe();
  const CaveSettings& s = parsed->settings;
  EXPECT_EQ(s.model, "room.obj");
  EXPECT_EQ(s.facet, 3u);
  EXPECT_EQ(s.side, 2u);
  EXPECT_EQ(s.xScale, 1.5f);
  EXPECT_EQ(s.yScale, 0.5f);
  EXPECT_EQ(s.xSkew, -10.0f);
  EXPECT_EQ(s.ySkew, 20.0f);
  EXPECT_EQ(s.zRotation, 90.0f);
  EXPECT_EQ(parsed->modelLine, 2u);
}

TEST(Cave, DefaultsAreTheThesis) {
  const CaveSettings s;
  EXPECT_EQ(s.facet, 0u);
  EXPECT_EQ(s.side, 0u);
  EXPECT_EQ(s.xScale, 1.0f);
  EXPECT_EQ(s.yScale, 1.0f);
  EXPECT_EQ(s.xSkew, 0.0f);
  EXPECT_EQ(s.zRotation, 0.0f);
}

TEST(Cave, ErrorsRejectTheWholeFileAndSayWhere) {
  const struct {
    const char* text;
    const char* message;
  } cases[] = {
      {"Zrotation[10]\nmodel x.obj\n", "b.cave:1:1: Zrotation cannot be set before a model is named"},
      {"model x.obj\nfacet[-1]\n", "b.cave:2:7: '-1' is not a facet index"},
      {"model x.obj\nXscale[0]\n", "b.cave:2:8: Xscale must be more than 0"},
      {"model x.obj\nXskew[95]\n", "b.cave:2:7: Xskew is an angle in degrees between -90 and 90"},
      {"model x.obj\nfacet[1\n", "b.cave:2:6: '[' is not closed by ']'"},
      {"model x.obj\nzoom[2]\n", "b.cave:2:1: 'zoom' is not a cave statement"},
      {"model\n", "b.cave:1:1: 'model' needs the name of the cave geometry's OBJ file"},
      {"facet[1] side[2]\n", "b.cave:1:1: 'facet' takes one value in brackets"},
  };
  for (const auto& c : cases) {
    auto parsed = parseCaveText(c.text, "b.cave", {}, false);
    ASSERT_FALSE(parsed) << c.text;
    EXPECT_EQ(parsed.error().describe().rfind(c.message, 0), 0u) << parsed.error().describe();
  }
}

TEST(Cave, ZrotationIsAllowedWhenAnEarlierFileNamedTheModel) {
  EXPECT_TRUE(parseCaveText("Zrotation[45]\n", "c.cave", {}, true));
}

TEST(CaveGeometry, ACubeSeenFromInsideHasSixFlatConvexInwardFacets) {
  std::vector<Diagnostic> warnings;
  auto g = geometry(kCube, warnings);
  ASSERT_TRUE(g) << g.error().describe();
  ASSERT_EQ(g->facets.size(), 6u);
  EXPECT_TRUE(warnings.empty()) << test::listWarnings(warnings);
  EXPECT_EQ(g->center, (Vec3{0.5f, 0.5f, 0.5f}));
  const CaveFacet& floor = g->facets[0];
  EXPECT_EQ(floor.normal, (Vec3{0, 1, 0}));
  EXPECT_FLOAT_EQ(floor.planeOffset, 0.0f);
  EXPECT_FLOAT_EQ(floor.area, 1.0f);
  EXPECT_EQ(floor.corners.size(), 4u);
  EXPECT_EQ(floor.line, 9u);
  for (const CaveFacet& f : g->facets) EXPECT_TRUE(f.facesInward);
}

TEST(CaveGeometry, LongestSideIsFound) {
  std::vector<Diagnostic> warnings;
  auto g = geometry("v 0 0 0\nv 3 0 0\nv 3 1 0\nv 0 1 0\nf 2 3 4 1\n", warnings);
  ASSERT_TRUE(g) << g.error().describe();
  EXPECT_EQ(g->facets[0].longestSide, 1u) << "from corner 1 (3,1) to corner 2 (0,1)";
}

TEST(CaveGeometry, TwistedConcaveAndDegenerateFacetsAreRejectedByNumber) {
  const struct {
    const char* text;
    const char* message;
  } cases[] = {
      {"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0.2\nv 0 0 1\nf 1 2 5\nf 1 2 3 4\n", "cave.obj:7: facet 1 is not flat"},
      {"v 0 0 0\nv 2 0 0\nv 2 2 0\nv 1 0.5 0\nv 0 2 0\nf 1 2 3 4 5\n",
       "cave.obj:6: facet 0 is not convex: its outline turns the other way at corner 3"},
      {"v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n", "cave.obj:4: facet 0 has no area"},
      {"v 0 0 0\nv 1 0 0\nf 1 2\n", "cave.obj:3: facet 0 has 2 corners"},
      {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", "cave.obj:4:7: facet 0: '4' is not a vertex index"},
      {"v 0 0 0\n", "cave.obj: the cave geometry has no facets"},
      {"v 0 0 nan\n", "cave.obj:1:7: 'nan' is not a finite number"},
  };
  for (const auto& c : cases) {
    std::vector<Diagnostic> warnings;
    auto g = geometry(c.text, warnings);
    ASSERT_FALSE(g) << c.text;
    EXPECT_EQ(g.error().describe().rfind(c.message, 0), 0u) << g.error().describe();
  }
}

TEST(CaveGeometry, OutwardFacetsAndOtherStatementsAreWarnedAbout) {
  std::vector<Diagnostic> warnings;
  // The cube with its last facet's corners reversed (facing out), plus normals that are ignored.
  std::string text = kCube;
  text.replace(text.find("f 2 6 7 3"), 9, "f 3 7 6 2");
  text += "vn 0 0 1\nusemtl x\n";
  auto g = geometry(text, warnings);
  ASSERT_TRUE(g) << g.error().describe();
  EXPECT_FALSE(g->facets[5].facesInward);
  EXPECT_TRUE(test::hasWarning(warnings, "facet 5 faces outward")) << test::listWarnings(warnings);
  EXPECT_TRUE(test::hasWarning(warnings, "2 statements other than 'v' and 'f' were ignored"))
      << test::listWarnings(warnings);
}

TEST(CaveFiles, LoadValidateAndReadInSuccession) {
  const auto dir = basalt::test::scratchDir("cave-files");
  std::ofstream(dir / "cube.obj") << kCube;
  std::ofstream(dir / "first.cave") << "model cube.obj\nfacet[2]\nside[1]\nXscale[1.25]\n";
  std::ofstream(dir / "second.cave") << "facet[4]\nZrotation[30]\n";
  std::ofstream(dir / "bad-facet.cave") << "facet[6]\n";
  std::ofstream(dir / "bad-side.cave") << "side[4]\n";
  auto first = loadCave(dir / "first.cave", nullptr, test::quiet());
  ASSERT_TRUE(first) << first.error().describe();
  ASSERT_TRUE(first->geometry);
  EXPECT_EQ(first->geometry->facets.size(), 6u);
  auto second = loadCave(dir / "second.cave", &*first, test::quiet());
  ASSERT_TRUE(second) << second.error().describe();
  EXPECT_EQ(second->geometry, first->geometry) << "the model carries over";
  EXPECT_EQ(second->settings.facet, 4u);
  EXPECT_EQ(second->settings.side, 1u);
  EXPECT_EQ(second->settings.xScale, 1.25f);
  EXPECT_EQ(second->settings.zRotation, 30.0f);
  auto badFacet = loadCave(dir / "bad-facet.cave", &*second, test::quiet());
  ASSERT_FALSE(badFacet);
  EXPECT_NE(badFacet.error().describe().find("bad-facet.cave:1: facet 6 does not exist"), std::string::npos)
      << badFacet.error().describe();
  auto badSide = loadCave(dir / "bad-side.cave", &*second, test::quiet());
  ASSERT_FALSE(badSide);
  EXPECT_NE(badSide.error().describe().find("side 4 does not exist: facet 4 has sides 0 to 3"), std::string::npos)
      << badSide.error().describe();
}

TEST(CaveFiles, AMissingOrInvalidGeometryRejectsTheCaveFile) {
  const auto dir = basalt::test::scratchDir("cave-geometry-errors");
  std::ofstream(dir / "twisted.obj") << "v 0 0 0\nv 1 0 0\nv 1 1 0.5\nv 0 1 0\nf 1 2 3 4\n";
  std::ofstream(dir / "a.cave") << "model missing.obj\n";
  std::ofstream(dir / "b.cave") << "# twisted\nmodel twisted.obj\n";
  auto a = loadCave(dir / "a.cave", nullptr, test::quiet());
  ASSERT_FALSE(a);
  EXPECT_EQ(a.error().code(), Errc::kNotFound);
  EXPECT_NE(a.error().describe().find("a.cave:1"), std::string::npos);
  auto b = loadCave(dir / "b.cave", nullptr, test::quiet());
  ASSERT_FALSE(b);
  EXPECT_NE(b.error().describe().find("twisted.obj:5: the cave geometry named on line 2"), std::string::npos)
      << b.error().describe();
  EXPECT_NE(b.error().describe().find("facet 0 is not flat"), std::string::npos) << b.error().describe();
}

TEST(CaveFiles, WrittenCavesReadBackTheSame) {
  const auto dir = basalt::test::scratchDir("cave-roundtrip");
  std::ofstream(dir / "cube.obj") << kCube;
  CaveSettings s;
  s.model = "cube.obj";
  s.facet = 5;
  s.side = 3;
  s.xScale = 0.875f;
  s.yScale = 1.0625f;
  s.xSkew = -2.5f;
  s.ySkew = 0.1f;
  s.zRotation = 180.0f;
  ASSERT_TRUE(writeCave(dir / "out.cave", s));
  auto back = loadCave(dir / "out.cave", nullptr, test::quiet());
  ASSERT_TRUE(back) << back.error().describe();
  EXPECT_EQ(back->settings, s);
  CaveSettings noModel;
  noModel.zRotation = 10;
  EXPECT_FALSE(writeCave(dir / "invalid.cave", noModel)) << "Zrotation without a model cannot be written";
}

}  // namespace
}  // namespace basalt::formats
