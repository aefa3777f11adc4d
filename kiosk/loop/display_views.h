#pragma once

/// \file
/// \brief The views a show manifest asks for (`[[views]]`), drawn each frame: plain views, one
/// stereo eye per view (a passive projector per eye), facets of a polyhedral display (thesis
/// §4.4) in mono or any stereo layout, tiled in one output or each filling an output, and the
/// visual aids of a facet view (§4.4.6: the display seen from outside with the current facet,
/// its normal, the viewer and the computed vectors, over the world).
/// Holds each facet view's calibration, adjustable live with the thesis' keys (Appendix B) and
/// saved back to its `.cave` file, or, where the show's folder is not the node's to write (a
/// service), to a cave file of its own in a folder of saved calibrations, read back at start.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "kiosk/manifest/manifest.h"
#include "render/facet_view.h"
#include "render/renderer.h"
#include "runtime/cave_aids.h"
#include "runtime/cave_keys.h"
#include "runtime/formats/cave.h"

namespace basalt::kiosk {

/// \brief Draws the frame instead of the single plain view (FrameLoop::setViewDrawer).
class ViewDrawer {
 public:
  virtual ~ViewDrawer() = default;
  virtual void drawViews(const runtime::Show& show, render::Size output,
                         const std::function<void(runtime::ViewTransforms&)>& adjust) = 0;
};

/// \brief A manifest's views, ready to draw.
///
/// Threading: the frame loop's thread (it draws with GL).
class DisplayViews final : public ViewDrawer {
 public:
  /// \brief Loads each facet view's cave file and checks its facet; views without a viewport
  /// are tiled over the output (a grid, left to right, top to bottom). Needs the GL context.
  /// With `savedCalibrations` (a folder, such as the service's state folder), calibrations are
  /// saved there, one cave file per view (savedCalibrationFile), and a view whose saved file is
  /// newer than the show's cave file starts from it; empty: they are saved to the show's cave file.
  [[nodiscard]] static Result<std::unique_ptr<DisplayViews>> create(
      const std::vector<ViewSpec>& views, render::Renderer& renderer, render::Size output,
      const std::filesystem::path& savedCalibrations = {});
  /// \brief Where view `name`'s calibration is saved in `folder`: `NAME.cave`, with characters
  /// other than letters, digits, '.', '-' and '_' turned into '_'.
  [[nodiscard]] static std::filesystem::path savedCalibrationFile(const std::filesystem::path& folder,
                                                                  std::string_view name);

  void drawViews(const runtime::Show& show, render::Size output,
                 const std::function<void(runtime::ViewTransforms&)>& adjust) override;

  /// \brief Where the facet views' viewer is while no tracker moves it (`[viewer] position`),
  /// in the display geometry's units; the origin until set. A tracked head (`Show::head()`)
  /// takes its place while it is tracked, and places the stereo eyes along its right vector.
  void setViewer(const Vec3& position) { viewer_ = position; }
  [[nodiscard]] const Vec3& viewer() const { return viewer_; }

