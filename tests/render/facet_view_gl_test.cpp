// Facet views drawn headless (thesis §4.4): the show seen through one facet of the thesis'
// display geometries with the black border of §4.4.5, in mono and in each stereo layout
// (anaglyph, side by side, top and bottom), with golden images and numeric checks: every pixel
// well outside the facet's projected outline is black and every pixel well inside shows the
// scene; the passive layouts put each eye in its half; plain views honour the layouts too.
// Example failures: the border drawn with the outline's winding reversed (the facet black, the
// outside drawn); a border that ignores the viewport of a tiled facet; the right eye drawn into
// the left half; an anaglyph eye's border wiping the other eye's channels.

#include <gtest/gtest.h>

#include <GLES3/gl3.h>

#include <cmath>

#include "render/facet_view.h"
#include "runtime/formats/cave.h"
#include "support/polyhedra.h"
#include "support/render_fixture.h"

namespace basalt::test {
namespace {

using runtime::Show;

formats::CaveGeometry geometryOf(const std::string& obj) {
  std::vector<formats::Diagnostic> warnings;
  auto g = formats::parseCaveGeometry(obj, "display.obj", {}, warnings);
  EXPECT_TRUE(g) << (g ? "" : g.error().describe());
  return g ? std::move(*g) : formats::CaveGeometry{};
}

// Inside the convex polygon by at least `margin` (NDC units), or outside by at least `margin`.
int sideOf(const std::vector<Vec2>& poly, Vec2 p, float margin) {
  float area = 0;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Vec2 a = poly[i], b = poly[(i + 1) % poly.size()];
    area += a.x * b.y - b.x * a.y;
  }
  float minDist = 1e9f;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Vec2 a = poly[i], b = poly[(i + 1) % poly.size()];
    const float ex = b.x - a.x, ey = b.y - a.y;
    const float d = ((p.x - a.x) * ey - (p.y - a.y) * ex) / std::sqrt(ex * ex + ey * ey) * (area >= 0 ? -1.0f : 1.0f);
    minDist = std::min(minDist, d);
  }
  if (minDist > margin) return 1;
  if (minDist < -margin) return -1;
  return 0;
}

class FacetViews : public RenderTest {
 protected:
  void SetUp() override {
    RenderTest::SetUp();
    if (IsSkipped()) return;
    auto f = render::FacetRenderer::create();
    ASSERT_TRUE(f) << f.error().describe();
    facets_ = std::move(*f);
  }

  Image drawFacet(const Show& show, const formats::CaveFacet& facet, bool stereo = false,
                  runtime::StereoMode mode = runtime::StereoMode::kAnaglyph, float spacing = 0.2f,
                  const formats::CaveSettings& calibration = {}, Vec3 eyeAxis = {}) {
    render::FacetPass pass;
    pass.eyeAxis = eyeAxis;
    pass.facet = &facet;
    pass.input.worldFromCave = runtime::cavePlacement(show);
    pass.input.calibration = calibration;
    pass.input.farDistance = 50;
    pass.viewport = {0, 0, kRenderSize, kRenderSize};
    pass.stereo = stereo;
    pass.stereoMode = mode;
    pass.eyeSpacing = spacing;
    EXPECT_TRUE(output().beginFrame());
    EXPECT_TRUE(facets_->draw(renderer(), show, pass));
    Image image;
    auto read = output().readBack(image);
    EXPECT_TRUE(read) << read.error().describe();
    return image;
  }

  void expectGolden(const Image& image, const std::string& name) {
    const std::string problem = matchesGolden(image, name);
    EXPECT_TRUE(problem.empty()) << name << ": " << problem;
  }

  static Show greyShow() {
    Show show = Show::makeDefault();
    show.global().background = {0.3f, 0.4f, 0.5f};
    return show;
  }

  std::unique_ptr<render::FacetRenderer> facets_;
};

struct BorderCount {
  int inside = 0, outside = 0, wrong = 0;  // pixels well inside, well outside, and of those the wrong colour
  bool opaque = true;                      // alpha 255 everywhere
};

