// Scene files (thesis C.3): every statement, the material state applied to the models imported
// after it, imports of files and folders with parents across files, terrain from a height map
// (and the viewer kept on it), what the Show gets, and a written scene reading back the same.
// Example failures: the material state of a later line applied to an earlier import; a
// directional light pointing the wrong way; a missing model that aborts the whole scene; a
// terrain whose height at a point is not the map's; a written scene that loses its fog.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "formats_test_util.h"
#include "runtime/formats/scene.h"
#include "support/test_paths.h"

namespace basalt::formats {
namespace {

using test::hasWarning;
using test::listWarnings;

constexpr const char* kFullScene =
    "# everything the thesis lists\n"
    "viewport position[10,20] resolution[640,480]\n"
    "projection fov[45] nearclip[0.5] farclip[500]\n"
    "eyespacing[0.065]\n"
    "bgcolor[255,128,0]\n"
    "background sky.png\n"
    "skybox box.png\n"
    "fog start[1] end[50] density[0.04] color[128,128,128] function[exp2]\n"
    "mapmin[-10,-1,-10]\nmapmax[10,5,10]\n"
    "position[1,2,3]\nrotation[0,90,0]\n"
    "positionchange[10]\nrotationchange[0.5]\n"
    "light position[0,1,0,0] ambient[51,51,51] diffuse[255,255,255] specular[255,255,255]\n"
    "light position[2,4,6,2] ambient[0,0,0] diffuse[255,0,0] specular[0,0,0]\n"
    "diffuse[255,0,0]\nshininess[20]\n"
    "import tri.obj\n"
    "emission[0,0,255]\nambient[0,0,0]\nspecular[255,255,255]\n"
    "import tri2.obj\n"
    "terrain hills.pgm amplitude[2] position[-1,0,-1]\n";

Result<SceneDescription> parse(std::string_view text, std::vector<Diagnostic>& warnings,
                               const std::string& name = "s.sce") {
  return parseSceneText(text, name, test::quiet(), warnings);
}

// Makes sure a scene whose camera lines parse but cannot be honoured as written says so at the
// line (what `basalt check` shows). Example failure: a viewport without a resolution silently
// drawn over the whole view; a start outside the map bounds silently jumping at the first step.
TEST(Scene, CameraValuesThatCannotBeHonouredAreNamedAtTheirLine) {
  struct Case {
    const char* text;
    const char* where;
    const char* says;
  };
  const Case cases[] = {
      {"# a viewport with no size\nviewport position[10,10]\n", "s.sce:2:", "no area"},
      {"mapmin[0,0,0]\nmapmax[10,10,10]\n\nposition[20,1,1]\n", "s.sce:4:", "outside mapmin..mapmax"},
      {"mapmin[0,0,0]\nmapmax[10,-1,10]\n", "s.sce:2:", "mapmin is beyond mapmax"},
      {"\nprojection fov[60] nearclip[0.0001] farclip[1000]\n", "s.sce:2:", "raise nearclip"},
  };
  for (const Case& c : cases) {
    std::vector<Diagnostic> warnings;
    ASSERT_TRUE(parse(c.text, warnings)) << c.text;
    ASSERT_EQ(warnings.size(), 1u) << c.text << listWarnings(warnings);
    EXPECT_TRUE(warnings[0].where.starts_with(c.where)) << warnings[0].describe();
    EXPECT_NE(warnings[0].message.find(c.says), std::string::npos) << warnings[0].describe();
  }
  std::vector<Diagnostic> none;
  ASSERT_TRUE(
      parse("viewport position[0,0] resolution[640,480]\nprojection fov[40] nearclip[0.5] farclip[500]\n"
            "mapmin[-10,-10,-10]\nmapmax[10,10,10]\nposition[1,2,3]\n",
            none));
  EXPECT_TRUE(none.empty()) << listWarnings(none);
}

// Found by fuzzing: `eyespacing[-6` then a byte that ends no number was skipped with a warning,
// yet the -6 read before the bad byte stayed in the scene (and a negative eye spacing, which the
// reader otherwise replaces, was written back). A skipped statement changes nothing.
TEST(Scene, SkippedScalarLeavesTheValueAsItWas) {
  for (const std::string statement : {"eyespacing[-6\xE0]", "eyespacing[0.5x]", "positionchange[7x]"}) {
    std::vector<Diagnostic> warnings;
    auto s = parse(statement + "\n", warnings);
    ASSERT_TRUE(s) << statement;
    EXPECT_EQ(warnings.size(), 1u) << statement << listWarnings(warnings);
    const SceneDescription defaults;
    EXPECT_EQ(s->eyeSpacing, defaults.eyeSpacing) << statement;
    EXPECT_EQ(s->positionChange, defaults.positionChange) << statement;
  }
}

TEST(Scene, EveryStatementOfTheThesis) {
  std::vector<Diagnostic> warnings;
  auto s = parse(kFullScene, warnings);
  ASSERT_TRUE(s) << s.error().describe();
  EXPECT_TRUE(warnings.empty()) << listWarnings(warnings);
  ASSERT_TRUE(s->viewport);
  EXPECT_EQ(*s->viewport, (std::array<std::int32_t, 4>{10, 20, 640, 480}));
  EXPECT_EQ(s->fieldOfView, 45.0f);
  EXPECT_EQ(s->nearClip, 0.5f);
  EXPECT_EQ(s->farClip, 500.0f);
  EXPECT_FLOAT_EQ(s->eyeSpacing, 0.065f);
  EXPECT_EQ(s->background, (runtime::Color3{1, 128.0f / 255.0f, 0}));
  EXPECT_EQ(s->backgroundImage, "sky.png");
  EXPECT_EQ(s->skybox, "box.png");
  ASSERT_TRUE(s->fog);
  EXPECT_EQ(s->fog->function, SceneFogFunction::kExp2);
  EXPECT_EQ(s->fog->end, 50.0f);
  EXPECT_FLOAT_EQ(s->fog->density, 0.04f);
  EXPECT_EQ(s->mapMin, (Vec3{-10, -1, -10}));
  EXPECT_EQ(s->position, (Vec3{1, 2, 3}));
  EXPECT_EQ(s->rotation, (Vec3{0, 90, 0}));
  EXPECT_EQ(s->positionChange, 10.0f);
  EXPECT_EQ(s->rotationChange, 0.5f);
  ASSERT_EQ(s->lights.size(), 2u);
  EXPECT_EQ(s->lights[1].position, (Vec4{2, 4, 6, 2}));
  EXPECT_EQ(s->lights[0].ambient, (runtime::Color3{0.2f, 0.2f, 0.2f}));
  ASSERT_EQ(s->sources.size(), 3u);
  // The material state in force at each import, not at the end of the file.
  EXPECT_EQ(s->sources[0].material.diffuse, (runtime::Color3{1, 0, 0}));
  EXPECT_EQ(s->sources[0].material.emission, (runtime::Color3{0, 0, 0}));
  EXPECT_EQ(s->sources[0].material.shininess, 20.0f);
  EXPECT_EQ(s->sources[1].material.emission, (runtime::Color3{0, 0, 1}));
  EXPECT_EQ(s->sources[1].material.ambient, (runtime::Color3{0, 0, 0}));
  EXPECT_EQ(s->sources[2].kind, SceneSource::Kind::kTerrain);
  EXPECT_EQ(s->sources[2].path, "hills.pgm");
  EXPECT_EQ(s->sources[2].amplitude, 2.0f);
  EXPECT_EQ(s->sources[2].position, (Vec3{-1, 0, -1}));
}

TEST(Scene, DefaultsAreTheThesis) {
  std::vector<Diagnostic> warnings;
  auto s = parse("", warnings);
  ASSERT_TRUE(s);
  EXPECT_EQ(s->fieldOfView, 60.0f);
  EXPECT_EQ(s->nearClip, 0.1f);
  EXPECT_EQ(s->farClip, 1000.0f);
  EXPECT_EQ(s->eyeSpacing, 0.04f);
  EXPECT_EQ(s->positionChange, 25.0f);
  EXPECT_EQ(s->rotationChange, 0.25f);
  EXPECT_EQ(s->mapMax, (Vec3{1000, 1000, 1000}));
  EXPECT_EQ(s->finalMaterial.diffuse, (runtime::Color3{0.8f, 0.8f, 0.8f}));
  EXPECT_EQ(s->finalMaterial.shininess, 1.0f);
  EXPECT_FALSE(s->fog);
}

TEST(Scene, LenientFormsAndBadStatementsWithTheirPlace) {
  std::vector<Diagnostic> warnings;
  auto s = parse(
      "bgcolor 0 0 255\nbgcolor [0, 255, 0]\neyespacing[x]\nfog start[1] colour[300,0,0] thickness[2]\n"
      "projection fov[200]\nlight position[1,2,3]\nwibble[1]\nimport\nbgcolor[1,2\nshininess[500]\n",
      warnings, "lenient.sce");
  ASSERT_TRUE(s);
  EXPECT_EQ(s->background, (runtime::Color3{0, 1, 0}));
  EXPECT_EQ(s->eyeSpacing, 0.04f);
  EXPECT_TRUE(hasWarning(warnings, "lenient.sce:3:12: 'x' is not a finite number")) << listWarnings(warnings);
  EXPECT_TRUE(hasWarning(warnings, "lenient.sce:4:14: 'colour' has values outside 0..255")) << listWarnings(warnings);
  EXPECT_TRUE(hasWarning(warnings, "lenient.sce:4:30: 'thickness' is not part of 'fog'")) << listWarnings(warnings);
  EXPECT_TRUE(hasWarning(warnings, "lenient.sce:5:12: fov is an angle between 0 and 180")) << listWarnings(warnings);
  EXPECT_TRUE(hasWarning(warnings, "lenient.sce:6:7: 'position' needs 4 values, not 3")) << listWarnings(warnings);
  EXPECT_TRUE(hasWarning(warnings, "lenient.sce:7:1: 'wibble' is not a scene statement")) << listWarnings(warnings);
  EXPECT_TRUE(hasWarning(warnings, "lenient.sce:8:1: 'import' needs a file name")) << listWarnings(warnings);
  EXPECT_TRUE(hasWarning(warnings, "lenient.sce:9:8: '[' is not closed")) << listWarnings(warnings);
  EXPECT_EQ(s->finalMaterial.shininess, 128.0f);
}

/// A scene folder with two models (one parented to the other across files), a height map and
/// a model that cannot be loaded.
std::filesystem::path makeSceneFolder(const std::string& name) {
  const auto dir = basalt::test::scratchDir(name);
  std::ofstream(dir / "tri.obj") << "o table\nposition 5 0 0\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  std::ofstream(dir / "tri2.obj") << "o lamp\nparent table\nposition 0 1 0\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  std::ofstream(dir / "broken.obj") << "f 1 2 3\n";
  std::filesystem::create_directories(dir / "more");
  std::ofstream(dir / "more" / "b.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  std::ofstream(dir / "more" / "a.OBJ") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  std::ofstream(dir / "more" / "notes.txt") << "not a model\n";
  // A 3 x 2 height map: 0 at the first pixel, 255 at the last.
  std::ofstream(dir / "hills.pgm", std::ios::binary) << "P2\n3 2\n255\n0 51 102\n153 204 255\n";
  std::ofstream(dir / "sky.png") << "x";
  std::ofstream(dir / "s.sce") << kFullScene << "import broken.obj\nimportdir more\n";
  return dir;
}

LoadOptions withDecoder() {
  LoadOptions options = test::quiet();
  // The tests decode plain PGM themselves: runtime/ has no image decoder of its own.
  options.decodeImage = [](const std::filesystem::path& path) -> Result<Image> {
    std::ifstream in(path);
    std::string magic;
    std::uint32_t w = 0, h = 0, max = 0;
    in >> magic >> w >> h >> max;
    if (magic != "P2" || w == 0 || h == 0) return fail(Errc::kParse, "not a plain PGM", path.string());
    Image image = Image::make(w, h, 1);
    for (auto& p : image.pixels) {
      unsigned v = 0;
      in >> v;
      p = static_cast<std::uint8_t>(v);
    }
    return image;
  };
  return options;
}

TEST(SceneFiles, LoadImportsEverythingAndTheShowGetsIt) {
  const auto dir = makeSceneFolder("scene-load");
  auto scene = loadScene(dir / "s.sce", withDecoder());
  ASSERT_TRUE(scene) << scene.error().describe();
  EXPECT_EQ(scene->models.size(), 4u) << "tri, tri2 and the folder's two models; broken.obj is skipped";
  EXPECT_TRUE(hasWarning(scene->warnings, "s.sce:25: the model could not be imported, the scene goes on without it"))
      << listWarnings(scene->warnings);
  ASSERT_EQ(scene->terrains.size(), 1u);

  runtime::Show show = runtime::Show::makeDefault();
  std::vector<Diagnostic> warnings;
  applyScene(show, *scene, &warnings);
  EXPECT_TRUE(warnings.empty()) << listWarnings(warnings);
  ASSERT_EQ(show.nodes().size(), 5u);  // table, lamp, two from the folder, the terrain
  // The lamp is placed relative to the table imported from another file.
  const auto lamp = show.findNode("lamp");
  ASSERT_TRUE(lamp);
  EXPECT_EQ(show.worldTransform(*lamp).transformPoint({0, 0, 0}), (Vec3{5, 1, 0}));
  // The material state in force at each import.
  const auto table = show.findPart("table");
  const auto lampPart = show.findPart("lamp");
  ASSERT_TRUE(table && lampPart);
  EXPECT_EQ(show.resolvedStyle(*table).front.color, (runtime::Color3{1, 0, 0}));
  EXPECT_EQ(show.resolvedStyle(*table).front.specularPower, 20.0f);
  EXPECT_EQ(show.resolvedStyle(*lampPart).front.specular, 1.0f);
  // Lights: OpenGL's global ambient (0.2) in light 0, then the scene's lights, each with its own
  // ambient, diffuse and specular colours (thesis §4.2.4) in scene units; LAVA's defaults are off.
  const auto& lights = show.lights();
  EXPECT_EQ(lights[0].type, runtime::LightType::kAmbient);
  EXPECT_TRUE(lights[0].on);
  EXPECT_EQ(lights[0].color, (runtime::Color3{0.2f, 0.2f, 0.2f}));
  EXPECT_EQ(lights[1].ambient, (runtime::Color3{0.2f, 0.2f, 0.2f})) << "light 1's own ambient[51,51,51]";
  EXPECT_EQ(lights[1].units, runtime::Units::kScene);
  EXPECT_TRUE(lights[2].ownSpecular);
  EXPECT_EQ(lights[2].specular, (runtime::Color3{0, 0, 0})) << "light 2's specular[0,0,0], not its diffuse";
  EXPECT_EQ(lights[2].ambient, (runtime::Color3{0, 0, 0}));
  EXPECT_EQ(lights[1].type, runtime::LightType::kDirectional);
  EXPECT_EQ(lights[1].direction, (Vec3{0, -1, 0})) << "w = 0: shining from +Y down";
  EXPECT_EQ(lights[2].type, runtime::LightType::kPositional);
  EXPECT_EQ(lights[2].position, (Vec3{1, 2, 3}));
  EXPECT_EQ(lights[2].color, (runtime::Color3{1, 0, 0}));
  EXPECT_FALSE(lights[3].on);
  // Background, fog and viewer.
  EXPECT_EQ(show.backgroundKind(), runtime::BackgroundKind::kSkybox);
  EXPECT_EQ(show.backgroundImage(), (dir / "box.png").string());
  EXPECT_EQ(show.fog().mode, runtime::FogMode::kExp2);
  EXPECT_EQ(show.fog().units, runtime::Units::kScene);
  EXPECT_FLOAT_EQ(show.stereo().eyeSpacing, 0.065f) << "eyespacing[0.065] drives the stereo eyes";
  EXPECT_EQ(show.stereo().units, runtime::Units::kScene);
  // The second import's state: emission[0,0,255], ambient[0,0,0] as the part's own colours.
  const runtime::SurfaceAttributes& lampFront = show.resolvedStyle(*lampPart).front;
  EXPECT_EQ(lampFront.emission, (runtime::Color3{0, 0, 1}));
  EXPECT_TRUE(lampFront.ambientColor.own);
  EXPECT_EQ(lampFront.ambientColor.color, (runtime::Color3{0, 0, 0}));
  EXPECT_EQ(show.resolvedStyle(*table).front.ambientColor.color, (runtime::Color3{0.2f, 0.2f, 0.2f}))
      << "the thesis' default ambient material";
  EXPECT_EQ(show.viewer().fieldOfView, 45.0f);
  EXPECT_EQ(show.viewer().viewportWidth, 640);
  EXPECT_TRUE(show.viewer().fromScene);
  EXPECT_EQ(show.viewer().framing, runtime::Framing::kScene) << "drawn from its own camera";
  EXPECT_TRUE(show.viewer().followTerrain);
  // The terrain: heights from the map scaled by the amplitude, placed at its position.
  auto h = show.terrainHeightAt(-1, -1);
  ASSERT_TRUE(h);
  EXPECT_FLOAT_EQ(*h, 0.0f);
  EXPECT_FLOAT_EQ(*show.terrainHeightAt(1, 0), 2.0f) << "the brightest pixel, last column, last row";
  EXPECT_NEAR(*show.terrainHeightAt(-0.5f, -0.5f), (0 + 0.4 + 1.2 + 1.6) / 4, 1e-5);
  EXPECT_FALSE(show.terrainHeightAt(5, 5)) << "off the map";
}

TEST(SceneFiles, TerrainWithoutADecoderOrWithABadMapIsSkippedWithAWarning) {
  const auto dir = makeSceneFolder("scene-terrain-skip");
  auto scene = loadScene(dir / "s.sce", test::quiet());
  ASSERT_TRUE(scene);
  EXPECT_TRUE(scene->terrains.empty());
  EXPECT_TRUE(hasWarning(scene->warnings, "s.sce:24: no image decoder was given")) << listWarnings(scene->warnings);
  std::ofstream(dir / "hills.pgm") << "garbage";
  auto bad = loadScene(dir / "s.sce", withDecoder());
  ASSERT_TRUE(bad);
  EXPECT_TRUE(bad->terrains.empty());
  EXPECT_TRUE(hasWarning(bad->warnings, "the terrain's height map could not be read")) << listWarnings(bad->warnings);
}

TEST(SceneFiles, WrittenScenesReadBackTheSame) {
  const auto dir = basalt::test::scratchDir("scene-roundtrip");
  std::vector<Diagnostic> warnings;
  auto original = parse(kFullScene, warnings);
  ASSERT_TRUE(original);
  ASSERT_TRUE(writeScene(dir / "out.sce", *original));
  const std::string text = test::readText(dir / "out.sce");
  auto back = parse(text, warnings, "out.sce");
  ASSERT_TRUE(back);
  EXPECT_TRUE(warnings.empty()) << listWarnings(warnings);
  EXPECT_TRUE(*back == *original) << text;
  EXPECT_EQ(formatScene(*back), text) << "writing again gives the same file";
}

TEST(SceneFiles, AShowDescribedAndWrittenLoadsBackToTheSameLightsAndViewer) {
  const auto dir = makeSceneFolder("scene-describe");
  auto scene = loadScene(dir / "s.sce", withDecoder());
  ASSERT_TRUE(scene);
  runtime::Show show;
  applyScene(show, *scene);
  const SceneDescription described = describeScene(show, dir);
  ASSERT_TRUE(writeScene(dir / "saved.sce", described));
  auto again = loadScene(dir / "saved.sce", withDecoder());
  ASSERT_TRUE(again) << again.error().describe();
  runtime::Show reloaded;
  applyScene(reloaded, *again);
  EXPECT_EQ(reloaded.lights(), show.lights());
  EXPECT_EQ(reloaded.viewer().fieldOfView, show.viewer().fieldOfView);
  EXPECT_EQ(reloaded.viewer().position, show.viewer().position);
  EXPECT_EQ(reloaded.fog(), show.fog());
  EXPECT_EQ(reloaded.backgroundImage(), show.backgroundImage());
  EXPECT_EQ(again->models.size(), 4u) << "one import per model file the Show came from";
}

TEST(SceneFiles, AnInstanceKeepsItsOwnMaterialAndTheOriginalItsOwn) {
  // Thesis §4.2.9: instances share "vertex and face data", each has "an independent location,
  // orientation, and scale"; §4.3.5: "Current (last read) material properties are applied to
  // objects when they are loaded". The egg is imported yellow, its instance magenta.
  const auto dir = basalt::test::scratchDir("scene-instance-material");
  std::ofstream(dir / "egg.obj") << "o egg\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  std::ofstream(dir / "egg2.obj") << "o egg2\ninstanceof egg\nposition 3 0 0\nscale 2\n";
  std::ofstream(dir / "s.sce") << "diffuse[255,255,0]\nimport egg.obj\ndiffuse[255,0,255]\nimport egg2.obj\n";
  auto scene = loadScene(dir / "s.sce", test::quiet());
  ASSERT_TRUE(scene) << scene.error().describe();
  runtime::Show show;
  applyScene(show, *scene);
  const auto egg = show.findNode("egg");
  const auto egg2 = show.findNode("egg2");
  ASSERT_TRUE(egg && egg2);
  EXPECT_EQ(show.nodes()[*egg].mesh, show.nodes()[*egg2].mesh) << "one mesh";
  ASSERT_EQ(show.nodes()[*egg2].partIds.size(), 1u);
  const runtime::PartId original = show.nodes()[*egg].partIds[0];
  const runtime::PartId instance = show.nodes()[*egg2].partIds[0];
  EXPECT_NE(original, instance);
  EXPECT_EQ(show.part(instance).name, "egg2");
  EXPECT_EQ(show.resolvedStyle(original).front.color, (runtime::Color3{1, 1, 0})) << "the original stays yellow";
  EXPECT_EQ(show.resolvedStyle(instance).front.color, (runtime::Color3{1, 0, 1})) << "the instance is magenta";
  EXPECT_EQ(show.worldTransform(*egg2).transformPoint({1, 0, 0}), (Vec3{5, 0, 0})) << "its own placement";
}

TEST(SceneFiles, ScaledScenesKeepTheirEyeSpacingInSceneUnits) {
  // Seen from its own camera a scene keeps its units: eyespacing[2] is 2 world units. Fitted
  // into LAVA's window (view = "fit"), a 0..10 square's bounds have radius 5 sqrt 2, so one scene
  // unit is 1 / (5 sqrt 2) window units, and the eyes are 2 / (5 sqrt 2) = 0.282843 apart.
  const auto dir = basalt::test::scratchDir("scene-eyespacing");
  std::ofstream(dir / "sq.obj") << "v 0 0 0\nv 10 0 0\nv 10 10 0\nv 0 10 0\nf 1 2 3 4\n";
  std::ofstream(dir / "s.sce") << "eyespacing[2]\nimport sq.obj\n";
  auto scene = loadScene(dir / "s.sce", test::quiet());
  ASSERT_TRUE(scene);
  runtime::Show show;
  applyScene(show, *scene);
  EXPECT_NEAR(runtime::eyeSpacingInWindowUnits(show), 2.0, 1e-5) << "the scene's own camera";
  useFitFraming(show);
  EXPECT_NEAR(runtime::eyeSpacingInWindowUnits(show), 2.0 / (5.0 * std::sqrt(2.0)), 1e-5);
  show.stereo().units = runtime::Units::kWindow;
  EXPECT_FLOAT_EQ(runtime::eyeSpacingInWindowUnits(show), 2.0f) << "LAVA's spacing is in window units";
}

TEST(SceneFiles, AModelWithItsOwnMaterialsSaysTheSceneStateDoesNotApply) {
  const auto dir = basalt::test::scratchDir("scene-mtl");
  std::ofstream(dir / "m.mtl") << "newmtl red\nKd 1 0 0\n";
  std::ofstream(dir / "m.obj") << "mtllib m.mtl\nusemtl red\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  std::ofstream(dir / "s.sce") << "diffuse[0,255,0]\nimport m.obj\n";
  auto scene = loadScene(dir / "s.sce", test::quiet());
  ASSERT_TRUE(scene);
  EXPECT_TRUE(hasWarning(scene->warnings, "s.sce:2: m.obj has materials of its own (MTL)"))
      << listWarnings(scene->warnings);
}

TEST(Terrain, GridNormalsAndLimits) {
  Image map = Image::make(3, 3, 1);
  map.pixels = {0, 0, 0, 0, 255, 0, 0, 0, 0};
  auto t = makeTerrain(map, 1.0f, {0, 0, 0}, "bump", Limits{});
  ASSERT_TRUE(t) << t.error().describe();
  const runtime::Mesh& m = *t->mesh;
  EXPECT_EQ(m.positions.size(), 9u);
  EXPECT_EQ(m.triangleCount(), 8u);
  EXPECT_EQ(m.facetSizes.size(), 4u);
  EXPECT_EQ(m.positions[4], (Vec3{1, 1, 1}));
  EXPECT_EQ(m.normals[4], (Vec3{0, 1, 0})) << "the top of the bump is level";
  for (std::size_t i = 0; i < m.triangles.size(); i += 3) {
    const Vec3 a = m.positions[m.triangles[i]], b = m.positions[m.triangles[i + 1]],
               c = m.positions[m.triangles[i + 2]];
    EXPECT_GT(cross(b - a, c - a).y, 0.0f) << "triangles face up";
  }
  Limits small;
  small.maxTerrainSide = 2;
  EXPECT_EQ(makeTerrain(map, 1, {}, "x", small).error().code(), Errc::kResourceExhausted);
  EXPECT_FALSE(makeTerrain(Image::make(1, 5, 1), 1, {}, "x", Limits{}));
}

}  // namespace
}  // namespace basalt::formats
