// Depth cueing (XGL "Depth Cueing": linear, and scaled between the reference planes with their
// scale factors, clamped outside them; the cue colour given or the background's) and fog
// (thesis §4.3.3: linear, exp and exp2) checked numerically: white squares facing the camera at
// four known depths, unlit, and each one's colour compared with the equations computed here.
// Depth is the eye-space distance; the normalised depth runs from the near plane (0) to the far
// plane (1), and VDC z from +1 at the near plane to -1 at the far plane.
// Example failures: depth taken from the non-linear depth buffer; the scale factors swapped
// between the planes; fog blended the wrong way round (the fog colour near, the object far).

#include <gtest/gtest.h>

#include <cmath>

#include "support/render_fixture.h"

namespace basalt::test {
namespace {

using runtime::PartStyle;
using runtime::Show;

constexpr double kEye = 3.0;
constexpr double kNear = 1.0;
constexpr double kFar = 5.0;
constexpr double kDepths[4] = {1.5, 2.5, 3.5, 4.5};

float f32(double v) { return static_cast<float>(v); }

/// Four small white squares, one part each, at eye depths 1.5 to 4.5.
Show depthSquares() {
  auto mesh = std::make_shared<runtime::Mesh>();
  for (int i = 0; i < 4; ++i) {
    const float z = f32(kEye - kDepths[i]);
    const float x = -0.6f + 0.4f * static_cast<float>(i);
    // Scale x by the depth so every square lands in its own column of the image.
    const float s = f32(kDepths[i] / kEye);
    auto quad = makeQuad(0.12f * s, z, 1, fmt::format("square {}", i));
    const auto base = static_cast<std::uint32_t>(mesh->positions.size());
    runtime::MeshPart part = quad->parts[0];
    part.firstTriangleIndex = static_cast<std::uint32_t>(mesh->triangles.size());
    part.firstEdgeIndex = static_cast<std::uint32_t>(mesh->edges.size());
    for (Vec3 p : quad->positions) mesh->positions.push_back({p.x + x * s, p.y, p.z});
    for (Vec3 n : quad->normals) mesh->normals.push_back(n);
    for (Vec2 t : quad->texcoords) mesh->texcoords.push_back(t);
    for (std::uint32_t v : quad->triangles) mesh->triangles.push_back(base + v);
    for (std::uint32_t v : quad->edges) mesh->edges.push_back(base + v);
    mesh->parts.push_back(part);
  }
  Show show = showOf(mesh);
  show.editGlobalStyle([](PartStyle& s) {
    s.front.illumination = runtime::Illumination::kNone;
    s.front.color = {1, 1, 1};
  });
  return show;
}

class Atmosphere : public RenderTest {
 protected:
  /// Renders and returns the colour at the centre of square i.
  std::array<std::array<double, 3>, 4> squareColours(const Show& show) {
    const runtime::ViewTransforms view = testCamera(f32(kEye), 1.0f, f32(kNear), f32(kFar));
    const Image image = render(show, view);
    std::array<std::array<double, 3>, 4> out{};
    for (int i = 0; i < 4; ++i) {
      const float s = f32(kDepths[i] / kEye);
      const Vec2 p = worldToPixel(view, {(-0.6f + 0.4f * static_cast<float>(i)) * s, 0, f32(kEye - kDepths[i])});
      const auto x = static_cast<std::uint32_t>(std::lround(p.x));
      const auto y = static_cast<std::uint32_t>(std::lround(p.y));
      for (std::uint32_t c = 0; c < 3; ++c) out[static_cast<std::size_t>(i)][c] = channel(image, x, y, c);
    }
    return out;
  }