// Every pixel more than `marginPixels` outside the outline should be black, every pixel more
// than that inside not (the grey background or the cube).
BorderCount countBorder(const Image& image, const std::vector<Vec2>& outline, float marginPixels) {
  BorderCount c;
  const float margin = marginPixels * 2.0f / static_cast<float>(kRenderSize);
  for (std::uint32_t y = 0; y < kRenderSize; ++y) {
    for (std::uint32_t x = 0; x < kRenderSize; ++x) {
      const Vec2 ndc{(static_cast<float>(x) + 0.5f) / kRenderSize * 2 - 1,
                     1 - (static_cast<float>(y) + 0.5f) / kRenderSize * 2};
      const int side = sideOf(outline, ndc, margin);
      const bool black = image.at(x, y, 0) == 0 && image.at(x, y, 1) == 0 && image.at(x, y, 2) == 0;
      if (side > 0) ++c.inside, c.wrong += black ? 1 : 0;
      if (side < 0) ++c.outside, c.wrong += black ? 0 : 1;
      c.opaque = c.opaque && image.at(x, y, 3) == 255;
    }
  }
  return c;
}

void expectBorder(const Image& image, const std::vector<Vec2>& outline, const std::string& what) {
  const BorderCount c = countBorder(image, outline, 1.5f);
  EXPECT_EQ(c.wrong, 0) << what << ": " << c.inside << " pixels inside, " << c.outside << " outside";
  EXPECT_GT(c.inside, 1000) << what;
}

TEST_F(FacetViews, EverythingOutsideTheFacetIsBlackForEveryThesisShape) {
  const Show show = greyShow();
  for (const std::string& obj : {cubeDisplayObj(), prismDisplayObj(), icositetrahedronDisplayObj()}) {
    const formats::CaveGeometry g = geometryOf(obj);
    for (std::size_t i = 0; i < g.facets.size(); i += 3) {
      const Image image = drawFacet(show, g.facets[i]);
      expectBorder(image, facets_->lastProjection().border, fmt::format("facet {} of {}", i, g.facets.size()));
    }
  }
}

TEST_F(FacetViews, OverABlackClearTheBorderCoversOnlyTheOutlinesBoxAndNothingShowsOutside) {
  // A view whose clear colour is black draws its background and scene only inside the outline's
  // bounding box, and the border then covers only that box (the clear left the rest black). An
  // earth-sky (sky and ground, no black in it) drawn over a black clear shows whether anything
  // leaks outside, or the border misses a corner inside the box.
  Show show = Show::makeDefault();
  show.backgroundKind() = runtime::BackgroundKind::kEarthSky;
  show.earthSky().mode = runtime::EarthSkyClear::kSkyGround;
  ASSERT_EQ(render::Renderer::clearColor(show).r, 0.0f);
  for (const std::string& obj : {cubeDisplayObj(), prismDisplayObj(), icositetrahedronDisplayObj()}) {
    const formats::CaveGeometry g = geometryOf(obj);
    for (std::size_t i = 0; i < g.facets.size(); i += 3) {
      const Image image = drawFacet(show, g.facets[i]);
      expectBorder(image, facets_->lastProjection().border, fmt::format("facet {} of {}", i, g.facets.size()));
    }
  }
  // Side by side: each eye's box in its own half.
  const formats::CaveGeometry prism = geometryOf(prismDisplayObj());
  const Image pair = drawFacet(show, prism.facets[6], true, runtime::StereoMode::kSideBySide);
  EXPECT_NE(pair.at(kRenderSize / 4, kRenderSize / 2, 2), 0) << "the left eye's sky";
  EXPECT_NE(pair.at(kRenderSize * 3 / 4, kRenderSize / 2, 2), 0) << "the right eye's sky";
  EXPECT_EQ(pair.at(1, 1, 2), 0) << "outside the left eye's facet";
  EXPECT_EQ(pair.at(kRenderSize - 2, 1, 2), 0) << "outside the right eye's facet";
}

