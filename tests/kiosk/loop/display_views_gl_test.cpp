// A manifest's views drawn by the kiosk (kiosk/loop/display_views.h): the six facets of a cube
// display tiled in one output from `[[views]]` specs and a `.cave` file, compared with a golden
// image; calibration changed live (directly and through the thesis' keys) moves the picture and
// is saved back to the cave file, which reads back the same.
// Example failures: tiles overlapping or flipped top to bottom; a manifest `facet` ignored in
// favour of the cave file's; a calibration saved that the loader then rejects.

#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <sstream>

#include "kiosk/loop/display_views.h"
#include "runtime/image.h"
#include "runtime/log.h"
#include "support/polyhedra.h"
#include "support/render_fixture.h"
#include "support/test_paths.h"

namespace basalt::test {
namespace {

class DisplayViewsTest : public RenderTest {
 protected:
  void SetUp() override {
    RenderTest::SetUp();
    if (IsSkipped()) return;
    // A folder per test: ctest runs the fixture's tests in parallel processes.
    folder_ = scratchDir(std::string("display_views-") + testing::UnitTest::GetInstance()->current_test_info()->name());
    std::ofstream(folder_ / "display.obj") << cubeDisplayObj();
    std::ofstream(folder_ / "display.cave") << "# the test cube\nmodel display.obj\nfacet[5]\n";
  }
  std::vector<kiosk::ViewSpec> sixFacets() const {
    std::vector<kiosk::ViewSpec> specs;
    for (std::uint32_t i = 0; i < 6; ++i) {
      kiosk::ViewSpec s;
      s.name = fmt::format("wall {}", i);
      s.kind = kiosk::ViewKind::kFacet;
      s.cave = folder_ / "display.cave";
      s.facet = i;
      s.facetGiven = true;
      specs.push_back(s);
    }
    return specs;
  }
  Image draw(kiosk::DisplayViews& views, const runtime::Show& show) {
    EXPECT_TRUE(output().beginFrame());
    views.drawViews(show, output().size(), {});
    Image image;
    EXPECT_TRUE(output().readBack(image));
    return image;
  }
  std::filesystem::path folder_;
};

TEST_F(DisplayViewsTest, SixFacetsTiledInOneOutput) {
  auto views = kiosk::DisplayViews::create(sixFacets(), renderer(), output().size());
  ASSERT_TRUE(views) << views.error().describe();
  runtime::Show show = runtime::Show::makeDefault();
  show.global().background = {0.3f, 0.4f, 0.5f};
  const Image image = draw(**views, show);
  const std::string problem = matchesGolden(image, "views_cube_six_tiled");
  EXPECT_TRUE(problem.empty()) << problem;
  // 3 x 2 tiles of 85 x 128 pixels: each square facet fills its tile's width, so the rows above
  // and below it are black and the middle is not.
  for (std::uint32_t t = 0; t < 6; ++t) {
    const std::uint32_t cx = (t % 3) * 256 / 3 + 256 / 6, top = (t / 3) * 128;
    EXPECT_EQ(image.at(cx, top + 4, 0) + image.at(cx, top + 4, 1) + image.at(cx, top + 4, 2), 0) << "tile " << t;
    EXPECT_GT(image.at(cx, top + 64, 0) + image.at(cx, top + 64, 1) + image.at(cx, top + 64, 2), 0) << "tile " << t;
  }
}

// Makes sure a facet view draws from the viewer it is given (`[viewer] position`) and, while the
// Show's head is tracked, from the head instead, in the display's units placed in the world.
// Example failures: the viewer set but the frusta still drawn from the display's centre; a
// tracked head ignored; a head that is no longer tracked still drawn from.
TEST_F(DisplayViewsTest, FacetViewsDrawFromTheViewerAndFromATrackedHead) {
  kiosk::ViewSpec front;
  front.name = "front";
  front.kind = kiosk::ViewKind::kFacet;
  front.cave = folder_ / "display.cave";  // facet[5]
  auto views = kiosk::DisplayViews::create({front}, renderer(), output().size());
  ASSERT_TRUE(views) << views.error().describe();
  runtime::Show show = runtime::Show::makeDefault();
  const Mat4 placement = runtime::cavePlacement(show);
  const auto eyeAt = [&](const Vec3& v) { return placement.transformPoint(v); };
  const auto sameAs = [](const Vec3& a, const Vec3& b) { return length(a - b) < 1e-5f; };

  const Image centre = draw(**views, show);
  EXPECT_TRUE(sameAs((*views)->lastProjection(0)->eye, eyeAt({0, 0, 0})));

  (*views)->setViewer({0.3f, -0.2f, 0.1f});
  const Image aside = draw(**views, show);
  EXPECT_TRUE(sameAs((*views)->lastProjection(0)->eye, eyeAt({0.3f, -0.2f, 0.1f})));
  EXPECT_NE(centre.pixels, aside.pixels) << "the picture follows the viewer";

  show.head() = {true, {-0.4f, 0.1f, 0.2f}, {1, 0, 0}, Nanos{0}};
  const Image tracked = draw(**views, show);
  EXPECT_TRUE(sameAs((*views)->lastProjection(0)->eye, eyeAt({-0.4f, 0.1f, 0.2f}))) << "the tracked head wins";
  EXPECT_NE(tracked.pixels, aside.pixels);

  show.head().tracked = false;
  const Image back = draw(**views, show);
  EXPECT_TRUE(sameAs((*views)->lastProjection(0)->eye, eyeAt({0.3f, -0.2f, 0.1f})));
  EXPECT_EQ(back.pixels, aside.pixels) << "the same viewer draws the same picture";
}

TEST_F(DisplayViewsTest, CalibrationChangesLiveAndIsSavedToTheCaveFile) {
  kiosk::ViewSpec one;
  one.name = "front";
  one.kind = kiosk::ViewKind::kFacet;
  one.cave = folder_ / "display.cave";  // facet[5] from the cave file
  auto views = kiosk::DisplayViews::create({one}, renderer(), output().size());
  ASSERT_TRUE(views) << views.error().describe();
  runtime::Show show = runtime::Show::makeDefault();
  const Image before = draw(**views, show);
  ASSERT_NE((*views)->calibration(0), nullptr);
  EXPECT_EQ((*views)->calibration(0)->facet, 5u);
  (*views)->calibration(0)->xScale = 1.5f;
  Event shift;
  shift.kind = EventKind::kKey;
  shift.index = 42;
  shift.value = 1;
  Event colon = shift;
  colon.index = 39;  // ':' Xskew small up
  (*views)->applyKey(shift);
  EXPECT_TRUE((*views)->applyKey(colon));
  const Image after = draw(**views, show);
  std::size_t changed = 0;
  for (std::size_t i = 0; i < before.pixels.size(); ++i) changed += before.pixels[i] != after.pixels[i] ? 1U : 0U;
  EXPECT_GT(changed, 1000u) << "the calibration did not change the picture";
  ASSERT_TRUE((*views)->saveCalibration(0));
  auto reread = formats::loadCave(folder_ / "display.cave");
  ASSERT_TRUE(reread) << reread.error().describe();
  EXPECT_EQ(reread->settings.xScale, 1.5f);
  EXPECT_EQ(reread->settings.xSkew, 0.5f);
  EXPECT_EQ(reread->settings.facet, 5u);
  EXPECT_EQ(reread->settings.model, "display.obj");
}

// Makes sure that with a folder of saved calibrations (a service's state folder: the show's folder
// is read-only to it) a calibration is saved there and not to the show's cave file, reads back
// alone, and is where the view starts next time, unless the cave file was changed since.
// Example failures: a save that writes the read-only show folder (500 "Read-only file system"
// under the unit); a saved calibration never read back, lost at the next restart; a saved file
// that outlives an edit of the cave file and silently overrides it.
TEST_F(DisplayViewsTest, CalibrationSavedInAStateFolderStartsTheViewNextTime) {
  const std::filesystem::path saved = folder_ / "state/calibration";
  const std::string caveText = "# the test cube\nmodel display.obj\nfacet[5]\n";
  kiosk::ViewSpec one;
  one.name = "front wall";
  one.kind = kiosk::ViewKind::kFacet;
  one.cave = folder_ / "display.cave";
  {
    auto views = kiosk::DisplayViews::create({one}, renderer(), output().size(), saved);
    ASSERT_TRUE(views) << views.error().describe();
    auto answer = (*views)->calibrate("front wall", "Xscale[1.25]; Yskew[-2]", true);
    ASSERT_TRUE(answer) << answer.error().describe();
    EXPECT_NE(answer->find("(saved to " + (saved / "front_wall.cave").string() + ")"), std::string::npos) << *answer;
  }
  std::ifstream caveFile(folder_ / "display.cave");
  std::ostringstream caveNow;
  caveNow << caveFile.rdbuf();
  EXPECT_EQ(caveNow.str(), caveText) << "the show's cave file is untouched";
  // The saved file is a cave file of its own: it names the geometry where it is.
  auto alone = formats::loadCave(saved / "front_wall.cave");
  ASSERT_TRUE(alone) << alone.error().describe();
  EXPECT_EQ(alone->settings.facet, 5u);
  EXPECT_EQ(alone->settings.xScale, 1.25f);
  EXPECT_EQ(alone->settings.ySkew, -2.0f);
  ASSERT_NE(alone->geometry, nullptr);
  EXPECT_EQ(alone->geometry->facets.size(), 6u);

  {
    auto views = kiosk::DisplayViews::create({one}, renderer(), output().size(), saved);
    ASSERT_TRUE(views) << views.error().describe();
    ASSERT_NE((*views)->calibration(0), nullptr);
    EXPECT_EQ((*views)->calibration(0)->xScale, 1.25f) << "the saved calibration is where the view starts";
    EXPECT_EQ((*views)->calibration(0)->ySkew, -2.0f);
    EXPECT_EQ((*views)->calibration(0)->facet, 5u);
  }
  // The cave file edited after the save wins.
  std::filesystem::last_write_time(
      folder_ / "display.cave", std::filesystem::last_write_time(saved / "front_wall.cave") + std::chrono::seconds(10));
  {
    auto views = kiosk::DisplayViews::create({one}, renderer(), output().size(), saved);
    ASSERT_TRUE(views) << views.error().describe();
    EXPECT_EQ((*views)->calibration(0)->xScale, 1.0f) << "the cave file changed after the save";
  }
  // Without the folder, as before: saved to the cave file.
  {
    auto views = kiosk::DisplayViews::create({one}, renderer(), output().size());
    ASSERT_TRUE(views) << views.error().describe();
    auto answer = (*views)->calibrate("", "Xscale[1.5]", true);
    ASSERT_TRUE(answer) << answer.error().describe();
    auto reread = formats::loadCave(folder_ / "display.cave");
    ASSERT_TRUE(reread) << reread.error().describe();
    EXPECT_EQ(reread->settings.xScale, 1.5f);
  }
  EXPECT_EQ(kiosk::DisplayViews::savedCalibrationFile("/s", "left/../eye 2"),
            std::filesystem::path("/s/left_.._eye_2.cave"));
}

TEST_F(DisplayViewsTest, AFacetPastTheDisplayIsAClearError) {
  auto specs = sixFacets();
  specs[2].facet = 6;
  auto views = kiosk::DisplayViews::create(specs, renderer(), output().size());
  ASSERT_FALSE(views);
  EXPECT_NE(views.error().message().find("facet 6 does not exist; the display has facets 0 to 5"), std::string::npos)
      << views.error().describe();
}

}  // namespace
}  // namespace basalt::test

