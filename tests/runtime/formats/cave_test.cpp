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

TEST(CaveGeometry, OtherStatementsAreWarnedAboutAndOutwardFacetsMarked) {
  std::vector<Diagnostic> warnings;
  // The cube with its last facet's corners reversed (facing out), plus normals that are ignored.
  std::string text = kCube;
  text.replace(text.find("f 2 6 7 3"), 9, "f 3 7 6 2");
  text += "vn 0 0 1\nusemtl x\n";
  auto g = geometry(text, warnings);
  ASSERT_TRUE(g) << g.error().describe();
  EXPECT_FALSE(g->facets[5].facesInward);
  // The facing is said once for the whole geometry (caveFacingProblem), not per facet here.
  EXPECT_FALSE(test::hasWarning(warnings, "facet 5")) << test::listWarnings(warnings);
  EXPECT_EQ(warnings.size(), 1u) << test::listWarnings(warnings);
  EXPECT_TRUE(test::hasWarning(warnings, "2 statements other than 'v' and 'f' were ignored"))
      << test::listWarnings(warnings);
}

// The facing rules come from the thesis, not from the code under test:
//   §4.2.1: "If its vertices are oriented in clockwise order from the point of view of the
//   viewer, they represent a back-face, and are not drawn (culled)."
//   §4.4.3: "The default viewer position is the origin of the display geometry."
//   §4.4.1: "limiting it to a convex polyhedron ... with all facets facing inward ensures that
//   each facet is visible from any position within the SID."
// A cube -1..1 around the origin wound inward, and the same file with each `f` line reversed.
constexpr const char* kCentredCube =
    "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n"
    "f 2 6 7 3\nf 5 1 4 8\nf 4 3 7 8\nf 1 5 6 2\nf 6 5 8 7\nf 1 2 3 4\n";

std::string reversed(std::string_view obj) {
  std::string out;
  std::size_t at = 0;
  while (at < obj.size()) {
    const std::size_t end = obj.find('\n', at);
    std::string line(obj.substr(at, end - at));
    at = end == std::string_view::npos ? obj.size() : end + 1;
    if (line.rfind("f ", 0) == 0) {
      std::vector<std::string> corners;
      for (std::size_t p = 2; p < line.size();) {
        const std::size_t space = std::min(line.find(' ', p), line.size());
        corners.push_back(line.substr(p, space - p));
        p = space + 1;
      }
      line = "f";
      for (auto c = corners.rbegin(); c != corners.rend(); ++c) line += " " + *c;
    }
    out += line + "\n";
  }
  return out;
}

// Makes sure an outward-wound display (the usual export of modelling tools) is told apart from
// an inward one by where the thesis' viewer stands, said in one warning that names the file and
// every facet's line and offers both fixes. Example failures: one warning per facet (32 for a
// truncated icosahedron); no line; an inward display flagged.
TEST(CaveFacing, AnOutwardWoundDisplayIsSaidOnceWithItsLinesAndTheFix) {
  std::vector<Diagnostic> warnings;
  auto inward = geometry(kCentredCube, warnings);
  ASSERT_TRUE(inward) << inward.error().describe();
  EXPECT_FALSE(caveFacingProblem(*inward, FacetWinding::kInward));
  auto outward = geometry(reversed(kCentredCube), warnings);
  ASSERT_TRUE(outward) << outward.error().describe();
  EXPECT_TRUE(warnings.empty()) << test::listWarnings(warnings);
  // The viewer at the origin is on the back of every facet: dot(normal, 0) - offset < 0.
  for (const CaveFacet& f : outward->facets) {
    EXPECT_LT(dot(f.normal, Vec3{0, 0, 0}) - f.planeOffset, 0.0f) << f.line;
    EXPECT_FALSE(f.facesViewer) << f.line;
  }
  const auto problem = caveFacingProblem(*outward, FacetWinding::kInward);
  ASSERT_TRUE(problem);
  EXPECT_EQ(problem->where, "cave.obj:9");
  EXPECT_NE(problem->message.find("all 6 facets face away from the viewer (lines 9-14)"), std::string::npos)
      << problem->message;
  EXPECT_NE(problem->message.find("winding = \"outward\""), std::string::npos) << problem->message;
  EXPECT_NE(problem->message.find("reverse the order of the corners"), std::string::npos) << problem->message;
  // Said the right way round: with the option the outward file is fine, the inward one is not.
  EXPECT_FALSE(caveFacingProblem(*outward, FacetWinding::kOutward));
  EXPECT_FALSE(caveFacingProblem(*outward, FacetWinding::kAuto));
  const auto backwards = caveFacingProblem(*inward, FacetWinding::kOutward);
  ASSERT_TRUE(backwards);
  EXPECT_NE(backwards->message.find("wound inward"), std::string::npos) << backwards->message;
  EXPECT_FALSE(caveFacingProblem(*inward, FacetWinding::kAuto));
}

