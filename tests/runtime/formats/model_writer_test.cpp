// Writing models: Extended OBJ written and read back gives the same objects and meshes, exactly
// (every model in the shared test data, and hand-made ones with parents, instances, maps and
// colours); plain OBJ ("Save Object") puts everything in scene coordinates; materials go to an
// MTL beside the model; files appear whole or not at all.
// Example failures: a part order or vertex order that changes on every save; an instance
// written as a copy; a rotation that comes back different; a texture path that only works
// from the folder it was loaded from; a half-written file after a failed save.

#include <gtest/gtest.h>

#include <fstream>

#include "formats_test_util.h"
#include "runtime/formats/mtl.h"
#include "support/test_paths.h"

namespace basalt::formats {
namespace {

using test::listWarnings;

/// Writes a model to `dir/name` and reads it back.
LoadedModel roundTrip(const LoadedModel& model, const std::filesystem::path& dir, const std::string& name,
                      bool extended = true) {
  ObjWriteOptions options;
  options.extended = extended;
  const auto path = dir / name;
  auto written = writeObj(path, model, options);
  EXPECT_TRUE(written) << written.error().describe();
  auto back = loadModel(path, test::quiet());
  EXPECT_TRUE(back) << back.error().describe();
  return back ? std::move(*back) : LoadedModel{};
}

void expectSameObjects(const LoadedModel& a, const LoadedModel& b, const std::string& what) {
  ASSERT_EQ(a.objects.size(), b.objects.size()) << what;
  for (std::size_t i = 0; i < a.objects.size(); ++i) {
    const ModelObject& x = a.objects[i];
    const ModelObject& y = b.objects[i];
    EXPECT_EQ(x.name, y.name) << what;
    EXPECT_TRUE(x == y) << what << ": object '" << x.name << "' changed on the round trip";
    if (x.mesh && y.mesh) {
      EXPECT_EQ(x.mesh->positions, y.mesh->positions) << what << " " << x.name;
      EXPECT_EQ(x.mesh->triangles, y.mesh->triangles) << what << " " << x.name;
      EXPECT_EQ(x.mesh->parts, y.mesh->parts) << what << " " << x.name;
      EXPECT_EQ(x.mesh->colors, y.mesh->colors) << what << " " << x.name;
      EXPECT_EQ(x.mesh->materials, y.mesh->materials) << what << " " << x.name;
    }
  }
}

TEST(ObjWriter, EverySharedModelSurvivesAnExtendedRoundTrip) {
  const auto models = test::modelsDir();
  if (models.empty()) GTEST_SKIP() << "the shared test data (../shared/testdata) is not on this machine";
  const auto dir = basalt::test::scratchDir("obj-roundtrip");
  int checked = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(models)) {
    const std::string ext = entry.path().extension().string();
    if (!entry.is_regular_file() || (ext != ".obj" && ext != ".off")) continue;
    auto first = loadModel(entry.path(), test::quiet());
    if (!first) continue;  // the rejected files have their own cases
    const std::string name = "rt" + std::to_string(checked++) + ".obj";
    const LoadedModel second = roundTrip(*first, dir, name);
    expectSameObjects(*first, second, entry.path().string());
    // Saving again gives the same text: the format is stable.
    std::string mtl1, mtl2;
    EXPECT_EQ(formatObj(*first, dir, {}, "x.mtl", mtl1), formatObj(second, dir, {}, "x.mtl", mtl2)) << entry.path();
    EXPECT_EQ(mtl1, mtl2) << entry.path();
  }
  EXPECT_GT(checked, 60);
}

TEST(ObjWriter, ExtendedStatementsSurviveTheRoundTrip) {
  const auto dir = basalt::test::scratchDir("obj-extended");
  std::ofstream(dir / "skin.jpg") << "x";
  std::ofstream(dir / "env.jpg") << "x";
  auto model = parseObjText(
      "o body\nposition 1.5 -2 3.25\nrotation 10 20 30\nscale 0.5\nusemap skin.jpg color\nusemap env.jpg reflect\n"
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nvc 255 0 0 128\nvc 0 255 0 255\nvc 0 0 255 0\nf 1 2 3\n"
      "o arm\nparent body\nscale 1 2 3\nv 0 0 1\nv 1 0 1\nv 0 1 1\nvt 0.25 0.75\nl 4/1 5/1 6/1\np 4\n"
      "o arm2\nparent arm\ninstanceof arm\nposition 0 -1 0\n",
      (dir / "src.obj").string(), dir, test::quiet());
  ASSERT_TRUE(model) << model.error().describe();
  const LoadedModel back = roundTrip(*model, dir, "out.obj");
  expectSameObjects(*model, back, "extended");
  EXPECT_TRUE(back.extended);
  EXPECT_EQ(back.objects[0].colorMap, (dir / "skin.jpg").string());
}

// 'vc' lines belong to the file's n-th vertex, not the object's: an object with opaque colours
// before one with translucent ones must not shift them (a fuzzing finding).
TEST(ObjWriter, TranslucentColoursInALaterObjectStayOnTheirVertices) {
  const auto dir = basalt::test::scratchDir("obj-vc-later");
  auto model = parseObjText(
      "o a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvc 255 128 64 255\nvc 255 255 255 255\nvc 0 0 0 255\nl 1 2\n"
      "o b\nv 0 0 1\nv 1 0 1\nv 0 1 1\nvc 10 20 30 40\nvc 0 0 0 0\nvc 0 0 0 0\nf 4 5 6\n"
      "o c\nv 0 0 2\nv 1 0 2\nv 0 1 2\nvc 1 1 1 1\nvc 0.1 0.2 0.3 0.4\nf 7 8 9\n",
      (dir / "src.obj").string(), dir, test::quiet());
  ASSERT_TRUE(model) << model.error().describe();
  const LoadedModel back = roundTrip(*model, dir, "out.obj");
  expectSameObjects(*model, back, "colours");
  ASSERT_EQ(back.objects.size(), 3u);
  ASSERT_TRUE(back.objects[0].mesh && back.objects[1].mesh && back.objects[2].mesh);
  EXPECT_EQ(back.objects[0].mesh->colors.at(0), (Vec4{1, 128 / 255.0f, 64 / 255.0f, 1}));
  EXPECT_EQ(back.objects[1].mesh->colors.at(0), (Vec4{10 / 255.0f, 20 / 255.0f, 30 / 255.0f, 40 / 255.0f}));
  EXPECT_EQ(back.objects[2].mesh->colors.at(1), (Vec4{0.1f, 0.2f, 0.3f, 0.4f}));
}

// Texture names with blanks at the ends or words that look like options are quoted in the MTL
// written, and the reader takes a quoted name whole.
TEST(ObjWriter, AwkwardTextureNamesAreQuotedAndReadBack) {
  const auto dir = basalt::test::scratchDir("obj-mtl-names");
  std::filesystem::create_directories(dir / " art");
  std::ofstream(dir / " art" / "wood -old.png") << "x";
  std::ofstream(dir / "a.mtl") << "newmtl wood\nmap_Kd -clamp on \" art/wood -old.png\" -s 1 1 1\n";
  std::ofstream(dir / "a.obj") << "mtllib a.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl wood\nf 1 2 3\n";
  auto model = loadModel(dir / "a.obj", test::quiet());
  ASSERT_TRUE(model);
  EXPECT_EQ(test::firstMesh(*model).materials.at(0).diffuseMap, (dir / " art" / "wood -old.png").string());
  ASSERT_TRUE(writeObj(dir / "b.obj", *model));
  const std::string text = test::readText(dir / "b.mtl");
  EXPECT_NE(text.find("map_Kd \" art/wood -old.png\""), std::string::npos) << text;
  auto back = loadModel(dir / "b.obj", test::quiet());
  ASSERT_TRUE(back);
  EXPECT_TRUE(back->warnings.empty()) << listWarnings(back->warnings);
  EXPECT_EQ(test::firstMesh(*back).materials, test::firstMesh(*model).materials);
}

TEST(ObjWriter, InterleavedGroupsAndMaterialsKeepTheirPartsAndOrder) {
  const auto dir = basalt::test::scratchDir("obj-interleaved");
  std::ofstream(dir / "m.mtl") << "newmtl red\nKd 1 0 0\nNs 30\nd 0.5\nnewmtl blue\nKd 0 0 1\n";
  std::ofstream(dir / "m.obj")
      << "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 2 2 0\n"
         "g a\nusemtl red\nf 1 2 3\ng b\nusemtl blue\nf 2 4 3\nl 4 5\ng a\nusemtl red\nf 3 4 5\n"
         "p 5\ng b\nusemtl blue\nf 1 3 5\n";
  auto model = loadModel(dir / "m.obj", test::quiet());
  ASSERT_TRUE(model) << model.error().describe();
  const LoadedModel back = roundTrip(*model, dir, "out.obj");
  expectSameObjects(*model, back, "interleaved");
  const runtime::Mesh& m = test::firstMesh(back);
  ASSERT_EQ(m.parts.size(), 2u);
  EXPECT_EQ(m.materials.at(0).shininess, 30.0f);
  EXPECT_EQ(m.materials.at(0).opacity, 0.5f);
}

TEST(ObjWriter, PlainObjPutsEverythingInSceneCoordinates) {
  const auto dir = basalt::test::scratchDir("obj-plain");
  auto model = parseObjText(
      "o base\nposition 10 0 0\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"
      "o child\nparent base\ninstanceof base\nposition 0 5 0\nrotation 0 0 90\n",
      "tree.obj", dir, test::quiet());
  ASSERT_TRUE(model);
  const LoadedModel plain = roundTrip(*model, dir, "plain.obj", false);
  EXPECT_FALSE(plain.extended) << "a plain OBJ has no Extended statements";
  ASSERT_EQ(plain.objects.size(), 2u);
  ASSERT_TRUE(plain.objects[1].mesh) << "the instance is written out in full";
  const Vec3 corner = plain.objects[1].mesh->positions[1];  // (1,0,0) turned 90 about Z, moved by 0,5,0 and 10,0,0
  EXPECT_NEAR(corner.x, 10.0f, 1e-5f);
  EXPECT_NEAR(corner.y, 6.0f, 1e-5f);
  EXPECT_EQ(plain.objects[0].mesh->positions[1], (Vec3{11, 0, 0}));
}

TEST(ObjWriter, MaterialsGoToALibraryBesideTheModelWithRelativeTexturePaths) {
  const auto dir = basalt::test::scratchDir("obj-mtl");
  std::filesystem::create_directories(dir / "textures");
  std::ofstream(dir / "textures" / "wood.png") << "x";
  std::ofstream(dir / "a.mtl") << "newmtl wood\nKa 0.1 0.2 0.3\nKd 0.5 0.25 0\nKs 1 1 1\nKe 0 0 0.5\nNs 12\n"
                                  "map_Kd textures/wood.png\nmap_bump textures/wood.png\n";
  std::ofstream(dir / "a.obj") << "mtllib a.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl wood\nf 1 2 3\n";
  auto model = loadModel(dir / "a.obj", test::quiet());
  ASSERT_TRUE(model);
  std::filesystem::create_directories(dir / "out");
  ASSERT_TRUE(writeObj(dir / "out" / "b.obj", *model));
  const std::string text = test::readText(dir / "out" / "b.mtl");
  EXPECT_NE(text.find("map_Kd ../textures/wood.png"), std::string::npos) << text;
  auto back = loadModel(dir / "out" / "b.obj", test::quiet());
  ASSERT_TRUE(back);
  EXPECT_TRUE(back->warnings.empty()) << listWarnings(back->warnings);
  EXPECT_EQ(test::firstMesh(*back).materials, test::firstMesh(*model).materials);
}

TEST(ObjWriter, FailedSavesLeaveNothingBehind) {
  const auto dir = basalt::test::scratchDir("obj-fail");
  auto model = test::obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  ASSERT_TRUE(model);
  std::filesystem::create_directories(dir / "taken.obj");  // a folder where the file should go
  auto r = writeObj(dir / "taken.obj", *model);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().describe().find("taken.obj"), std::string::npos);
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    EXPECT_EQ(e.path().filename().string().find("partial"), std::string::npos) << e.path();
  }
}

}  // namespace
}  // namespace basalt::formats