// The manifest keys of facet views: stereo layout, eye spacing, projection, and facet.
// Example failure: `projection = "front"` accepted but ignored; a typo in `stereo` accepted.
namespace basalt::test {
namespace {

TEST(DisplayViewsManifest, FacetViewKeysAreReadAndChecked) {
  const std::filesystem::path folder = scratchDir("display_views_manifest");
  std::ofstream(folder / "display.obj") << cubeDisplayObj();
  std::ofstream(folder / "display.cave") << "model display.obj\n";
  kiosk::Diagnostics diagnostics;
  auto m = kiosk::readManifestText(
      "[show]\nname = \"cave\"\nentry = \"default\"\n[[views]]\nname = \"front\"\nkind = \"facet\"\ncave = "
      "\"display.cave\"\nfacet = 5\n"
      "stereo = \"side_by_side\"\neye_spacing = 0.065\nprojection = \"front\"\n",
      folder / "show.toml", diagnostics);
  ASSERT_TRUE(m) << diagnostics.format();
  ASSERT_EQ(m->views.size(), 1u);
  const kiosk::ViewSpec& v = m->views[0];
  EXPECT_EQ(v.stereo, kiosk::ViewSpec::Stereo::kSideBySide);
  ASSERT_TRUE(v.eyeSpacing);
  EXPECT_FLOAT_EQ(*v.eyeSpacing, 0.065f);
  EXPECT_FALSE(v.rearProjection);
  EXPECT_TRUE(v.facetGiven);
  EXPECT_EQ(v.facet, 5u);

  kiosk::Diagnostics bad;
  EXPECT_FALSE(
      kiosk::readManifestText("[show]\nname = \"cave\"\nentry = \"default\"\n[[views]]\nkind = \"facet\"\ncave = "
                              "\"display.cave\"\nstereo = \"sidebyside\"\n",
                              folder / "show.toml", bad));
}

}  // namespace
}  // namespace basalt::test

