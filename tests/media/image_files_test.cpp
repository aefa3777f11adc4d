// Every image under ../shared/testdata/textures (and the JPEG textures under models), one test
// case per file: it decodes to the expected size, channels and sample depth, or is rejected
// with the expected message. A last case fails when a file in those folders has no entry here.
// Example failures: an arithmetic-coded or progressive JPEG rejected; a 16-bit PNG squashed to
// 8 bits; a PAM file "not supported"; a plain PBM with unseparated bits misread; a truncated PNG
// that decodes to garbage instead of an error; a 12-bit JPEG that crashes the decoder.

#include <gtest/gtest.h>

#include <set>

#include "media/image_io.h"
#include "support/test_paths.h"

namespace basalt::media {
namespace {

struct ImageCase {
  const char* path;  // under the test data folder
  std::uint32_t width, height, channels;
  ChannelType type;
  const char* error = nullptr;  // for rejected files: text the message must contain
};

constexpr ChannelType k8 = ChannelType::kU8;
constexpr ChannelType k16 = ChannelType::kU16;

// clang-format off
const ImageCase kImages[] = {
    {"models/obj/assimp/SpiderTex.jpg", 249, 250, 3, k8},
    {"models/obj/assimp/drkwood2.jpg", 768, 768, 3, k8},
    {"models/obj/assimp/engineflare1.jpg", 128, 128, 3, k8},
    {"models/obj/assimp/wal67ar_small.jpg", 250, 250, 3, k8},
    {"models/obj/assimp/wal69ar_small.jpg", 250, 250, 3, k8},
    {"textures/jpg/exif-xmp-metadata.jpg", 5, 5, 3, k8},
    {"textures/jpg/portrait_2.jpg", 113, 150, 3, k8},
    {"textures/jpg/progressive/3.jpg", 650, 470, 3, k8},
    {"textures/jpg/progressive/cat.jpg", 320, 240, 3, k8},
    {"textures/jpg/progressive/test.jpg", 32, 23, 3, k8},
    {"textures/libjpeg-turbo/LICENSE.txt", 0, 0, 0, k8, "could not find a format reader"},
    {"textures/libjpeg-turbo/monkey12.jpg", 0, 0, 0, k8, "Unsupported JPEG data precision 12"},
    {"textures/libjpeg-turbo/monkey16.pgm", 149, 227, 1, k16},
    {"textures/libjpeg-turbo/testimgari.jpg", 227, 149, 3, k8},
    {"textures/libjpeg-turbo/testimgint.jpg", 227, 149, 3, k8},
    {"textures/libjpeg-turbo/testorig.jpg", 227, 149, 3, k8},
    {"textures/libjpeg-turbo/testorig.png", 227, 149, 1, k8},
    {"textures/libjpeg-turbo/testorig.ppm", 227, 149, 3, k8},
    {"textures/png/16bpc/basi0g16.png", 32, 32, 1, k16},
    {"textures/png/16bpc/basn2c16.png", 32, 32, 3, k16},
    {"textures/png/16bpc/basn6a16.png", 32, 32, 4, k16},
    {"textures/png/bugfixes/issue#2026.png", 1, 1, 1, k8},
    {"textures/png/bugfixes/issue#403.png", 100, 50, 3, k8},
    {"textures/png/interlaced/basi2c08.png", 32, 32, 3, k8},
    {"textures/png/transparency/acid2.png", 2, 2, 4, k8},
    {"textures/png/transparency/tbbn0g04.png", 32, 32, 2, k8},
    {"textures/png/transparency/tbbn3p08.png", 32, 32, 4, k8},
    {"textures/png/transparency/tbgn3p08.png", 32, 32, 4, k8},
    {"textures/png/transparency/tbrn2c08.png", 32, 32, 4, k8},
    {"textures/png/transparency/tbwn3p08.png", 32, 32, 4, k8},
    {"textures/png/transparency/tbyn3p08.png", 32, 32, 4, k8},
    {"textures/png/transparency/tm3n3p02.png", 32, 32, 4, k8},
    {"textures/png/transparency/tp0n0g08.png", 32, 32, 1, k8},
    {"textures/png/transparency/tp0n2c08.png", 32, 32, 3, k8},
    {"textures/png/transparency/tp0n3p08.png", 32, 32, 3, k8},
    {"textures/png/transparency/tp1n3p08.png", 32, 32, 4, k8},
    {"textures/png/transparency/tp1n3p08_xmp.png", 32, 32, 4, k8},
    {"textures/pnm/pam/l1.pam", 9, 7, 1, k8},
    {"textures/pnm/pam/l16.pam", 9, 7, 1, k16},
    {"textures/pnm/pam/l8.pam", 9, 7, 1, k8},
    {"textures/pnm/pam/la1.pam", 9, 7, 2, k8},
    {"textures/pnm/pam/la16.pam", 9, 7, 2, k16},
    {"textures/pnm/pam/la8.pam", 9, 7, 2, k8},
    {"textures/pnm/pam/r16.pam", 9, 7, 3, k16},
    {"textures/pnm/pam/r8.pam", 9, 7, 3, k8},
    {"textures/pnm/pam/ra16.pam", 9, 7, 4, k16},
    {"textures/pnm/pam/ra8.pam", 9, 7, 4, k8},
    {"textures/pnm/pbm/issue-794.pbm", 10, 10, 1, k8},
    {"textures/pnm/pbm/l1a.pbm", 9, 7, 1, k8},
    {"textures/pnm/pbm/l1b.pnm", 9, 7, 1, k8},
    {"textures/pnm/pbm/narrow.pbm", 1, 9, 1, k8},
    {"textures/pnm/pgm/l16a.pgm", 9, 7, 1, k16},
    {"textures/pnm/pgm/l16b.pnm", 9, 7, 1, k16},
    {"textures/pnm/pgm/l8a.pgm", 9, 7, 1, k8},
    {"textures/pnm/pgm/l8b.pgm", 9, 7, 1, k8},
    {"textures/pnm/ppm/r16a.ppm", 9, 7, 3, k16},
    {"textures/pnm/ppm/r16b.ppm", 9, 7, 3, k16},
    {"textures/pnm/ppm/r8a.ppm", 9, 7, 3, k8},
    {"textures/pnm/ppm/r8b.pnm", 9, 7, 3, k8},
    {"textures/small/jpeg.jpg", 1, 1, 1, k8},
    {"textures/small/pbm.pbm", 1, 1, 1, k8},
    {"textures/small/pbmb.pbm", 1, 1, 1, k8},
    {"textures/small/pgm.pgm", 1, 1, 1, k8},
    {"textures/small/pgmb.pgm", 1, 1, 1, k8},
    {"textures/small/png-transparent.png", 1, 1, 4, k8},
    {"textures/small/png-truncated.png", 0, 0, 0, k8, "Read error: hit end of file"},
    {"textures/small/ppm.ppm", 1, 1, 3, k8},
    {"textures/small/ppmb.ppm", 1, 1, 3, k8},
    {"textures/small/targa.tga", 1, 1, 3, k8},
};
// clang-format on

TEST(TestData, Available) {
  if (basalt::test::testdataDir().empty()) {
    GTEST_SKIP() << "the shared test data (../shared/testdata) is not on this machine";
  }
}

class ImageFile : public ::testing::TestWithParam<ImageCase> {};

TEST_P(ImageFile, DecodesToTheExpectedShapeOrIsRejectedClearly) {
  const auto data = basalt::test::testdataDir();
  if (data.empty()) GTEST_SKIP() << "the shared test data (../shared/testdata) is not on this machine";
  const ImageCase& c = GetParam();
  auto image = readImage(data / c.path);
  if (c.error) {
    ASSERT_FALSE(image) << c.path << " decoded but must be rejected";
    EXPECT_NE(image.error().describe().find(c.error), std::string::npos) << image.error().describe();
    EXPECT_NE(image.error().describe().find(std::filesystem::path(c.path).filename().string()), std::string::npos)
        << "the message names the file: " << image.error().describe();
    return;
  }
  ASSERT_TRUE(image) << image.error().describe();
  if (c.width != 0) {
    EXPECT_EQ(image->width, c.width);
    EXPECT_EQ(image->height, c.height);
  }
  EXPECT_GT(image->width, 0u);
  EXPECT_EQ(image->channels, c.channels);
  EXPECT_EQ(image->type, c.type);
  EXPECT_EQ(image->pixels.size(), image->byteSize());
}

INSTANTIATE_TEST_SUITE_P(SharedTestData, ImageFile, ::testing::ValuesIn(kImages),
                         [](const auto& p) { return test::caseName(p.param.path); });

TEST(ImageFiles, EveryFileInTheSharedTexturesFolderHasACase) {
  const auto data = basalt::test::testdataDir();
  if (data.empty()) GTEST_SKIP() << "the shared test data (../shared/testdata) is not on this machine";
  std::set<std::string> covered;
  for (const ImageCase& c : kImages) covered.insert(c.path);
  for (const auto& entry : std::filesystem::recursive_directory_iterator(data / "textures")) {
    if (!entry.is_regular_file()) continue;
    const std::string rel = entry.path().lexically_relative(data).generic_string();
    EXPECT_TRUE(covered.contains(rel)) << rel << " has no test case; add it to image_files_test.cpp";
  }
}

// Values, not just shapes: the plain and raw Netpbm encodings of one picture agree (and PBM
// with PAM's black-and-white), and 16-bit samples keep their precision.
TEST(ImageFiles, NetpbmEncodingsOfOnePictureAgree) {
  const auto data = basalt::test::testdataDir();
  if (data.empty()) GTEST_SKIP() << "the shared test data (../shared/testdata) is not on this machine";
  const auto pnm = data / "textures/pnm";
  auto plain = readImage(pnm / "pbm/l1a.pbm");
  auto raw = readImage(pnm / "pbm/l1b.pnm");
  auto pam = readImage(pnm / "pam/l1.pam");
  ASSERT_TRUE(plain && raw && pam);
  EXPECT_EQ(plain->pixels, raw->pixels) << "plain PBM with unseparated bits reads like the raw one";
  EXPECT_EQ(pam->pixels, raw->pixels) << "PAM BLACKANDWHITE (1 = white) matches PBM (1 = black)";
  auto grey8 = readImage(pnm / "pgm/l8a.pgm");
  auto grey8b = readImage(pnm / "pgm/l8b.pgm");
  ASSERT_TRUE(grey8 && grey8b);
  EXPECT_EQ(grey8->pixels, grey8b->pixels) << "plain and raw PGM";
  auto grey16a = readImage(pnm / "pgm/l16a.pgm");
  auto grey16b = readImage(pnm / "pgm/l16b.pnm");
  ASSERT_TRUE(grey16a && grey16b);
  EXPECT_EQ(grey16a->pixels, grey16b->pixels) << "plain and raw 16-bit PGM";
  auto rgb16a = readImage(pnm / "ppm/r16a.ppm");
  auto rgb16b = readImage(pnm / "ppm/r16b.ppm");
  ASSERT_TRUE(rgb16a && rgb16b);
  EXPECT_EQ(rgb16a->pixels, rgb16b->pixels) << "plain and raw 16-bit PPM";
  // 16-bit samples are not rounded to 8 bits: some sample is not a multiple of 257.
  bool fine = false;
  for (std::size_t i = 0; i + 1 < rgb16a->pixels.size(); i += 2) {
    const unsigned v = rgb16a->pixels[i] | (unsigned{rgb16a->pixels[i + 1]} << 8);
    fine = fine || v % 257 != 0;
  }
  EXPECT_TRUE(fine);
}

// The same photo as baseline, integer-DCT and arithmetic-coded JPEG, and as PPM: all decode to
// nearly the same pixels.
TEST(ImageFiles, JpegCodingsDecodeToTheSamePicture) {
  const auto data = basalt::test::testdataDir();
  if (data.empty()) GTEST_SKIP() << "the shared test data (../shared/testdata) is not on this machine";
  auto ppm = readImage(data / "textures/libjpeg-turbo/testorig.ppm");
  ASSERT_TRUE(ppm);
  for (const char* name : {"testorig.jpg", "testimgint.jpg", "testimgari.jpg"}) {
    auto jpeg = readImage(data / "textures/libjpeg-turbo" / name);
    ASSERT_TRUE(jpeg) << name;
    const ImageDifference d = compareImages(*jpeg, *ppm, 32);
    EXPECT_TRUE(d.sameShape) << name;
    EXPECT_LT(d.meanAbsoluteDelta, 4.0) << name;
  }
}

}  // namespace
}  // namespace basalt::media
