// `basalt check` on the content formats (.sce, .obj, .off, .cave), run as a user runs it, and
// the same checkers on files a manifest names: good files pass, and each broken one fails with
// its file:line and what is wrong; a scene whose imports all fail is an error, not a silent
// empty show.
// Example failures: a broken model that `basalt check` calls fine; an error without its line;
// a manifest that names a broken scene and is accepted; a missing checker for one extension.

#include <gtest/gtest.h>

#include <fmt/format.h>

#include <fstream>
#include <sstream>
#include <string>

#include "kiosk/manifest/check_formats.h"
#include "kiosk/manifest/manifest.h"
#include "support/polyhedra.h"
#include "support/process.h"
#include "support/test_paths.h"

namespace basalt::kiosk {
namespace {

namespace fs = std::filesystem;

void writeFile(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path) << text;
}

test::ProcessResult check(const std::vector<fs::path>& files) {
  std::vector<std::string> args{(test::binaryDir() / "basalt").string(), "check"};
  for (const fs::path& f : files) args.push_back(f.string());
  return test::run(args);
}

fs::path models() { return test::testdataDir() / "models"; }

constexpr const char* kTriangle = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

TEST(CheckFormats, GoodModelsFromOtherProjectsPass) {
  if (!fs::exists(models())) GTEST_SKIP() << "no ../shared/testdata here";
  for (const fs::path& file : {models() / "obj/tinyobjloader/cornell_box.obj", models() / "off/assimp/Cube.off",
                               models() / "obj/common-3d-test-models/spot.obj"}) {
    const auto r = check({file});
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find(file.string() + ": no errors"), std::string::npos) << r.output;
  }
}

TEST(CheckFormats, BrokenModelsFromOtherProjectsNameTheLine) {
  if (!fs::exists(models())) GTEST_SKIP() << "no ../shared/testdata here";
  const fs::path invalidOff = models() / "off/assimp/invalid.off";
  const auto off = check({invalidOff});
  EXPECT_EQ(off.exitCode, 1) << off.output;
  EXPECT_NE(off.output.find(invalidOff.string() + ":"), std::string::npos) << off.output;
  EXPECT_NE(off.output.find(invalidOff.string() + ":6: error: column 1: a face needs at least 3 corners"),
            std::string::npos)
      << off.output;
  // A bad index is skipped with a warning naming its line; the rest of the model loads.
  const fs::path badIndex = models() / "obj/tinyobjloader/invalid-relative-vertex-index.obj";
  const auto obj = check({badIndex});
  EXPECT_NE(obj.output.find(badIndex.string() + ":"), std::string::npos) << obj.output;
  EXPECT_NE(obj.output.find("warning"), std::string::npos) << obj.output;
}

TEST(CheckFormats, ScenesAndCavesGoodAndBroken) {
  const fs::path dir = test::scratchDir("check-formats");
  writeFile(dir / "tri.obj", kTriangle);
  writeFile(dir / "good.sce", "bgcolor[0,0,0]\nposition[0,0,4]\nimport tri.obj\n");
  writeFile(dir / "typo.sce", "bgcolor[0,0,0]\nfieldofview[40]\nimport tri.obj\n");
  writeFile(dir / "empty.sce", "bgcolor[0,0,0]\nimport gone.obj\n");
  writeFile(dir / "facet.obj", "v 0 0 0\nv 0 1 0\nv 1 0 0\nf 1 2 3\n");
  writeFile(dir / "room.cave", "model facet.obj\nfacet[0]\nside[1]\n");
  writeFile(dir / "broken.cave", "facet[zero]\n");
  const auto good = check({dir / "good.sce", dir / "tri.obj"});
  EXPECT_EQ(good.exitCode, 0) << good.output;
  EXPECT_NE(good.output.find("good.sce: no errors (1 imports checked)"), std::string::npos) << good.output;
  const auto typo = check({dir / "typo.sce"});
  EXPECT_NE(typo.output.find((dir / "typo.sce").string() + ":2: warning: "), std::string::npos) << typo.output;
  const auto empty = check({dir / "empty.sce"});
  EXPECT_EQ(empty.exitCode, 1) << empty.output;
  EXPECT_NE(empty.output.find("none of its 1 imports could be loaded"), std::string::npos) << empty.output;
  EXPECT_NE(empty.output.find("gone.obj"), std::string::npos) << "the import that failed is named: " << empty.output;
  const auto cave = check({dir / "room.cave"});
  EXPECT_EQ(cave.exitCode, 0) << cave.output;
  EXPECT_NE(cave.output.find("room.cave: 0 errors"), std::string::npos) << cave.output;
  const auto broken = check({dir / "broken.cave"});
  EXPECT_EQ(broken.exitCode, 1) << broken.output;
  EXPECT_NE(broken.output.find((dir / "broken.cave").string() + ":1: error: column 7: 'zero' is not a facet index"),
            std::string::npos)
      << broken.output;
}

std::size_t count(const std::string& text, const std::string& needle) {
  std::size_t n = 0;
  for (std::size_t at = text.find(needle); at != std::string::npos; at = text.find(needle, at + 1)) ++n;
  return n;
}

