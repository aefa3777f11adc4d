// A `.sce` scene drawn from its own camera in its own units (thesis §4.3.1, §4.3.4, C.3, F.1),
// each picture compared with a pinhole camera worked out in this file, not with Basalt's
// matrices.
//
// The thesis, F.1: the camera has "position: location of camera", "rotation: orientation of
// camera - Euler rotation angles (X, Y, Z), in degrees", "fov: field of view in degrees",
// "nearclip: distance to the near clipping plane", "farclip: distance to the far clipping
// plane"; §4.3.1: "Collectively, the field-of-view, near clipping distance, and far clipping
// distance define a viewing frustum [...] The viewer (camera) is located at the apex of the
// pyramid." §4.3.4: the window structure "stores the viewport, which is the screen coordinate
// rectangle that OpenGL renders within".
//
// Basalt's reading (decision "scene camera and units"), restated here as the model the pictures
// are checked against:
// - the camera looks down its -Z axis with +Y up; it is turned rotation.y degrees about the
//   world's Y axis (positive turns left, towards -X), then rotation.x about its own X axis
//   (positive looks up), then rotation.z about its line of sight;
// - fov is the vertical angle (gluPerspective's), the horizontal one follows the aspect ratio
//   of the viewport;
// - the viewport is glViewport's: x, y from the bottom left of the view, width, height.
//
// A point p is seen at camera coordinates q = Rz^-1 Rx^-1 Ry^-1 (p - position); on screen at
// x = q.x / (-q.z) / (tan(fov/2) aspect), y = q.y / (-q.z) / tan(fov/2), in -1..1 over the
// viewport. A box is convex, so its picture is the convex hull of its eight corners' images.
// Every pixel whose centre is more than one pixel from that hull's outline must be lit inside
// it and dark outside it.
//
// Example failures: the scene shrunk to fit the window whatever its camera (the pictures from
// two cameras identical); the heading turned the wrong way (the box on the other side); the
// field of view read as horizontal; the viewport line ignored or taken from the top left;
// near and far planes left at LAVA's.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <numbers>

#include "runtime/formats/scene.h"
#include "support/render_fixture.h"
#include "support/test_paths.h"