// The example show configs/shows/cube-cave: its six facet views load and draw.
// Example failure: the example's cave or geometry rejected, so the documented show cannot start.
namespace basalt::test {
namespace {

TEST_F(DisplayViewsTest, TheCubeCaveExampleDrawsItsSixWalls) {
  kiosk::Diagnostics d;
  const auto m = kiosk::readManifest(sourceDir() / "configs/shows/cube-cave/show.toml", d);
  ASSERT_TRUE(m) << d.format();
  ASSERT_EQ(m->views.size(), 6u);
  auto views = kiosk::DisplayViews::create(m->views, renderer(), output().size());
  ASSERT_TRUE(views) << views.error().describe();
  const Image image = draw(**views, runtime::Show::makeDefault());
  // The front wall (last tile, bottom right) sees the cube: some pixel there is bright.
  int brightest = 0;
  for (std::uint32_t y = 128; y < 256; ++y) {
    for (std::uint32_t x = 171; x < 256; ++x) brightest = std::max(brightest, static_cast<int>(image.at(x, y, 0)));
  }
  EXPECT_GT(brightest, 100);
}

}  // namespace
}  // namespace basalt::test

// The visual aids of thesis §4.4.6 as an aids view: the cube display seen from outside beside
// its front facet view, with the current facet filled, its normal, the viewer's cone and the
// vectors; a facet changed by calibration moves the filled facet. The manifest's aids keys.
// Example failures: the aids hidden by the world drawn over them; the filled facet not following
// the facet view's calibration; an aids view naming no facet view accepted.
namespace basalt::test {
namespace {

/// Pixels of a colour family: the filled facet's yellow, the normal's magenta.
std::size_t countPixels(const Image& image, std::uint32_t x0, std::uint32_t x1, bool (*match)(int r, int g, int b)) {
  std::size_t n = 0;
  for (std::uint32_t y = 0; y < image.height; ++y) {
    for (std::uint32_t x = x0; x < x1; ++x)
      n += match(image.at(x, y, 0), image.at(x, y, 1), image.at(x, y, 2)) ? 1U : 0U;
  }
  return n;
}
bool yellowish(int r, int g, int b) { return r > 150 && g > 120 && b < 90 && r - b > 100; }
bool magenta(int r, int g, int b) { return r > 200 && g < 110 && b > 200; }

TEST_F(DisplayViewsTest, VisualAidsShowTheDisplayFromOutside) {
  kiosk::ViewSpec front;
  front.name = "front";
  front.kind = kiosk::ViewKind::kFacet;
  front.cave = folder_ / "display.cave";  // facet[5]
  front.viewport = std::array<std::uint32_t, 4>{0, 0, 128, 256};
  kiosk::ViewSpec aids;
  aids.name = "check";
  aids.kind = kiosk::ViewKind::kAids;
  aids.viewport = std::array<std::uint32_t, 4>{128, 0, 128, 256};
  aids.from = std::array<float, 3>{1.5f, 0.7f, 0.4f};  // from the right: the cone and vectors side on
  auto views = kiosk::DisplayViews::create({front, aids}, renderer(), output().size());
  ASSERT_TRUE(views) << views.error().describe();
  runtime::Show show = runtime::Show::makeDefault();
  const Image image = draw(**views, show);
  const std::string problem = matchesGolden(image, "views_cube_aids");
  EXPECT_TRUE(problem.empty()) << problem;
  ASSERT_NE((*views)->aids(1), nullptr);
  EXPECT_EQ((*views)->aids(1)->currentFacet(), 5u);
  EXPECT_EQ((*views)->aids(0), nullptr);
  // The aids are in the right half only, and drawn over the world.
  EXPECT_GT(countPixels(image, 128, 256, yellowish), 200u) << "no filled facet";
  EXPECT_GT(countPixels(image, 128, 256, magenta), 5u) << "no facet normal";
  EXPECT_EQ(countPixels(image, 0, 128, magenta), 0u);

  // Another facet through the calibration: the filled facet moves with it.
  (*views)->calibration(0)->facet = 0;
  const Image other = draw(**views, show);
  EXPECT_EQ((*views)->aids(1)->currentFacet(), 0u);
  std::size_t moved = 0;
  for (std::uint32_t y = 0; y < image.height; ++y) {
    for (std::uint32_t x = 128; x < 256; ++x) {
      const bool was = yellowish(image.at(x, y, 0), image.at(x, y, 1), image.at(x, y, 2));
      const bool is = yellowish(other.at(x, y, 0), other.at(x, y, 1), other.at(x, y, 2));
      moved += was != is ? 1U : 0U;
    }
  }
  EXPECT_GT(moved, 200u) << "the filled facet did not follow the calibration";
}

TEST_F(DisplayViewsTest, AnAidsViewNeedsAFacetView) {
  kiosk::ViewSpec aids;
  aids.name = "check";
  aids.kind = kiosk::ViewKind::kAids;
  auto views = kiosk::DisplayViews::create({aids}, renderer(), output().size());
  ASSERT_FALSE(views);
  EXPECT_NE(views.error().message().find("need a facet view"), std::string::npos) << views.error().describe();
}

TEST(DisplayViewsManifest, AidsViewKeysAreReadAndChecked) {
  const std::filesystem::path folder = scratchDir("display_views_aids_manifest");
  std::ofstream(folder / "display.obj") << cubeDisplayObj();
  std::ofstream(folder / "display.cave") << "model display.obj\n";
  const std::string facet =
      "[show]\nname = \"cave\"\nentry = \"default\"\n[[views]]\nname = \"front\"\nkind = \"facet\"\ncave = "
      "\"display.cave\"\n";
  kiosk::Diagnostics diagnostics;
  auto m = kiosk::readManifestText(facet +
                                       "[[views]]\nname = \"check\"\nkind = \"aids\"\nof = \"front\"\n"
                                       "from = [0, 1, 2.5]\n",
                                   folder / "show.toml", diagnostics);
  ASSERT_TRUE(m) << diagnostics.format();
  ASSERT_EQ(m->views.size(), 2u);
  EXPECT_EQ(m->views[1].kind, kiosk::ViewKind::kAids);
  EXPECT_EQ(m->views[1].of, "front");
  ASSERT_TRUE(m->views[1].from);
  EXPECT_FLOAT_EQ((*m->views[1].from)[2], 2.5f);

  kiosk::Diagnostics unknown;
  EXPECT_FALSE(
      kiosk::readManifestText(facet + "[[views]]\nkind = \"aids\"\nof = \"back\"\n", folder / "show.toml", unknown));
  EXPECT_NE(unknown.format().find("names 'back', which is not a facet view"), std::string::npos) << unknown.format();
  kiosk::Diagnostics none;
  EXPECT_FALSE(kiosk::readManifestText("[show]\nname = \"x\"\nentry = \"default\"\n[[views]]\nkind = \"aids\"\n",
                                       folder / "show.toml", none));
  EXPECT_NE(none.format().find("needs a facet view to show"), std::string::npos) << none.format();
  kiosk::Diagnostics zero;
  EXPECT_FALSE(
      kiosk::readManifestText(facet + "[[views]]\nkind = \"aids\"\nfrom = [0, 0, 0]\n", folder / "show.toml", zero));
  EXPECT_NE(zero.format().find("from: must be a direction"), std::string::npos) << zero.format();
}

// ---- Display geometry wound outward ------------------------------------------------------------

// Collects the views' log records (the views' category) while it lives.
class ViewLog {
 public:
  ViewLog() { log::addSink(sink_); }
  ~ViewLog() { log::removeSink(sink_); }
  ViewLog(const ViewLog&) = delete;
  ViewLog& operator=(const ViewLog&) = delete;
  [[nodiscard]] std::size_t count(const std::string& needle) const {
    std::size_t n = 0;
    for (const log::Record& r : sink_->snapshot()) n += r.message.find(needle) != std::string::npos ? 1U : 0U;
    return n;
  }

