// Every model and material library under ../shared/testdata/models, one test case per file: it
// loads with the expected counts (objects, vertices after de-duplication, triangles, polygons,
// line segments, points, parts, materials), or is rejected with the expected file:line:column
// message. Images in that folder are checked in image_files_test.cpp. A last case fails when a
// file in the folder has no entry here, so that new test data cannot go untested.
// Example failures: negative indices resolved against the wrong base; a UTF-16 file read as
// garbage; a concave polygon fanned into triangles outside it; a material library with spaces in
// its name not found; an invalid file that crashes or loads silently.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "formats_test_util.h"
#include "runtime/formats/mtl.h"
#include "support/test_paths.h"

namespace basalt::formats {
namespace {

using test::hasWarning;
using test::listWarnings;
using test::modelsDir;
using test::quiet;

struct ModelCase {
  const char* path;  // under models/
  // Expected counts, or -1 objects for a file that must be rejected.
  int objects, vertices, triangles, facets, lines, points, parts, materials;
  const char* error = nullptr;    // for rejected files: text the message must contain
  const char* warning = nullptr;  // for loaded files: text some warning must contain
};

// clang-format off
const ModelCase kModels[] = {
    {"obj/assimp/WusonOBJ.obj", 1, 2117, 3732, 3732, 0, 0, 1, 0},
    {"obj/assimp/box.obj", 1, 24, 12, 6, 0, 0, 1, 1, nullptr, "material 'Default' is not defined"},
    {"obj/assimp/box_UTF16BE.obj", 1, 24, 12, 6, 0, 0, 1, 1, nullptr, "UTF-16 (big-endian); it was decoded"},
    {"obj/assimp/box_longline.obj", 1, 956, 944, 6, 0, 0, 1, 1},
    {"obj/assimp/box_mat_with_spaces.obj", 1, 24, 12, 6, 0, 0, 1, 1},
    {"obj/assimp/box_without_lineending.obj", 1, 24, 12, 6, 0, 0, 1, 1},
    {"obj/assimp/concave_polygon.obj", 1, 64, 64, 1, 0, 0, 1, 1},
    {"obj/assimp/cube_mtllib_after_g.obj", 1, 24, 12, 12, 0, 0, 1, 1, nullptr,
     "material library 'cube_mtllib_after_g.mat' was not found"},
    {"obj/assimp/cube_usemtl.obj", 1, 24, 12, 12, 0, 0, 3, 3, nullptr, "material 'mtl3' is not defined"},
    {"obj/assimp/cube_with_vertexcolors.obj", 1, 24, 12, 12, 0, 0, 1, 0},
    {"obj/assimp/cube_with_vertexcolors_uni.obj", 1, 24, 12, 12, 0, 0, 1, 0},
    {"obj/assimp/empty_mat.obj", 1, 450, 256, 256, 0, 0, 1, 1},
    {"obj/assimp/mtl_different_folder.obj", 1, 24, 12, 6, 0, 0, 1, 1, nullptr, "texture 'image.jpg' was not found"},
    {"obj/assimp/multiple_spaces.obj", 1, 3, 1, 1, 0, 0, 1, 0},
    {"obj/assimp/number_formats.obj", 1, 3, 1, 1, 0, 0, 1, 0, nullptr, "number_formats.obj:11:14: '3.1+e2' is not a number"},
    {"obj/assimp/only_a_part_of_vertexcolors.obj", 1, 9, 3, 3, 0, 0, 1, 0},
    {"obj/assimp/point_cloud.obj", 1, 3, 0, 0, 0, 3, 1, 0, nullptr, "they are shown as points"},
    {"obj/assimp/regr01.obj", 1, 8130, 2710, 2710, 0, 0, 55, 12},
    {"obj/assimp/regr_3429812.obj", 1, 10, 4, 3, 0, 0, 3, 1},
    {"obj/assimp/space_in_material_name.obj", 1, 64, 64, 1, 0, 0, 1, 1},
    {"obj/assimp/spider.obj", 1, 974, 1368, 1368, 0, 0, 19, 4},
    {"obj/assimp/testline.obj", 1, 8, 0, 0, 18, 0, 1, 1},
    {"obj/assimp/testmixed.obj", 1, 32, 12, 6, 18, 24, 1, 1},
    {"obj/assimp/testpoints.obj", 1, 8, 0, 0, 0, 24, 1, 1},
    {"obj/common-3d-test-models/spot.obj", 1, 17568, 5856, 5856, 0, 0, 1, 0},
    {"obj/threejs/verify.obj", 2, 188, 84, 42, 26, 8, 17, 6, nullptr, "texture coordinate index 7 is out of range"},
    {"obj/tinyobjloader/catmark_torus_creases0.obj", 1, 128, 64, 32, 0, 0, 1, 0, nullptr,
     "'t' (8x, first on line 94)"},
    {"obj/tinyobjloader/colorspace-issue-184.obj", 1, 3, 1, 1, 0, 0, 1, 1},
    {"obj/tinyobjloader/cornell_box.obj", 9, 72, 36, 18, 0, 0, 8, 4},
    {"obj/tinyobjloader/cornell_box_multimaterial.obj", 9, 72, 36, 18, 0, 0, 9, 4},
    {"obj/tinyobjloader/cube-vertex-w-component.obj", 1, 24, 12, 6, 0, 0, 6, 3},
    {"obj/tinyobjloader/cube-vertexcol.obj", 1, 24, 12, 6, 0, 0, 6, 3},
    {"obj/tinyobjloader/cube.obj", 1, 24, 12, 6, 0, 0, 6, 3},
    {"obj/tinyobjloader/invalid-face-definition.obj", -1, 0, 0, 0, 0, 0, 0, 0,
     "invalid-face-definition.obj:15:1: a face needs at least 3 vertices, this one has 1"},
    {"obj/tinyobjloader/invalid-relative-texture-index.obj", -1, 0, 0, 0, 0, 0, 0, 0,
     "invalid-relative-texture-index.obj:2:3: vertex index 1 is out of range (0 defined before this line)"},
    {"obj/tinyobjloader/invalid-relative-vertex-index.obj", -1, 0, 0, 0, 0, 0, 0, 0,
     "invalid-relative-vertex-index.obj:1:3: vertex index -4 is out of range"},
    {"obj/tinyobjloader/issue-138.obj", 1, 24, 12, 12, 0, 0, 2, 2},
    {"obj/tinyobjloader/issue-140-zero-face-idx.obj", 1, 3, 1, 1, 0, 0, 1, 1, nullptr,
     "issue-140-zero-face-idx.obj:16:3: vertex index 0 is not valid (OBJ indices start at 1"},
    {"obj/tinyobjloader/issue-161-inconsistent-f.obj", 1, 26, 12, 12, 0, 0, 1, 1},
    {"obj/tinyobjloader/issue-162-smoothing-group.obj", 1, 24, 12, 12, 0, 0, 2, 2},
    {"obj/tinyobjloader/issue-235-usemtl-then-o.obj", 2, 6, 2, 2, 0, 0, 2, 2},
    {"obj/tinyobjloader/issue-244-mtl-searchpaths.obj", 2, 6, 2, 2, 0, 0, 2, 2, nullptr,
     "material library 'issue-244.mtl' was not found"},
    {"obj/tinyobjloader/issue-246-usemtl-whitespace.obj", 1, 3, 1, 1, 0, 0, 1, 1},
    {"obj/tinyobjloader/issue-248-texres-texopt.obj", 1, 24, 12, 6, 0, 0, 6, 3},
    {"obj/tinyobjloader/issue-295-trianguation-failure.obj", 1, 56, 28, 14, 0, 0, 1, 0},
    {"obj/tinyobjloader/issue-319-002.obj", 1, 20, 14, 3, 0, 0, 1, 0},
    {"obj/tinyobjloader/issue-319-003.obj", 1, 10, 8, 1, 0, 0, 1, 0},
    {"obj/tinyobjloader/issue-330.obj", 1, 7, 3, 2, 0, 0, 1, 0},
    {"obj/tinyobjloader/issue-356-leading-spaces-newmtl.obj", -1, 0, 0, 0, 0, 0, 0, 0,
     "the file has no vertices, faces, lines or points"},
    {"obj/tinyobjloader/issue-92.obj", 1, 3, 1, 1, 0, 0, 1, 1},
    {"obj/tinyobjloader/issue-95-2.obj", 1, 3, 1, 1, 0, 0, 1, 1},
    {"obj/tinyobjloader/issue-95.obj", 1, 3, 1, 1, 0, 0, 1, 1},
    {"obj/tinyobjloader/leading-decimal-dot-issue-201.obj", 1, 3, 1, 1, 0, 0, 1, 1},
    {"obj/tinyobjloader/leading-zero-in-exponent-notation-issue-210.obj", 1, 3, 1, 1, 0, 0, 1, 1},
    {"obj/tinyobjloader/line-prim.obj", 1, 8, 0, 0, 6, 0, 1, 1},
    {"obj/tinyobjloader/map-bump.obj", 1, 676, 400, 400, 0, 0, 2, 2},
    {"obj/tinyobjloader/missing_material_file.obj", 9, 72, 36, 18, 0, 0, 8, 4, nullptr,
     "material 'white' is not defined"},
    {"obj/tinyobjloader/mtl filename with whitespace issue46.obj", 1, 24, 12, 6, 0, 0, 6, 1},
    {"obj/tinyobjloader/mtllib-multiple-files-issue-112.obj", 1, 3, 1, 1, 0, 0, 1, 1, nullptr,
     "material library 'invalid-file-aaa.mtl' was not found"},
    {"obj/tinyobjloader/no_material.obj", 9, 72, 36, 18, 0, 0, 8, 0},
    {"obj/tinyobjloader/norm-texopt.obj", 1, 3, 1, 1, 0, 0, 1, 1},
    {"obj/tinyobjloader/pbr-mat-ext.obj", 1, 4, 2, 1, 0, 0, 1, 1},
    {"obj/tinyobjloader/points-prim.obj", 1, 8, 0, 0, 0, 8, 1, 1},
    {"obj/tinyobjloader/refl.obj", 1, 24, 12, 6, 0, 0, 6, 3},
    {"obj/tinyobjloader/skin-weight.obj", 1, 24, 12, 6, 0, 0, 6, 3, nullptr, "'vw' (7x"},
    {"obj/tinyobjloader/smoothing-group-two-squares.obj", 1, 5, 3, 2, 0, 0, 1, 0, nullptr,
     "normal index 1 is out of range"},
    {"obj/tinyobjloader/smoothing-normal.obj", 1, 10, 6, 3, 0, 0, 2, 1},
    {"obj/tinyobjloader/test-nan.obj", 9, 68, 34, 17, 0, 0, 8, 4, nullptr, "test-nan.obj:14:3: '1.#IND' is not a number"},
    {"obj/tinyobjloader/tests/issue-177.obj", 1, 24, 12, 6, 0, 0, 6, 3},
    {"obj/tinyobjloader/texture-filename-with-whitespace.obj", 1, 24, 12, 6, 0, 0, 6, 3},
    {"obj/tinyobjloader/texture-options-issue-85.obj", 1, 3, 1, 1, 0, 0, 1, 1},
    {"obj/tinyobjloader/tr-and-d-issue-43.obj", 1, 676, 400, 400, 0, 0, 2, 2},
    {"obj/tinyobjloader/usemtl-issue-104.obj", 1, 12, 6, 3, 0, 0, 1, 0},
    {"obj/tinyobjloader/usemtl-issue-68.obj", 1, 676, 400, 400, 0, 0, 2, 2},
    {"off/assimp/Cube.off", 1, 24, 12, 6, 0, 0, 1, 0},
    {"off/assimp/Wuson.off", 1, 11196, 3732, 3732, 0, 0, 1, 0},
    {"off/assimp/formatDetection", 1, 24, 12, 6, 0, 0, 1, 0},
    {"off/assimp/invalid.off", -1, 0, 0, 0, 0, 0, 0, 0,
     "invalid.off:6:1: a face needs at least 3 corners, this one has 0"},
};
// clang-format on

class ModelFile : public ::testing::TestWithParam<ModelCase> {};

TEST_P(ModelFile, LoadsWithTheExpectedCountsOrIsRejectedClearly) {
  if (modelsDir().empty()) GTEST_SKIP() << "the shared test data (../shared/testdata) is not on this machine";
  const ModelCase& c = GetParam();
  const auto path = modelsDir() / c.path;
  auto model = loadModel(path, quiet());
  if (c.objects < 0) {
    ASSERT_FALSE(model) << c.path << " loaded but must be rejected";
    EXPECT_EQ(model.error().code(), Errc::kParse);
    EXPECT_NE(model.error().describe().find(c.error), std::string::npos) << model.error().describe();
    return;
  }
  ASSERT_TRUE(model) << model.error().describe();
  const ModelCounts n = countModel(*model);
  EXPECT_EQ(n.objects, static_cast<std::size_t>(c.objects));
  EXPECT_EQ(n.vertices, static_cast<std::size_t>(c.vertices));
  EXPECT_EQ(n.triangles, static_cast<std::size_t>(c.triangles));
  EXPECT_EQ(n.facets, static_cast<std::size_t>(c.facets));
  EXPECT_EQ(n.lineSegments, static_cast<std::size_t>(c.lines));
  EXPECT_EQ(n.points, static_cast<std::size_t>(c.points));
  EXPECT_EQ(n.parts, static_cast<std::size_t>(c.parts));
  EXPECT_EQ(n.materials, static_cast<std::size_t>(c.materials));
  if (c.warning) {
    EXPECT_TRUE(hasWarning(model->warnings, c.warning)) << listWarnings(model->warnings);
  }
  // Whatever the file, the mesh is consistent: indices in range, arrays the same length, polygons
  // accounted for, every number finite.
  for (const ModelObject& o : model->objects) {
    if (!o.mesh) continue;
    const runtime::Mesh& m = *o.mesh;
    const std::size_t count = m.positions.size();
    for (const auto* list : {&m.triangles, &m.edges, &m.lines, &m.points}) {
      for (std::uint32_t i : *list) ASSERT_LT(i, count);
    }
    for (const auto& p : m.positions) ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
    EXPECT_TRUE(m.normals.empty() || m.normals.size() == count);
    EXPECT_TRUE(m.texcoords.empty() || m.texcoords.size() == count);
    EXPECT_TRUE(m.colors.empty() || m.colors.size() == count);
    std::size_t corners = 0, triangles = 0;
    for (std::uint32_t s : m.facetSizes) {
      corners += s;
      triangles += s - 2;
    }
    EXPECT_EQ(corners * 2, m.edges.size());
    EXPECT_EQ(triangles * 3, m.triangles.size());
  }
}

INSTANTIATE_TEST_SUITE_P(SharedTestData, ModelFile, ::testing::ValuesIn(kModels),
                         [](const auto& p) { return basalt::test::caseName(p.param.path); });

struct MaterialCase {
  const char* path;
  int materials;
  const char* firstName;
  float firstDiffuseR;
  const char* firstMapEndsWith;  // "" when the first material has no diffuse map
};

// clang-format off
const MaterialCase kMaterials[] = {
    {"obj/assimp/box_spaces.mtl", 12, "Material name with many, many spaces", 0.2f, ""},
    {"obj/assimp/concave_polygon.mtl", 1, "test", 0.141176f, ""},
    {"obj/assimp/cube_mtllib_after_g.mtl", 1, "MyMaterial", 1.0f, ""},
    {"obj/assimp/cube_usemtl.mtl", 2, "mtl", 1.0f, ""},
    {"obj/assimp/empty_mat.mtl", 1, "", 0.8f, ""},
    {"obj/assimp/folder/mtl_different_folder.mtl", 1, "Whatever", 0.141176f, "folder/image.jpg"},
    {"obj/assimp/regr01.mtl", 12, "Base", 0.2f, ""},
    {"obj/assimp/regr_3429812.mtl", 1, "Trim", 1.0f, ""},
    {"obj/assimp/space_in_material_name.mtl", 1, "Hard Shiny Plastic White", 0.141176f, ""},
    {"obj/assimp/spider.mtl", 5, "Skin", 0.827451f, "assimp/wal67ar_small.jpg"},
    {"obj/threejs/verify.mtl", 6, "red", 1.0f, "female02/02_-_Default1noCulling.JPG"},
    {"obj/tinyobjloader/colorspace-issue-184.mtl", 1, "default", 0.0f, "diffuse.jpg"},
    {"obj/tinyobjloader/cornell_box.mtl", 5, "white", 1.0f, ""},
    {"obj/tinyobjloader/cube.mtl", 5, "white", 1.0f, ""},
    {"obj/tinyobjloader/invalid-face-definition.mtl", 5, "white", 1.0f, ""},
    {"obj/tinyobjloader/issue-138.mtl", 2, "test1", 0.5f, ""},
    {"obj/tinyobjloader/issue-140-zero-face-idx.mtl", 1, "main", 1.0f, ""},
    {"obj/tinyobjloader/issue-162-smoothing-group.mtl", 2, "test1", 0.5f, ""},
    {"obj/tinyobjloader/issue-235.mtl", 2, "None", 0.0f, ""},
    {"obj/tinyobjloader/issue-246-usemtl-whitespace.mtl", 1, "1", 1.0f, ""},
    {"obj/tinyobjloader/issue-248-texres-texopt.mtl", 5, "white", 1.0f, "input.jpg"},
    {"obj/tinyobjloader/issue-356-leading-spaces-newmtl.mtl", 1, "aaa", 0.8f, ""},
    {"obj/tinyobjloader/issue-92.mtl", 1, "default", 0.0f, "tmp.png"},
    {"obj/tinyobjloader/issue-95-2.mtl", 1, "default", 0.0f, ""},
    {"obj/tinyobjloader/issue-95.mtl", 1, "default", 0.0f, ""},
    {"obj/tinyobjloader/leading-decimal-dot-issue-201.mtl", 1, "default", 0.0f, ""},
    {"obj/tinyobjloader/leading-zero-in-exponent-notation-issue-210.mtl", 1, "default", 0.0f, ""},
    {"obj/tinyobjloader/map-bump.mtl", 2, "Material.001", 0.0f, ""},
    {"obj/tinyobjloader/mtl filename with whitespace issue46.mtl", 1, "green", 0.0f, ""},
    {"obj/tinyobjloader/mtllib-multiple-files-issue-112.mtl", 1, "default", 0.0f, "tmp.png"},
    {"obj/tinyobjloader/norm-texopt.mtl", 1, "default", 0.0f, ""},
    {"obj/tinyobjloader/pbr-mat-ext.mtl", 1, "pbr", 1.0f, ""},
    {"obj/tinyobjloader/refl.mtl", 5, "white", 1.0f, ""},
    {"obj/tinyobjloader/smoothing-normal.mtl", 5, "white", 1.0f, ""},
    {"obj/tinyobjloader/tests/assets/issue-244.mtl", 2, "None", 0.0f, ""},
    {"obj/tinyobjloader/tests/issue-177.mtl", 5, "white", 1.0f, ""},
    {"obj/tinyobjloader/texture-filename-with-whitespace.mtl", 5, "white", 1.0f, "texture 01.png"},
    {"obj/tinyobjloader/texture-options-issue-85.mtl", 3, "default", 0.0f, "diffuse.jpg"},
    {"obj/tinyobjloader/tr-and-d-issue-43.mtl", 2, "Material.001", 0.0f, ""},
    {"obj/tinyobjloader/usemtl-issue-68.mtl", 2, "Material.001", 0.0f, ""},
};
// clang-format on

class MaterialFile : public ::testing::TestWithParam<MaterialCase> {};

TEST_P(MaterialFile, ReadsTheExpectedMaterials) {
  if (modelsDir().empty()) GTEST_SKIP() << "the shared test data (../shared/testdata) is not on this machine";
  const MaterialCase& c = GetParam();
  std::vector<Diagnostic> warnings;
  auto materials = readMtlFile(modelsDir() / c.path, quiet(), warnings);
  ASSERT_TRUE(materials) << materials.error().describe();
  ASSERT_EQ(materials->size(), static_cast<std::size_t>(c.materials)) << listWarnings(warnings);
  const runtime::Material& first = materials->front();
  EXPECT_EQ(first.name, c.firstName);
  EXPECT_NEAR(first.diffuse.r, c.firstDiffuseR, 1e-5f);
  const std::string map = first.diffuseMap;
  const std::string suffix = c.firstMapEndsWith;
  if (suffix.empty()) {
    EXPECT_TRUE(map.empty()) << map;
  } else {
    ASSERT_GE(map.size(), suffix.size()) << map;
    EXPECT_EQ(map.substr(map.size() - suffix.size()), suffix);
  }
}

INSTANTIATE_TEST_SUITE_P(SharedTestData, MaterialFile, ::testing::ValuesIn(kMaterials),
                         [](const auto& p) { return basalt::test::caseName(p.param.path); });

// Every file under models/ has a case here or in image_files_test.cpp (the JPEG textures).
TEST(ModelFiles, EveryFileInTheSharedModelsFolderHasACase) {
  if (modelsDir().empty()) GTEST_SKIP() << "the shared test data (../shared/testdata) is not on this machine";
  std::set<std::string> covered;
  for (const ModelCase& c : kModels) covered.insert(c.path);
  for (const MaterialCase& c : kMaterials) covered.insert(c.path);
  for (const char* image : {"obj/assimp/SpiderTex.jpg", "obj/assimp/drkwood2.jpg", "obj/assimp/engineflare1.jpg",
                            "obj/assimp/wal67ar_small.jpg", "obj/assimp/wal69ar_small.jpg"}) {
    covered.insert(image);
  }
  for (const auto& entry : std::filesystem::recursive_directory_iterator(modelsDir())) {
    if (!entry.is_regular_file()) continue;
    const std::string rel = entry.path().lexically_relative(modelsDir()).generic_string();
    EXPECT_TRUE(covered.contains(rel)) << rel << " has no test case; add it to model_files_test.cpp";
  }
}

// ---- What the counts do not show ----------------------------------------------------------------

Result<LoadedModel> load(const char* path, const LoadOptions& options = quiet()) {
  return loadModel(modelsDir() / path, options);
}

#define REQUIRE_TESTDATA() \
  if (modelsDir().empty()) GTEST_SKIP() << "the shared test data (../shared/testdata) is not on this machine"

// The UTF-16 box must be the same box as the UTF-8 one, not a garbled or empty model.
TEST(ModelFiles, Utf16FileDecodesToTheSameModelAsItsUtf8Twin) {
  REQUIRE_TESTDATA();
  auto utf8 = load("obj/assimp/box.obj");
  auto utf16 = load("obj/assimp/box_UTF16BE.obj");
  ASSERT_TRUE(utf8 && utf16);
  EXPECT_EQ(test::firstMesh(*utf8).positions, test::firstMesh(*utf16).positions);
  EXPECT_EQ(test::firstMesh(*utf8).triangles, test::firstMesh(*utf16).triangles);
}

// Negative indices count back from the latest vertex: the Cornell box's light is a square at
// y = 548 with the four vertices defined just before it.
TEST(ModelFiles, NegativeIndicesReferToTheVerticesJustBefore) {
  REQUIRE_TESTDATA();
  auto model = load("obj/tinyobjloader/cornell_box.obj");
  ASSERT_TRUE(model);
  const ModelObject* light = nullptr;
  for (const ModelObject& o : model->objects) {
    if (o.name == "light") light = &o;
  }
  ASSERT_TRUE(light && light->mesh);
  for (const Vec3& p : light->mesh->positions) EXPECT_FLOAT_EQ(p.y, 548.0f);
  EXPECT_NEAR(test::triangleArea(*light->mesh), 130.0 * 105.0, 1e-3);
}

// Concave polygons: the triangles cover exactly the polygon (their areas add up to its area,
// none is flipped), which a fan from corner 0 would not.
TEST(ModelFiles, ConcavePolygonsAreTriangulatedInsideTheirOutline) {
  REQUIRE_TESTDATA();
  for (const char* path :
       {"obj/assimp/concave_polygon.obj", "obj/tinyobjloader/issue-319-003.obj", "obj/tinyobjloader/issue-319-002.obj",
        "obj/tinyobjloader/issue-295-trianguation-failure.obj"}) {
    auto model = load(path);
    ASSERT_TRUE(model) << path;
    const runtime::Mesh& m = test::firstMesh(*model);
    // Polygon areas from their outlines (Newell), and the triangles' facing against the outline.
    double polygonArea = 0;
    std::size_t edge = 0, tri = 0;
    for (std::uint32_t s : m.facetSizes) {
      std::vector<Vec3> corners(s);
      for (std::size_t k = 0; k < s; ++k) corners[k] = m.positions[m.edges[edge + 2 * k]];
      edge += 2 * std::size_t{s};
      Vec3 n{0, 0, 0};
      for (std::size_t i = 0; i < corners.size(); ++i) {
        const Vec3& a = corners[i];
        const Vec3& b = corners[(i + 1) % corners.size()];
        n = n + Vec3{(a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y)};
      }
      polygonArea += 0.5 * static_cast<double>(length(n));
      for (std::uint32_t t = 0; t + 2 < s; ++t, ++tri) {
        const Vec3 a = m.positions[m.triangles[3 * tri]], b = m.positions[m.triangles[3 * tri + 1]],
                   c = m.positions[m.triangles[3 * tri + 2]];
        EXPECT_GE(dot(cross(b - a, c - a), n), -1e-3f * length(n)) << path << ": triangle " << tri << " is flipped";
      }
    }
    EXPECT_NEAR(test::triangleArea(m), polygonArea, polygonArea * 1e-4) << path;
  }
}

// NaN and infinite coordinates never reach the mesh; the faces that use them are skipped and
// said to be.
TEST(ModelFiles, NonFiniteVerticesAreSkippedWithTheirFaces) {
  REQUIRE_TESTDATA();
  auto model = load("obj/tinyobjloader/test-nan.obj");
  ASSERT_TRUE(model);
  EXPECT_TRUE(hasWarning(model->warnings, "test-nan.obj:12:3: vertex 1 has a coordinate that is not a finite number"))
      << listWarnings(model->warnings);
  EXPECT_TRUE(hasWarning(model->warnings, "test-nan.obj:27:3: the face uses vertex 1, which could not be read"))
      << listWarnings(model->warnings);
}

// Materials carry over to the next object (usemtl before o), and part names keep their spaces.
TEST(ModelFiles, PartsAndMaterialsAreNamedAsInTheFile) {
  REQUIRE_TESTDATA();
  auto model = load("obj/tinyobjloader/issue-235-usemtl-then-o.obj");
  ASSERT_TRUE(model);
  ASSERT_EQ(model->objects.size(), 2u);
  for (const ModelObject& o : model->objects) {
    ASSERT_TRUE(o.mesh);
    ASSERT_EQ(o.mesh->parts.size(), 1u);
    ASSERT_GE(o.mesh->parts[0].material, 0) << o.name << " lost the material set before its 'o'";
  }
  auto cube = load("obj/tinyobjloader/skin-weight.obj");
  ASSERT_TRUE(cube);
  std::vector<std::string> names;
  for (const auto& p : test::firstMesh(*cube).parts) names.push_back(p.name);
  EXPECT_NE(std::find(names.begin(), names.end(), "back cube"), names.end()) << "'g back  cube' is part 'back cube'";
  auto spaces = load("obj/assimp/space_in_material_name.obj");
  ASSERT_TRUE(spaces);
  EXPECT_EQ(test::firstMesh(*spaces).materials.at(0).name, "Hard Shiny Plastic White");
  EXPECT_NEAR(test::firstMesh(*spaces).materials.at(0).diffuse.g, 0.184314f, 1e-5f);
}

// Windows paths in material libraries (".\SpiderTex.jpg") find the textures beside the model.
TEST(ModelFiles, WindowsStyleTexturePathsAreFound) {
  REQUIRE_TESTDATA();
  auto model = load("obj/assimp/spider.obj");
  ASSERT_TRUE(model);
  EXPECT_FALSE(hasWarning(model->warnings, "was not found")) << listWarnings(model->warnings);
  for (const runtime::Material& m : test::firstMesh(*model).materials) {
    ASSERT_FALSE(m.diffuseMap.empty()) << m.name;
    EXPECT_TRUE(std::filesystem::is_regular_file(m.diffuseMap)) << m.diffuseMap;
  }
}

// A material library in another folder is found through the search paths.
TEST(ModelFiles, SearchPathsFindMaterialLibrariesElsewhere) {
  REQUIRE_TESTDATA();
  LoadOptions options = quiet();
  options.searchPaths.push_back(modelsDir() / "obj/tinyobjloader/tests/assets");
  auto model = load("obj/tinyobjloader/issue-244-mtl-searchpaths.obj", options);
  ASSERT_TRUE(model);
  EXPECT_FALSE(hasWarning(model->warnings, "not found")) << listWarnings(model->warnings);
  EXPECT_EQ(model->objects.at(0).mesh->materials.at(0).diffuse, (runtime::Color3{0, 0, 1}));
}

// Vertex colours given on some vertices only: the others are white, none is dropped.
TEST(ModelFiles, PartialVertexColoursFillTheRestWithWhite) {
  REQUIRE_TESTDATA();
  auto model = load("obj/assimp/only_a_part_of_vertexcolors.obj");
  ASSERT_TRUE(model);
  const runtime::Mesh& m = test::firstMesh(*model);
  ASSERT_EQ(m.colors.size(), m.positions.size());
  bool sawBlue = false, sawWhite = false;
  for (const Vec4& c : m.colors) {
    sawBlue = sawBlue || c == Vec4{0, 0, 1, 1};
    sawWhite = sawWhite || c == Vec4{1, 1, 1, 1};
  }
  EXPECT_TRUE(sawBlue && sawWhite);
}

// Transparency: d wins over Tr whatever their order.
TEST(ModelFiles, OpacityPrefersDOverTr) {
  REQUIRE_TESTDATA();
  auto model = load("obj/tinyobjloader/tr-and-d-issue-43.obj");
  ASSERT_TRUE(model);
  for (const runtime::Material& m : test::firstMesh(*model).materials) EXPECT_FLOAT_EQ(m.opacity, 0.75f) << m.name;
}

// Numbers in every form C writes them: ".8e-1", "-.7e+2", "e-001".
TEST(ModelFiles, UnusualNumberFormatsAreRead) {
  REQUIRE_TESTDATA();
  auto dot = load("obj/tinyobjloader/leading-decimal-dot-issue-201.obj");
  auto zero = load("obj/tinyobjloader/leading-zero-in-exponent-notation-issue-210.obj");
  ASSERT_TRUE(dot && zero);
  EXPECT_TRUE(dot->warnings.empty() || !hasWarning(dot->warnings, "not a number")) << listWarnings(dot->warnings);
  EXPECT_FALSE(hasWarning(zero->warnings, "not a number")) << listWarnings(zero->warnings);
}

}  // namespace
}  // namespace basalt::formats
