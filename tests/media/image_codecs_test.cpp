// Image formats beyond the shared files: Sun rasterfiles (LAVA's .ras/.im8/.im24/.im32) read and
// written by Basalt's codec, every depth, type and run-length encoding; PAM written and read
// back; TGA from every origin, raw and run-length; EXIF orientation applied to JPEGs.
// Example failures: a .im24 written as RGB where Sun files hold BGR; an odd-width row without
// its padding byte; a run-length escape misread; a TGA stored bottom-up shown upside down; a
// camera's portrait photo shown lying on its side.

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

#include "media/image_io.h"
#include "media/netpbm.h"
#include "media/sun_raster.h"
#include "support/test_paths.h"

namespace basalt::media {
namespace {

Image pattern(std::uint32_t w, std::uint32_t h, std::uint32_t channels) {
  Image img = Image::make(w, h, channels);
  for (std::uint32_t y = 0; y < h; ++y)
    for (std::uint32_t x = 0; x < w; ++x)
      for (std::uint32_t c = 0; c < channels; ++c)
        img.pixels[(std::size_t{y} * w + x) * channels + c] =
            static_cast<std::uint8_t>((x * 37 + y * 11 + c * 90) & 0xff);
  return img;
}

void put32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) out.push_back(static_cast<std::uint8_t>(v >> s));
}

std::vector<std::uint8_t> sunHeader(std::uint32_t w, std::uint32_t h, std::uint32_t depth, std::uint32_t type,
                                    std::uint32_t mapType, std::uint32_t mapLength) {
  std::vector<std::uint8_t> out;
  for (std::uint32_t v : {kSunRasterMagic, w, h, depth, 0u, type, mapType, mapLength}) put32(out, v);
  return out;
}

TEST(SunRaster, RoundTripsAtEveryDepthItWrites) {
  const auto dir = basalt::test::scratchDir("sun-raster");
  const struct {
    const char* name;
    std::uint32_t channels;
    std::uint32_t readChannels;
  } cases[] = {{"grey.im8", 1, 1}, {"grey.ras", 1, 1},  {"rgb.im24", 3, 3},
               {"rgb.ras", 3, 3},  {"rgba.im32", 4, 4}, {"rgba.ras", 4, 4}};
  for (const auto& c : cases) {
    const Image original = pattern(7, 5, c.channels);  // odd width: rows need padding
    ASSERT_TRUE(writeImage(dir / c.name, original)) << c.name;
    auto back = readImage(dir / c.name);
    ASSERT_TRUE(back) << c.name << ": " << back.error().describe();
    EXPECT_EQ(back->channels, c.readChannels) << c.name;
    EXPECT_EQ(back->pixels, original.pixels) << c.name;
  }
  // RGB written as 32-bit gains an opaque alpha; colour written as 8-bit becomes its luminance.
  ASSERT_TRUE(writeImage(dir / "rgb.im32", pattern(3, 2, 3)));
  auto rgba = readImage(dir / "rgb.im32");
  ASSERT_TRUE(rgba);
  EXPECT_EQ(rgba->channels, 4u);
  EXPECT_EQ(rgba->pixels[3], 255);
  ASSERT_TRUE(writeImage(dir / "rgb.im8", pattern(3, 2, 3)));
  auto grey = readImage(dir / "rgb.im8");
  ASSERT_TRUE(grey);
  EXPECT_EQ(grey->channels, 1u);
}

TEST(SunRaster, TheWrittenBytesAreSunsLayout) {
  Image img = Image::make(1, 1, 3);
  img.pixels = {10, 20, 30};
  auto bytes = encodeSunRaster(img, 24);
  ASSERT_TRUE(bytes);
  ASSERT_EQ(bytes->size(), 32u + 4u) << "one BGR pixel padded to 16 bits";
  EXPECT_EQ((*bytes)[0], 0x59);
  EXPECT_EQ((*bytes)[15], 24) << "depth";
  EXPECT_EQ((*bytes)[23], 1) << "standard type";
  EXPECT_EQ((std::vector<std::uint8_t>(bytes->begin() + 32, bytes->end())), (std::vector<std::uint8_t>{30, 20, 10, 0}));
}

