// Head tracking (thesis §4.4.3: the facet frusta follow the viewer): the smoothing of tracker
// samples, the head's right vector, and the facet views seen from a viewer at the display's
// centre and away from it. The expected pictures are worked out here from the pinhole model:
// the ray from the eye to a point crosses the facet's plane, and the facet fills the viewport,
// so where it crosses the facet is where the point is drawn.
// Example failures: a frustum still centred on the display's origin after the viewer moved (a
// point drawn where the centre viewer would see it); a smoothing whose weight ignores the time
// between samples (a different path at 90 and at 250 samples a second); eyes placed along the
// facet instead of the head.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "runtime/facet_projection.h"
#include "runtime/formats/cave.h"
#include "runtime/head_tracking.h"

namespace basalt::runtime {
namespace {

using namespace std::chrono_literals;

// A box display 4 wide (x), 2 high (y), 2 deep (z) around its origin, every facet wound
// counter-clockwise seen from inside, each listed from its bottom-left corner as the viewer
// inside sees it: the front facet (z = -1) first, then the right one (x = 2).
constexpr const char* kBoxObj = R"(v -2 -1 -1
v 2 -1 -1
v 2 1 -1
v -2 1 -1
v -2 -1 1
v 2 -1 1
v 2 1 1
v -2 1 1
f 1 2 3 4
f 2 6 7 3
f 6 5 8 7
f 5 1 4 8
f 4 3 7 8
f 5 6 2 1
)";

formats::CaveGeometry box() {
  std::vector<formats::Diagnostic> warnings;
  auto g = formats::parseCaveGeometry(kBoxObj, "box.obj", formats::LoadOptions{}, warnings);
  EXPECT_TRUE(g) << (g ? "" : g.error().describe());
  return g ? std::move(*g) : formats::CaveGeometry{};
}

// One facet as the test knows it: its bottom-left corner, its right and up axes (unit) and size.
struct KnownFacet {
  Vec3 bottomLeft, right, up;
  float width, height;
};

// The pixel (x from the left, y from the bottom) where an eye at `eye` sees `point` (both in the
// display's coordinates) on a viewport of w x h pixels that the facet fills: the pinhole
// projection onto the facet's plane, then the facet's own coordinates, mirrored for a rear
// projector.
Vec2 pinholePixel(const KnownFacet& f, const Vec3& eye, const Vec3& point, float w, float h, bool rear) {
  const Vec3 normal = cross(f.right, f.up);  // towards the viewer inside
  const float planeEye = dot(eye - f.bottomLeft, normal);
  const float planePoint = dot(point - f.bottomLeft, normal);
  const float t = planeEye / (planeEye - planePoint);
  const Vec3 hit = eye + (point - eye) * t;
  float u = dot(hit - f.bottomLeft, f.right) / f.width;  // 0..1 across the facet
  const float v = dot(hit - f.bottomLeft, f.up) / f.height;
  if (rear) u = 1 - u;
  return {u * w, v * h};
}

Vec2 drawnPixel(const FacetProjection& p, const Vec3& worldPoint, float w, float h) {
  const Vec4 clip = p.projection * (p.view * Vec4{worldPoint.x, worldPoint.y, worldPoint.z, 1});
  return {(clip.x / clip.w + 1) * 0.5f * w, (clip.y / clip.w + 1) * 0.5f * h};
}

struct Case {
  const char* what;
  std::size_t facet;
  KnownFacet known;
  float w, h;
  Vec3 eye;       // display units
  Vec3 objectAt;  // world units
  bool rear;
};

TEST(TrackedViewer, AnObjectLandsWhereThePinholeThroughTheFacetPutsIt) {
  const formats::CaveGeometry g = box();
  ASSERT_EQ(g.facets.size(), 6U);
  // The display sits 4 units out along +Z in the world (LAVA's eye), so world = display + (0, 0, 4).
  const Mat4 worldFromCave = Mat4::translation({0, 0, 4});
  const KnownFacet front{{-2, -1, -1}, {1, 0, 0}, {0, 1, 0}, 4, 2};
  const KnownFacet right{{2, -1, -1}, {0, 0, 1}, {0, 1, 0}, 2, 2};
  const Case cases[] = {
      {"front, centre", 0, front, 800, 400, {0, 0, 0}, {1.3f, 0.6f, 1.0f}, false},
      {"front, off centre", 0, front, 800, 400, {0.7f, -0.3f, 0.4f}, {1.3f, 0.6f, 1.0f}, false},
      {"front, off centre, rear projection", 0, front, 800, 400, {-1.1f, 0.5f, -0.2f}, {-0.4f, -0.9f, -2.5f}, true},
      {"right, centre", 1, right, 400, 400, {0, 0, 0}, {5.0f, 0.3f, 3.2f}, true},
      {"right, off centre", 1, right, 400, 400, {1.2f, 0.4f, 0.6f}, {5.0f, 0.3f, 3.2f}, true},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    FacetViewInput in;
    in.viewer = c.eye;
    in.worldFromCave = worldFromCave;
    in.aspect = c.w / c.h;
    in.rearProjection = c.rear;
    FacetProjection p;
    ASSERT_TRUE(computeFacetView(g.facets[c.facet], in, p));
    ASSERT_TRUE(p.visible);
    const Vec3 objectInDisplay = c.objectAt - Vec3{0, 0, 4};
    const Vec2 expected = pinholePixel(c.known, c.eye, objectInDisplay, c.w, c.h, c.rear);
    const Vec2 drawn = drawnPixel(p, c.objectAt, c.w, c.h);
    EXPECT_NEAR(drawn.x, expected.x, 1.0f);
    EXPECT_NEAR(drawn.y, expected.y, 1.0f);
  }
  // Moving the viewer moves the picture: the same object seen from the centre and from off
  // centre lands tens of pixels apart (so the cases above test the viewer, not a constant).
  const Vec2 fromCentre = pinholePixel(front, {0, 0, 0}, Vec3{1.3f, 0.6f, -3.0f}, 800, 400, false);
  const Vec2 fromAside = pinholePixel(front, {0.7f, -0.3f, 0.4f}, Vec3{1.3f, 0.6f, -3.0f}, 800, 400, false);
  EXPECT_GT(std::hypot(fromCentre.x - fromAside.x, fromCentre.y - fromAside.y), 20.0f);
}

TEST(HeadSmoother, ExponentialReachesSixtyThreePercentAfterOneTimeConstant) {
  HeadSmoothing config;
  config.kind = HeadSmoothing::Kind::kExponential;
  config.timeConstant = 100ms;
  HeadSmoother s(config);
  s.add(0ns, {0, 0, 0}, {1, 0, 0});
  // A step to x = 1, sampled every 10 ms for 100 ms: each step keeps exp(-dt / tau) of the gap.
  for (int i = 1; i <= 10; ++i) s.add(Nanos{i * 10'000'000LL}, {1, 0, 0}, {1, 0, 0});
  EXPECT_NEAR(s.pose().position.x, 1.0 - std::exp(-1.0), 1e-5);
  // The same step sampled every 4 ms reaches the same point at the same time.
  HeadSmoother fast(config);
  fast.add(0ns, {0, 0, 0}, {1, 0, 0});
  for (int i = 1; i <= 25; ++i) fast.add(Nanos{i * 4'000'000LL}, {1, 0, 0}, {1, 0, 0});
  EXPECT_NEAR(fast.pose().position.x, s.pose().position.x, 1e-5);
  EXPECT_EQ(s.pose().sampleTime, 100ms);
  EXPECT_TRUE(s.pose().tracked);
}

TEST(HeadSmoother, OneEuroIsALowPassAtRestAndFollowsQuicklyWhenMoving) {
  HeadSmoothing config;
  config.kind = HeadSmoothing::Kind::kOneEuro;
  config.minCutoff = 1.0;
  config.beta = 0;  // no speed term: a plain low pass at 1 Hz
  HeadSmoother s(config);
  s.add(0ns, {0, 0, 0}, {1, 0, 0});
  for (int i = 1; i <= 10; ++i) s.add(Nanos{i * 10'000'000LL}, {0, 1, 0}, {1, 0, 0});
  const double tau = 1.0 / (2.0 * std::numbers::pi);
  const double keep = tau / (tau + 0.01);
  EXPECT_NEAR(s.pose().position.y, 1.0 - std::pow(keep, 10), 1e-5);

  // With the speed term, a head moving at 1 unit/s lags less than without it.
  config.beta = 2.0;
  HeadSmoother quick(config);
  config.beta = 0;
  HeadSmoother slow(config);
  for (int i = 0; i <= 50; ++i) {
    const Nanos t{i * 10'000'000LL};
    const Vec3 at{0.01f * static_cast<float>(i), 0, 0};
    quick.add(t, at, {1, 0, 0});
    slow.add(t, at, {1, 0, 0});
  }
  EXPECT_LT(0.5f - quick.pose().position.x, 0.5f * (0.5f - slow.pose().position.x));
}

TEST(HeadSmoother, OffTakesEachSampleAndARepeatedStampChangesNothing) {
  HeadSmoother off(HeadSmoothing{HeadSmoothing::Kind::kOff});
  off.add(0ns, {0, 0, 0}, {1, 0, 0});
  off.add(5ms, {0.25f, -0.5f, 2}, {0, 0, 2});
  EXPECT_EQ(off.pose().position, (Vec3{0.25f, -0.5f, 2}));
  EXPECT_EQ(off.pose().right, (Vec3{0, 0, 1}));

  HeadSmoother s;
  s.add(10ms, {0, 0, 0}, {1, 0, 0});
  s.add(10ms, {5, 5, 5}, {1, 0, 0});
  EXPECT_EQ(s.pose().position, (Vec3{0, 0, 0}));
  EXPECT_TRUE(std::isfinite(s.pose().position.x));
}

TEST(HeadTracking, TheHeadsRightVectorTurnsWithTheHead) {
  const Vec3 ahead = headRight({0, 0, 0});
  EXPECT_NEAR(ahead.x, 1, 1e-6);
  // Turned 90 degrees to the left about Y (counter-clockwise seen from above): +X goes to -Z.
  const Vec3 left = headRight({0, 90, 0});
  EXPECT_NEAR(left.x, 0, 1e-6);
  EXPECT_NEAR(left.z, -1, 1e-6);
  // Rolled 30 degrees about Z: right rises by sin 30.
  const Vec3 rolled = headRight({0, 0, 30});
  EXPECT_NEAR(rolled.y, 0.5, 1e-6);
  const TrackerPlacement placement{{0, 1.6f, 0}, 0.001f};  // millimetres, the origin 1.6 below
  const Vec3 d = placement.toDisplay({100, -200, 300});
  EXPECT_NEAR(d.x, 0.1f, 1e-6);
  EXPECT_NEAR(d.y, 1.4f, 1e-6);
  EXPECT_NEAR(d.z, 0.3f, 1e-6);
}

}  // namespace
}  // namespace basalt::runtime
