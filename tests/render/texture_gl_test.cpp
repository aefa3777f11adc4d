// Textures on parts (LAVA §6.2.2, thesis §4.2.6): image textures by the name a part carries,
// with the mesh's coordinates or LAVA's automatic binding, sphere reflection maps, streams
// registered from outside (the video contract: just a TextureView), and vertex-level texture
// mapping (LAVA Appendix 1) converging to the per-pixel picture as subdivision grows.
// Example failures: textures upside down; a missing texture stopping the show or warning every
// frame; VLTM that does not subdivide (no convergence) or subdivides wrongly (a worse picture with
// more segments); the sphere map sampled with the wrong reflection vector.

#include <gtest/gtest.h>

#include <cmath>

#include "media/image_io.h"
#include "runtime/log.h"
#include "support/render_fixture.h"
#include "support/test_paths.h"

namespace basalt::test {
namespace {

using runtime::PartStyle;
using runtime::Show;

class Textures : public RenderTest {
 protected:
  void expectGolden(const Image& image, const std::string& name) {
    const std::string problem = matchesGolden(image, name);
    EXPECT_TRUE(problem.empty()) << name << ": " << problem;
  }
};

Image quadrantImage() {
  Image image = Image::make(64, 64, 3);
  for (std::uint32_t y = 0; y < 64; ++y) {
    for (std::uint32_t x = 0; x < 64; ++x) {
      const bool right = x >= 32, bottom = y >= 32;
      std::uint8_t* p = image.row(y) + std::size_t{x} * 3;
      p[0] = static_cast<std::uint8_t>(right == bottom ? 255 : 0);
      p[1] = static_cast<std::uint8_t>(right ? 255 : 0);
      p[2] = static_cast<std::uint8_t>(bottom ? 255 : 0);
    }
  }
  return image;
}

/// A quad filling the view, unlit white, textured with `name`.
Show texturedQuad(const std::string& name, int n = 1) {
  Show show = showOf(makeQuad(1.0f, 0.0f, n));
  show.editGlobalStyle([](PartStyle& s) {
    s.front.illumination = runtime::Illumination::kNone;
    s.front.color = {1, 1, 1};
  });
  show.setPartTexture(0, name);
  return show;
}

TEST_F(Textures, ImageTextureIsUprightOnItsCoordinates) {
  ASSERT_TRUE(renderer().textures().setImage("quadrants", quadrantImage()));
  const Image image = render(texturedQuad("quadrants"), testCamera());
  // The image's top row sits at v = 1, the top of the quad.
  EXPECT_EQ(image.at(20, 20, 0), 255);  // top left: red
  EXPECT_EQ(image.at(20, 20, 1), 0);
  EXPECT_EQ(image.at(235, 20, 1), 255);  // top right: green
  EXPECT_EQ(image.at(235, 20, 0), 0);
  EXPECT_EQ(image.at(20, 235, 2), 255);   // bottom left: blue
  EXPECT_EQ(image.at(235, 235, 0), 255);  // bottom right: white
}

TEST_F(Textures, StreamTexturesAreViews) {
  // A texture owned elsewhere (a movie's converted frame) is only named in the registry.
  const Image q = quadrantImage();
  render::gl::Texture owned = render::gl::Texture::create();
  glBindTexture(GL_TEXTURE_2D, owned.id());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB, 64, 64, 0, GL_RGB, GL_UNSIGNED_BYTE, q.pixels.data());
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  render::TextureView view{owned.id(), {64, 64}, false, 1};
  renderer().textures().setExternal("stream", view);
  Image image = render(texturedQuad("stream"), testCamera());
  EXPECT_EQ(image.at(20, 20, 0), 255) << "top left red, as for an image";
  EXPECT_EQ(image.at(20, 20, 1), 0);
  // A stream that renders bottom row first says so, and is still shown upright.
  view.bottomUp = true;
  renderer().textures().setExternal("stream", view);
  image = render(texturedQuad("stream"), testCamera());
  EXPECT_EQ(image.at(20, 20, 2), 255) << "row 0 now counts as the bottom: blue shows at the top";
  renderer().textures().remove("stream");
}

TEST_F(Textures, MissingTextureWarnsOnceAndDrawsUntextured) {
  auto ring = std::make_shared<log::RingSink>(32);
  log::addSink(ring);
  Show show = texturedQuad("never loaded");
  show.editGlobalStyle([](PartStyle& s) { s.front.color = {0.2f, 0.4f, 0.6f}; });
  Image image;
  for (int i = 0; i < 3; ++i) image = render(show, testCamera());
  log::removeSink(ring);
  EXPECT_NEAR(image.at(128, 128, 1), 102, 1);
  int warnings = 0;
  for (const log::Record& r : ring->snapshot(log::Level::kWarn)) {
    if (r.message.find("'never loaded'") != std::string::npos) ++warnings;
  }
  EXPECT_EQ(warnings, 1);
}

TEST_F(Textures, TextureSwitchOffDrawsUntextured) {
  ASSERT_TRUE(renderer().textures().setImage("quadrants", quadrantImage()));
  Show show = texturedQuad("quadrants");
  show.texture().source = runtime::TextureSource::kOff;
  const Image image = render(show, testCamera());
  EXPECT_EQ(image.at(20, 20, 1), 255) << "white, not red";
}

TEST_F(Textures, PhotoOnTheCube) {
  const auto path = testdataDir() / "textures/libjpeg-turbo/testorig.png";
  if (testdataDir().empty() || !std::filesystem::exists(path)) GTEST_SKIP() << "no shared test data at " << path;
  auto photo = media::readImage(path);
  ASSERT_TRUE(photo) << photo.error().describe();
  ASSERT_TRUE(renderer().textures().setImage("photo", *photo));
  Show show = Show::makeDefault();
  for (runtime::PartId id = 0; id < show.partCount(); ++id) show.setPartTexture(id, "photo");
  expectGolden(renderShow(show), "texture_photo_cube");
}

TEST_F(Textures, AutomaticBindingForMeshesWithoutCoordinates) {
  Image checker = Image::make(8, 8, 3);
  for (std::uint32_t y = 0; y < 8; ++y) {
    for (std::uint32_t x = 0; x < 8; ++x) {
      const std::uint8_t v = ((x + y) % 2) != 0 ? 255 : 60;
      for (std::uint32_t c = 0; c < 3; ++c) checker.row(y)[x * 3 + c] = v;
    }
  }
  ASSERT_TRUE(renderer().textures().setImage("checker", checker));
  auto cube = std::make_shared<runtime::Mesh>(*runtime::makeColorCube());
  cube->texcoords.clear();
  Show show = Show::makeDefault();
  show.clear();
  runtime::SceneNode node;
  node.mesh = cube;
  show.addNode(node);
  show.rotateGlobal({25, -35, 0});
  for (runtime::PartId id = 0; id < show.partCount(); ++id) show.setPartTexture(id, "checker");
  const Image image = renderShow(show);
  // Every visible face is checkered: along a line across the picture the brightness crosses the
  // checker's middle grey again and again (the magnified checker is smoothed by filtering).
  int crossings = 0;
  for (std::uint32_t x = 40; x < 216; ++x) {
    if ((image.at(x, 150, 1) < 120) != (image.at(x + 1, 150, 1) < 120)) ++crossings;
  }
  EXPECT_GT(crossings, 8);
  expectGolden(image, "texture_auto_binding");
}

TEST_F(Textures, SphereReflectionMap) {
  // A sphere map: white in the middle, shading to blue at the rim, with a red spot above the middle.
  Image map = Image::make(64, 64, 3);
  for (std::uint32_t y = 0; y < 64; ++y) {
    for (std::uint32_t x = 0; x < 64; ++x) {
      const float dx = (static_cast<float>(x) + 0.5f) / 32.0f - 1, dy = (static_cast<float>(y) + 0.5f) / 32.0f - 1;
      const float r = std::min(std::sqrt(dx * dx + dy * dy), 1.0f);
      std::uint8_t* p = map.row(y) + std::size_t{x} * 3;
      const bool spot = std::hypot(dx, dy + 0.5f) < 0.15f;
      p[0] = static_cast<std::uint8_t>(spot ? 255 : 255 * (1 - r));
      p[1] = static_cast<std::uint8_t>(spot ? 0 : 255 * (1 - r));
      p[2] = 255;
    }
  }
  ASSERT_TRUE(renderer().textures().setImage("sphere map", map));
  Show show = showOf(makeSphere(1.0f, 48, 96));
  show.editGlobalStyle([](PartStyle& s) {
    s.front.illumination = runtime::Illumination::kNone;
    s.front.color = {1, 1, 1};
  });
  show.setPartReflectionTexture(0, "sphere map");
  const runtime::ViewTransforms view = testCamera(3.0f, 1.2f);
  const Image image = render(show, view);
  // Facing the eye the reflection looks straight back: the middle of the map, white.
  EXPECT_GT(image.at(128, 128, 0), 230);
  EXPECT_GT(image.at(128, 128, 1), 230);
  // Towards the rim the reflection turns away: blue.
  EXPECT_LT(image.at(128, 128 + 95, 0), 150);
  expectGolden(image, "texture_sphere_map");
}

/// A smooth 16 x 16 texture, many pixels per texel.
Image smoothTexture() {
  Image image = Image::make(16, 16, 3);
  for (std::uint32_t y = 0; y < 16; ++y) {
    for (std::uint32_t x = 0; x < 16; ++x) {
      std::uint8_t* p = image.row(y) + std::size_t{x} * 3;
      p[0] = static_cast<std::uint8_t>(std::lround(127.5 + 127.5 * std::sin(2 * std::numbers::pi * x / 16.0)));
      p[1] = static_cast<std::uint8_t>(std::lround(127.5 + 127.5 * std::cos(2 * std::numbers::pi * y / 8.0)));
      p[2] = static_cast<std::uint8_t>(x * 16);
    }
  }
  return image;
}

double meanDifference(const Image& a, const Image& b) { return compareImages(a, b, 255).meanAbsoluteDelta; }

TEST_F(Textures, VertexLevelMappingConvergesToThePixelPicture) {
  ASSERT_TRUE(renderer().textures().setImage("smooth", smoothTexture()));
  Show show = texturedQuad("smooth");
  const runtime::ViewTransforms view = testCamera(3.0f, 1.1f);
  const Image pixel = render(show, view);
  show.texture().method = runtime::TextureMethod::kVertexLevel;
  show.texture().approx = runtime::TextureApprox::kNumSegments;
  double previous = 1e9;
  std::string figures;
  for (int m : {1, 2, 4, 8, 16, 32}) {
    show.texture().subsegments = m;
    const double d = meanDifference(render(show, view), pixel);
    figures += fmt::format(" m={}: {:.2f}", m, d);
    EXPECT_LT(d, previous) << "more segments must come closer to the per-pixel picture;" << figures;
    previous = d;
  }
  EXPECT_LT(previous, 1.0) << figures;
  std::printf("VLTM against per-pixel texturing, mean difference per channel (0-255):%s\n", figures.c_str());
  // Pixel tolerance: smaller tolerances come closer too.
  show.texture().approx = runtime::TextureApprox::kPixelTolerance;
  previous = 1e9;
  figures.clear();
  for (int tolerance : {128, 64, 32, 16}) {
    show.texture().pixelTolerance = tolerance;
    const double d = meanDifference(render(show, view), pixel);
    figures += fmt::format(" tol={}: {:.2f}", tolerance, d);
    EXPECT_LT(d, previous) << figures;
    previous = d;
  }
  EXPECT_LT(previous, 1.5) << figures;
  std::printf("VLTM against per-pixel texturing, mean difference per channel (0-255):%s\n", figures.c_str());
  // Combined takes the finer of the two.
  show.texture().approx = runtime::TextureApprox::kCombined;
  show.texture().subsegments = 2;
  show.texture().pixelTolerance = 16;
  EXPECT_NEAR(meanDifference(render(show, view), pixel), previous, 0.05);
  show.texture().approx = runtime::TextureApprox::kNumSegments;
  show.texture().subsegments = 3;
  expectGolden(render(show, view), "texture_vltm_m3");
}

}  // namespace
}  // namespace basalt::test