  static void expectMix(const std::array<double, 3>& got, double keep, const runtime::Color3& towards,
                        const std::string& what) {
    // C' = keep * C + (1 - keep) * towards, with C white.
    const double want[3] = {keep + (1 - keep) * static_cast<double>(towards.r),
                            keep + (1 - keep) * static_cast<double>(towards.g),
                            keep + (1 - keep) * static_cast<double>(towards.b)};
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(got[static_cast<std::size_t>(c)], want[c], 2.0 / 255) << what << " ch " << c;
  }
};

TEST_F(Atmosphere, LinearDepthCue) {
  Show show = depthSquares();
  show.depthCue().mode = runtime::DepthCueMode::kLinear;
  show.depthCue().color = {0.2f, 0.4f, 0.6f};
  const auto got = squareColours(show);
  for (int i = 0; i < 4; ++i) {
    const double z = (kDepths[i] - kNear) / (kFar - kNear);  // 0 at the front, 1 at the back
    expectMix(got[static_cast<std::size_t>(i)], 1 - z, show.depthCue().color, fmt::format("square {}", i));
  }
}

TEST_F(Atmosphere, ScaledDepthCueBetweenTheReferencePlanes) {
  Show show = depthSquares();
  runtime::DepthCue& dc = show.depthCue();
  dc.mode = runtime::DepthCueMode::kScaled;
  dc.color = {0.1f, 0.0f, 0.3f};
  dc.frontRefPlane = 0.5f;
  dc.backRefPlane = -0.5f;
  dc.maxScale = 0.9f;
  dc.minScale = 0.2f;
  const auto got = squareColours(show);
  for (int i = 0; i < 4; ++i) {
    const double zv = (kNear + kFar - 2.0 * kDepths[i]) / (kFar - kNear);  // +1 near .. -1 far
    const double front = wide(dc.frontRefPlane), back = wide(dc.backRefPlane), maxS = wide(dc.maxScale),
                 minS = wide(dc.minScale);
    double s = minS + (maxS - minS) * (zv - back) / (front - back);
    if (zv >= front) s = maxS;
    if (zv <= back) s = minS;
    expectMix(got[static_cast<std::size_t>(i)], s, dc.color, fmt::format("square {} at VDC z {}", i, zv));
  }
  // The outer squares are outside the planes (clamped), the inner ones between them.
  EXPECT_NEAR(got[0][1], 0.9, 2.0 / 255);
  EXPECT_NEAR(got[3][1], 0.2, 2.0 / 255);
}

TEST_F(Atmosphere, DepthCueToTheBackgroundColour) {
  Show show = depthSquares();
  show.global().background = {0.0f, 0.5f, 0.0f};
  show.depthCue().mode = runtime::DepthCueMode::kLinear;
  show.depthCue().color = {1, 0, 0};
  show.depthCue().useBackgroundColor = true;
  const auto got = squareColours(show);
  const double z = (kDepths[3] - kNear) / (kFar - kNear);
  expectMix(got[3], 1 - z, show.global().background, "cued to the background");
}

TEST_F(Atmosphere, FogFunctions) {
  struct Case {
    runtime::FogMode mode;
    const char* name;
  };
  for (const Case& c : {Case{runtime::FogMode::kLinear, "linear"}, Case{runtime::FogMode::kExp, "exp"},
                        Case{runtime::FogMode::kExp2, "exp2"}}) {
    Show show = depthSquares();
    runtime::Fog& fog = show.fog();
    fog.mode = c.mode;
    fog.color = {0.5f, 0.25f, 0.0f};
    fog.start = 2.0f;
    fog.end = 4.5f;
    fog.density = 0.35f;
    const auto got = squareColours(show);
    for (int i = 0; i < 4; ++i) {
      const double z = kDepths[i];
      double f = 0;
      const double start = wide(fog.start), end = wide(fog.end), density = wide(fog.density);
      if (c.mode == runtime::FogMode::kLinear) f = (end - z) / (end - start);
      if (c.mode == runtime::FogMode::kExp) f = std::exp(-density * z);
      if (c.mode == runtime::FogMode::kExp2) f = std::exp(-std::pow(density * z, 2));
      expectMix(got[static_cast<std::size_t>(i)], std::clamp(f, 0.0, 1.0), fog.color,
                fmt::format("{} fog, square {}", c.name, i));
    }
  }
}

TEST_F(Atmosphere, DepthCueThenFog) {
  Show show = depthSquares();
  show.depthCue().mode = runtime::DepthCueMode::kLinear;
  show.depthCue().color = {0, 0, 0};
  show.fog().mode = runtime::FogMode::kExp;
  show.fog().color = {1, 1, 1};
  show.fog().density = 0.2f;
  const auto got = squareColours(show);
  const double z = (kDepths[2] - kNear) / (kFar - kNear);
  const double cued = 1 - z;  // white towards black
  const double f = std::exp(-0.2 * kDepths[2]);
  EXPECT_NEAR(got[2][0], f * cued + (1 - f) * 1.0, 2.0 / 255);
}

}  // namespace
}  // namespace basalt::test
