// Backgrounds (thesis §4.3.2: colour, flat image, skybox from one 3 x 2 image; Performer's
// earth-sky with its clear modes), anaglyph stereo (thesis §5.1) and LAVA's stochastic jitter
// snapshot (§6.2.1), each with a golden image and numeric checks: which skybox face each view
// direction shows and that the faces of a row join up, the earth-sky colours at known elevations,
// the anaglyph's channels coming from the right eyes, and the snapshot being the mean of its
// eight jittered passes.
// Example failures: skybox faces swapped or read upside down; the horizon band drawn at the wrong
// angle; the background masked by an eye's colour mask; jitter offsets that do not move the view.

#include <gtest/gtest.h>

#include <cmath>

#include "support/render_fixture.h"

namespace basalt::test {
namespace {

using runtime::BackgroundKind;
using runtime::Color3;
using runtime::Show;

class Backgrounds : public RenderTest {
 protected:
  void expectGolden(const Image& image, const std::string& name) {
    const std::string problem = matchesGolden(image, name);
    EXPECT_TRUE(problem.empty()) << name << ": " << problem;
  }
  static void expectColour(const Image& image, std::uint32_t x, std::uint32_t y, const Color3& c, int tolerance,
                           const std::string& what) {
    const float want[3] = {c.r, c.g, c.b};
    for (std::uint32_t k = 0; k < 3; ++k) {
      EXPECT_NEAR(image.at(x, y, k), static_cast<double>(want[k]) * 255.0, tolerance + 0.5) << what << " channel " << k;
    }
  }
};

/// Four coloured quadrants: the top left red, top right green, bottom left blue, bottom right white.
Image quadrants() {
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

TEST_F(Backgrounds, FlatImageFillsTheViewUpright) {
  ASSERT_TRUE(renderer().textures().setImage("quadrants", quadrants()));
  Show show = Show::makeDefault();
  show.backgroundKind() = BackgroundKind::kImage;
  show.backgroundImage() = "quadrants";
  const Image image = renderShow(show);
  expectColour(image, 4, 4, {1, 0, 0}, 1, "top left");
  expectColour(image, 251, 4, {0, 1, 0}, 1, "top right");
  expectColour(image, 4, 251, {0, 0, 1}, 1, "bottom left");
  expectColour(image, 251, 251, {1, 1, 1}, 1, "bottom right");
  expectGolden(image, "background_image");
}

TEST_F(Backgrounds, MissingImageFallsBackToTheColour) {
  Show show = Show::makeDefault();
  show.global().background = {0.2f, 0.3f, 0.4f};
  show.backgroundKind() = BackgroundKind::kSkybox;
  show.backgroundImage() = "no such skybox";
  const Image image = renderShow(show);
  expectColour(image, 2, 2, {0.2f, 0.3f, 0.4f}, 1, "fallback");
}

// A 3 x 2 skybox image, 32 pixels a face: each face a colour of its own, and across the top row
// a red ramp that runs continuously from the left edge of -X to the right edge of +X.
const Color3 kFaceColour[6] = {{0.9f, 0.1f, 0.1f}, {0.1f, 0.9f, 0.1f}, {0.1f, 0.1f, 0.9f},
                               {0.9f, 0.9f, 0.1f}, {0.1f, 0.9f, 0.9f}, {0.9f, 0.1f, 0.9f}};
// Cells in the atlas: -X, +Z, +X on top; -Y, +Y, -Z below.
enum Face { kNegX, kPosZ, kPosX, kNegY, kPosY, kNegZ };

Image skyboxAtlas() {
  Image image = Image::make(96, 64, 3);
  for (std::uint32_t y = 0; y < 64; ++y) {
    for (std::uint32_t x = 0; x < 96; ++x) {
      const std::uint32_t cell = (y / 32) * 3 + x / 32;
      std::uint8_t* p = image.row(y) + std::size_t{x} * 3;
      const Color3 c = kFaceColour[cell];
      p[0] = static_cast<std::uint8_t>(std::lround(c.r * 255));
      p[1] = static_cast<std::uint8_t>(std::lround(c.g * 255));
      p[2] = static_cast<std::uint8_t>(std::lround(c.b * 255));
      if (y < 32) {
        // The ramp in the blue channel: x / 95 across the whole top row.
        p[2] = static_cast<std::uint8_t>(std::lround(255.0 * x / 95.0));
      }
    }
  }
  return image;
}

runtime::ViewTransforms lookingAlong(const Vec3& direction) {
  runtime::ViewTransforms t = testCamera(3.0f, 0.5f);
  const Vec3 up = std::fabs(direction.y) > 0.9f ? Vec3{0, 0, -1} : Vec3{0, 1, 0};
  t.eye = {0, 0, 0};
  t.view = Mat4::lookAt({0, 0, 0}, direction, up);
  t.projection = Mat4::perspective(60.0f, 1.0f, 0.1f, 10.0f);
  return t;
}

TEST_F(Backgrounds, SkyboxShowsTheFaceOfEachDirection) {
  ASSERT_TRUE(renderer().textures().setImage("sky atlas", skyboxAtlas()));
  Show show;  // nothing but the background
  show.backgroundKind() = BackgroundKind::kSkybox;
  show.backgroundImage() = "sky atlas";
  const std::pair<Vec3, Face> directions[6] = {{{-1, 0, 0}, kNegX}, {{1, 0, 0}, kPosX}, {{0, 1, 0}, kPosY},
                                               {{0, -1, 0}, kNegY}, {{0, 0, 1}, kPosZ}, {{0, 0, -1}, kNegZ}};
  for (const auto& [dir, face] : directions) {
    const Image image = render(show, lookingAlong(dir));
    const Color3 c = kFaceColour[face];
    // The red and green channels identify the face (blue carries the ramp on the top row).
    EXPECT_NEAR(image.at(128, 128, 0), static_cast<double>(c.r) * 255.0, 2.5)
        << "looking along " << dir.x << dir.y << dir.z;
    EXPECT_NEAR(image.at(128, 128, 1), static_cast<double>(c.g) * 255.0, 2.5)
        << "looking along " << dir.x << dir.y << dir.z;
  }
}

TEST_F(Backgrounds, SkyboxTopRowJoinsUp) {
  ASSERT_TRUE(renderer().textures().setImage("sky atlas", skyboxAtlas()));
  Show show;
  show.backgroundKind() = BackgroundKind::kSkybox;
  show.backgroundImage() = "sky atlas";
  // Looking between -X and +Z, then between +Z and +X: across the seam in the middle of the view
  // the ramp (blue) must run on without a jump.
  for (const Vec3& dir : {normalize(Vec3{-1, 0, 1}), normalize(Vec3{1, 0, 1})}) {
    const Image image = render(show, lookingAlong(dir));
    int largestStep = 0;
    for (std::uint32_t x = 100; x < 156; ++x) {
      largestStep = std::max(largestStep, std::abs(image.at(x + 1, 128, 2) - image.at(x, 128, 2)));
    }
    EXPECT_LE(largestStep, 6) << "a seam between faces of the top row";
  }
  // A corner of the box: -X, +Y and -Z meet.
  expectGolden(render(show, lookingAlong(normalize(Vec3{-1, 0.7f, -1}))), "background_skybox");
}

TEST_F(Backgrounds, EarthSkyColoursByElevation) {
  Show show;
  show.backgroundKind() = BackgroundKind::kEarthSky;
  runtime::EarthSky& sky = show.earthSky();
  sky.mode = runtime::EarthSkyClear::kSkyGround;
  // A viewer at the origin looking level: the middle row is the horizon.
  runtime::ViewTransforms view = lookingAlong({0, 0, -1});
  view.eye = {0, 1, 0};
  const Image image = render(show, view);
  auto elevationOf = [&](std::uint32_t y) {
    // Pixel row y (top first) of a 60-degree view: the ray's angle above the horizon.
    const float ndc = 1.0f - 2.0f * (static_cast<float>(y) + 0.5f) / 256.0f;
    return std::atan(ndc * std::tan(radians(30.0f)));
  };
  auto lerp = [](const Color3& a, const Color3& b, float t) {
    return Color3{a.r + (b.r - a.r) * t, a.g + (b.g - a.g) * t, a.b + (b.b - a.b) * t};
  };
  const float band = radians(sky.horizonAngle);
  for (std::uint32_t y : {2u, 40u, 100u, 120u, 127u, 136u, 150u, 200u, 253u}) {
    const float e = elevationOf(y);
    Color3 want;
    if (e >= band) {
      want = lerp(sky.skyBottom, sky.skyTop, (e - band) / (radians(90) - band));
    } else if (e >= 0) {
      want = lerp(sky.horizon, sky.skyBottom, e / band);
    } else if (-e < band) {
      want = lerp(sky.horizon, sky.groundFar, -e / band);
    } else {
      want = lerp(sky.groundFar, sky.groundNear, (-e - band) / (radians(90) - band));
    }
    expectColour(image, 128, y, want, 2, fmt::format("row {} (elevation {:.1f} degrees)", y, e * 57.2958f));
  }
  expectGolden(image, "background_earth_sky");

  sky.mode = runtime::EarthSkyClear::kSkyClear;
  sky.clear = {0.3f, 0.0f, 0.0f};
  const Image clearBelow = render(show, view);
  expectColour(clearBelow, 128, 200, sky.clear, 1, "sky_clear below the horizon");
  expectColour(clearBelow, 128, 40, lerp(sky.skyBottom, sky.skyTop, (elevationOf(40) - band) / (radians(90) - band)), 2,
               "sky_clear above");

  sky.mode = runtime::EarthSkyClear::kFast;
  const Image fast = render(show, view);
  expectColour(fast, 128, 40, sky.clear, 1, "fast clears to the clear colour");
}

TEST_F(Backgrounds, EarthSkyDefaultsFromPerformer) {
  Show show = Show::makeDefault();
  show.backgroundKind() = BackgroundKind::kEarthSky;
  show.earthSky().mode = runtime::EarthSkyClear::kSkyGround;
  expectGolden(renderShow(show), "background_earth_sky_show");
}

class Stereo : public RenderTest {};

TEST_F(Stereo, AnaglyphTakesRedFromTheLeftEyeAndCyanFromTheRight) {
  Show show = Show::makeDefault();
  show.global().background = {0.1f, 0.1f, 0.1f};
  show.global().stereo = true;
  show.stereo().eyeSpacing = 0.4f;
  const Image anaglyph = renderShow(show);
  show.global().stereo = false;
  const Image left = render(show, runtime::computeEyeView(show, 1.0f, -0.2f));
  const Image right = render(show, runtime::computeEyeView(show, 1.0f, 0.2f));
  std::size_t differ = 0;
  for (std::uint32_t y = 0; y < kRenderSize; ++y) {
    for (std::uint32_t x = 0; x < kRenderSize; ++x) {
      ASSERT_EQ(anaglyph.at(x, y, 0), left.at(x, y, 0)) << x << "," << y;
      ASSERT_EQ(anaglyph.at(x, y, 1), right.at(x, y, 1)) << x << "," << y;
      ASSERT_EQ(anaglyph.at(x, y, 2), right.at(x, y, 2)) << x << "," << y;
      if (left.at(x, y, 0) != right.at(x, y, 0)) ++differ;
    }
  }
  EXPECT_GT(differ, 500u) << "the eyes must see different pictures";
  const std::string problem = matchesGolden(anaglyph, "anaglyph");
  EXPECT_TRUE(problem.empty()) << problem;
}

class Snapshots : public RenderTest {};

TEST_F(Snapshots, StochasticIsTheMeanOfEightJitteredPasses) {
  const Show show = Show::makeDefault();
  ASSERT_TRUE(output().beginFrame());
  Image snapshot;
  ASSERT_TRUE(renderer().drawStochastic(show, {0, 0, kRenderSize, kRenderSize}, snapshot));
  ASSERT_EQ(snapshot.width, kRenderSize);

  std::vector<std::uint32_t> sum(std::size_t{kRenderSize} * kRenderSize * 4, 0);
  for (const Vec2& offset : render::Renderer::jitterOffsets()) {
    EXPECT_LE(std::fabs(offset.x), 0.5f);
    EXPECT_LE(std::fabs(offset.y), 0.5f);
    ASSERT_TRUE(output().beginFrame());
    render::ViewPass pass;
    pass.viewport = {0, 0, kRenderSize, kRenderSize};
    pass.jitter = offset;
    renderer().draw(show, runtime::computeView(show, 1.0f), pass);
    Image one;
    ASSERT_TRUE(output().readBack(one));
    for (std::size_t i = 0; i < sum.size(); ++i) sum[i] += one.pixels[i];
  }
  for (std::size_t i = 0; i < sum.size(); ++i) {
    ASSERT_EQ(snapshot.pixels[i], (sum[i] + 4) / 8) << "byte " << i;
  }
  // Antialiased: the plain frame has hard edges, the snapshot blends them with the background.
  const Image plain = renderShow(show);
  auto partial = [](const Image& image) {
    std::size_t n = 0;
    for (std::uint32_t y = 0; y < kRenderSize; ++y) {
      for (std::uint32_t x = 0; x + 1 < kRenderSize; ++x) {
        const int a = image.at(x, y, 0) + image.at(x, y, 1) + image.at(x, y, 2);
        const int b = image.at(x + 1, y, 0) + image.at(x + 1, y, 1) + image.at(x + 1, y, 2);
        if (a > 0 && b == 0) ++n;  // an object pixel right beside the background
      }
    }
    return n;
  };
  EXPECT_GT(partial(snapshot), 0u);
  const std::string problem = matchesGolden(snapshot, "stochastic");
  EXPECT_TRUE(problem.empty()) << problem;
  (void)plain;
}

}  // namespace
}  // namespace basalt::test