TEST(SunRaster, ReadsEveryKindOfFile) {
  // 1-bit without a map: 1 is black; rows padded to 16 bits.
  auto bits = sunHeader(3, 2, 1, 1, 0, 0);
  bits.insert(bits.end(), {0b10100000, 0, 0b01000000, 0});
  auto b = decodeSunRaster(bits);
  ASSERT_TRUE(b) << b.error().describe();
  EXPECT_EQ(b->pixels, (std::vector<std::uint8_t>{0, 255, 0, 255, 0, 255}));
  // 8-bit with a colour map (two entries: red and blue).
  auto mapped = sunHeader(2, 1, 8, 1, 1, 6);
  mapped.insert(mapped.end(), {255, 0, 0, 0, 0, 255, 1, 0});
  auto m = decodeSunRaster(mapped);
  ASSERT_TRUE(m) << m.error().describe();
  EXPECT_EQ(m->channels, 3u);
  EXPECT_EQ(m->pixels, (std::vector<std::uint8_t>{0, 0, 255, 255, 0, 0}));
  // 24-bit RGB-ordered (type 3), one row of one pixel plus padding.
  auto rgb = sunHeader(1, 1, 24, 3, 0, 0);
  rgb.insert(rgb.end(), {1, 2, 3, 0});
  auto r = decodeSunRaster(rgb);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->pixels, (std::vector<std::uint8_t>{1, 2, 3}));
  // 32-bit with zero pad bytes: no alpha.
  auto xbgr = sunHeader(1, 1, 32, 1, 0, 0);
  xbgr.insert(xbgr.end(), {0, 3, 2, 1});
  auto x = decodeSunRaster(xbgr);
  ASSERT_TRUE(x);
  EXPECT_EQ(x->channels, 3u);
  EXPECT_EQ(x->pixels, (std::vector<std::uint8_t>{1, 2, 3}));
  // Run-length (type 2): 0x80 n v repeats v n+1 times, 0x80 0 is a literal 0x80.
  auto rle = sunHeader(6, 1, 8, 2, 0, 0);
  rle.insert(rle.end(), {0x80, 3, 7, 0x80, 0, 9});
  auto l = decodeSunRaster(rle);
  ASSERT_TRUE(l) << l.error().describe();
  EXPECT_EQ(l->pixels, (std::vector<std::uint8_t>{7, 7, 7, 7, 0x80, 9}));
}

TEST(SunRaster, BadFilesAreRejectedWithAReason) {
  const struct {
    std::vector<std::uint8_t> bytes;
    const char* message;
  } cases[] = {
      {{0x59, 0xa6}, "too short"},
      {sunHeader(0, 1, 8, 1, 0, 0), "1 to 16384 a side"},
      {sunHeader(100000, 1, 8, 1, 0, 0), "1 to 16384 a side"},
      {sunHeader(1, 1, 16, 1, 0, 0), "depth 16 is not a Sun rasterfile depth"},
      {sunHeader(1, 1, 8, 4, 0, 0), "type 4 is not supported"},
      {sunHeader(1, 1, 8, 1, 1, 100), "ends inside its colour map"},
      {sunHeader(4, 4, 24, 1, 0, 0), "the file ends after 0 of the image's 48 bytes"},
      {sunHeader(16000, 16000, 32, 2, 0, 0), "far too short"},
  };
  for (const auto& c : cases) {
    auto r = decodeSunRaster(c.bytes);
    ASSERT_FALSE(r) << c.message;
    EXPECT_NE(r.error().message().find(c.message), std::string::npos) << r.error().message();
  }
  std::vector<std::uint8_t> rle = sunHeader(8, 1, 8, 2, 0, 0);
  rle.insert(rle.end(), {0x80, 2});
  EXPECT_FALSE(decodeSunRaster(rle)) << "a run cut off in the middle";
}

TEST(Netpbm, PamWritesAndReadsBack) {
  const auto dir = basalt::test::scratchDir("netpbm");
  for (std::uint32_t channels : {1u, 2u, 3u, 4u}) {
    const Image original = pattern(5, 3, channels);
    const auto path = dir / ("p" + std::to_string(channels) + ".pam");
    ASSERT_TRUE(writeImage(path, original));
    auto back = readImage(path);
    ASSERT_TRUE(back) << back.error().describe();
    EXPECT_EQ(back->channels, channels);
    EXPECT_EQ(back->pixels, original.pixels);
  }
  Image wide = Image::make(2, 1, 1, ChannelType::kU16);
  wide.pixels = {0x34, 0x12, 0xff, 0xff};  // 0x1234 and 0xffff, native little-endian
  auto bytes = encodeNetpbm(wide, true);
  ASSERT_TRUE(bytes);
  auto back = decodeNetpbm(*bytes);
  ASSERT_TRUE(back);
  EXPECT_EQ(back->type, ChannelType::kU16);
  EXPECT_EQ(back->pixels, wide.pixels);
}

