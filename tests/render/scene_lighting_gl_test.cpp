// A `.sce` scene's lights, materials, fog and instances drawn the way the thesis defines them,
// through the loader and LAVA's view (the scene fitted into the window, view = "fit"), each
// pixel compared with a value worked out by hand below from the thesis' equations.
//
// The thesis, §4.2.4: "In calculating color for a vertex, OpenGL starts with the material
// emission color, which is not dependent on lighting. Added to that is a global OpenGL ambient
// color which is scaled by the material ambient color. Added to that is the color determined by
// lighting calculations. [...] each light's ambient color is simply scaled by the ambient
// material color. [...] Each light's diffuse color is scaled by the diffuse material color."
// Each light has "ambient color, diffuse color, and specular color". The global ambient is
// OpenGL's default, 0.2 (a scene file cannot set it). The thesis' §4.3.3 fog: "the distance
// from the viewer at which the fog function takes effect, the corresponding ending distance, the
// density", OpenGL's functions: linear f = (end - z) / (end - start), exp f = e^(-density z),
// exp2 f = e^(-(density z)^2), colour = f C + (1 - f) fog colour, z the eye distance.
//
// Every scene here has one quad, one polygon: XGL's default illumination is per facet ("one
// lighting calculation for each polygon"), and Basalt lights a polygon at its first corner
// (v1 of `f 1 2 3 4`), so each value is worked out there and the whole quad must show it.
//
// Distances in scene units: the LAVA view puts the eye `view.perspective` = 4 window units from
// the centre of the scene's bounds, and one window unit is the bounds' radius (half the box's
// diagonal), so the eye is 4 radii away in scene units.
//
// Tolerance 2/255 per channel (8-bit rounding and float arithmetic).
// Example failures: emission dropped (the emissive quad black); each light's specular colour
// replaced by its diffuse; the lights' ambient colours merged and scaled by the diffuse colour;
// a light placed in window units (one unit in front of a quad ten units from the origin ends up
// behind it: black); fog on the window-unit depth (linear 5..15 at 10 units: no fog at all);
// an instance's material painted over its original.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "runtime/formats/scene.h"
#include "support/render_fixture.h"
#include "support/test_paths.h"

