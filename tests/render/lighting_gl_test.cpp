// The XGL lighting equations (XGL Programmer's Guide ch. 16, as issue 3 states them) checked
// numerically: a flat quad and a sphere under one light of each type, rendered headless, and
// chosen pixels compared with the equations evaluated here, in double precision, at the world
// point each pixel shows. Also per-facet and per-vertex illumination, face distinguishing, the
// per-channel clamp and the light components switch.
// Tolerance: 2/255 per channel for per-pixel lighting (8-bit rounding plus float differences),
// 3/255 where Gouraud interpolation or the sphere's tessellation enters.
// Example failures: attenuation applied as 1/(c1 + c2 d^2); the spot cone tested against the
// wrong angle; a reflection vector built from L instead of -L; lights summed without the clamp;
// back faces lit with the front normal under face distinguishing.

#include <gtest/gtest.h>

#include <cmath>

#include "support/render_fixture.h"

namespace basalt::test {
namespace {

using runtime::Color3;
using runtime::Illumination;
using runtime::Light;
using runtime::LightType;
using runtime::PartStyle;
using runtime::Show;

struct D3 {
  double x = 0, y = 0, z = 0;
};
D3 d3(const Vec3& v) { return {wide(v.x), wide(v.y), wide(v.z)}; }
D3 d3(const Color3& c) { return {wide(c.r), wide(c.g), wide(c.b)}; }
D3 operator+(D3 a, D3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
D3 operator-(D3 a, D3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
D3 operator*(D3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
D3 mul(D3 a, D3 b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
double dotd(D3 a, D3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
double len(D3 a) { return std::sqrt(dotd(a, a)); }
D3 unit(D3 a) { return a * (1.0 / len(a)); }

/// The reflection model of issue 3, item 2, written out independently of the shader.
D3 reference(const Show& show, const runtime::SurfaceAttributes& s, D3 P, D3 N, D3 eye) {
  const D3 E = unit(eye - P);
  const D3 Od = d3(s.color), Os = d3(s.specularColor);
  D3 sum;
  for (const Light& light : show.lights()) {
    if (!light.on) continue;
    const D3 Lc = d3(light.color);
    if (light.type == LightType::kAmbient) {
      if (s.lightComponents & runtime::kLightAmbient) sum = sum + mul(Od, Lc) * static_cast<double>(s.ambient);
      continue;
    }
    D3 L;
    double A = 1;
    if (light.type == LightType::kDirectional) {
      L = unit(d3(light.direction)) * -1.0;
    } else {
      const D3 toLight = d3(light.position) - P;
      const double d = len(toLight);
      L = toLight * (1.0 / d);
      A = 1.0 / (static_cast<double>(light.attenuation1) + static_cast<double>(light.attenuation2) * d);
      if (light.type == LightType::kSpot) {
        const double c = dotd(L * -1.0, unit(d3(light.direction)));
        A = c < std::cos(static_cast<double>(light.angle)) ? 0.0 : A * std::pow(c, static_cast<double>(light.exponent));
      }
    }
    const double NL = dotd(N, L);
    if (NL <= 0) continue;  // the light is behind the surface
    D3 c;
    if (s.lightComponents & runtime::kLightDiffuse) c = c + mul(Od, Lc) * (static_cast<double>(s.diffuse) * NL);
    if (s.lightComponents & runtime::kLightSpecular) {
      const D3 R = N * (2 * NL) - L;
      c = c + mul(Os, Lc) * (static_cast<double>(s.specular) *
                             std::pow(std::max(dotd(E, R), 0.0), static_cast<double>(s.specularPower)));
    }
    sum = sum + c * A;
  }
  auto clamp1 = [](double v) { return std::clamp(v, 0.0, 1.0); };
  return {clamp1(sum.x), clamp1(sum.y), clamp1(sum.z)};
}

void expectPixel(const Image& image, std::uint32_t x, std::uint32_t y, D3 expected, double tolerance,
                 const std::string& what) {
  const double got[3] = {channel(image, x, y, 0), channel(image, x, y, 1), channel(image, x, y, 2)};
  const double want[3] = {expected.x, expected.y, expected.z};
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(got[c], want[c], tolerance) << what << " at pixel " << x << "," << y << " channel " << c;
  }
}

/// A material with distinct diffuse and specular colours, so that a swapped term shows.
void setMaterial(Show& show, Illumination illumination) {
  show.editGlobalStyle([&](PartStyle& s) {
    s.front.color = {0.9f, 0.6f, 0.3f};
    s.front.specularColor = {0.4f, 0.7f, 1.0f};
    s.front.ambient = 0.3f;
    s.front.diffuse = 0.7f;
    s.front.specular = 0.6f;
    s.front.specularPower = 12.0f;
    s.front.illumination = illumination;
  });
}

Light makeLight(LightType type) {
  Light l;
  l.on = true;
  l.type = type;
  l.color = {1.0f, 0.9f, 0.8f};
  switch (type) {
    case LightType::kAmbient: l.color = {0.6f, 0.8f, 1.0f}; break;
    case LightType::kDirectional: l.direction = normalize(Vec3{-0.3f, -0.4f, -1.0f}); break;
    case LightType::kPositional:
      l.position = {0.4f, 0.6f, 1.2f};
      l.attenuation1 = 0.6f;
      l.attenuation2 = 0.5f;
      break;
    case LightType::kSpot:
      l.position = {0.2f, 0.3f, 1.5f};
      l.direction = normalize(Vec3{-0.1f, -0.2f, -1.0f});
      l.angle = 0.45f;
      l.exponent = 4.0f;
      l.attenuation1 = 0.8f;
      l.attenuation2 = 0.2f;
      break;
  }
  return l;
}

constexpr LightType kLightTypes[] = {LightType::kAmbient, LightType::kDirectional, LightType::kPositional,
                                     LightType::kSpot};
const char* typeName(LightType t) {
  switch (t) {
    case LightType::kAmbient: return "ambient light";
    case LightType::kDirectional: return "directional light";
    case LightType::kPositional: return "positional light";
    case LightType::kSpot: return "spot light";
  }
  return "?";
}

class Lighting : public RenderTest {
 protected:
  void checkQuad(LightType type) {
    Show show = showOf(makeQuad(1.0f, 0.0f, 1));
    lightsOff(show);
    show.lights()[0] = makeLight(type);
    setMaterial(show, Illumination::kPerPixel);
    const runtime::ViewTransforms view = testCamera();
    const Image image = render(show, view);
    int lit = 0;
    for (std::uint32_t y = 16; y < kRenderSize; y += 28) {
      for (std::uint32_t x = 16; x < kRenderSize; x += 28) {
        const D3 P = d3(pixelOnPlane(view, x, y, 0));
        const D3 expected = reference(show, show.globalStyle().front, P, {0, 0, 1}, d3(view.eye));
        if (expected.x + expected.y + expected.z > 0.05) ++lit;
        expectPixel(image, x, y, expected, 2.0 / 255, "quad");
      }
    }
    EXPECT_GT(lit, 10) << "the light should reach most of the quad";
  }

  void checkSphere(LightType type) {
    Show show = showOf(makeSphere(1.0f, 96, 192));
    lightsOff(show);
    show.lights()[0] = makeLight(type);
    setMaterial(show, Illumination::kPerPixel);
    const runtime::ViewTransforms view = testCamera(3.0f, 1.2f);
    const Image image = render(show, view);
    int checked = 0;
    for (std::uint32_t y = 20; y < kRenderSize; y += 18) {
      for (std::uint32_t x = 20; x < kRenderSize; x += 18) {
        Vec3 hit;
        if (!pixelOnSphere(view, x, y, {0, 0, 0}, 1.0f, hit)) continue;
        if (hit.z < 0.35f) continue;  // near the outline the tessellation and the sphere part ways
        const D3 P = d3(hit);
        const D3 expected = reference(show, show.globalStyle().front, P, unit(P), d3(view.eye));
        expectPixel(image, x, y, expected, 3.0 / 255, "sphere");
        ++checked;
      }
    }
    EXPECT_GT(checked, 60);
  }
};

TEST_F(Lighting, FlatQuadPerPixelFollowsTheEquations) {
  for (const LightType type : kLightTypes) {
    SCOPED_TRACE(typeName(type));
    checkQuad(type);
  }
}

TEST_F(Lighting, SpherePerPixelFollowsTheEquations) {
  for (const LightType type : kLightTypes) {
    SCOPED_TRACE(typeName(type));
    checkSphere(type);
  }
}

class Illuminations : public RenderTest {};

// XGL Programmer's Guide ch. 16, "Illumination and Shading": "Facet: Illumination per facet
// results in one lighting calculation for each polygon. XGL draws the entire polygon in this
// reflected color. [...] The vertex chosen for the lighting calculation is device-dependent."
// Basalt's choice is the polygon's first corner (OpenGL's provoking vertex of a GL_POLYGON, the
// thesis' primitive), with the polygon's normal. So a quad (two triangles) and a pentagon (three)
// must each show one colour: the reflection model evaluated at the first corner. Each light is
// aimed so that the corners see it differently (a lit colour per triangle would show).
// Example failure: each triangle lit at its own last vertex, a quad in two colours.

/// A convex polygon's mesh: the corners in order, fanned from the first, one facet.
std::shared_ptr<runtime::Mesh> makePolygon(const std::vector<Vec3>& corners) {
  auto mesh = std::make_shared<runtime::Mesh>();
  const auto n = static_cast<std::uint32_t>(corners.size());
  for (const Vec3& c : corners) {
    mesh->positions.push_back(c);
    mesh->normals.push_back({0, 0, 1});
  }
  for (std::uint32_t i = 1; i + 1 < n; ++i) {
    for (std::uint32_t v : {0U, i, i + 1}) mesh->triangles.push_back(v);
  }
  for (std::uint32_t i = 0; i < n; ++i) {
    mesh->edges.push_back(i);
    mesh->edges.push_back((i + 1) % n);
  }
  mesh->facetSizes.push_back(n);
  runtime::MeshPart part;
  part.name = "polygon";
  part.triangleIndexCount = static_cast<std::uint32_t>(mesh->triangles.size());
  part.edgeIndexCount = static_cast<std::uint32_t>(mesh->edges.size());
  part.facetCount = 1;
  mesh->parts.push_back(part);
  return mesh;
}

/// A spot light above `target`, pointed at it, narrow enough to miss the far corners.
Light spotAt(const Vec3& target) {
  Light l = makeLight(LightType::kSpot);
  l.position = target + Vec3{0.3f, 0.2f, 1.2f};
  l.direction = normalize(target - l.position);
  l.angle = 0.3f;
  l.attenuation2 = 0.0f;
  return l;
}

TEST_F(Illuminations, PerFacetLightsEachPolygonOnceAtItsFirstCorner) {
  const std::vector<Vec3> quad = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  std::vector<Vec3> pentagon;
  for (int k = 0; k < 5; ++k) {
    const double a = 3.14159265358979 * (1.25 + 0.4 * k);  // the first corner lower left
    pentagon.push_back({static_cast<float>(0.95 * std::cos(a)), static_cast<float>(0.95 * std::sin(a)), 0});
  }
  for (const auto& [corners, name] : {std::pair{quad, "quad"}, std::pair{pentagon, "pentagon"}}) {
    const Light lights[] = {makeLight(LightType::kPositional), spotAt(corners[0])};
    for (const Light& light : lights) {
      SCOPED_TRACE(std::string(name) + (light.type == LightType::kSpot ? ", spot light" : ", positional light"));
      Show show = showOf(makePolygon(corners));
      lightsOff(show);
      show.lights()[0] = light;
      setMaterial(show, Illumination::kPerFacet);
      const runtime::ViewTransforms view = testCamera();
      const Image image = render(show, view);
      const D3 expected = reference(show, show.globalStyle().front, d3(corners[0]), {0, 0, 1}, d3(view.eye));
      EXPECT_GT(expected.x + expected.y + expected.z, 0.1) << "the first corner is lit";
      // Each triangle of the fan, at its centroid and halfway from there to each of its corners.
      for (std::size_t i = 1; i + 1 < corners.size(); ++i) {
        const Vec3 tri[3] = {corners[0], corners[i], corners[i + 1]};
        const Vec3 centroid = (tri[0] + tri[1] + tri[2]) / 3.0f;
        for (const Vec3& towards : {centroid, tri[0], tri[1], tri[2]}) {
          const Vec2 px = worldToPixel(view, (centroid + towards) * 0.5f);
          expectPixel(image, static_cast<std::uint32_t>(px.x), static_cast<std::uint32_t>(px.y), expected, 2.0 / 255,
                      fmt::format("triangle {}", i));
        }
      }
    }
  }
}

TEST_F(Illuminations, PerVertexInterpolatesTheVertexColours) {
  Show show = showOf(makeQuad(1.0f, 0.0f, 16));
  lightsOff(show);
  Light light = makeLight(LightType::kPositional);
  show.lights()[0] = light;
  setMaterial(show, Illumination::kPerVertex);
  show.editGlobalStyle([](PartStyle& s) { s.front.lightComponents = runtime::kLightDiffuse; });
  const runtime::ViewTransforms view = testCamera();
  const Image image = render(show, view);
  // Grid vertices sit every 16 pixels; the pixel whose corner a vertex is matches it closely.
  for (std::uint32_t k = 1; k < 16; k += 3) {
    for (std::uint32_t m = 1; m < 16; m += 3) {
      const std::uint32_t x = k * 16, y = m * 16;
      const D3 P = d3(pixelOnPlane(view, x, y, 0));
      expectPixel(image, x, y, reference(show, show.globalStyle().front, P, {0, 0, 1}, d3(view.eye)), 3.0 / 255,
                  "gouraud");
    }
  }
}

TEST_F(Illuminations, NoneAndInterpolatedColourIgnoreTheLights) {
  auto mesh = makeQuad(1.0f, 0.0f, 1);
  mesh->colors = {{1, 0, 0, 1}, {0, 1, 0, 1}, {0, 0, 1, 1}, {1, 1, 1, 1}};
  Show show = showOf(mesh);
  show.editGlobalStyle([](PartStyle& s) {
    s.front.illumination = Illumination::kNone;
    s.front.colorSelector = runtime::SurfaceColorSelector::kContext;
    s.front.color = {0.25f, 0.5f, 0.75f};
  });
  const runtime::ViewTransforms view = testCamera();
  Image image = render(show, view);
  expectPixel(image, 128, 128, {0.25, 0.5, 0.75}, 1.0 / 255, "illumination none, context colour");
  show.editGlobalStyle([](PartStyle& s) {
    s.front.illumination = Illumination::kInterpColor;
    s.front.colorSelector = runtime::SurfaceColorSelector::kIllumIndependent;
  });
  image = render(show, view);
  // Lower left is red, lower right green; the middle of the bottom edge mixes them.
  expectPixel(image, 2, 253, {1, 0, 0}, 6.0 / 255, "vertex colour at a corner");
  EXPECT_GT(channel(image, 128, 253, 0), 0.3);
  EXPECT_GT(channel(image, 128, 253, 1), 0.3);
}

TEST_F(Illuminations, LightComponentsSwitchTerms) {
  Show show = showOf(makeQuad(1.0f, 0.0f, 1));
  lightsOff(show);
  show.lights()[0] = makeLight(LightType::kAmbient);
  show.lights()[1] = makeLight(LightType::kDirectional);
  setMaterial(show, Illumination::kPerPixel);
  const runtime::ViewTransforms view = testCamera();
  for (std::uint8_t components : {std::uint8_t{runtime::kLightAmbient}, std::uint8_t{runtime::kLightDiffuse},
                                  std::uint8_t{runtime::kLightSpecular}, std::uint8_t{0}}) {
    show.editGlobalStyle([&](PartStyle& s) { s.front.lightComponents = components; });
    const Image image = render(show, view);
    const D3 P = d3(pixelOnPlane(view, 150, 100, 0));
    expectPixel(image, 150, 100, reference(show, show.globalStyle().front, P, {0, 0, 1}, d3(view.eye)), 2.0 / 255,
                fmt::format("components {}", components));
  }
}

TEST_F(Illuminations, SumIsClampedPerChannel) {
  Show show = showOf(makeQuad(1.0f, 0.0f, 1));
  lightsOff(show);
  for (int i = 0; i < 3; ++i) {
    Light l;
    l.on = true;
    l.type = LightType::kDirectional;
    l.direction = {0, 0, -1};
    l.color = {1, 0.5f, 0.1f};
    show.lights()[static_cast<std::size_t>(i)] = l;
  }
  show.editGlobalStyle([](PartStyle& s) {
    s.front.illumination = Illumination::kPerPixel;
    s.front.lightComponents = runtime::kLightDiffuse;
  });
  const Image image = render(show, testCamera());
  // Per light: 0.8 * Od * Lc; three lights: 2.4, 1.2, 0.24 before the clamp.
  expectPixel(image, 128, 128, {1.0, 1.0, 0.24}, 2.0 / 255, "three lights");
}

TEST_F(Illuminations, FaceDistinguishingLightsTheBackWithItsOwnAttributes) {
  Show show = showOf(makeQuad(1.0f, 0.0f, 1));
  lightsOff(show);
  Light light = makeLight(LightType::kDirectional);
  light.direction = {0, 0, -1};
  show.lights()[0] = light;
  Light ambient = makeLight(LightType::kAmbient);
  show.lights()[1] = ambient;
  show.editGlobalStyle([](PartStyle& s) {
    s.front.illumination = Illumination::kPerVertex;
    s.front.color = {0, 1, 0};
    s.back.illumination = Illumination::kPerVertex;
    s.back.color = {1, 0, 0};
    s.back.specular = 0;
  });
  // Turn the quad round: the camera sees its back face.
  show.position().global = Mat4::rotationY(180);
  const runtime::ViewTransforms view = testCamera();
  runtime::ViewTransforms turned = view;
  turned.model = show.position().global;

  show.editGlobalStyle([](PartStyle& s) { s.render.faceDistinguishing = true; });
  Image image = render(show, turned);
  // The back's normal is reversed (+Z in the world, towards the light): lit with the back surface.
  const D3 back = reference(show, show.globalStyle().back, {0, 0, 0}, {0, 0, 1}, d3(view.eye));
  expectPixel(image, 128, 128, back, 2.0 / 255, "back with face distinguishing");
  EXPECT_GT(channel(image, 128, 128, 0), 0.5);

  show.editGlobalStyle([](PartStyle& s) { s.render.faceDistinguishing = false; });
  image = render(show, turned);
  // Without it the back takes the front's attributes and normal (-Z: away from the light).
  const D3 front = reference(show, show.globalStyle().front, {0, 0, 0}, {0, 0, -1}, d3(view.eye));
  expectPixel(image, 128, 128, front, 2.0 / 255, "back without face distinguishing");
  EXPECT_LT(channel(image, 128, 128, 0), 0.05);
}

TEST_F(Illuminations, FaceCullingAndHiddenSurfaceRemoval) {
  // Two squares, the near one (z = 0.5, green) drawn first, the far one (z = 0, red) second.
  auto nearSquare = makeQuad(0.5f, 0.5f, 1, "near");
  auto farSquare = makeQuad(0.8f, 0.0f, 1, "far");
  Show show = showOf(combine({nearSquare, farSquare}));
  show.editGlobalStyle([](PartStyle& s) { s.front.illumination = Illumination::kNone; });
  show.editPartStyle(*show.findPart("near"), runtime::AttrId::kFrontColor,
                     [](PartStyle& s) { s.front.color = {0, 1, 0}; });
  show.editPartStyle(*show.findPart("far"), runtime::AttrId::kFrontColor,
                     [](PartStyle& s) { s.front.color = {1, 0, 0}; });
  const runtime::ViewTransforms view = testCamera();
  Image image = render(show, view);
  EXPECT_EQ(image.at(128, 128, 1), 255) << "hidden surface removal: the near square wins";
  show.editGlobalStyle([](PartStyle& s) { s.render.hiddenSurfaceRemoval = false; });
  image = render(show, view);
  EXPECT_EQ(image.at(128, 128, 0), 255) << "without it the part drawn last wins";
  // Both squares face the camera: culling front faces removes them, culling back faces keeps them.
  show.editGlobalStyle([](PartStyle& s) {
    s.render.hiddenSurfaceRemoval = true;
    s.render.faceCulling = runtime::FaceCulling::kFront;
  });
  image = render(show, view);
  EXPECT_EQ(image.at(128, 128, 0) + image.at(128, 128, 1), 0) << "front faces culled";
  show.editGlobalStyle([](PartStyle& s) { s.render.faceCulling = runtime::FaceCulling::kBack; });
  image = render(show, view);
  EXPECT_EQ(image.at(128, 128, 1), 255) << "back-face culling keeps faces that face the eye";
}

}  // namespace
}  // namespace basalt::test
