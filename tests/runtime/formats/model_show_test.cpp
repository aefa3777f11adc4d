// Models into the Show and back: LAVA's load_object replaces the object and resets every
// attribute; objects become scene nodes with their parents (transforms compose at any depth)
// and instances (one mesh however many nodes); parts get their textures and their materials'
// colours; Save Object writes what the Show holds.
// Example failures: attributes of the previous object surviving a load; an instance that copies
// the mesh (twice the GPU memory); a child placed in world coordinates instead of its parent's;
// a textured part with no texture name for the renderer; a parent cycle that hangs.

#include <gtest/gtest.h>

#include <fstream>

#include "formats_test_util.h"
#include "support/test_paths.h"

namespace basalt::formats {
namespace {

using test::hasWarning;
using test::listWarnings;

TEST(ModelShow, LoadObjectReplacesTheObjectAndResetsAttributes) {
  runtime::Show show = runtime::Show::makeDefault();
  show.editGlobalStyle([](runtime::PartStyle& s) { s.render.primType = runtime::PrimType::kWireframe; });
  show.fog().mode = runtime::FogMode::kLinear;
  auto model = test::obj("v 0 0 0\nv 1 0 0\nv 0 1 0\ng tri\nf 1 2 3\n");
  ASSERT_TRUE(model);
  ASSERT_TRUE(replaceObject(show, *model));
  ASSERT_EQ(show.nodes().size(), 1u);
  EXPECT_EQ(show.partCount(), 1u) << "the cube's six faces are gone";
  ASSERT_TRUE(show.findPart("tri"));
  EXPECT_EQ(show.globalStyle().render.primType, runtime::PrimType::kSolid);
  EXPECT_EQ(show.fog().mode, runtime::FogMode::kNone);
  EXPECT_FALSE(show.motion().globalFreeRun);
}

TEST(ModelShow, AModelWithNothingToShowKeepsTheCurrentObject) {
  runtime::Show show = runtime::Show::makeDefault();
  LoadedModel empty;
  auto r = replaceObject(show, empty);
  ASSERT_FALSE(r);
  EXPECT_EQ(show.partCount(), 6u);
}

TEST(ModelShow, InstancesShareOneMeshAndParentsComposeAtAnyDepth) {
  auto model = test::obj(
      "o root\nposition 10 0 0\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"
      "o a\nparent root\nposition 0 1 0\ninstanceof root\n"
      "o b\nparent a\nposition 0 0 1\nrotation 0 0 90\ninstanceof root\n"
      "o c\nparent b\nposition 1 0 0\ninstanceof a\n");
  ASSERT_TRUE(model) << model.error().describe();
  runtime::Show show;
  ASSERT_TRUE(replaceObject(show, *model));
  ASSERT_EQ(show.nodes().size(), 4u);
  const auto& nodes = show.nodes();
  for (const auto& n : nodes) EXPECT_EQ(n.mesh.get(), nodes[0].mesh.get()) << n.name << " must share root's mesh";
  EXPECT_EQ(nodes[0].mesh.use_count(), 5) << "one mesh: the model's and four nodes' references";
  // c sits 1 along b's X, which b's 90 degree turn makes world Y: 10,0,0 + 0,1,0 + 0,0,1 + 0,1,0.
  const auto c = show.findNode("c");
  ASSERT_TRUE(c);
  const Vec3 origin = show.worldTransform(*c).transformPoint({0, 0, 0});
  EXPECT_NEAR(origin.x, 10.0f, 1e-5f);
  EXPECT_NEAR(origin.y, 2.0f, 1e-5f);
  EXPECT_NEAR(origin.z, 1.0f, 1e-5f);
  // Thesis §4.2.9: "instances share all vertex and face data" and each egg "has an independent
  // location, orientation, and scale"; the material is the model's own (§4.2.4, §4.3.5), so an
  // instance's parts are its own, named after it, and setting them leaves the original alone.
  EXPECT_EQ(show.partCount(), 4u) << "each instance has parts of its own";
  for (const char* name : {"root", "a", "b", "c"}) {
    const auto node = show.findNode(name);
    const auto part = show.findPart(name);
    ASSERT_TRUE(node && part) << name;
    EXPECT_EQ(show.nodes()[*node].partIds, std::vector<runtime::PartId>{*part}) << name;
  }
}

TEST(ModelShow, UnknownParentsAndCyclesArePlacedAtTheRootWithAWarning) {
  auto model = test::obj(
      "o a\nparent b\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\no b\nparent a\ninstanceof a\n"
      "o c\nparent nobody\ninstanceof a\no d\ninstanceof ghost\n");
  ASSERT_TRUE(model);
  runtime::Show show;
  std::vector<Diagnostic> warnings;
  addModels(show, {ModelImport{&*model, nullptr}}, warnings);
  ASSERT_EQ(show.nodes().size(), 4u);
  EXPECT_TRUE(hasWarning(warnings, "form a circle")) << listWarnings(warnings);
  EXPECT_TRUE(hasWarning(warnings, "the parent 'nobody' of 'c' is not loaded")) << listWarnings(warnings);
  EXPECT_TRUE(hasWarning(warnings, "'d' is an instance of 'ghost', which is not loaded")) << listWarnings(warnings);
  for (std::size_t i = 0; i < show.nodes().size(); ++i) {
    const auto& n = show.nodes()[i];
    EXPECT_LT(n.parent, static_cast<std::int32_t>(i)) << "parents come before children";
  }
}

TEST(ModelShow, PartsGetTexturesAndMaterialColours) {
  const auto dir = basalt::test::scratchDir("model-show-materials");
  std::ofstream(dir / "m.mtl") << "newmtl glass\nKa 0.1 0.1 0.1\nKd 0.2 0.4 0.6\nKs 0.5 0.5 0.25\nNs 40\nd 0.25\n"
                                  "newmtl wood\nKd 1 1 1\nmap_Kd wood.png\n";
  std::ofstream(dir / "wood.png") << "x";
  std::ofstream(dir / "sky.jpg") << "x";
  // 'usemtl' lasts until the next one, so the part without a material comes first.
  std::ofstream(dir / "m.obj") << "mtllib m.mtl\no thing\nusemap sky.jpg\nv 0 0 0\nv 1 0 0\nv 0 1 0\n"
                                  "g plain\nf 1 2 3\ng window\nusemtl glass\nf 1 2 3\ng table\nusemtl wood\nf 1 2 3\n";
  auto model = loadModel(dir / "m.obj", test::quiet());
  ASSERT_TRUE(model) << model.error().describe();
  runtime::Show show;
  ASSERT_TRUE(replaceObject(show, *model));
  const auto window = show.findPart("window");
  const auto table = show.findPart("table");
  const auto plain = show.findPart("plain");
  ASSERT_TRUE(window && table && plain);
  EXPECT_EQ(show.part(*table).texture, (dir / "wood.png").string()) << "the material's map wins";
  EXPECT_EQ(show.part(*window).texture, (dir / "sky.jpg").string()) << "else the object's colour map";
  EXPECT_EQ(show.part(*plain).texture, (dir / "sky.jpg").string());
  const runtime::PartStyle& glass = show.resolvedStyle(*window);
  EXPECT_EQ(glass.front.color, (runtime::Color3{0.2f, 0.4f, 0.6f}));
  EXPECT_EQ(glass.lines.color, glass.front.color);
  EXPECT_NEAR(glass.front.specular, 0.5f, 1e-6f);
  EXPECT_EQ(glass.front.specularColor, (runtime::Color3{1, 1, 0.5f}));
  EXPECT_EQ(glass.front.specularPower, 40.0f);
  EXPECT_NEAR(glass.front.transparency, 0.75f, 1e-6f);
  EXPECT_EQ(glass.front.transparencyMethod, runtime::TransparencyMethod::kBlended);
  // Ka 0.1 against Kd's luminance: XGL's ambient factor.
  EXPECT_NEAR(glass.front.ambient, 0.1f / (0.2126f * 0.2f + 0.7152f * 0.4f + 0.0722f * 0.6f), 1e-4f);
  // A part without a material follows the global style.
  EXPECT_FALSE(show.part(*plain).mask.test(static_cast<std::size_t>(runtime::AttrId::kFrontColor)));
}

TEST(ModelShow, SaveObjectWritesTheShowAndReadsBackTheSameScene) {
  const auto dir = basalt::test::scratchDir("model-show-save");
  runtime::Show show;
  auto model = test::obj(
      "o base\nposition 1 2 3\nrotation 30 -45 60\nscale 2 3 4\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"
      "o top\nparent base\ninstanceof base\nrotation 0 90 0\n");
  ASSERT_TRUE(model);
  ASSERT_TRUE(replaceObject(show, *model));
  ASSERT_TRUE(saveObject(show, dir / "extended.obj", true));
  ASSERT_TRUE(saveObject(show, dir / "plain.obj", false));
  auto extended = loadModel(dir / "extended.obj", test::quiet());
  ASSERT_TRUE(extended) << extended.error().describe();
  runtime::Show again;
  ASSERT_TRUE(replaceObject(again, *extended));
  ASSERT_EQ(again.nodes().size(), 2u);
  EXPECT_EQ(again.nodes()[1].mesh.get(), again.nodes()[0].mesh.get());
  for (runtime::NodeId i = 0; i < 2; ++i) {
    const Mat4 a = show.worldTransform(i), b = again.worldTransform(i);
    for (std::size_t k = 0; k < 16; ++k) EXPECT_NEAR(a.m[k], b.m[k], 1e-5f) << "node " << i << " element " << k;
  }
  // The plain file holds the same triangles in scene coordinates.
  auto plain = loadModel(dir / "plain.obj", test::quiet());
  ASSERT_TRUE(plain);
  ASSERT_EQ(plain->objects.size(), 2u);
  for (runtime::NodeId i = 0; i < 2; ++i) {
    const auto& p = plain->objects[i].mesh->positions;
    for (std::size_t k = 0; k < p.size(); ++k) {
      const Vec3 expected = show.worldTransform(i).transformPoint(show.nodes()[i].mesh->positions[k]);
      EXPECT_NEAR(p[k].x, expected.x, 1e-4f);
      EXPECT_NEAR(p[k].y, expected.y, 1e-4f);
      EXPECT_NEAR(p[k].z, expected.z, 1e-4f);
    }
  }
}

TEST(ModelShow, SaveObjectOfTheDefaultCube) {
  const auto dir = basalt::test::scratchDir("model-show-cube");
  runtime::Show show = runtime::Show::makeDefault();
  ASSERT_TRUE(saveObject(show, dir / "cube.obj"));
  auto back = loadModel(dir / "cube.obj", test::quiet());
  ASSERT_TRUE(back) << back.error().describe();
  const ModelCounts n = countModel(*back);
  EXPECT_EQ(n.facets, 6u);
  EXPECT_EQ(n.triangles, 12u);
  EXPECT_EQ(n.parts, 6u);
  EXPECT_EQ(back->objects[0].mesh->parts[2].name, "face 3");
}

}  // namespace
}  // namespace basalt::formats