TEST_F(FacetViews, GoldenFacetViewsWithTheBorder) {
  const Show show = greyShow();
  // The cube's -Z wall looks at the default show's cube, as the plain view does (mirrored for
  // rear projection); a kite of the icositetrahedron shows its non-rectangular border.
  const formats::CaveGeometry cube = geometryOf(cubeDisplayObj());
  expectGolden(drawFacet(show, cube.facets[5]), "facet_cube_front");
  const formats::CaveGeometry ico = geometryOf(icositetrahedronDisplayObj());
  std::size_t kite = 0;
  float best = -2;
  for (std::size_t i = 0; i < ico.facets.size(); ++i) {
    // The wall most ahead (-Z) faces the viewer: its inward normal points most along +Z.
    if (ico.facets[i].normal.z > best) best = ico.facets[i].normal.z, kite = i;
  }
  formats::CaveSettings calibration;
  calibration.xSkew = 8;
  calibration.yScale = 1.2f;
  expectGolden(drawFacet(show, ico.facets[kite], false, runtime::StereoMode::kAnaglyph, 0, calibration),
               "facet_kite_calibrated");
}

TEST_F(FacetViews, StereoLayoutsPutEachEyeInItsPlace) {
  const Show show = greyShow();
  const formats::CaveGeometry cube = geometryOf(cubeDisplayObj());
  const Image anaglyph = drawFacet(show, cube.facets[5], true, runtime::StereoMode::kAnaglyph, 0.3f);
  expectGolden(anaglyph, "facet_stereo_anaglyph");
  const Image sideBySide = drawFacet(show, cube.facets[5], true, runtime::StereoMode::kSideBySide, 0.3f);
  expectGolden(sideBySide, "facet_stereo_side_by_side");
  const Image topBottom = drawFacet(show, cube.facets[5], true, runtime::StereoMode::kTopBottom, 0.3f);
  expectGolden(topBottom, "facet_stereo_top_bottom");
  // Side by side: each half is a squeezed facet image with its border: the left half's
  // centre shows the scene, the column between the halves at the facet's sides is black.
  // The square facet at a square viewport fills each half fully, so both halves' middles
  // show content and the halves differ (parallax) but are close.
  std::uint64_t diff = 0;
  for (std::uint32_t y = 0; y < kRenderSize; ++y) {
    for (std::uint32_t x = 0; x < kRenderSize / 2; ++x) {
      diff += static_cast<std::uint64_t>(std::abs(sideBySide.at(x, y, 1) - sideBySide.at(x + kRenderSize / 2, y, 1)));
    }
  }
  EXPECT_GT(diff, 0u) << "the two eyes see the same picture: no eye spacing";
  // Top and bottom: both halves show the cube (not background) at their centres.
  const auto notBackground = [](const Image& im, std::uint32_t x, std::uint32_t y) {
    return std::abs(im.at(x, y, 0) - static_cast<int>(std::lround(0.3 * 255))) > 3 ||
           std::abs(im.at(x, y, 2) - static_cast<int>(std::lround(0.5 * 255))) > 3;
  };
  EXPECT_TRUE(notBackground(topBottom, kRenderSize / 2, kRenderSize / 4));
  EXPECT_TRUE(notBackground(topBottom, kRenderSize / 2, 3 * kRenderSize / 4));
  EXPECT_TRUE(notBackground(sideBySide, kRenderSize / 4, kRenderSize / 2));
  EXPECT_TRUE(notBackground(sideBySide, 3 * kRenderSize / 4, kRenderSize / 2));
}

