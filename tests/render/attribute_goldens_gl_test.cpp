// One golden image per LAVA attribute group (issue 3 "Tests"), rendered headless at 256 x 256:
// markers, line patterns, wide lines with their ends and joins, stipples, edges, transparency,
// fill styles, model clipping, illumination types, floor and shadow. Each golden has NAME.txt
// beside it (renderer, size, tolerance). Where a property can be read off a pixel, the test checks
// that too, so that a wrong golden cannot hide a wrong picture.
// Example failures: a marker type drawing the wrong shape; a line pattern starting off; a stipple
// pattern rotated; a transparent part drawn before what is behind it; a clipping plane keeping the
// wrong side; the shadow drawn above the floor or in the wrong colour.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "support/render_fixture.h"

namespace basalt::test {
namespace {

using runtime::AttrId;
using runtime::Color3;
using runtime::PartStyle;
using runtime::Show;

class Goldens : public RenderTest {
 protected:
  void expectGolden(const Image& image, const std::string& name) {
    const std::string problem = matchesGolden(image, name);
    EXPECT_TRUE(problem.empty()) << name << ": " << problem;
  }
  static runtime::PartId part(const Show& show, const std::string& name) {
    const auto id = show.findPart(name);
    EXPECT_TRUE(id.has_value()) << name;
    return id.value_or(0);
  }
};

/// A 3 x 3 grid of points around (x, y).
std::vector<Vec3> pointGrid(float x, float y, float step) {
  std::vector<Vec3> points;
  for (int j = -1; j <= 1; ++j) {
    for (int i = -1; i <= 1; ++i)
      points.push_back({x + step * static_cast<float>(i), y + step * static_cast<float>(j), 0});
  }
  return points;
}

TEST_F(Goldens, Markers) {
  // The eight marker types, two rows of four, each part with its own colour; the bowties and the
  // circle antialiased.
  std::vector<std::shared_ptr<runtime::Mesh>> parts;
  for (int i = 0; i < 8; ++i) {
    const float x = -0.72f + 0.48f * static_cast<float>(i % 4);
    const float y = i < 4 ? 0.45f : -0.45f;
    parts.push_back(makePoints(pointGrid(x, y, 0.14f), fmt::format("markers {}", i)));
  }
  Show show = showOf(combine(parts));
  const Color3 colours[8] = {{1, 1, 1},    {1, 0.3f, 0.3f}, {0.3f, 1, 0.3f}, {0.4f, 0.6f, 1},
                             {1, 1, 0.2f}, {1, 0.4f, 1},    {0.3f, 1, 1},    {1, 0.6f, 0.2f}};
  for (int i = 0; i < 8; ++i) {
    const runtime::PartId id = part(show, fmt::format("markers {}", i));
    show.editPartStyle(id, AttrId::kMarkersType,
                       [&](PartStyle& s) { s.markers.type = static_cast<runtime::MarkerType>(i); });
    show.editPartStyle(id, AttrId::kMarkersColor, [&](PartStyle& s) { s.markers.color = colours[i]; });
    show.editPartStyle(id, AttrId::kMarkersScaleFactor, [&](PartStyle& s) { s.markers.scaleFactor = 13; });
    if (i == 3 || i >= 6) {
      show.editPartStyle(id, AttrId::kMarkersAntialiasing,
                         [&](PartStyle& s) { s.markers.antialiasing = runtime::Antialiasing::kArbitraryBackground; });
    }
  }
  const runtime::ViewTransforms view = testCamera();
  const Image image = render(show, view);
  // The plus marker's centre is lit, a point diagonally off it is not; the square's centre is not.
  auto pixel = [](float v) { return static_cast<std::uint32_t>(std::lround(v)); };
  const Vec2 plus = worldToPixel(view, {-0.24f, 0.45f, 0});
  EXPECT_GT(image.at(pixel(plus.x), pixel(plus.y), 0), 200);
  EXPECT_EQ(image.at(pixel(plus.x + 4), pixel(plus.y + 4), 0), 0);
  const Vec2 square = worldToPixel(view, {-0.24f, -0.45f, 0});
  EXPECT_EQ(image.at(pixel(square.x), pixel(square.y), 1), 0);
  expectGolden(image, "markers");
}

TEST_F(Goldens, LinePatterns) {
  // LAVA's eight patterns, two pixels wide, then two alt-patterned lines.
  std::vector<std::shared_ptr<runtime::Mesh>> parts;
  for (int i = 0; i < 10; ++i) {
    const float y = 0.85f - 0.19f * static_cast<float>(i);
    parts.push_back(makePolyline({{-0.9f, y, 0}, {0.9f, y, 0}}, fmt::format("line {}", i)));
  }
  Show show = showOf(combine(parts));
  show.editGlobalStyle([](PartStyle& s) {
    s.lines.style = runtime::LineStyle::kPatterned;
    s.lines.width = 2;
    s.lines.color = {1, 1, 1};
  });
  for (int i = 0; i < 10; ++i) {
    const runtime::PartId id = part(show, fmt::format("line {}", i));
    show.editPartStyle(id, AttrId::kLinesPattern,
                       [&](PartStyle& s) { s.lines.pattern = static_cast<runtime::LinePattern>(i % 8); });
    if (i >= 8) {
      show.editPartStyle(id, AttrId::kLinesStyle,
                         [](PartStyle& s) { s.lines.style = runtime::LineStyle::kAltPatterned; });
      show.editPartStyle(id, AttrId::kLinesAltColor, [](PartStyle& s) { s.lines.altColor = {1, 0.2f, 0.2f}; });
      show.editPartStyle(id, AttrId::kLinesWidth, [](PartStyle& s) { s.lines.width = 4; });
    }
  }
  const Image image = render(show, testCamera());
  expectGolden(image, "line_patterns");
}

TEST_F(Goldens, WideLinesEndsAndJoins) {
  // Zigzags 12 pixels wide: butt ends with mitred joins, square ends with bevels, round ends with
  // device joins, then a sharp zigzag whose mitres exceed the limit (bevelled), then antialiased.
  std::vector<std::shared_ptr<runtime::Mesh>> parts;
  for (int i = 0; i < 5; ++i) {
    const float y = 0.7f - 0.35f * static_cast<float>(i);
    const float h = i == 3 ? 0.22f : 0.1f;
    const float step = i == 3 ? 0.25f : 0.45f;
    std::vector<Vec3> zig;
    for (int k = 0; k < 5; ++k) {
      const float x = -0.8f + step * static_cast<float>(k) * (i == 3 ? 1.7f : 1.0f);
      zig.push_back({x, y + ((k & 1) != 0 ? h : -h), 0});
    }
    parts.push_back(makePolyline(zig, fmt::format("zigzag {}", i)));
  }
  Show show = showOf(combine(parts));
  show.editGlobalStyle([](PartStyle& s) {
    s.lines.width = 12;
    s.lines.color = {0.9f, 0.9f, 0.5f};
  });
  auto set = [&](int i, runtime::EndpointStyle end, runtime::JoinStyle join) {
    const runtime::PartId id = part(show, fmt::format("zigzag {}", i));
    show.editPartStyle(id, AttrId::kLinesEndpointStyle, [&](PartStyle& s) { s.lines.endpointStyle = end; });
    show.editPartStyle(id, AttrId::kLinesJoinStyle, [&](PartStyle& s) { s.lines.joinStyle = join; });
  };
  set(0, runtime::EndpointStyle::kButt, runtime::JoinStyle::kMiter);
  set(1, runtime::EndpointStyle::kSquare, runtime::JoinStyle::kBevel);
  set(2, runtime::EndpointStyle::kRound, runtime::JoinStyle::kDevice);
  set(3, runtime::EndpointStyle::kButt, runtime::JoinStyle::kMiter);
  set(4, runtime::EndpointStyle::kRound, runtime::JoinStyle::kMiter);
  show.editPartStyle(part(show, "zigzag 4"), AttrId::kLinesAntialiasing,
                     [](PartStyle& s) { s.lines.antialiasing = runtime::Antialiasing::kArbitraryBackground; });
  const runtime::ViewTransforms view = testCamera();
  const Image image = render(show, view);
  // Square ends reach half a width past the end point; butt ends stop there.
  const Vec2 buttEnd = worldToPixel(view, {-0.8f, 0.6f, 0});
  const Vec2 squareEnd = worldToPixel(view, {-0.8f, 0.25f, 0});
  EXPECT_EQ(image.at(static_cast<std::uint32_t>(buttEnd.x - 4), static_cast<std::uint32_t>(buttEnd.y), 0), 0);
  EXPECT_GT(image.at(static_cast<std::uint32_t>(squareEnd.x - 4), static_cast<std::uint32_t>(squareEnd.y), 0), 200);
  expectGolden(image, "lines_wide");
}

TEST_F(Goldens, VertexColoursOnLinesAndMarkers) {
  // A wide line from red to blue and a point at each end: with the vertex colour selector the
  // line takes its first vertex's colour, or blends along when colour interpolation is on; the
  // markers take their vertices' colours.
  auto line = makePolyline({{-0.8f, 0, 0}, {0.8f, 0, 0}}, "line");
  line->colors = {{1, 0, 0, 1}, {0, 0, 1, 1}};
  auto points = makePoints({{-0.8f, 0.5f, 0}, {0.8f, 0.5f, 0}}, "points");
  points->colors = {{0, 1, 0, 1}, {1, 1, 0, 1}};
  Show show = showOf(combine({line, points}));
  show.editGlobalStyle([](PartStyle& s) {
    s.lines.width = 6;
    s.lines.antialiasing = runtime::Antialiasing::kConstantBackground;  // the wide-line path
    s.lines.colorSelector = runtime::ColorSelector::kVertex;
    s.markers.type = runtime::MarkerType::kSquare;
    s.markers.scaleFactor = 15;
    s.markers.colorSelector = runtime::ColorSelector::kVertex;
  });
  const runtime::ViewTransforms view = testCamera();
  auto at = [&](const Image& image, float x, float y, std::uint32_t c) {
    const Vec2 p = worldToPixel(view, {x, y, 0});
    return image.at(static_cast<std::uint32_t>(std::lround(p.x)), static_cast<std::uint32_t>(std::lround(p.y)), c);
  };
  Image image = render(show, view);
  EXPECT_GT(at(image, 0.6f, 0, 0), 240) << "flat: the first vertex's red all along";
  EXPECT_LT(at(image, 0.6f, 0, 2), 15);
  show.editGlobalStyle([](PartStyle& s) { s.lines.colorInterpolation = true; });
  image = render(show, view);
  EXPECT_NEAR(at(image, 0, 0, 0), 128, 12) << "interpolated: half way between red and blue";
  EXPECT_NEAR(at(image, 0, 0, 2), 128, 12);
  EXPECT_GT(at(image, 0.6f, 0, 2), 200);
  // The square markers' outlines (corners on the marker's circle: 5 pixels from the vertex) in their colours.
  const Vec2 left = worldToPixel(view, {-0.8f, 0.5f, 0});
  EXPECT_GT(
      image.at(static_cast<std::uint32_t>(std::lround(left.x)) + 5, static_cast<std::uint32_t>(std::lround(left.y)), 1),
      200);
}

TEST_F(Goldens, StipplePatterns) {
  // The twelve stipple patterns over a red square: stipple lets it through, opaque stipple (the
  // right column) paints the background colour instead.
  std::vector<std::shared_ptr<runtime::Mesh>> parts;
  parts.push_back(makeQuad(0.95f, -0.5f, 1, "behind"));
  for (int i = 0; i < 12; ++i) {
    auto q = makeQuad(0.2f, 0.0f, 1, fmt::format("stipple {}", i));
    const int row = i / 4, column = i % 4;
    const float x = -0.7f + 0.47f * static_cast<float>(column), y = 0.62f - 0.62f * static_cast<float>(row);
    for (Vec3& p : q->positions) p = {p.x + x, p.y + y, p.z};
    parts.push_back(q);
  }
  Show show = showOf(combine(parts));
  show.global().background = {0.1f, 0.1f, 0.3f};
  show.editGlobalStyle([](PartStyle& s) {
    s.front.illumination = runtime::Illumination::kNone;
    s.front.color = {1, 1, 1};
  });
  show.editPartStyle(part(show, "behind"), AttrId::kFrontColor, [](PartStyle& s) { s.front.color = {0.8f, 0, 0}; });
  for (int i = 0; i < 12; ++i) {
    const runtime::PartId id = part(show, fmt::format("stipple {}", i));
    show.editPartStyle(id, AttrId::kFrontFillStyle, [&](PartStyle& s) {
      s.front.fillStyle = i % 4 == 3 ? runtime::FillStyle::kOpaqueStipple : runtime::FillStyle::kStipple;
    });
    show.editPartStyle(id, AttrId::kFrontStipplePattern,
                       [&](PartStyle& s) { s.front.stipplePattern = static_cast<runtime::StipplePattern>(i); });
  }
  const Image image = render(show, testCamera(3.0f, 1.0f, 1.0f, 5.0f));
  expectGolden(image, "stipples");
}

TEST_F(Goldens, Edges) {
  // The colour cube with XGL edges three pixels wide beside a sphere showing only its
  // silhouette edges, dashed and antialiased.
  Show show;
  runtime::SceneNode cube;
  cube.name = "cube";
  cube.mesh = runtime::makeColorCube();
  cube.local =
      Mat4::translation({-1.3f, 0, 0}) * Mat4::rotationY(-30) * Mat4::rotationX(20) * Mat4::scaling({0.8f, 0.8f, 0.8f});
  show.addNode(cube);
  runtime::SceneNode sphere;
  sphere.name = "sphere";
  sphere.mesh = makeSphere(1.0f, 16, 24);
  sphere.local = Mat4::translation({1.3f, 0, 0});
  show.addNode(sphere);
  show.editGlobalStyle([](PartStyle& s) {
    s.edges.show = runtime::EdgeMode::kOn;
    s.edges.width = 3;
    s.edges.color = {0.1f, 0.2f, 0.8f};
  });
  const runtime::PartId sp = part(show, "sphere");
  show.editPartStyle(sp, AttrId::kEdgesSilhouette, [](PartStyle& s) { s.edges.silhouette = true; });
  show.editPartStyle(sp, AttrId::kEdgesStyle, [](PartStyle& s) { s.edges.style = runtime::LineStyle::kPatterned; });
  show.editPartStyle(sp, AttrId::kEdgesPattern, [](PartStyle& s) { s.edges.pattern = runtime::LinePattern::kDashed; });
  show.editPartStyle(sp, AttrId::kEdgesColor, [](PartStyle& s) { s.edges.color = {1, 0.3f, 0.1f}; });
  show.editPartStyle(sp, AttrId::kEdgesAntialiasing,
                     [](PartStyle& s) { s.edges.antialiasing = runtime::Antialiasing::kArbitraryBackground; });
  show.editPartStyle(sp, AttrId::kEdgesShow, [](PartStyle& s) { s.edges.show = runtime::EdgeMode::kSoftware; });
  const Image image = renderShow(show);
  // The sphere's middle shows no edge (silhouette only): a lit surface, not orange.
  const runtime::ViewTransforms view = runtime::computeView(show, 1.0f);
  const Vec2 centre = worldToPixel(view, view.model.transformPoint({1.3f, 0, 1.0f}));
  const auto cx = static_cast<std::uint32_t>(centre.x), cy = static_cast<std::uint32_t>(centre.y);
  EXPECT_FALSE(image.at(cx, cy, 0) > 200 && image.at(cx, cy, 2) < 60) << "an inner edge drawn on the sphere";
  expectGolden(image, "edges");
}

TEST_F(Goldens, Transparency) {
  // Over a white bar: screen door, blended to an arbitrary background, added to the background,
  // and blended to the constant background, each at transparency 0.5.
  std::vector<std::shared_ptr<runtime::Mesh>> parts;
  auto bar = makeQuad(1.0f, -0.3f, 1, "bar");
  for (Vec3& p : bar->positions) p.y *= 0.25f;
  parts.push_back(bar);
  for (int i = 0; i < 4; ++i) {
    auto q = makeQuad(0.2f, 0.2f, 1, fmt::format("glass {}", i));
    for (Vec3& p : q->positions) p = {p.x - 0.66f + 0.44f * static_cast<float>(i), p.y * 2.5f, p.z};
    parts.push_back(q);
  }
  Show show = showOf(combine(parts));
  show.global().background = {0.0f, 0.0f, 0.4f};
  show.editGlobalStyle([](PartStyle& s) {
    s.front.illumination = runtime::Illumination::kNone;
    s.front.color = {0.0f, 0.9f, 0.0f};
    s.front.transparency = 0.5f;
  });
  show.editPartStyle(part(show, "bar"), AttrId::kFrontColor, [](PartStyle& s) { s.front.color = {1, 1, 1}; });
  using runtime::TransparencyBlend;
  using runtime::TransparencyMethod;
  const std::pair<TransparencyMethod, TransparencyBlend> modes[4] = {
      {TransparencyMethod::kScreenDoor, TransparencyBlend::kNone},
      {TransparencyMethod::kBlended, TransparencyBlend::kArbitraryBackground},
      {TransparencyMethod::kBlended, TransparencyBlend::kAddToBackground},
      {TransparencyMethod::kBlended, TransparencyBlend::kConstantBackground}};
  for (int i = 0; i < 4; ++i) {
    const runtime::PartId id = part(show, fmt::format("glass {}", i));
    show.editPartStyle(id, AttrId::kFrontTranspMethod,
                       [&](PartStyle& s) { s.front.transparencyMethod = modes[i].first; });
    show.editPartStyle(id, AttrId::kFrontTranspBlendEq,
                       [&](PartStyle& s) { s.front.transparencyBlend = modes[i].second; });
  }
  const runtime::ViewTransforms view = testCamera();
  const Image image = render(show, view);
  auto at = [&](float x, float y, std::uint32_t c) {
    const Vec2 p = worldToPixel(view, {x, y, 0.2f});
    return image.at(static_cast<std::uint32_t>(p.x), static_cast<std::uint32_t>(p.y), c);
  };
  // Arbitrary background over the white bar: half green, half white.
  EXPECT_NEAR(at(-0.22f, 0, 0), 128, 3);
  EXPECT_NEAR(at(-0.22f, 0, 1), 242, 3);
  // Added: white plus half green, clamped.
  EXPECT_EQ(at(0.22f, 0, 0), 255);
  // Constant background: half green, half the blue background, whatever is behind.
  EXPECT_NEAR(at(0.66f, 0, 2), 51, 3);
  EXPECT_NEAR(at(0.66f, 0, 1), 115, 3);
  // Screen door: of a 4 x 4 block, half the pixels are green.
  int green = 0;
  const Vec2 door = worldToPixel(view, {-0.66f, 0, 0.2f});
  for (std::uint32_t dy = 0; dy < 4; ++dy) {
    for (std::uint32_t dx = 0; dx < 4; ++dx) {
      if (image.at(static_cast<std::uint32_t>(door.x) + dx, static_cast<std::uint32_t>(door.y) + dy, 0) < 50) ++green;
    }
  }
  EXPECT_EQ(green, 8);
  expectGolden(image, "transparency");
}

TEST_F(Goldens, FillStyles) {
  // Solid, hollow (polygon outlines in the surface colour), empty with edges, and pattern (the
  // part's texture tiled on the screen), left to right.
  std::vector<std::shared_ptr<runtime::Mesh>> parts;
  const char* names[4] = {"solid", "hollow", "empty", "pattern"};
  for (int i = 0; i < 4; ++i) {
    auto q = makeQuad(0.2f, 0.0f, 2, names[i]);
    for (Vec3& p : q->positions) p.x += -0.66f + 0.44f * static_cast<float>(i);
    parts.push_back(q);
  }
  Show show = showOf(combine(parts));
  show.editGlobalStyle([](PartStyle& s) { s.front.color = {0.9f, 0.8f, 0.3f}; });
  show.editPartStyle(part(show, "hollow"), AttrId::kFrontFillStyle,
                     [](PartStyle& s) { s.front.fillStyle = runtime::FillStyle::kHollow; });
  const runtime::PartId empty = part(show, "empty");
  show.editPartStyle(empty, AttrId::kFrontFillStyle,
                     [](PartStyle& s) { s.front.fillStyle = runtime::FillStyle::kEmpty; });
  show.editPartStyle(empty, AttrId::kEdgesShow, [](PartStyle& s) { s.edges.show = runtime::EdgeMode::kOn; });
  show.editPartStyle(empty, AttrId::kEdgesColor, [](PartStyle& s) { s.edges.color = {0.3f, 1, 1}; });
  const runtime::PartId pattern = part(show, "pattern");
  show.editPartStyle(pattern, AttrId::kFrontFillStyle,
                     [](PartStyle& s) { s.front.fillStyle = runtime::FillStyle::kPattern; });
  Image checker = Image::make(8, 8, 3);
  for (std::uint32_t y = 0; y < 8; ++y) {
    for (std::uint32_t x = 0; x < 8; ++x) {
      const bool on = ((x / 4) + (y / 4)) % 2 == 0;
      checker.row(y)[x * 3 + 0] = on ? 255 : 30;
      checker.row(y)[x * 3 + 1] = on ? 255 : 30;
      checker.row(y)[x * 3 + 2] = on ? 255 : 200;
    }
  }
  ASSERT_TRUE(renderer().textures().setImage("checker 8", checker));
  show.setPartTexture(pattern, "checker 8");
  const Image image = render(show, testCamera());
  expectGolden(image, "fill_styles");
}

TEST_F(Goldens, ModelClipping) {
  // The default cube cut by LAVA's first default plane (x <= 0.25) and by one of our own that
  // takes off the (+x, +y, +z) corner; through the cuts the inside shows its back faces.
  Show show = Show::makeDefault();
  show.modelClipping().numPlanes = 2;
  show.modelClipping().planes[1] = {{0.2f, 0.2f, 0.2f}, normalize(Vec3{-1, -1, -1})};
  const Image image = renderShow(show);
  expectGolden(image, "clipping");
  // The cuts open up a large part of the picture: the front faces give way to the inside.
  const Image whole = renderShow(Show::makeDefault());
  Image diff;
  const ImageDifference d = compareImages(whole, image, 40, &diff);
  EXPECT_GT(d.pixelsOverTolerance, 5000u);
}

TEST_F(Goldens, SixteenClippingPlanesEachCut) {
  // LAVA's maximum of 16 model clipping planes, all at once: a square cut by 16 planes around its
  // centre (each keeps the side towards the centre), so that what is left is a 16-sided polygon.
  // Just inside each plane the square is drawn, just outside it is not; with 15 planes the last
  // one's cut is back. Example failure: planes past the eighth ignored by the shader's loop.
  Show show = showOf(makeQuad(0.9f, 0.0f, 1, "square"));
  show.global().background = {0, 0, 0};
  show.editGlobalStyle([](PartStyle& s) {
    s.front.illumination = runtime::Illumination::kNone;
    s.front.color = {1, 1, 1};
  });
  constexpr float kRadius = 0.6f;
  auto direction = [](int k) {
    const float a = 2.0f * std::numbers::pi_v<float> * static_cast<float>(k) / 16.0f;
    return Vec3{std::cos(a), std::sin(a), 0};
  };
  show.modelClipping().numPlanes = 16;
  for (int k = 0; k < 16; ++k) {
    show.modelClipping().planes[static_cast<std::size_t>(k)] = {direction(k) * kRadius, -direction(k)};
  }
  const runtime::ViewTransforms view = testCamera();
  auto drawn = [&](const Image& image, const Vec3& p) {
    const Vec2 px = worldToPixel(view, p);
    return image.at(static_cast<std::uint32_t>(px.x), static_cast<std::uint32_t>(px.y), 0) > 128;
  };
  const Image all = render(show, view);
  for (int k = 0; k < 16; ++k) {
    EXPECT_TRUE(drawn(all, direction(k) * (kRadius - 0.06f))) << "inside plane " << k;
    EXPECT_FALSE(drawn(all, direction(k) * (kRadius + 0.025f))) << "outside plane " << k;
  }
  show.modelClipping().numPlanes = 15;
  const Image fifteen = render(show, view);
  // Just past plane 15 and inside its neighbours (22.5 degrees away: 0.625 cos 22.5 < 0.6).
  EXPECT_TRUE(drawn(fifteen, direction(15) * (kRadius + 0.025f))) << "plane 15 still cuts with 15 planes on";
  EXPECT_FALSE(drawn(fifteen, direction(14) * (kRadius + 0.025f)));
}

TEST_F(Goldens, IlluminationTypes) {
  // One sphere three times: per facet, per vertex, per pixel, under LAVA's default lights.
  Show show;
  const auto sphere = makeSphere(1.0f, 12, 18, "ball");
  const char* names[3] = {"facet", "vertex", "pixel"};
  for (int i = 0; i < 3; ++i) {
    auto copy = std::make_shared<runtime::Mesh>(*sphere);
    copy->parts[0].name = names[i];
    runtime::SceneNode node;
    node.name = names[i];
    node.mesh = copy;
    node.local = Mat4::translation({-2.2f + 2.2f * static_cast<float>(i), 0, 0});
    show.addNode(node);
  }
  show.editGlobalStyle([](PartStyle& s) { s.front.color = {0.8f, 0.5f, 0.3f}; });
  show.editPartStyle(part(show, "vertex"), AttrId::kFrontIllum,
                     [](PartStyle& s) { s.front.illumination = runtime::Illumination::kPerVertex; });
  show.editPartStyle(part(show, "pixel"), AttrId::kFrontIllum,
                     [](PartStyle& s) { s.front.illumination = runtime::Illumination::kPerPixel; });
  expectGolden(renderShow(show), "illumination");
}

TEST_F(Goldens, FloorAndShadow) {
  // The default cube turned on its local axes above a fine grid floor, with LAVA's fake shadow.
  Show show = Show::makeDefault();
  show.rotateLocal({30, 20, 0});
  show.environment().floor = runtime::FloorKind::kFineGrid;
  show.environment().floorPosition = -0.3f;
  show.environment().floorColor = {0.6f, 0.6f, 0.7f};
  show.environment().shadowDarkness = 0.4f;
  show.view().objectScale = runtime::ObjectScale::kHalfScreen;
  const Image lit = renderShow(show);
  show.environment().shadow = true;
  const Image image = renderShow(show);
  expectGolden(image, "floor_shadow");
  // Where the shadow falls the floor takes `shadowDarkness` of its colour; nothing else changes.
  int shadowed = 0;
  for (std::uint32_t y = 0; y < kRenderSize; ++y) {
    for (std::uint32_t x = 0; x < kRenderSize; ++x) {
      if (lit.at(x, y, 2) == image.at(x, y, 2)) continue;
      ++shadowed;
      for (std::uint32_t c = 0; c < 3; ++c) {
        ASSERT_NEAR(image.at(x, y, c), 0.4 * lit.at(x, y, c), 2.0) << "pixel " << x << "," << y;
      }
    }
  }
  EXPECT_GT(shadowed, 200) << "no visible shadow";

  show.environment().floor = runtime::FloorKind::kCoarseGrid;
  show.environment().floorPrimType = runtime::FloorPrimType::kWireframe;
  expectGolden(renderShow(show), "floor_wireframe");
}

TEST_F(Goldens, SingleSquareFloorCoversItsSquare) {
  // LAVA's "single square" floor: one solid square under the object. Its corners' surroundings
  // and its front edge show the floor where the plain show shows the background.
  // Example failure: the single square drawn as a grid, or not at all.
  Show show = Show::makeDefault();
  show.view().objectScale = runtime::ObjectScale::kHalfScreen;
  show.environment().floor = runtime::FloorKind::kNone;
  const Image bare = renderShow(show);
  show.environment().floor = runtime::FloorKind::kSingleSquare;
  show.environment().floorColor = {0.2f, 0.8f, 0.3f};
  const Image floor = renderShow(show);
  const runtime::FloorGeometry geometry = runtime::computeFloor(show);
  const runtime::ViewTransforms view = runtime::computeView(show, 1.0f);
  int covered = 0;
  for (const Vec3& p :
       {Vec3{-0.4f, 0, 0.6f}, Vec3{0.4f, 0, 0.6f}, Vec3{0, 0, 0.7f}, Vec3{-0.6f, 0, 0.35f}, Vec3{0.6f, 0, 0.35f}}) {
    const Vec2 px = worldToPixel(view, geometry.floor.transformPoint(p));
    const auto x = static_cast<std::uint32_t>(px.x), y = static_cast<std::uint32_t>(px.y);
    ASSERT_LT(x, kRenderSize);
    ASSERT_LT(y, kRenderSize);
    EXPECT_EQ(bare.at(x, y, 1), 0) << "background at " << x << "," << y;
    // Lit by LAVA's default lights, the floor keeps its hue: green above red and blue.
    EXPECT_GT(floor.at(x, y, 1), floor.at(x, y, 0)) << "floor at " << x << "," << y;
    EXPECT_GT(floor.at(x, y, 1), floor.at(x, y, 2)) << "floor at " << x << "," << y;
    covered += floor.at(x, y, 1) > 20 ? 1 : 0;
  }
  EXPECT_EQ(covered, 5);
}

}  // namespace
}  // namespace basalt::test

