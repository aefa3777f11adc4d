// OFF as Geomview defines it and as files in the wild write it: header keywords with their
// prefixes, counts on the header line or the next, no header at all, comments, vertex normals
// and colours, face colours in both ranges, and the errors for lying or truncated files.
// Example failures: a COFF colour read as coordinates; face colours 0..255 taken as 0..1; a
// header promising a billion vertices that allocates them; a truncated file that loads half.

#include <gtest/gtest.h>

#include "formats_test_util.h"

namespace basalt::formats {
namespace {

using test::hasWarning;
using test::listWarnings;

Result<LoadedModel> off(std::string_view text, const std::string& name = "test.off") {
  return parseOffText(text, name, test::quiet());
}

constexpr const char* kTetra =
    "0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
    "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";

TEST(Off, PlainHeaderHeaderlessAndCountsOnTheHeaderLine) {
  for (const std::string& text :
       {std::string("OFF\n4 4 6\n") + kTetra, std::string("4 4 6\n") + kTetra, std::string("OFF 4 4 6\n") + kTetra,
        std::string("# tetra\nOFF # keyword\n\n4 4 6\n") + kTetra}) {
    auto model = off(text);
    ASSERT_TRUE(model) << text << "\n" << model.error().describe();
    const runtime::Mesh& m = test::firstMesh(*model);
    EXPECT_EQ(m.triangleCount(), 4u);
    EXPECT_EQ(m.facetSizes.size(), 4u);
    EXPECT_EQ(m.normals.size(), m.positions.size()) << "flat normals are generated";
  }
  auto headerless = off(std::string("4 4 6\n") + kTetra);
  EXPECT_TRUE(hasWarning(headerless->warnings, "no 'OFF' keyword")) << listWarnings(headerless->warnings);
}

TEST(Off, VertexNormalsAreSharedAndVertexColoursRead) {
  auto model = off("NOFF\n3 1 0\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n");
  ASSERT_TRUE(model) << model.error().describe();
  EXPECT_EQ(test::firstMesh(*model).positions.size(), 3u);
  auto colours = off("COFF\n3 1 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n0 1 0 0 0 1.0 1.0\n3 0 1 2\n");
  ASSERT_TRUE(colours) << colours.error().describe();
  const runtime::Mesh& m = test::firstMesh(*colours);
  ASSERT_EQ(m.colors.size(), 3u);
  EXPECT_EQ(m.colors[0], (Vec4{1, 0, 0, 1}));
  EXPECT_EQ(m.colors[2], (Vec4{0, 0, 1, 1}));
}

TEST(Off, FaceColoursInBothRangesAndTheDefaultGrey) {
  auto model = off("OFF\n4 3 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2 255 0 0\n3 1 3 2 0.0 0.5 1.0 0.5\n3 0 2 1\n");
  ASSERT_TRUE(model) << model.error().describe();
  const runtime::Mesh& m = test::firstMesh(*model);
  ASSERT_EQ(m.colors.size(), 9u);
  EXPECT_EQ(m.colors[0], (Vec4{1, 0, 0, 1}));
  EXPECT_EQ(m.colors[3], (Vec4{0, 0.5f, 1, 0.5f}));
  EXPECT_NEAR(m.colors[6].x, 0.666f, 1e-6f);
}

TEST(Off, HomogeneousVerticesAreDividedByW) {
  auto model = off("4OFF\n3 1 0\n2 0 0 2\n0 4 0 2\n0 0 0 1\n3 0 1 2\n");
  ASSERT_TRUE(model) << model.error().describe();
  const runtime::Mesh& m = test::firstMesh(*model);
  EXPECT_EQ(m.positions[0], (Vec3{1, 0, 0}));
  EXPECT_EQ(m.positions[1], (Vec3{0, 2, 0}));
}

TEST(Off, BadFacesAreSkippedAndNamed) {
  auto model = off("OFF\n3 4 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1 7\n2 0 1\n5 0 1 2\n", "faces.off");
  ASSERT_TRUE(model) << model.error().describe();
  EXPECT_EQ(test::firstMesh(*model).triangleCount(), 1u);
  EXPECT_TRUE(hasWarning(model->warnings, "faces.off:7:7: '7' is not a vertex index (0 to 2)"))
      << listWarnings(model->warnings);
  EXPECT_TRUE(hasWarning(model->warnings, "faces.off:8:1: a face needs at least 3 corners, this one has 2"))
      << listWarnings(model->warnings);
  EXPECT_TRUE(hasWarning(model->warnings, "faces.off:9:7: the face says it has 5 corners but lists 3"))
      << listWarnings(model->warnings);
}

TEST(Off, LyingAndTruncatedFilesAreRejectedWithoutAllocatingForTheLie) {
  auto huge = off("OFF\n2000000000 1 0\n0 0 0\n", "huge.off");
  ASSERT_FALSE(huge);
  EXPECT_EQ(huge.error().code(), Errc::kResourceExhausted);
  EXPECT_EQ(huge.error().where(), "huge.off:2");
  auto truncated = off("OFF\n1000 1 0\n0 0 0\n1 0 0\n", "short.off");
  ASSERT_FALSE(truncated);
  EXPECT_NE(truncated.error().describe().find("the file ends after 2 of the 1000 vertices"), std::string::npos)
      << truncated.error().describe();
  auto fewerFaces = off("OFF\n3 5 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  ASSERT_TRUE(fewerFaces);
  EXPECT_TRUE(hasWarning(fewerFaces->warnings, "the header promises 5 faces but the file has 1"));
  auto binary = off("OFF BINARY\n");
  ASSERT_FALSE(binary);
  EXPECT_NE(binary.error().message().find("binary OFF files are not supported"), std::string::npos);
  auto notOff = off("hello world\n", "what.off");
  ASSERT_FALSE(notOff);
  EXPECT_EQ(notOff.error().where(), "what.off:1:1");
}

}  // namespace
}  // namespace basalt::formats