// Thesis §4.4.3 offsets each eye from the viewer along the view's right; a tracked head turns
// the eyes with it (FacetPass::eyeAxis, the head's right vector). Side by side, each eye's
// picture of the cube sits apart from the other's along the direction the eyes are apart. With
// no head (the view's right) the cube moves sideways between the halves and not up or down. Of
// the two cave axes across this facet, the one along the view's right gives that same shift, and
// the other, a head rolled a quarter turn, moves the cube up or down instead (by twice as many
// pixels: side by side halves the width).
// Example failure: the eyes always along the view's right, whatever the head does.
TEST_F(FacetViews, StereoEyesSitAlongTheTrackedHeadsRightVector) {
  const Show show = greyShow();
  const formats::CaveGeometry cube = geometryOf(cubeDisplayObj());
  // How far the cube's picture moves from the left eye's half to the right eye's: the centres of
  // the pixels that are neither the background nor the border.
  const auto shift = [&](Vec3 axis) {
    const Image im = drawFacet(show, cube.facets[5], true, runtime::StereoMode::kSideBySide, 0.4f, {}, axis);
    std::array<double, 2> centre[2] = {};
    for (std::uint32_t half = 0; half < 2; ++half) {
      double sx = 0, sy = 0, n = 0;
      for (std::uint32_t y = 0; y < kRenderSize; ++y) {
        for (std::uint32_t x = 0; x < kRenderSize / 2; ++x) {
          const std::uint32_t px = x + half * kRenderSize / 2;
          const int r = im.at(px, y, 0), g = im.at(px, y, 1), b = im.at(px, y, 2);
          const bool background = std::abs(r - 77) <= 3 && std::abs(g - 102) <= 3 && std::abs(b - 128) <= 3;
          if (background || r + g + b == 0) continue;
          sx += x;
          sy += y;
          n += 1;
        }
      }
      EXPECT_GT(n, 500) << "the cube shows in each half";
      centre[half] = {n > 0 ? sx / n : 0, n > 0 ? sy / n : 0};
    }
    return std::array<double, 2>{centre[1][0] - centre[0][0], centre[1][1] - centre[0][1]};
  };
  const auto plain = shift({});
  EXPECT_GT(std::abs(plain[0]), 1.0) << "the view's right: the cube moves sideways";
  EXPECT_LT(std::abs(plain[1]), 0.5) << "the view's right: not up or down";
  const auto alongX = shift({1, 0, 0});
  const auto alongY = shift({0, 1, 0});
  // One cave axis lies along the facet's horizontal, the other along its vertical.
  const bool xIsRight = std::abs(alongX[0]) > std::abs(alongX[1]);
  const auto& right = xIsRight ? alongX : alongY;
  const auto& rolled = xIsRight ? alongY : alongX;
  EXPECT_NEAR(std::abs(right[0]), std::abs(plain[0]), 0.5) << "the head's right along the view's: the same shift";
  EXPECT_LT(std::abs(right[1]), 0.5);
  EXPECT_GT(std::abs(rolled[1]), 1.0) << "a rolled head: the cube moves up or down between the eyes";
  EXPECT_LT(std::abs(rolled[0]), std::abs(rolled[1]) / 4) << "a rolled head: hardly sideways";
  EXPECT_NEAR(std::abs(rolled[1]), 2 * std::abs(plain[0]), 0.25 * std::abs(plain[0]))
      << "the same eye spacing, twice the pixels up the full height as across the halved width";
}

TEST_F(FacetViews, PlainViewsHonourThePassiveStereoLayouts) {
  Show show = greyShow();
  show.global().stereo = true;
  show.stereo().eyeSpacing = 0.4f;
  show.stereo().mode = runtime::StereoMode::kSideBySide;
  expectGolden(renderShow(show), "plain_stereo_side_by_side");
  show.stereo().mode = runtime::StereoMode::kTopBottom;
  expectGolden(renderShow(show), "plain_stereo_top_bottom");
}

TEST_F(FacetViews, TiledFacetsStayInTheirViewports) {
  // Two facets of the prism side by side in one output: each border is cut to its own tile.
  const Show show = greyShow();
  const formats::CaveGeometry prism = geometryOf(prismDisplayObj());
  ASSERT_TRUE(output().beginFrame());
  std::vector<std::vector<Vec2>> outlines;
  for (std::uint32_t t = 0; t < 2; ++t) {
    render::FacetPass pass;
    pass.facet = &prism.facets[t + 6];
    pass.input.worldFromCave = runtime::cavePlacement(show);
    pass.viewport = {static_cast<std::int32_t>(t * kRenderSize / 2), 0, kRenderSize / 2, kRenderSize};
    ASSERT_TRUE(facets_->draw(renderer(), show, pass));
    outlines.push_back(facets_->lastProjection().border);
  }
  Image picture;
  ASSERT_TRUE(output().readBack(picture));
  const Image* image = &picture;
  expectGolden(picture, "facet_tiled_prism");
  // The prism's walls are 2 high and about 0.65 wide: tall facets in tall tiles, grey inside.
  for (std::uint32_t t = 0; t < 2; ++t) {
    const std::uint32_t cx = t * kRenderSize / 2 + kRenderSize / 4;
    EXPECT_FALSE(image->at(cx, kRenderSize / 2, 0) == 0 && image->at(cx, kRenderSize / 2, 2) == 0) << "tile " << t;
  }
}

