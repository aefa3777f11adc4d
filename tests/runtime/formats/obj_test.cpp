// The OBJ and Extended OBJ reader on hand-made input: every face index form, relative indices,
// line ends, comments, n-gons, smoothing groups, groups split by material, the thesis'
// Extended statements, and the errors and caps that keep bad input from doing harm.
// Example failures: "v//vn" read as a texture index; a CR-only file read as one line; a smooth
// surface lit flat; an instance that copies its geometry; a file with a million-corner face
// that hangs the loader; a message without the line and column of the problem.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "formats_test_util.h"
#include "runtime/formats/obj_internal.h"
#include "support/test_paths.h"

namespace basalt::formats {
namespace {

using test::hasWarning;
using test::listWarnings;
using test::obj;

constexpr const char* kSquare =
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
    "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
    "vn 0 0 1\n";

TEST(Obj, EveryFaceIndexFormGivesTheSameSquare) {
  for (const char* face : {"f 1 2 3 4", "f 1/1 2/2 3/3 4/4", "f 1//1 2//1 3//1 4//1", "f 1/1/1 2/2/1 3/3/1 4/4/1",
                           "f -4/-4/-1 -3/-3/-1 -2/-2/-1 -1/-1/-1"}) {
    auto model = obj(std::string(kSquare) + face + "\n");
    ASSERT_TRUE(model) << face << ": " << model.error().describe();
    const runtime::Mesh& m = test::firstMesh(*model);
    EXPECT_EQ(m.positions.size(), 4u) << face;
    EXPECT_EQ(m.triangleCount(), 2u) << face;
    EXPECT_EQ(m.facetSizes, std::vector<std::uint32_t>{4}) << face;
    EXPECT_NEAR(test::triangleArea(m), 1.0, 1e-6) << face;
    ASSERT_EQ(m.normals.size(), 4u) << face;
    for (const Vec3& n : m.normals) EXPECT_EQ(n, (Vec3{0, 0, 1})) << face;
    const bool textured =
        std::string(face).find('/') != std::string::npos && std::string(face).find("//") == std::string::npos;
    EXPECT_EQ(m.texcoords.size(), textured ? 4u : 0u) << face;
  }
}

TEST(Obj, VerticesSharedByFacesAreStoredOnce) {
  // Two triangles sharing an edge with the same v/vt/vn: 4 vertices, not 6.
  auto model = obj(std::string(kSquare) + "f 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n");
  ASSERT_TRUE(model);
  EXPECT_EQ(test::firstMesh(*model).positions.size(), 4u);
  // The same position with another texture coordinate is another vertex.
  auto seam = obj(std::string(kSquare) + "f 1/1/1 2/2/1 3/3/1\nf 1/2/1 3/3/1 4/4/1\n");
  ASSERT_TRUE(seam);
  EXPECT_EQ(test::firstMesh(*seam).positions.size(), 5u);
}

TEST(Obj, LineEndsOfEverySystemAndNoFinalEnd) {
  for (const char* text : {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nf 1 2 3\r\n",
                           "v 0 0 0\rv 1 0 0\rv 0 1 0\rf 1 2 3\r", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3",
                           "v 0 0 0\nv 1 0 \\\n 0\nv 0 1 0\nf 1 \\\n 2 3\n"}) {
    auto model = obj(text);
    ASSERT_TRUE(model) << model.error().describe();
    EXPECT_EQ(test::firstMesh(*model).triangleCount(), 1u);
    EXPECT_TRUE(model->warnings.empty()) << listWarnings(model->warnings);
  }
}

TEST(Obj, CommentsBlankLinesAndRunsOfBlanksAreIgnored) {
  auto model = obj("# a comment\n\n   \t\nv  0\t0   0 # after a vertex\nv 1 0 0\n  v 0 1 0\nf   1  2\t3   # face\n");
  ASSERT_TRUE(model) << model.error().describe();
  EXPECT_EQ(test::firstMesh(*model).triangleCount(), 1u);
  EXPECT_TRUE(model->warnings.empty()) << listWarnings(model->warnings);
}

TEST(Obj, ProblemsAreReportedAtTheirLineAndColumn) {
  auto model = obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 x 0\nf 1 2 3\nf 1 2 9\nf 1 2 4\nf 1 2 a/b\n", "where.obj");
  ASSERT_TRUE(model) << model.error().describe();
  EXPECT_EQ(test::firstMesh(*model).triangleCount(), 1u);
  EXPECT_TRUE(hasWarning(model->warnings, "where.obj:4:5: 'x' is not a number")) << listWarnings(model->warnings);
  EXPECT_TRUE(hasWarning(model->warnings, "where.obj:6:7: vertex index 9 is out of range (4 defined before this line)"))
      << listWarnings(model->warnings);
  EXPECT_TRUE(hasWarning(model->warnings, "where.obj:7:7: the face uses vertex 4, which could not be read"))
      << listWarnings(model->warnings);
  EXPECT_TRUE(hasWarning(model->warnings, "where.obj:8:7: 'a/b' is not a vertex reference"))
      << listWarnings(model->warnings);
}

TEST(Obj, AFileWithNothingSoundIsRejectedWithTheFirstProblem) {
  auto model = obj("v 0 0 0\nf 1 2 3\nf 0 1 1\n", "bad.obj");
  ASSERT_FALSE(model);
  EXPECT_EQ(model.error().code(), Errc::kParse);
  EXPECT_EQ(model.error().where(), "bad.obj:2:5");
  EXPECT_NE(model.error().message().find("vertex index 2 is out of range"), std::string::npos);
  auto empty = obj("# only a comment\n", "empty.obj");
  ASSERT_FALSE(empty);
  EXPECT_NE(empty.error().describe().find("empty.obj: the file has no vertices"), std::string::npos);
}

TEST(Obj, WarningsAreCappedAndCounted) {
  std::string text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  for (int i = 0; i < 200; ++i) text += "f 1 2 99\n";
  auto model = obj(text);
  ASSERT_TRUE(model);
  const std::size_t cap = Limits{}.maxWarnings;
  EXPECT_LE(model->warnings.size(), cap + 1);
  EXPECT_TRUE(hasWarning(model->warnings, "more warnings were not listed")) << listWarnings(model->warnings);
}

TEST(Obj, PolygonsOfAnySizeBecomeNMinusTwoTriangles) {
  // A regular 12-gon and an L-shaped (concave) hexagon.
  std::string text;
  for (int i = 0; i < 12; ++i) {
    const double a = 2 * std::numbers::pi * i / 12;
    text += "v " + std::to_string(std::cos(a)) + " " + std::to_string(std::sin(a)) + " 0\n";
  }
  text += "f 1 2 3 4 5 6 7 8 9 10 11 12\n";
  text += "v 0 0 1\nv 2 0 1\nv 2 1 1\nv 1 1 1\nv 1 2 1\nv 0 2 1\nf -6 -5 -4 -3 -2 -1\n";
  auto model = obj(text);
  ASSERT_TRUE(model) << model.error().describe();
  const runtime::Mesh& m = test::firstMesh(*model);
  EXPECT_EQ(m.triangleCount(), 10u + 4u);
  EXPECT_EQ(m.facetSizes, (std::vector<std::uint32_t>{12, 6}));
  const double dodecagon = 0.5 * 12 * std::sin(2 * std::numbers::pi / 12);
  EXPECT_NEAR(test::triangleArea(m), dodecagon + 3.0, 1e-4);
}

TEST(Obj, DegenerateAndTangledPolygonsStillGiveNMinusTwoTriangles) {
  // All corners on one line; and a polygon that runs round the same square 50 times.
  std::string text = "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 3 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3 4\nf";
  for (int i = 0; i < 50; ++i) text += " 1 2 6 5";
  text += "\n";
  auto model = obj(text);
  ASSERT_TRUE(model) << model.error().describe();
  EXPECT_EQ(test::firstMesh(*model).triangleCount(), 2u + 198u);
}

TEST(Obj, MissingNormalsAreSmoothWithinASmoothingGroupAndFlatOtherwise) {
  // Two faces folded along the edge 2-3, at right angles.
  const std::string geometry = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 1 0 -1\nv 1 1 -1\n";
  auto smooth = obj(geometry + "s 1\nf 1 2 3 4\nf 2 5 6 3\n");
  ASSERT_TRUE(smooth);
  const runtime::Mesh& s = test::firstMesh(*smooth);
  EXPECT_EQ(s.positions.size(), 6u) << "a smoothing group shares its vertices";
  const float h = std::sqrt(0.5f);
  for (std::size_t i = 0; i < s.positions.size(); ++i) {
    if (s.positions[i].x == 1 && s.positions[i].z == 0) {
      EXPECT_NEAR(s.normals[i].x, h, 1e-5f);
      EXPECT_NEAR(s.normals[i].z, h, 1e-5f);
    }
  }
  auto flat = obj(geometry + "s off\nf 1 2 3 4\nf 2 5 6 3\n");
  ASSERT_TRUE(flat);
  const runtime::Mesh& f = test::firstMesh(*flat);
  EXPECT_EQ(f.positions.size(), 8u) << "flat faces keep their own corners";
  for (const Vec3& n : f.normals) EXPECT_TRUE(n == (Vec3{0, 0, 1}) || n == (Vec3{1, 0, 0})) << n.x << " " << n.z;
}

TEST(Obj, GroupsAndObjectsBecomeNamedParts) {
  auto model =
      obj("v 0 0 0\nv 1 0 0\nv 0 1 0\n"
          "f 1 2 3\n"
          "g wheel\nusemtl red\nf 1 2 3\nusemtl blue\nf 1 2 3\n"
          "g  two   words \nf 1 2 3\n"
          "g wheel\nusemtl red\nf 1 2 3\n",
          "car.obj");
  ASSERT_TRUE(model);
  const runtime::Mesh& m = test::firstMesh(*model);
  ASSERT_EQ(m.parts.size(), 4u);
  EXPECT_EQ(m.parts[0].name, "car") << "geometry before any group is the object's own part";
  EXPECT_EQ(m.parts[1].name, "wheel");
  EXPECT_EQ(m.parts[1].triangleIndexCount, 6u) << "both red wheel faces";
  EXPECT_EQ(m.parts[2].name, "wheel");
  EXPECT_EQ(m.materials.at(static_cast<std::size_t>(m.parts[2].material)).name, "blue");
  EXPECT_EQ(m.parts[3].name, "two words");
  EXPECT_EQ(m.parts[0].material, -1);
}

TEST(Obj, LinesAndPoints) {
  auto model = obj("v 0 0 0\nv 1 0 0\nv 1 1 0\nl 1 2 3\np 1 3\nl 3/1 1\nvt 0 0\n", "lp.obj");
  ASSERT_TRUE(model) << "a texture coordinate that does not exist yet costs only itself";
  EXPECT_TRUE(hasWarning(model->warnings, "lp.obj:6:3: texture coordinate index 1 is out of range"))
      << listWarnings(model->warnings);
  model = obj("v 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0.5 0.5\nl 1 2 3\np 1 3\nl 3/1 1/1\n");
  ASSERT_TRUE(model) << model.error().describe();
  const runtime::Mesh& m = test::firstMesh(*model);
  EXPECT_EQ(m.lines.size(), 6u);
  EXPECT_EQ(m.points.size(), 2u);
  EXPECT_EQ(m.triangleCount(), 0u);
}

TEST(Obj, VertexColoursFromVAndVc) {
  auto model = obj("v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0\nf 1 2 3\n");
  ASSERT_TRUE(model);
  const runtime::Mesh& m = test::firstMesh(*model);
  ASSERT_EQ(m.colors.size(), 3u);
  EXPECT_EQ(m.colors[0], (Vec4{1, 0, 0, 1}));
  EXPECT_EQ(m.colors[2], (Vec4{1, 1, 1, 1}));
  auto vc = obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nvc 255 0 0 128\nvc 0 255 0 255\nvc 0 0 255 0\nf 1 2 3\n");
  ASSERT_TRUE(vc);
  EXPECT_TRUE(vc->extended);
  EXPECT_EQ(test::firstMesh(*vc).colors[0], (Vec4{1, 0, 0, 128.0f / 255.0f}));
  EXPECT_EQ(test::firstMesh(*vc).colors[2], (Vec4{0, 0, 1, 0}));
}

// ---- Extended OBJ (thesis C.2) ------------------------------------------------------------------

TEST(ExtendedObj, ObjectsWithParentsInstancesPlacementAndMaps) {
  auto model =
      obj("o body\nposition 1 2 3\nrotation 0 90 0\nscale 2\nusemap skin.jpg\nusemap env.jpg\nusemap bump.jpg bump\n"
          "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"
          "o arm\nparent body\nposition 0 1 0\nscale 1 2 3\nusemap shiny.jpg reflect\n"
          "v 0 0 1\nv 1 0 1\nv 0 1 1\nf -3 -2 -1\n"
          "o arm2\nparent body\ninstanceof arm\nposition 0 -1 0\n",
          "robot.obj");
  ASSERT_TRUE(model) << model.error().describe();
  EXPECT_TRUE(model->extended);
  ASSERT_EQ(model->objects.size(), 3u);
  const ModelObject& body = model->objects[0];
  EXPECT_EQ(body.name, "body");
  EXPECT_EQ(body.position, (Vec3{1, 2, 3}));
  EXPECT_EQ(body.rotation, (Vec3{0, 90, 0}));
  EXPECT_EQ(body.scale, (Vec3{2, 2, 2}));
  EXPECT_NE(body.colorMap.find("skin.jpg"), std::string::npos) << "the first untyped map is the colour map";
  EXPECT_NE(body.reflectionMap.find("env.jpg"), std::string::npos) << "the second untyped map is the reflection map";
  EXPECT_NE(body.bumpMap.find("bump.jpg"), std::string::npos);
  const ModelObject& arm = model->objects[1];
  EXPECT_EQ(arm.parent, "body");
  EXPECT_EQ(arm.scale, (Vec3{1, 2, 3}));
  EXPECT_NE(arm.reflectionMap.find("shiny.jpg"), std::string::npos);
  ASSERT_TRUE(arm.mesh);
  EXPECT_EQ(arm.mesh->positions[0], (Vec3{0, 0, 1})) << "vertex indices run on across objects";
  const ModelObject& arm2 = model->objects[2];
  EXPECT_EQ(arm2.instanceOf, "arm");
  EXPECT_FALSE(arm2.mesh) << "an instance holds no geometry of its own";
  EXPECT_TRUE(hasWarning(model->warnings, "texture 'skin.jpg' was not found")) << listWarnings(model->warnings);
}

TEST(ExtendedObj, LocalTransformIsTranslateRotateXYZScale) {
  ModelObject o;
  o.position = {1, 2, 3};
  o.rotation = {0, 0, 90};
  o.scale = {2, 2, 2};
  const Vec3 p = o.localTransform().transformPoint({1, 0, 0});
  EXPECT_NEAR(p.x, 1.0f, 1e-5f);
  EXPECT_NEAR(p.y, 4.0f, 1e-5f);
  EXPECT_NEAR(p.z, 3.0f, 1e-5f);
  o.rotation = {90, 90, 0};
  // X after Y in the product T * Rx * Ry * Rz * S: the Y turn is applied to the point first.
  const Vec3 q = o.localTransform().transformPoint({1, 0, 0});
  const Vec3 expected =
      Mat4::translation(o.position)
          .transformPoint(Mat4::rotationX(90).transformPoint(Mat4::rotationY(90).transformPoint({2, 0, 0})));
  EXPECT_NEAR(q.x, expected.x, 1e-5f);
  EXPECT_NEAR(q.y, expected.y, 1e-5f);
  EXPECT_NEAR(q.z, expected.z, 1e-5f);
}

TEST(ExtendedObj, BadExtendedStatementsAreSkippedWithWarnings) {
  auto model = obj("o a\nposition 1 2\nscale x\nrotation 1 2 3 4\nparent\nusemap\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
                   "x.obj");
  ASSERT_TRUE(model) << model.error().describe();
  EXPECT_TRUE(hasWarning(model->warnings, "x.obj:2:10: 'position' needs 3 numbers")) << listWarnings(model->warnings);
  EXPECT_TRUE(hasWarning(model->warnings, "x.obj:3:7: 'x' is not a number")) << listWarnings(model->warnings);
  EXPECT_TRUE(hasWarning(model->warnings, "x.obj:4:16: 'rotation' has more than 3 numbers"))
      << listWarnings(model->warnings);
  EXPECT_TRUE(hasWarning(model->warnings, "'parent' names no object")) << listWarnings(model->warnings);
  EXPECT_TRUE(hasWarning(model->warnings, "'usemap' names no file")) << listWarnings(model->warnings);
  EXPECT_EQ(model->objects[0].position, (Vec3{0, 0, 0}));
}

// ---- Caps and hostile input ---------------------------------------------------------------------

TEST(ObjLimits, CountsOverTheCapsRejectTheFile) {
  LoadOptions options = test::quiet();
  options.limits.maxVertices = 3;
  auto model = parseObjText("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\n", "big.obj", ".", options);
  ASSERT_FALSE(model);
  EXPECT_EQ(model.error().code(), Errc::kResourceExhausted);
  EXPECT_EQ(model.error().where(), "big.obj:4:1");
  options = test::quiet();
  options.limits.maxFaceCorners = 4;
  model = parseObjText("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 3 1 2\n", "corners.obj", ".", options);
  ASSERT_TRUE(model) << "an over-long face is skipped, not the file";
  EXPECT_TRUE(hasWarning(model->warnings, "corners.obj:5:11: a face with more than 4 corners is skipped"))
      << listWarnings(model->warnings);
  options = test::quiet();
  options.limits.maxNames = 2;
  model =
      parseObjText("v 0 0 0\nv 1 0 0\nv 0 1 0\ng a\nf 1 2 3\ng b\nf 1 2 3\ng c\nf 1 2 3\n", "names.obj", ".", options);
  ASSERT_FALSE(model);
  EXPECT_EQ(model.error().code(), Errc::kResourceExhausted);
}

TEST(ObjLimits, FilesOverTheSizeCapAreNotRead) {
  const auto dir = basalt::test::scratchDir("obj-size-cap");
  std::ofstream(dir / "big.obj") << std::string(4096, '#') << "\nv 0 0 0\n";
  LoadOptions options = test::quiet();
  options.limits.maxFileBytes = 1024;
  auto model = loadModel(dir / "big.obj", options);
  ASSERT_FALSE(model);
  EXPECT_EQ(model.error().code(), Errc::kResourceExhausted);
  EXPECT_NE(model.error().describe().find("big.obj"), std::string::npos);
}

TEST(ObjLimits, BinaryDataIsRejectedAtItsPlace) {
  const std::string text = std::string("v 0 0 0\nv 1 0 0\nv 0 1") + '\0' + "0\nf 1 2 3\n";
  auto model = obj(text, "blob.obj");
  ASSERT_FALSE(model);
  EXPECT_EQ(model.error().where(), "blob.obj:3:6");
  EXPECT_NE(model.error().message().find("not a text file"), std::string::npos);
}

TEST(ObjLimits, Utf16LittleEndianWithoutBomIsDecoded) {
  const std::string ascii = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  std::string utf16;
  for (char c : ascii) {
    utf16 += c;
    utf16 += '\0';
  }
  auto model = obj(utf16);
  ASSERT_TRUE(model) << model.error().describe();
  EXPECT_EQ(test::firstMesh(*model).triangleCount(), 1u);
  EXPECT_TRUE(hasWarning(model->warnings, "UTF-16 (little-endian)"));
}

TEST(ObjLimits, HugeAndOddNumbersDoNotBreakTheMesh) {
  auto model = obj("v 1e39 0 0\nv 1e-50 0 0\nv 1 0 0\nv 0 1 0\nv -0 -0 -0\nf 2 3 4\nf 1 3 4\nf 5 3 4\n");
  ASSERT_TRUE(model) << model.error().describe();
  EXPECT_EQ(test::firstMesh(*model).triangleCount(), 2u) << "the face using the out-of-range vertex is skipped";
  EXPECT_TRUE(hasWarning(model->warnings, "'1e39' is not a number")) << listWarnings(model->warnings);
}

// ---- Files on disk ------------------------------------------------------------------------------

TEST(ObjFiles, FormatIsRecognisedByContentWhenTheNameSaysNothing) {
  const auto dir = basalt::test::scratchDir("obj-sniff");
  std::ofstream(dir / "model") << "# no extension\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  std::ofstream(dir / "mislabelled.obj") << "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  std::ofstream(dir / "notes.txt") << "hello\n";
  auto a = loadModel(dir / "model", test::quiet());
  ASSERT_TRUE(a) << a.error().describe();
  EXPECT_EQ(a->format, ModelFormat::kObj);
  auto b = loadModel(dir / "mislabelled.obj", test::quiet());
  ASSERT_TRUE(b) << b.error().describe();
  EXPECT_EQ(b->format, ModelFormat::kOff);
  EXPECT_TRUE(hasWarning(b->warnings, "named .obj but holds OFF"));
  auto c = loadModel(dir / "notes.txt", test::quiet());
  ASSERT_FALSE(c);
  EXPECT_EQ(c.error().code(), Errc::kUnsupported);
  auto d = loadModel(dir / "missing.obj", test::quiet());
  ASSERT_FALSE(d);
  EXPECT_EQ(d.error().code(), Errc::kNotFound);
}

TEST(ObjFiles, MaterialLibrariesWithBlanksInTheirNamesAndSeveralPerLine) {
  const auto dir = basalt::test::scratchDir("obj-mtllib");
  std::ofstream(dir / "my materials.mtl") << "newmtl red\nKd 1 0 0\nmap_Kd sub\\Red Wood.PNG\n";
  std::ofstream(dir / "b.mtl") << "newmtl blue\nKd 0 0 1\n";
  std::filesystem::create_directories(dir / "sub");
  std::ofstream(dir / "sub" / "red wood.png") << "not really a PNG";
  std::ofstream(dir / "m.obj") << "mtllib my materials.mtl\nmtllib b.mtl missing.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n"
                                  "usemtl red\nf 1 2 3\nusemtl blue\nf 1 2 3\n";
  auto model = loadModel(dir / "m.obj", test::quiet());
  ASSERT_TRUE(model) << model.error().describe();
  const runtime::Mesh& m = test::firstMesh(*model);
  ASSERT_EQ(m.materials.size(), 2u);
  EXPECT_EQ(m.materials[0].diffuse, (runtime::Color3{1, 0, 0}));
  EXPECT_EQ(m.materials[1].diffuse, (runtime::Color3{0, 0, 1}));
  // Windows separators and a case mismatch still find sub/red wood.png.
  EXPECT_EQ(std::filesystem::path(m.materials[0].diffuseMap), (dir / "sub" / "red wood.png").lexically_normal());
  EXPECT_TRUE(hasWarning(model->warnings, "material library 'missing.mtl' was not found"))
      << listWarnings(model->warnings);
}

// ---- Reading in chunks --------------------------------------------------------------------------

// OBJ files are read a chunk at a time. Whatever the chunk size, the model and its warnings
// (line and column included) are those of reading the whole text at once: a line, a "\r\n" or a
// backslash continuation cut by a chunk boundary is put together again.
// Example failure: a face split across two chunks read as two broken statements.
TEST(ObjChunks, EveryChunkSizeGivesTheSameModelAsTheWholeText) {
  const auto dir = basalt::test::scratchDir("obj-chunks");
  std::vector<std::filesystem::path> files;
  // Line ends, continuations and a byte-order mark that chunk boundaries must not break.
  const std::string tricky =
      "\xEF\xBB\xBFmtllib none.mtl\r\nv 0 0 0\r\nv 1 0 \\\r\n 0\rv 1 1 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 \\\n 3/1 \\\n"
      " 4/1\no name\\\nv 2 2 2\nf -1 -2 -3\nf 1 2 99\n";
  std::ofstream(dir / "tricky.obj", std::ios::binary) << tricky;
  files.push_back(dir / "tricky.obj");
  if (const auto models = test::modelsDir(); !models.empty()) {
    for (const char* f : {"obj/assimp/spider.obj", "obj/tinyobjloader/test-nan.obj", "obj/threejs/verify.obj",
                          "obj/assimp/box_without_lineending.obj", "obj/tinyobjloader/cornell_box.obj",
                          "obj/assimp/number_formats.obj"}) {
      files.push_back(models / f);
    }
  }
  for (const auto& path : files) {
    Diagnostics decoding(path.string(), 50, false);
    auto text = decodeText(test::readText(path), decoding);
    ASSERT_TRUE(text);
    auto whole = readObjFile(*text, path, test::quiet());
    ASSERT_TRUE(whole) << path << ": " << whole.error().describe();
    for (std::size_t chunk : {std::size_t{1}, std::size_t{2}, std::size_t{7}, std::size_t{64}, std::size_t{4096}}) {
      bool fallback = true;
      auto streamed = readObjStreamed(path, test::quiet(), fallback, chunk);
      ASSERT_FALSE(fallback) << path;
      ASSERT_TRUE(streamed) << path << " in chunks of " << chunk << ": " << streamed.error().describe();
      ASSERT_EQ(streamed->objects.size(), whole->objects.size()) << path << " " << chunk;
      for (std::size_t i = 0; i < whole->objects.size(); ++i) {
        EXPECT_TRUE(streamed->objects[i] == whole->objects[i]) << path << " object " << i << ", chunks of " << chunk;
      }
      EXPECT_EQ(streamed->warnings, whole->warnings) << path << ", chunks of " << chunk << "\n"
                                                     << listWarnings(streamed->warnings) << "whole:\n"
                                                     << listWarnings(whole->warnings);
    }
  }
}

TEST(ObjChunks, AZeroByteInALaterChunkIsFoundAtItsPlace) {
  const auto dir = basalt::test::scratchDir("obj-chunks-zero");
  std::string text;
  for (int i = 0; i < 100; ++i) text += "v 0 0 0\r\n";
  text += std::string("v 1") + '\0' + "\n";
  std::ofstream(dir / "z.obj", std::ios::binary) << text;
  bool fallback = false;
  auto model = readObjStreamed(dir / "z.obj", test::quiet(), fallback, 16);
  ASSERT_FALSE(fallback);
  ASSERT_FALSE(model);
  EXPECT_EQ(model.error().where(), (dir / "z.obj").string() + ":101:4");
}

}  // namespace
}  // namespace basalt::formats