// Makes sure `basalt check` says once, with the geometry file and its `f` lines, that an
// outward-wound display (each facet's corners reversed from the test cube's) faces away from the
// viewer, and offers the fix; and that a manifest whose facet views set winding = "outward" is
// clean, while one without it is told once however many views show the display.
// Thesis §4.2.1: "If its vertices are oriented in clockwise order from the point of view of the
// viewer, they represent a back-face, and are not drawn (culled)." §4.4.3: "The default viewer
// position is the origin of the display geometry."
// Example failures: one warning per facet (32 for a soccer-ball display); a warning with no line;
// the warning repeated for each of six views; the option not silencing it.
TEST(CheckFormats, AnOutwardWoundDisplayIsNamedOnceWithTheFix) {
  const fs::path dir = test::scratchDir("check-formats-outward");
  writeFile(dir / "inward.obj", test::cubeDisplayObj());
  writeFile(dir / "outward.obj", test::reverseFacetWinding(test::cubeDisplayObj()));
  writeFile(dir / "inward.cave", "model inward.obj\n");
  writeFile(dir / "outward.cave", "model outward.obj\nfacet[5]\n");
  // The `f` lines of the generated cube, counted here rather than taken from the checker.
  std::vector<int> faceLines;
  {
    std::istringstream in(test::cubeDisplayObj());
    int n = 0;
    for (std::string line; std::getline(in, line);) {
      ++n;
      if (line.rfind("f ", 0) == 0) faceLines.push_back(n);
    }
  }
  ASSERT_EQ(faceLines.size(), 6u);
  const std::string lines = fmt::format("lines {}-{}", faceLines.front(), faceLines.back());

  const auto good = check({dir / "inward.cave"});
  EXPECT_EQ(good.exitCode, 0) << good.output;
  EXPECT_NE(good.output.find("inward.cave: no errors"), std::string::npos) << good.output;
  const auto bad = check({dir / "outward.cave"});
  EXPECT_EQ(bad.exitCode, 0) << "a warning, not an error: " << bad.output;
  EXPECT_EQ(count(bad.output, "warning:"), 1u) << bad.output;
  EXPECT_NE(bad.output.find(fmt::format("{}:{}: warning: all 6 facets face away from the viewer ({})",
                                        (dir / "outward.obj").string(), faceLines.front(), lines)),
            std::string::npos)
      << bad.output;
  EXPECT_NE(bad.output.find("winding = \"outward\""), std::string::npos) << bad.output;
  EXPECT_NE(bad.output.find("0 errors, 1 warning"), std::string::npos) << bad.output;

  const std::string views =
      "[[views]]\nname = \"front\"\nkind = \"facet\"\ncave = \"outward.cave\"\n{}"
      "[[views]]\nname = \"back\"\nkind = \"facet\"\ncave = \"outward.cave\"\nfacet = 4\n{}";
  writeFile(dir / "plain.toml", fmt::format(fmt::runtime(views), "", ""));
  const auto plain = check({dir / "plain.toml"});
  EXPECT_EQ(count(plain.output, "warning:"), 1u) << plain.output;
  EXPECT_NE(plain.output.find(fmt::format("{}:{}: warning: facet view 'front': all 6 facets face away",
                                          (dir / "outward.obj").string(), faceLines.front())),
            std::string::npos)
      << plain.output;
  const std::string option = "winding = \"outward\"\n";
  writeFile(dir / "turned.toml", fmt::format(fmt::runtime(views), option, option));
  const auto turned = check({dir / "turned.toml"});
  EXPECT_EQ(turned.exitCode, 0) << turned.output;
  EXPECT_EQ(count(turned.output, "warning:"), 0u) << turned.output;
  // The option on the inward file is the mistake then.
  writeFile(dir / "wrong.toml", "[[views]]\nname = \"a\"\nkind = \"facet\"\ncave = \"inward.cave\"\n" + option);
  const auto wrong = check({dir / "wrong.toml"});
  EXPECT_EQ(count(wrong.output, "warning:"), 1u) << wrong.output;
  EXPECT_NE(wrong.output.find("it is wound inward"), std::string::npos) << wrong.output;
}

TEST(CheckFormats, AManifestsSceneAndModelAreParsed) {
  const fs::path dir = test::scratchDir("check-formats-manifest");
  writeFile(dir / "tri.obj", kTriangle);
  writeFile(dir / "bad.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n");
  writeFile(dir / "wall.sce", "import gone.obj\n");
  writeFile(dir / "show.toml",
            "[show]\nentry = \"tri.obj\"\n[kiosk]\n[[kiosk.playlist]]\nname = \"wall\"\nentry = \"wall.sce\"\n"
            "[[kiosk.playlist]]\nname = \"off\"\nentry = \"bad.off\"\n");
  Diagnostics diagnostics;
  ReadOptions options;
  options.fileCheckers = &contentCheckers();
  const auto manifest = readManifest(dir / "show.toml", diagnostics, options);
  const std::string text = diagnostics.format();
  EXPECT_FALSE(manifest) << text;
  EXPECT_NE(text.find("wall.sce: nothing to show"), std::string::npos) << text;
  EXPECT_NE(text.find("bad.off:"), std::string::npos) << text;
  EXPECT_EQ(text.find("tri.obj"), std::string::npos) << "the good model has nothing to say: " << text;
  EXPECT_EQ(text.find("contents are not checked"), std::string::npos) << text;
}

}  // namespace
}  // namespace basalt::kiosk