TEST_F(FacetViews, TheBorderCoversEveryPixelOutsideAnyOutlineAndNoneInside) {
  // The border is drawn as the pieces of the viewport outside each edge. Outlines that test
  // its seams: a 64-gon (the most corners a facet may have), a triangle reaching past the
  // viewport, a sliver, both windings, and a pixel-centred edge that must stay the facet's.
  auto mask = render::BorderMask::create();
  ASSERT_TRUE(mask) << mask.error().describe();
  std::vector<std::pair<std::string, std::vector<Vec2>>> outlines;
  std::vector<Vec2> circle;
  for (int i = 0; i < 64; ++i) {
    const float a = static_cast<float>(i) * 2.0f * 3.14159265f / 64.0f;
    circle.push_back({0.9f * std::cos(a), 0.9f * std::sin(a)});
  }
  outlines.emplace_back("64-gon", circle);
  outlines.emplace_back("64-gon clockwise", std::vector<Vec2>(circle.rbegin(), circle.rend()));
  outlines.emplace_back("triangle past the viewport", std::vector<Vec2>{{-1.5f, -0.8f}, {1.4f, -0.3f}, {0.1f, 1.6f}});
  outlines.emplace_back("sliver", std::vector<Vec2>{{-0.9f, -0.05f}, {0.9f, -0.02f}, {0.9f, 0.04f}});
  for (const auto& [what, outline] : outlines) {
    ASSERT_TRUE(output().beginFrame());
    glClearColor(0.3f, 0.4f, 0.5f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    (*mask)->draw(outline, {0, 0, kRenderSize, kRenderSize});
    Image image;
    ASSERT_TRUE(output().readBack(image));
    // A quarter pixel either side of the outline may go either way.
    const BorderCount c = countBorder(image, outline, 0.25f);
    EXPECT_EQ(c.wrong, 0) << what << ": " << c.inside << " pixels inside, " << c.outside << " outside";
    EXPECT_GT(c.inside, 100) << what;
    EXPECT_GT(c.outside, 100) << what;
    EXPECT_TRUE(c.opaque) << what << " leaves alpha below 255";
  }
  // An edge through a row of pixel centres: that row belongs to the facet, as it did when
  // every pixel was tested against the outline.
  const float row = 1 - (100.5f / kRenderSize) * 2;  // centre of image row 100
  ASSERT_TRUE(output().beginFrame());
  glClearColor(0.3f, 0.4f, 0.5f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  (*mask)->draw(std::vector<Vec2>{{-0.5f, -0.5f}, {0.5f, -0.5f}, {0.5f, row}, {-0.5f, row}},
                {0, 0, kRenderSize, kRenderSize});
  Image image;
  ASSERT_TRUE(output().readBack(image));
  EXPECT_NE(image.at(kRenderSize / 2, 100, 2), 0) << "the row on the edge";
  EXPECT_EQ(image.at(kRenderSize / 2, 99, 2), 0) << "the row above it";
  // No outline: the whole viewport.
  ASSERT_TRUE(output().beginFrame());
  glClearColor(0.3f, 0.4f, 0.5f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  (*mask)->draw({}, {0, 0, kRenderSize, kRenderSize});
  ASSERT_TRUE(output().readBack(image));
  EXPECT_EQ(image.at(3, 3, 2), 0);
  EXPECT_EQ(image.at(kRenderSize / 2, kRenderSize / 2, 2), 0);
}

}  // namespace
}  // namespace basalt::test