namespace basalt::test {
namespace {

constexpr double kTolerance = 2.0 / 255;

/// A quad from (x0, y0) to (x1, y1) in the plane z, facing +Z, its first corner lower left.
std::string quadObj(const std::string& object, double x0, double y0, double x1, double y1, double z) {
  return fmt::format("o {}\nv {} {} {}\nv {} {} {}\nv {} {} {}\nv {} {} {}\nf 1 2 3 4\n", object, x0, y0, z, x1, y0, z,
                     x1, y1, z, x0, y1, z);
}

void writeFile(const std::filesystem::path& path, const std::string& text) { std::ofstream(path) << text; }

/// Loads `scene` (with `files` beside it) into a Show, as `basalt run` does.
runtime::Show loadShow(const std::string& name, const std::string& scene,
                       const std::vector<std::pair<std::string, std::string>>& files) {
  const auto dir = scratchDir(name);
  for (const auto& [file, text] : files) writeFile(dir / file, text);
  writeFile(dir / "s.sce", scene);
  formats::LoadOptions options;
  options.logWarnings = false;
  auto loaded = formats::loadScene(dir / "s.sce", options);
  runtime::Show show = runtime::Show::makeDefault();
  EXPECT_TRUE(loaded) << (loaded ? "" : loaded.error().describe());
  if (!loaded) return show;
  EXPECT_TRUE(loaded->warnings.empty()) << loaded->warnings.front().describe();
  std::vector<formats::Diagnostic> warnings;
  formats::applyScene(show, *loaded, &warnings);
  EXPECT_TRUE(warnings.empty());
  // Framed as LAVA frames a model (a manifest's view = "fit"): the values below are worked out
  // for LAVA's eye, and lights and fog must keep the scene's units under that framing too.
  // scene_camera_gl_test.cpp checks the scene's own camera.
  formats::useFitFraming(show);
  return show;
}

void expectColour(const Image& image, std::uint32_t x, std::uint32_t y, double r, double g, double b,
                  const std::string& what) {
  EXPECT_NEAR(channel(image, x, y, 0), r, kTolerance) << what << " at " << x << "," << y << " red";
  EXPECT_NEAR(channel(image, x, y, 1), g, kTolerance) << what << " at " << x << "," << y << " green";
  EXPECT_NEAR(channel(image, x, y, 2), b, kTolerance) << what << " at " << x << "," << y << " blue";
}

/// Pixels inside a quad that fills at least the middle 100 pixels, both of its triangles.
constexpr std::uint32_t kInside[][2] = {{90, 170}, {170, 90}, {100, 110}, {160, 150}, {128, 90}, {90, 128}};

class SceneLighting : public RenderTest {};

TEST_F(SceneLighting, EmissionAloneLightsAQuad) {
  // emission (255, 128, 0) / 255; ambient, diffuse and specular black; the one light shines on
  // the back (from -Z), so: colour = emission + 0.2 x ambient (0) + nothing = (1, 0.50196, 0).
  const runtime::Show show =
      loadShow("scene-emission",
               "light position[0,0,-1,0] ambient[0,0,0] diffuse[255,255,255] specular[255,255,255]\n"
               "emission[255,128,0]\nambient[0,0,0]\ndiffuse[0,0,0]\nspecular[0,0,0]\nimport quad.obj\n",
               {{"quad.obj", quadObj("quad", -1, -1, 1, 1, 0)}});
  const Image image = renderShow(show);
  for (const auto& p : kInside) expectColour(image, p[0], p[1], 1.0, 128.0 / 255, 0.0, "emissive quad");
}

TEST_F(SceneLighting, EachLightHasItsOwnAmbientDiffuseAndSpecular) {
  // Material: ambient, diffuse and specular white, shininess 1. Two directional lights from +Z
  // (L = N = (0, 0, 1), so N.L = 1 and the reflected ray R = (0, 0, 1)):
  //   light 1: ambient (51, 0, 0) = (0.2, 0, 0), diffuse (0, 102, 0) = (0, 0.4, 0),
  //            specular (0, 0, 128) = (0, 0, 0.50196)
  //   light 2: ambient (0, 0, 51) = (0, 0, 0.2), diffuse (102, 0, 0) = (0.4, 0, 0), specular 0
  // The quad (-1..1 square at z = 0) has radius sqrt 2, so the eye is at (0, 0, 4 sqrt 2) =
  // (0, 0, 5.65685) in scene units; the lit corner P = (-1, -1, 0), E = (1, 1, 5.65685) /
  // sqrt(1 + 1 + 32) = (1, 1, 5.65685) / 5.83095, E.R = 0.970143, raised to shininess 1.
  //   red   = 0.2 (global x 1) + 0.2 (light 1 ambient) + 0.4 (light 2 diffuse)          = 0.8
  //   green = 0.2 + 0.4 (light 1 diffuse)                                               = 0.6
  //   blue  = 0.2 + 0.50196 x 0.970143 (light 1 specular) + 0.2 (light 2 ambient)       = 0.886974
  const runtime::Show show =
      loadShow("scene-light-colours",
               "light position[0,0,1,0] ambient[51,0,0] diffuse[0,102,0] specular[0,0,128]\n"
               "light position[0,0,1,0] ambient[0,0,51] diffuse[102,0,0] specular[0,0,0]\n"
               "ambient[255,255,255]\ndiffuse[255,255,255]\nspecular[255,255,255]\nshininess[1]\n"
               "import quad.obj\n",
               {{"quad.obj", quadObj("quad", -1, -1, 1, 1, 0)}});
  const Image image = renderShow(show);
  const double blue = 0.2 + (128.0 / 255) * (4 * std::sqrt(2.0) / std::sqrt(34.0)) + 0.2;
  EXPECT_NEAR(blue, 0.886974, 1e-6) << "the arithmetic above";
  for (const auto& p : kInside) expectColour(image, p[0], p[1], 0.8, 0.6, blue, "two lights");
}

TEST_F(SceneLighting, APositionalLightOneUnitInFrontOfAQuad) {
  // The quad is the -1..1 square at z = -10, the light at (0, 0, -9): one unit in front of its
  // centre. Default material (thesis E.5): ambient 0.2, diffuse 0.8, specular black. The light:
  // ambient black, diffuse white; OpenGL's default attenuation is 1 (constant 1, no distance
  // term). At the lit corner P = (-1, -1, -10): to the light (1, 1, 1), L = (1, 1, 1) / sqrt 3,
  // N.L = 0.57735.  colour = 0.2 x 0.2 (global ambient) + 0.8 x 0.57735 = 0.501880 per channel.
  const runtime::Show show =
      loadShow("scene-positional",
               "light position[0,0,-9,1] ambient[0,0,0] diffuse[255,255,255] specular[255,255,255]\n"
               "import quad.obj\n",
               {{"quad.obj", quadObj("quad", -1, -1, 1, 1, -10)}});
  const Image image = renderShow(show);
  const double grey = 0.04 + 0.8 / std::sqrt(3.0);
  for (const auto& p : kInside) expectColour(image, p[0], p[1], grey, grey, grey, "positional light");
}

TEST_F(SceneLighting, FogAtTheEyeDistanceInSceneUnits) {
  // The quad runs from (-1.5, -2) to (1.5, 2): its bounds' radius is half of sqrt(3^2 + 4^2) =
  // 2.5, so the eye is 4 x 2.5 = 10 scene units in front of it. The quad is emissive white and
  // the lights give nothing, so C = 1, and the fog colour is black: the pixel is f.
  //   linear start 5 end 15:   f = (15 - 10) / (15 - 5) = 0.5
  //   exp density 0.1:         f = e^(-0.1 x 10) = e^-1 = 0.367879
  //   exp2 density 0.05:       f = e^(-(0.05 x 10)^2) = e^-0.25 = 0.778801
  struct Case {
    const char* fog;
    double f;
  };
  const Case cases[] = {{"start[5] end[15] density[0.1] color[0,0,0] function[linear]", 0.5},
                        {"start[5] end[15] density[0.1] color[0,0,0] function[exp]", std::exp(-1.0)},
                        {"start[5] end[15] density[0.05] color[0,0,0] function[exp2]", std::exp(-0.25)}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.fog);
    const runtime::Show show =
        loadShow("scene-fog",
                 fmt::format("fog {}\n"
                             "light position[0,0,1,0] ambient[0,0,0] diffuse[0,0,0] specular[0,0,0]\n"
                             "emission[255,255,255]\nambient[0,0,0]\ndiffuse[0,0,0]\nspecular[0,0,0]\n"
                             "import quad.obj\n",
                             c.fog),
                 {{"quad.obj", quadObj("quad", -1.5, -2, 1.5, 2, 0)}});
    const Image image = renderShow(show);
    for (const auto& p : kInside) expectColour(image, p[0], p[1], c.f, c.f, c.f, "fogged quad");
  }
}

TEST_F(SceneLighting, AnInstanceKeepsItsOwnMaterialAndTheOriginalItsOwn) {
  // egg (the -1..1 square) is imported yellow; egg2, an instance of it 3 units to the right, is
  // imported magenta. Both are lit by one directional light along the view with no ambient and
  // no highlight: N.L = 1, so each shows 0.2 x 0.2 (global ambient x default ambient) + its
  // diffuse colour: egg (1.04, 1.04, 0.04) -> (1, 1, 0.04), egg2 (1, 0.04, 1).
  // The two squares span x = -1..4, radius sqrt(2.5^2 + 1^2) = 2.69258 scene units per window
  // unit; egg's centre (0, 0) is 1.5 to the left of the scene's centre (1.5, 0) and egg2's 1.5 to
  // the right: 1.5 / 2.69258 = 0.557086 window units, 0.557086 x 128 = 71.3 pixels from the middle.
  const runtime::Show show = loadShow(
      "scene-instance",
      "light position[0,0,1,0] ambient[0,0,0] diffuse[255,255,255] specular[0,0,0]\n"
      "diffuse[255,255,0]\nimport egg.obj\ndiffuse[255,0,255]\nimport egg2.obj\n",
      {{"egg.obj", quadObj("egg", -1, -1, 1, 1, 0)}, {"egg2.obj", "o egg2\ninstanceof egg\nposition 3 0 0\n"}});
  const auto egg = show.findPart("egg");
  const auto egg2 = show.findPart("egg2");
  ASSERT_TRUE(egg && egg2) << "the instance has a part of its own";
  EXPECT_NE(*egg, *egg2);
  const Image image = renderShow(show);
  const double offset = 1.5 / std::sqrt(2.5 * 2.5 + 1.0) * 128.0;
  const auto left = static_cast<std::uint32_t>(std::lround(128.0 - offset));
  const auto right = static_cast<std::uint32_t>(std::lround(128.0 + offset));
  for (std::uint32_t dy : {110U, 146U}) {
    expectColour(image, left, dy, 1.0, 1.0, 0.04, "the original, yellow");
    expectColour(image, right, dy, 1.0, 0.04, 1.0, "the instance, magenta");
  }
}

TEST_F(SceneLighting, EyeSpacingSeparatesTheStereoEyes) {
  // A white quad 2 scene units in front of the scene's centre plane and a black one 2 behind it,
  // drawn as LAVA's red/cyan anaglyph. With eyespacing[0] both eyes see the same picture, so no
  // pixel is red without green; with eyespacing[1] the eyes part and the white quad's sides show
  // red-only fringes (the thesis' C.3 "eyespacing[%lf] # stereo, distance between eyes").
  const auto redOnly = [](const Image& image) {
    int n = 0;
    for (std::uint32_t y = 0; y < kRenderSize; ++y) {
      for (std::uint32_t x = 0; x < kRenderSize; ++x) {
        if (channel(image, x, y, 0) > 0.5 && channel(image, x, y, 1) < 0.5) ++n;
      }
    }
    return n;
  };
  int fringes[2] = {0, 0};
  for (int spacing : {0, 1}) {
    runtime::Show show =
        loadShow("scene-eyespacing",
                 fmt::format("eyespacing[{}]\n"
                             "light position[0,0,1,0] ambient[0,0,0] diffuse[0,0,0] specular[0,0,0]\n"
                             "emission[255,255,255]\nambient[0,0,0]\ndiffuse[0,0,0]\nspecular[0,0,0]\n"
                             "import front.obj\nemission[0,0,0]\nimport back.obj\n",
                             spacing),
                 {{"front.obj", quadObj("front", -1, -1, 1, 1, 2)}, {"back.obj", quadObj("back", 2, -1, 4, 1, -2)}});
    show.global().stereo = true;
    fringes[spacing] = redOnly(renderShow(show));
  }
  EXPECT_EQ(fringes[0], 0) << "eyes 0 apart see one picture";
  EXPECT_GT(fringes[1], 50) << "eyes 1 scene unit apart see the near quad shifted";
}

}  // namespace
}  // namespace basalt::test