TEST(Netpbm, HeadersAndSamplesThatLieAreRejected) {
  const auto bytes = [](std::string_view s) { return std::vector<std::uint8_t>(s.begin(), s.end()); };
  EXPECT_FALSE(decodeNetpbm(bytes("P5\n100000 1\n255\n")));
  EXPECT_FALSE(decodeNetpbm(bytes("P6\n4 4\n255\nabc")));
  EXPECT_FALSE(decodeNetpbm(bytes("P2\n2 1\n10\n3 11\n")));
  EXPECT_FALSE(decodeNetpbm(bytes("P7\nWIDTH 2\nHEIGHT 2\nDEPTH 5\nMAXVAL 255\nENDHDR\n")));
  EXPECT_FALSE(decodeNetpbm(bytes("P7\nWIDTH 2\n")));
  EXPECT_FALSE(decodeNetpbm(bytes("P1\n3 1\n1 0 2\n")));
  auto ok = decodeNetpbm(bytes("P2 # comment\n2 1 # size\n10\n0 10\n"));
  ASSERT_TRUE(ok);
  EXPECT_EQ(ok->pixels, (std::vector<std::uint8_t>{0, 255}));
}

/// A 2 x 2 TGA of red, green / blue, white (as seen), stored from `origin`, raw or run-length.
std::vector<std::uint8_t> tga(bool top, bool right, bool rle, bool alpha) {
  struct Px {
    std::uint8_t r, g, b;
  };
  const Px seen[2][2] = {{{255, 0, 0}, {0, 255, 0}}, {{0, 0, 255}, {255, 255, 255}}};
  const std::uint8_t bpp = alpha ? 32 : 24;
  std::vector<std::uint8_t> out = {
      0, 0,   static_cast<std::uint8_t>(rle ? 10 : 2),
      0, 0,   0,
      0, 0,   0,
      0, 0,   0,
      2, 0,   2,
      0, bpp, static_cast<std::uint8_t>((alpha ? 8 : 0) | (right ? 0x10 : 0) | (top ? 0x20 : 0))};
  for (int row = 0; row < 2; ++row) {
    const int y = top ? row : 1 - row;
    if (rle) out.push_back(0x01);  // a raw packet of 2 pixels
    for (int col = 0; col < 2; ++col) {
      const int x = right ? 1 - col : col;
      out.insert(out.end(), {seen[y][x].b, seen[y][x].g, seen[y][x].r});
      if (alpha) out.push_back(200);
    }
  }
  return out;
}

TEST(Targa, EveryOriginRawAndRunLengthIsShownTheRightWayUp) {
  const auto dir = basalt::test::scratchDir("targa");
  int n = 0;
  for (bool rle : {false, true}) {
    for (bool alpha : {false, true}) {
      for (bool top : {false, true}) {
        for (bool right : {false, true}) {
          const auto bytes = tga(top, right, rle, alpha);
          const auto path = dir / ("t" + std::to_string(n++) + ".tga");
          std::ofstream(path, std::ios::binary)
              .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
          auto image = readImage(path);
          ASSERT_TRUE(image) << path << ": " << image.error().describe();
          const std::string what = std::string(top ? "top" : "bottom") + (right ? "-right" : "-left") +
                                   (rle ? " run-length" : " raw") + (alpha ? " with alpha" : "");
          ASSERT_EQ(image->channels, alpha ? 4u : 3u) << what;
          const auto c = image->channels;
          EXPECT_EQ(image->at(0, 0, 0), 255) << what << ": the top-left pixel is red";
          EXPECT_EQ(image->at(0, 0, 1), 0) << what;
          EXPECT_EQ(image->at(1, 0, 1), 255) << what << ": top-right is green";
          EXPECT_EQ(image->at(0, 1, 2), 255) << what << ": bottom-left is blue";
          EXPECT_EQ(image->at(0, 1, 0), 0) << what;
          if (alpha) {
            EXPECT_EQ(image->pixels[c - 1], 200) << what << ": alpha as stored";
          }
        }
      }
    }
  }
}

