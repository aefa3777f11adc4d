// Image files: PNG snapshots through libpng, every other format through the OpenImageIO module,
// and clear errors for bad paths and bad files.
// Example failures: a snapshot format chosen by extension that silently writes PNG; a corrupt
// image that crashes the reader; a half-written file left where the snapshot should be.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "media/image_io.h"
#include "support/test_paths.h"

namespace basalt::media {
namespace {

Image gradient(std::uint32_t w, std::uint32_t h, std::uint32_t channels) {
  Image img = Image::make(w, h, channels);
  for (std::uint32_t y = 0; y < h; ++y)
    for (std::uint32_t x = 0; x < w; ++x)
      for (std::uint32_t c = 0; c < channels; ++c)
        img.pixels[(std::size_t{y} * w + x) * channels + c] =
            static_cast<std::uint8_t>((x * 7 + y * 3 + c * 50) & 0xff);
  return img;
}

TEST(ImageIo, PngRoundTripsExactly) {
  const auto dir = test::scratchDir("image-io-png");
  for (std::uint32_t channels : {1u, 3u, 4u}) {
    const Image original = gradient(37, 19, channels);
    const auto path = dir / ("g" + std::to_string(channels) + ".png");
    ASSERT_TRUE(writeImage(path, original));
    auto back = readImage(path);
    ASSERT_TRUE(back) << back.error().describe();
    EXPECT_EQ(back->channels, channels);
    EXPECT_TRUE(back->pixels == original.pixels) << channels << " channels";
  }
}

TEST(ImageIo, OtherFormatsGoThroughOpenImageIoByExtension) {
  const auto dir = test::scratchDir("image-io-oiio");
  const Image original = gradient(64, 32, 3);
  for (const char* name : {"snap.tif", "snap.ppm", "snap.TGA"}) {
    const auto path = dir / name;
    auto written = writeImage(path, original);
    ASSERT_TRUE(written) << name << ": " << written.error().describe();
    auto back = readImage(path);
    ASSERT_TRUE(back) << name << ": " << back.error().describe();
    EXPECT_TRUE(back->pixels == original.pixels) << name << " is lossless but did not round-trip";
  }
  // JPEG is lossy: the picture must come back close, and the file must really be a JPEG.
  ASSERT_TRUE(writeImage(dir / "snap.jpg", original));
  std::ifstream jpeg(dir / "snap.jpg", std::ios::binary);
  unsigned char magic[2] = {};
  jpeg.read(reinterpret_cast<char*>(magic), 2);
  EXPECT_EQ(magic[0], 0xFF);
  EXPECT_EQ(magic[1], 0xD8) << "a .jpg snapshot must be written as JPEG";
}

// A snapshot is RGBA, and PPM has no alpha (Netpbm's ppm(5): "P6", width, height, maxval, then
// each pixel's red, green and blue): `--snapshot x.ppm` writes the colours and drops the alpha.
TEST(ImageIo, PpmSnapshotsDropTheAlpha) {
  const auto dir = test::scratchDir("image-io-ppm");
  const Image rgba = gradient(5, 3, 4);
  ASSERT_TRUE(writeImage(dir / "snap.ppm", rgba));
  std::ifstream in(dir / "snap.ppm", std::ios::binary | std::ios::ate);
  std::string bytes(static_cast<std::size_t>(in.tellg()), '\0');
  in.seekg(0);
  in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  const std::string header = "P6\n5 3\n255\n";
  ASSERT_TRUE(bytes.starts_with(header)) << bytes.substr(0, 16);
  ASSERT_EQ(bytes.size(), header.size() + 5 * 3 * 3);
  for (std::uint32_t y = 0; y < 3; ++y) {
    for (std::uint32_t x = 0; x < 5; ++x) {
      for (std::uint32_t c = 0; c < 3; ++c) {
        EXPECT_EQ(static_cast<std::uint8_t>(bytes[header.size() + (y * 5 + x) * 3 + c]), rgba.at(x, y, c))
            << x << "," << y << " channel " << c;
      }
    }
  }
  // Grey with alpha in a .pgm: P5 and the grey samples.
  const Image greyAlpha = gradient(4, 2, 2);
  ASSERT_TRUE(writeImage(dir / "snap.pgm", greyAlpha));
  auto grey = readImage(dir / "snap.pgm");
  ASSERT_TRUE(grey) << grey.error().describe();
  EXPECT_EQ(grey->channels, 1u);
  EXPECT_EQ(grey->at(3, 1, 0), greyAlpha.at(3, 1, 0));
}

TEST(ImageIo, NoPartialFileIsLeftBehind) {
  const auto dir = test::scratchDir("image-io-partial");
  ASSERT_TRUE(writeImage(dir / "a.png", gradient(8, 8, 4)));
  ASSERT_TRUE(writeImage(dir / "b.tif", gradient(8, 8, 4)));
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    EXPECT_EQ(entry.path().filename().string().find("partial"), std::string::npos) << entry.path();
  }
}

TEST(ImageIo, BadPathsAndFilesAreClearErrors) {
  const auto dir = test::scratchDir("image-io-errors");
  auto unknown = writeImage(dir / "snap.nosuchformat", gradient(4, 4, 3));
  ASSERT_FALSE(unknown);
  EXPECT_NE(unknown.error().describe().find("snap.nosuchformat"), std::string::npos) << unknown.error().describe();

  auto missing = readImage(dir / "missing.png");
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().code(), Errc::kNotFound);

  std::ofstream(dir / "garbage.png") << "this is not a PNG file";
  auto garbage = readImage(dir / "garbage.png");
  ASSERT_FALSE(garbage);
  EXPECT_NE(garbage.error().describe().find("garbage.png"), std::string::npos);

  EXPECT_FALSE(writeImage(dir / "empty.png", Image{}));

  // A folder in the way of the image: the rename's own cause is said, and no partial file stays.
  std::filesystem::create_directories(dir / "taken.png" / "inside");
  auto taken = writeImage(dir / "taken.png", gradient(4, 4, 3));
  ASSERT_FALSE(taken);
  EXPECT_NE(taken.error().describe().find("cannot move the image into place"), std::string::npos)
      << taken.error().describe();
  EXPECT_EQ(taken.error().describe().find("Success"), std::string::npos) << taken.error().describe();
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    EXPECT_EQ(entry.path().filename().string().find("partial"), std::string::npos) << entry.path();
  }
}

TEST(ImageIo, TruncatedPngFromTheWildIsRejected) {
  const auto data = test::testdataDir();
  if (data.empty()) GTEST_SKIP() << "the shared test data (../shared/testdata) is not on this machine";
  auto r = readImage(data / "textures/small/png-truncated.png");
  EXPECT_FALSE(r) << "a truncated PNG decoded without complaint";
  if (!r) {
    EXPECT_NE(r.error().describe().find("png-truncated.png"), std::string::npos);
  }
}

}  // namespace
}  // namespace basalt::media