namespace basalt::test {
namespace {

struct P3 {
  double x, y, z;
};
struct P2 {
  double x, y;
};

constexpr double kDeg = std::numbers::pi / 180.0;

/// World to camera coordinates, written out from the model above (not through Mat4).
P3 toCamera(P3 p, P3 position, P3 rotation) {
  double x = p.x - position.x, y = p.y - position.y, z = p.z - position.z;
  // Undo the heading: rotate by -rotation.y about Y.
  {
    const double c = std::cos(-rotation.y * kDeg), s = std::sin(-rotation.y * kDeg);
    const double nx = c * x + s * z, nz = -s * x + c * z;
    x = nx, z = nz;
  }
  // Undo the pitch: rotate by -rotation.x about X.
  {
    const double c = std::cos(-rotation.x * kDeg), s = std::sin(-rotation.x * kDeg);
    const double ny = c * y - s * z, nz = s * y + c * z;
    y = ny, z = nz;
  }
  // Undo the roll: rotate by -rotation.z about Z.
  {
    const double c = std::cos(-rotation.z * kDeg), s = std::sin(-rotation.z * kDeg);
    const double nx = c * x - s * y, ny = s * x + c * y;
    x = nx, y = ny;
  }
  return {x, y, z};
}

struct Camera {
  P3 position{0, 0, 0};
  P3 rotation{0, 0, 0};
  double fov = 60;
  // The viewport in pixels from the bottom left of the 256 x 256 image.
  double vx = 0, vy = 0, vw = kRenderSize, vh = kRenderSize;
};

/// Where a world point lands in the read-back image (x right, y down from the top row).
P2 pinhole(const Camera& c, P3 p) {
  const P3 q = toCamera(p, c.position, c.rotation);
  const double t = std::tan(c.fov * 0.5 * kDeg);
  const double nx = q.x / -q.z / (t * c.vw / c.vh);
  const double ny = q.y / -q.z / t;
  const double px = c.vx + (nx + 1) * 0.5 * c.vw;
  const double pyUp = c.vy + (ny + 1) * 0.5 * c.vh;
  return {px, kRenderSize - pyUp};
}

double cross(P2 o, P2 a, P2 b) { return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x); }

/// The convex hull, counter-clockwise in image coordinates' arithmetic (Andrew's monotone chain).
std::vector<P2> hull(std::vector<P2> points) {
  std::sort(points.begin(), points.end(), [](P2 a, P2 b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
  std::vector<P2> h(points.size() * 2);
  std::size_t k = 0;
  for (const P2& p : points) {
    while (k >= 2 && cross(h[k - 2], h[k - 1], p) <= 0) --k;
    h[k++] = p;
  }
  for (std::size_t i = points.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && cross(h[k - 2], h[k - 1], points[i]) <= 0) --k;
    h[k++] = points[i];
  }
  h.resize(k - 1);
  return h;
}

/// Signed distance from p to the convex polygon's outline: positive inside.
double insideBy(const std::vector<P2>& poly, P2 p) {
  double d = 1e9;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const P2 a = poly[i], b = poly[(i + 1) % poly.size()];
    const double len = std::hypot(b.x - a.x, b.y - a.y);
    d = std::min(d, cross(a, b, p) / len);
  }
  return d;
}

std::string boxObj(P3 lo, P3 hi) {
  std::string obj = "o box\n";
  for (int i = 0; i < 8; ++i) {
    obj += fmt::format("v {} {} {}\n", (i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z);
  }
  // Outward faces, counter-clockwise seen from outside (1-based: corner i is line i + 1).
  obj += "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
  return obj;
}

class SceneCamera : public RenderTest {
 protected:
  /// Loads a scene of one white (emissive) box with `camera` lines, as `basalt run` does.
  runtime::Show load(const std::string& name, const std::string& cameraLines, P3 lo, P3 hi) {
    const auto dir = scratchDir("scene-camera-" + name);
    std::ofstream(dir / "box.obj") << boxObj(lo, hi);
    std::ofstream(dir / "s.sce") << cameraLines << "\nemission[255,255,255]\nimport box.obj\n";
    formats::LoadOptions options;
    options.logWarnings = false;
    auto loaded = formats::loadScene(dir / "s.sce", options);
    runtime::Show show;
    EXPECT_TRUE(loaded) << (loaded ? "" : loaded.error().describe());
    if (!loaded) return show;
    for (const auto& w : loaded->warnings) ADD_FAILURE() << w.describe();
    formats::applyScene(show, *loaded);
    return show;
  }

  /// Every pixel more than a pixel from the box's projected outline is lit inside and dark
  /// outside; returns how many pixels are lit.
  std::size_t expectBox(const Image& image, const Camera& c, P3 lo, P3 hi, const std::string& what) {
    std::vector<P2> corners;
    for (int i = 0; i < 8; ++i) {
      corners.push_back(pinhole(c, {(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z}));
    }
    const std::vector<P2> outline = hull(corners);
    std::size_t wrong = 0, lit = 0;
    for (std::uint32_t y = 0; y < kRenderSize; ++y) {
      for (std::uint32_t x = 0; x < kRenderSize; ++x) {
        const bool on = image.at(x, y, 0) > 128;
        lit += on ? 1U : 0U;
        const double d = insideBy(outline, {x + 0.5, y + 0.5});
        if (std::fabs(d) <= 1.0) continue;
        if (on != (d > 0)) {
          if (wrong++ < 5) ADD_FAILURE() << what << ": pixel " << x << "," << y << (on ? " lit" : " dark");
        }
      }
    }
    EXPECT_EQ(wrong, 0u) << what;
    return lit;
  }
};

TEST_F(SceneCamera, TheBoxWhereThePinholePutsItFromEachCamera) {
  const P3 lo{-1, -0.5, -7}, hi{1, 0.75, -5};
  struct Case {
    const char* name;
    const char* lines;
    Camera camera;
  };
  const Case cases[] = {
      {"origin-fov60", "position[0,0,0]\nrotation[0,0,0]\nprojection fov[60]", {{0, 0, 0}, {0, 0, 0}, 60}},
      // Two units to the right and five back, turned 12 degrees to the left, zoomed in: the box's
      // centre is atan(2 / 11) = 10.3 degrees left of -Z from there, so just right of the line
      // of sight, and large.
      {"moved-turned-fov20", "position[2,0,5]\nrotation[0,12,0]\nprojection fov[20]", {{2, 0, 5}, {0, 12, 0}, 20}},
      {"pitch-roll", "position[0.5,2,1]\nrotation[-20,5,10]\nprojection fov[75]", {{0.5, 2, 1}, {-20, 5, 10}, 75}},
  };
  std::vector<std::size_t> litCounts;
  for (const Case& k : cases) {
    const runtime::Show show = load(k.name, k.lines, lo, hi);
    const Image image = renderShow(show);
    const std::size_t lit = expectBox(image, k.camera, lo, hi, k.name);
    EXPECT_GT(lit, 200u) << k.name << ": the box should be in sight";
    litCounts.push_back(lit);
  }
  EXPECT_NE(litCounts[0], litCounts[1]) << "two cameras, the same picture";
}

TEST_F(SceneCamera, TheViewportLineIsTheRectangleDrawnInto) {
  // viewport position[32,64] resolution[160,96]: the box seen through a 160 x 96 window whose
  // lower left corner is 32 pixels right of and 64 up from the view's; nothing lit outside it.
  const P3 lo{-1, -0.5, -7}, hi{1, 0.75, -5};
  const runtime::Show show =
      load("viewport", "viewport position[32,64] resolution[160,96]\nprojection fov[40]", lo, hi);
  const Image image = renderShow(show);
  Camera c;
  c.fov = 40;
  c.vx = 32, c.vy = 64, c.vw = 160, c.vh = 96;
  EXPECT_GT(expectBox(image, c, lo, hi, "viewport"), 200u);
  for (std::uint32_t y = 0; y < kRenderSize; ++y) {
    for (std::uint32_t x = 0; x < kRenderSize; ++x) {
      const std::uint32_t up = kRenderSize - 1 - y;
      if (x >= 32 && x < 192 && up >= 64 && up < 160) continue;
      ASSERT_LT(image.at(x, y, 0), 8) << "lit outside the scene's viewport at " << x << "," << y;
    }
  }
}

TEST_F(SceneCamera, NearAndFarPlanesClip) {
  // A wall 4 x 4 units across at distance d on the line of sight, the camera at the origin with
  // nearclip 2 and farclip 10: drawn for 2 < d < 10, clipped away before 2 and beyond 10.
  const char* lines = "projection fov[60] nearclip[2] farclip[10]";
  const auto litAt = [&](double d) {
    const runtime::Show show = load(fmt::format("clip-{}", d), lines, {-2, -2, -d - 0.01}, {2, 2, -d});
    const Image image = renderShow(show);
    return image.at(kRenderSize / 2, kRenderSize / 2, 0) > 128;
  };
  EXPECT_FALSE(litAt(1.9)) << "in front of the near plane";
  EXPECT_TRUE(litAt(2.1));
  EXPECT_TRUE(litAt(9.9));
  EXPECT_FALSE(litAt(10.1)) << "beyond the far plane";
}

}  // namespace
}  // namespace basalt::test