  /// \brief A keyboard event for the calibration keys; they act on the current facet view
  /// (the first, or the one chosen with selectView). True when something changed.
  bool applyKey(const Event& event);
  /// \brief The thesis' cave mode (Appendix B `c`): on (the default), facet views show their
  /// facets; off, each shows the plain view of the show in its viewport instead.
  void setCaveMode(bool on) { caveMode_ = on; }
  [[nodiscard]] bool caveMode() const { return caveMode_; }
  [[nodiscard]] bool hasFacetViews() const { return facetViewNamed({}).has_value(); }
  /// \brief The view the calibration keys act on; false when `index` is not a facet view.
  bool selectView(std::size_t index);
  /// \brief The calibration of view `index` (a facet view), to read or change live.
  [[nodiscard]] formats::CaveSettings* calibration(std::size_t index);
  /// \brief Calibration as text, for the control server: `statements` in the cave file's syntax
  /// (`facet`, `side`, `Xscale`, `Yscale`, `Xskew`, `Yskew`, `Zrotation`; no `model`), one per
  /// line or separated by ';', applied to the facet view named `name` ("" = the first) as one
  /// change: a bad statement changes nothing. With `save`, written back (saveCalibration).
  /// Returns the view's settings afterwards, in the cave file's bracket form on one line. Errors: kNotFound (no such
  /// facet view), kInvalidArgument or kParse (a bad statement), kIo (the file could not be written).
  [[nodiscard]] Result<std::string> calibrate(std::string_view name, std::string_view statements, bool save);
  /// \brief Writes view `index`'s calibration back to its cave file, or to its own file in the
  /// folder of saved calibrations when there is one (a whole cave file naming the geometry by its
  /// absolute path, so that `basalt check` reads it alone).
  [[nodiscard]] Result<void> saveCalibration(std::size_t index) const;
  /// \brief The file view `index`'s calibration is saved to (empty for other views).
  [[nodiscard]] std::filesystem::path calibrationFile(std::size_t index) const;
  /// \brief The projection drawn last for view `index` (facet views).
  [[nodiscard]] const runtime::FacetProjection* lastProjection(std::size_t index) const;
  /// \brief The visual aids drawn last by view `index` (aids views).
  [[nodiscard]] const runtime::CaveAids* aids(std::size_t index) const;
  [[nodiscard]] std::size_t size() const { return views_.size(); }
  /// \brief The views that draw nothing (a facet view whose facet the viewer sees from behind,
  /// thesis §4.4.1: wound outward, or the viewer outside the display), one line each saying why
  /// and what to do. Logged once when a view empties (and when it draws again), not per frame.
  [[nodiscard]] const std::vector<std::string>& problems() const { return problems_; }
  /// \brief Changes each time problems() does, so that a reader copies them only then.
  [[nodiscard]] std::uint64_t problemsVersion() const { return problemsVersion_; }

 private:
  struct View {
    ViewSpec spec;
    render::Viewport viewport;  ///< GL coordinates (from the bottom left)
    formats::LoadedCave cave;   ///< facet views
    runtime::FacetProjection last;
    float eyeSpacing = -1;                  ///< facet views: < 0 follows the show
    bool empty = false;                     ///< facet views: the last frame drew nothing (see problems())
    std::string emptyWhy;                   ///< facet views: why, while empty
    std::size_t shows = 0;                  ///< aids views: the facet view whose set-up they show
    std::optional<runtime::CaveAids> aids;  ///< aids views
  };
  /// The facet view `of` names (the first facet view when empty), if any.
  [[nodiscard]] std::optional<std::size_t> facetViewNamed(const std::string& of) const;
  /// The facet input of facet view `v` this frame (no aspect: the caller sets it).
  [[nodiscard]] runtime::FacetViewInput facetInput(const View& v, const runtime::Show& show) const;
  void drawAids(View& v, const runtime::Show& show, const std::function<void(runtime::ViewTransforms&)>& adjust);
  /// Notes that facet view `v` (showing facet `index`) drew nothing or something again: logged,
  /// and problems() rebuilt, only when that changes. `error` is the draw's error, if any; `at`
  /// the viewer it was drawn from (display units).
  void noteEmpty(View& v, std::uint32_t index, bool empty, const Error* error, const Vec3& at);
  /// Starts facet view `v` from its saved calibration when there is one newer than its cave file.
  void readSavedCalibration(View& v) const;
  DisplayViews(render::Renderer& renderer, std::unique_ptr<render::FacetRenderer> facets,
               std::filesystem::path savedCalibrations)
      : renderer_(renderer), facets_(std::move(facets)), savedCalibrations_(std::move(savedCalibrations)) {}

  render::Renderer& renderer_;
  std::unique_ptr<render::FacetRenderer> facets_;
  std::filesystem::path savedCalibrations_;  ///< empty: calibrations are saved to the cave files
  std::vector<View> views_;
  Vec3 viewer_;  ///< the fixed viewer (display units)
  std::size_t current_ = 0;
  bool caveMode_ = true;
  runtime::CaveKeys keys_;
  std::vector<std::string> problems_;
  std::uint64_t problemsVersion_ = 0;
};

}  // namespace basalt::kiosk