std::vector<std::uint8_t> fileBytes(const std::filesystem::path& p) {
  std::vector<std::uint8_t> out;
  std::FILE* f = std::fopen(p.c_str(), "rb");
  if (!f) return out;
  std::uint8_t buffer[4096];
  for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, f)) > 0;) out.insert(out.end(), buffer, buffer + n);
  std::fclose(f);
  return out;
}

void writeBytes(const std::filesystem::path& p, const std::vector<std::uint8_t>& b) {
  std::ofstream(p, std::ios::binary)
      .write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
}

/// The JPEG without its APP1 (EXIF) segments.
std::vector<std::uint8_t> withoutExif(const std::vector<std::uint8_t>& jpeg) {
  std::vector<std::uint8_t> out(jpeg.begin(), jpeg.begin() + 2);
  std::size_t i = 2;
  while (i + 4 <= jpeg.size() && jpeg[i] == 0xFF && jpeg[i + 1] != 0xDA) {
    const std::size_t length = std::size_t{jpeg[i + 2]} << 8 | jpeg[i + 3];
    if (jpeg[i + 1] != 0xE1)
      out.insert(out.end(), jpeg.begin() + static_cast<long>(i), jpeg.begin() + static_cast<long>(i + 2 + length));
    i += 2 + length;
  }
  out.insert(out.end(), jpeg.begin() + static_cast<long>(i), jpeg.end());
  return out;
}

/// The JPEG with an EXIF segment saying `orientation` right after its start marker.
std::vector<std::uint8_t> withOrientation(const std::vector<std::uint8_t>& jpeg, std::uint8_t orientation) {
  const std::vector<std::uint8_t> app1 = {0xFF, 0xE1, 0, 34, 'E', 'x', 'i', 'f', 0, 0,                  // APP1, "Exif"
                                          'M',  'M',  0, 42, 0,   0,   0,   8,                          // TIFF header
                                          0,    1,                                                      // one entry
                                          0x01, 0x12, 0, 3,  0,   0,   0,   1,   0, orientation, 0, 0,  // Orientation
                                          0,    0,    0, 0};                                            // no next IFD
  std::vector<std::uint8_t> out(jpeg.begin(), jpeg.begin() + 2);
  out.insert(out.end(), app1.begin(), app1.end());
  out.insert(out.end(), jpeg.begin() + 2, jpeg.end());
  return out;
}

TEST(ExifOrientation, MirroredAndRotatedPhotosAreShownAsTheCameraMeant) {
  const auto data = basalt::test::testdataDir();
  if (data.empty()) GTEST_SKIP() << "the shared test data (../shared/testdata) is not on this machine";
  const auto dir = basalt::test::scratchDir("exif");
  // portrait_2.jpg says "mirrored left to right" (orientation 2).
  const auto original = fileBytes(data / "textures/jpg/portrait_2.jpg");
  writeBytes(dir / "plain.jpg", withoutExif(original));
  auto oriented = readImage(data / "textures/jpg/portrait_2.jpg");
  auto plain = readImage(dir / "plain.jpg");
  ASSERT_TRUE(oriented && plain);
  ASSERT_EQ(oriented->width, plain->width);
  const std::uint32_t w = plain->width;
  std::size_t differing = 0;
  for (std::uint32_t y = 0; y < plain->height; ++y)
    for (std::uint32_t x = 0; x < w; ++x)
      for (std::uint32_t c = 0; c < 3; ++c) differing += oriented->at(x, y, c) != plain->at(w - 1 - x, y, c);
  EXPECT_EQ(differing, 0u) << "the EXIF mirror was not applied";
  // Orientation 6 (turned 90 degrees clockwise): the 227 x 149 picture becomes 149 x 227.
  writeBytes(dir / "turned.jpg", withOrientation(fileBytes(data / "textures/libjpeg-turbo/testorig.jpg"), 6));
  auto turned = readImage(dir / "turned.jpg");
  ASSERT_TRUE(turned) << turned.error().describe();
  EXPECT_EQ(turned->width, 149u);
  EXPECT_EQ(turned->height, 227u);
}

}  // namespace
}  // namespace basalt::media