 private:
  std::shared_ptr<log::RingSink> sink_ = std::make_shared<log::RingSink>(512);
};

// Makes sure a display geometry wound outward (each facet's corners reversed, as modelling tools
// export it) draws, with winding = "outward", the same six facet views as the same display wound
// inward, and that "auto" does too. Example failures: turned facets whose base side moved (each
// wall turned a quarter); the aids or the projection still using the outward facets (black views).
TEST_F(DisplayViewsTest, AnOutwardDisplayTurnedDrawsWhatTheInwardOneDraws) {
  std::ofstream(folder_ / "outward.obj") << reverseFacetWinding(cubeDisplayObj());
  std::ofstream(folder_ / "outward.cave") << "model outward.obj\nfacet[5]\n";
  runtime::Show show = runtime::Show::makeDefault();
  show.global().background = {0.3f, 0.4f, 0.5f};
  auto inward = kiosk::DisplayViews::create(sixFacets(), renderer(), output().size());
  ASSERT_TRUE(inward) << inward.error().describe();
  const Image expected = draw(**inward, show);
  for (const formats::FacetWinding winding : {formats::FacetWinding::kOutward, formats::FacetWinding::kAuto}) {
    std::vector<kiosk::ViewSpec> specs = sixFacets();
    for (kiosk::ViewSpec& s : specs) s.cave = folder_ / "outward.cave", s.winding = winding;
    auto turned = kiosk::DisplayViews::create(specs, renderer(), output().size());
    ASSERT_TRUE(turned) << turned.error().describe();
    const Image actual = draw(**turned, show);
    const ImageDifference diff = compareImages(expected, actual, 2);
    EXPECT_TRUE(diff.sameShape);
    EXPECT_EQ(diff.pixelsOverTolerance, 0u) << "largest difference " << diff.maxChannelDelta;
    EXPECT_TRUE((*turned)->problems().empty()) << (*turned)->problems().front();
  }
  // The inward picture is not black (else the comparison would prove nothing).
  std::size_t lit = 0;
  for (std::size_t i = 0; i < expected.pixels.size(); ++i) lit += expected.pixels[i] > 16 ? 1U : 0U;
  EXPECT_GT(lit, expected.pixels.size() / 4);
}

// Makes sure an outward display without the option is reported once per view that draws nothing
// (not once per frame), with the fix, and listed in problems() (what /health shows) while it lasts.
// Example failures: a black view with nothing in the log; the warning every frame (60 a second);
// problems() empty, so /health says "ok" over a black wall.
TEST_F(DisplayViewsTest, AnOutwardDisplayWithoutTheOptionIsReportedOnce) {
  std::ofstream(folder_ / "outward.obj") << reverseFacetWinding(cubeDisplayObj());
  std::ofstream(folder_ / "outward.cave") << "model outward.obj\nfacet[5]\n";
  kiosk::ViewSpec one;
  one.name = "front wall";
  one.kind = kiosk::ViewKind::kFacet;
  one.cave = folder_ / "outward.cave";
  ViewLog log;
  auto views = kiosk::DisplayViews::create({one}, renderer(), output().size());
  ASSERT_TRUE(views) << views.error().describe();
  runtime::Show show = runtime::Show::makeDefault();
  show.global().background = {0.3f, 0.4f, 0.5f};
  const std::uint64_t before = (*views)->problemsVersion();
  Image image;
  for (int frame = 0; frame < 5; ++frame) image = draw(**views, show);
  // Black: the viewer sees every facet from behind.
  std::size_t lit = 0;
  for (std::size_t i = 0; i < image.pixels.size(); i += 4) {
    lit += image.pixels[i] + image.pixels[i + 1] + image.pixels[i + 2] > 0 ? 1U : 0U;
  }
  EXPECT_EQ(lit, 0u);
  EXPECT_EQ(log.count("view 'front wall' draws nothing"), 1u);
  EXPECT_EQ(log.count("winding = \"outward\""), 1u);
  ASSERT_EQ((*views)->problems().size(), 1u);
  EXPECT_NE((*views)->problems()[0].find("view 'front wall' draws nothing: facet 5 of outward.obj"), std::string::npos)
      << (*views)->problems()[0];
  EXPECT_EQ((*views)->problemsVersion(), before + 1) << "changed once, not per frame";
}

}  // namespace
}  // namespace basalt::test