// Instancing on the GPU (Extended OBJ `instanceof`, issue 4): however many nodes share one Mesh,
// the renderer keeps one set of GPU buffers for it, and draws every instance.
// Example failure: a GPU copy per node (memory growing with the instance count).
namespace basalt::test {
namespace {

TEST_F(Goldens, InstancesShareOneGpuMesh) {
  auto fresh = render::Renderer::create();  // its own mesh cache, untouched by other tests
  ASSERT_TRUE(fresh) << fresh.error().describe();
  const std::shared_ptr<const runtime::Mesh> ball = makeSphere(0.2f, 8, 12, "ball");
  Show show;
  for (int i = 0; i < 25; ++i) {
    runtime::SceneNode node;
    node.name = fmt::format("ball {}", i);
    node.mesh = ball;
    node.local =
        Mat4::translation({-0.8f + 0.4f * static_cast<float>(i % 5), -0.8f + 0.4f * static_cast<float>(i / 5), 0});
    show.addNode(std::move(node));
  }
  ASSERT_TRUE(output().beginFrame());
  (*fresh)->draw(show, testCamera(), output().size());
  EXPECT_EQ((*fresh)->gpuMeshCount(), 1u) << "25 instances, one mesh";
  EXPECT_EQ((*fresh)->lastCounts().triangles, 25u * ball->triangleCount()) << "every instance drawn";
  // A second mesh is a second set of buffers.
  runtime::SceneNode other;
  other.name = "other";
  other.mesh = makeSphere(0.2f, 8, 12, "ball");
  show.addNode(std::move(other));
  (*fresh)->draw(show, testCamera(), output().size());
  EXPECT_EQ((*fresh)->gpuMeshCount(), 2u);
}

}  // namespace
}  // namespace basalt::test