// Makes sure turning an outward-wound display's facets gives exactly the inward file's facets
// (same corners in the same order, so the same longest side, normal and plane), and that "auto"
// turns only the facets seen from behind. Example failures: a turned facet whose longest side
// moved (the picture turned by 90 degrees on a square wall); "auto" turning good facets.
TEST(CaveFacing, TurningAnOutwardDisplayGivesTheInwardOne) {
  std::vector<Diagnostic> warnings;
  auto inward = geometry(kCentredCube, warnings);
  auto outward = geometry(reversed(kCentredCube), warnings);
  ASSERT_TRUE(inward && outward);
  const CaveGeometry turned = windFacets(*outward, FacetWinding::kOutward);
  ASSERT_EQ(turned.facets.size(), inward->facets.size());
  for (std::size_t i = 0; i < turned.facets.size(); ++i) {
    const CaveFacet& a = turned.facets[i];
    const CaveFacet& b = inward->facets[i];
    EXPECT_EQ(a.corners, b.corners) << i;
    EXPECT_EQ(a.normal, b.normal) << i;
    EXPECT_EQ(a.planeOffset, b.planeOffset) << i;
    EXPECT_EQ(a.longestSide, b.longestSide) << i;
    EXPECT_TRUE(a.facesViewer && a.facesInward) << i;
    EXPECT_EQ(a.line, b.line) << i;
  }
  // One facet reversed: "auto" turns that one only; the message names it and its line.
  std::string mixed = kCentredCube;
  mixed.replace(mixed.find("f 4 3 7 8"), 9, "f 8 7 3 4");
  auto one = geometry(mixed, warnings);
  ASSERT_TRUE(one);
  const auto problem = caveFacingProblem(*one, FacetWinding::kInward);
  ASSERT_TRUE(problem);
  EXPECT_EQ(problem->where, "cave.obj:11");
  EXPECT_NE(problem->message.find("facet 2 of 6 faces away from the viewer (line 11)"), std::string::npos)
      << problem->message;
  EXPECT_NE(problem->message.find("winding = \"auto\""), std::string::npos) << problem->message;
  const CaveGeometry fixed = windFacets(*one, FacetWinding::kAuto);
  for (std::size_t i = 0; i < fixed.facets.size(); ++i) EXPECT_EQ(fixed.facets[i].corners, inward->facets[i].corners);
  EXPECT_FALSE(caveFacingProblem(*one, FacetWinding::kAuto));
}

// Makes sure a display wound inward whose origin (the viewer) lies outside it is not called
// outward-wound: the fix there is the model's placement, not its winding.
TEST(CaveFacing, AViewerOutsideTheDisplayIsNotCalledAWindingProblem) {
  std::vector<Diagnostic> warnings;
  // The 0..1 cube: the origin is a corner, on the planes of facets 0, 2 and 4.
  auto g = geometry(kCube, warnings);
  ASSERT_TRUE(g);
  const auto problem = caveFacingProblem(*g, FacetWinding::kInward);
  ASSERT_TRUE(problem);
  EXPECT_NE(problem->message.find("the viewer, at the geometry's origin, is behind or on the plane of facets 0, 2 "
                                  "and 4 (lines 9, 11 and 13)"),
            std::string::npos)
      << problem->message;
  EXPECT_EQ(problem->message.find("winding"), std::string::npos) << problem->message;
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
