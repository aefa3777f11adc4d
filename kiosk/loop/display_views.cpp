#include "kiosk/loop/display_views.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "runtime/log.h"

namespace basalt::kiosk {
namespace {
BASALT_LOG_CATEGORY(Views, "views");
}  // namespace

Result<std::unique_ptr<DisplayViews>> DisplayViews::create(const std::vector<ViewSpec>& specs,
                                                           render::Renderer& renderer, render::Size output,
                                                           const std::filesystem::path& savedCalibrations) {
  auto facets = render::FacetRenderer::create();
  if (!facets) return std::unexpected(facets.error());
  std::unique_ptr<DisplayViews> d(new DisplayViews(renderer, std::move(*facets), savedCalibrations));
  std::size_t untiled = 0;
  for (const ViewSpec& s : specs) untiled += s.viewport ? 0U : 1U;
  const auto columns = static_cast<std::uint32_t>(std::ceil(std::sqrt(static_cast<double>(untiled))));
  const std::uint32_t rows = columns == 0 ? 0 : static_cast<std::uint32_t>((untiled + columns - 1) / columns);
  std::uint32_t tile = 0;
  bool currentSet = false;
  for (const ViewSpec& s : specs) {
    View v;
    v.spec = s;
    if (s.viewport) {
      const auto& r = *s.viewport;  // x, y from the top left in the manifest
      v.viewport = {static_cast<std::int32_t>(r[0]), static_cast<std::int32_t>(output.height - r[1] - r[3]), r[2],
                    r[3]};
    } else {
      const std::uint32_t c = tile % columns, r = tile / columns;
      const std::uint32_t x0 = output.width * c / columns, x1 = output.width * (c + 1) / columns;
      const std::uint32_t y0 = output.height * r / rows, y1 = output.height * (r + 1) / rows;
      v.viewport = {static_cast<std::int32_t>(x0), static_cast<std::int32_t>(output.height - y1), x1 - x0, y1 - y0};
      ++tile;
    }
    if (s.kind == ViewKind::kFacet) {
      auto cave = formats::loadCave(s.cave);
      if (!cave) return std::unexpected(cave.error());
      if (!cave->geometry) {
        return fail(Errc::kInvalidArgument,
                    fmt::format("view '{}': the cave file names no display geometry: add `model display.obj`", s.name),
                    s.cave.string());
      }
      if (s.facetGiven) {
        if (s.facet >= cave->geometry->facets.size()) {
          return fail(Errc::kInvalidArgument,
                      fmt::format("view '{}': facet {} does not exist; the display has facets 0 to {}", s.name, s.facet,
                                  cave->geometry->facets.size() - 1),
                      s.cave.string());
        }
        cave->settings.facet = s.facet;
      }
      v.cave = std::move(*cave);
      d->readSavedCalibration(v);
      // After the saved calibration, which may name the geometry again.
      if (s.winding != formats::FacetWinding::kInward) {
        v.cave.geometry =
            std::make_shared<const formats::CaveGeometry>(formats::windFacets(*v.cave.geometry, s.winding));
      }
      if (s.eyeSpacing) v.eyeSpacing = *s.eyeSpacing;
      if (!currentSet) d->current_ = d->views_.size(), currentSet = true;
    }
    d->views_.push_back(std::move(v));
  }
  // Aids views show a facet view's set-up: resolved once every facet view is loaded.
  for (View& v : d->views_) {
    if (v.spec.kind != ViewKind::kAids) continue;
    const auto target = d->facetViewNamed(v.spec.of);
    if (!target) {
      return fail(Errc::kInvalidArgument,
                  v.spec.of.empty() ? fmt::format("view '{}': the visual aids need a facet view to show", v.spec.name)
                                    : fmt::format("view '{}': '{}' is not a facet view", v.spec.name, v.spec.of));
    }
    v.shows = *target;
    auto aids = runtime::CaveAids::create(d->views_[*target].cave.geometry);
    if (!aids) return std::unexpected(aids.error());
    v.aids.emplace(std::move(*aids));
  }
  return d;
}

std::filesystem::path DisplayViews::savedCalibrationFile(const std::filesystem::path& folder, std::string_view name) {
  std::string file(name);
  for (char& c : file) {
    const bool plain =
        (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' || c == '-' || c == '_';
    if (!plain) c = '_';
  }
  return folder / (file + ".cave");
}

void DisplayViews::readSavedCalibration(View& v) const {
  if (savedCalibrations_.empty()) return;
  const std::filesystem::path saved = savedCalibrationFile(savedCalibrations_, v.spec.name);
  std::error_code ec;
  const auto savedTime = std::filesystem::last_write_time(saved, ec);
  if (ec) return;  // nothing saved yet
  // The cave file edited after the calibration was saved (or a show put in place since) wins.
  const auto caveTime = std::filesystem::last_write_time(v.spec.cave, ec);
  if (!ec && caveTime > savedTime) {
    log::warn(kLogViews, "view '{}': {} changed after the calibration saved in {}; playing the cave file's",
              v.spec.name, v.spec.cave.string(), saved.string());
    return;
  }
  const std::filesystem::path caveFile = v.cave.path;
  auto read = formats::loadCave(saved, &v.cave);
  if (!read) {
    log::warn(kLogViews, "view '{}': the saved calibration cannot be used ({}); playing {}", v.spec.name,
              read.error().describe(), v.spec.cave.string());
    return;
  }
  v.cave = std::move(*read);
  v.cave.path = caveFile;
  log::info(kLogViews, "view '{}': calibration read from {}", v.spec.name, saved.string());
}

std::optional<std::size_t> DisplayViews::facetViewNamed(const std::string& of) const {
  for (std::size_t i = 0; i < views_.size(); ++i) {
    if (views_[i].spec.kind == ViewKind::kFacet && (of.empty() || views_[i].spec.name == of)) return i;
  }
  return std::nullopt;
}

runtime::FacetViewInput DisplayViews::facetInput(const View& v, const runtime::Show& show) const {
  runtime::FacetViewInput input;
  input.viewer = show.head().tracked ? show.head().position : viewer_;
  input.calibration = v.cave.settings;
  // The camera places the display (thesis §4.4.4); the manifest says where it stands from the
  // camera and how many scene units one of its units is.
  input.worldFromCave = runtime::cavePlacement(show) *
                        Mat4::translation({v.spec.displayAt[0], v.spec.displayAt[1], v.spec.displayAt[2]}) *
                        Mat4::scaling({v.spec.displayScale, v.spec.displayScale, v.spec.displayScale});
  input.farDistance = show.viewer().farClip / v.spec.displayScale;  // the facet's eye space is in cave units
  input.rearProjection = v.spec.rearProjection;
  return input;
}

void DisplayViews::drawAids(View& v, const runtime::Show& show,
                            const std::function<void(runtime::ViewTransforms&)>& adjust) {
  const View& target = views_[v.shows];
  const formats::CaveGeometry& g = *target.cave.geometry;
  const std::uint32_t index = target.cave.settings.facet < g.facets.size() ? target.cave.settings.facet : 0;
  runtime::FacetViewInput input = facetInput(target, show);
  const render::Viewport& tvp = target.viewport;
  input.aspect = static_cast<float>(std::max(tvp.width, 1U)) / static_cast<float>(std::max(tvp.height, 1U));
  // The facet view's own projection, computed afresh so that the aids follow a calibration
  // changed this frame whichever view is drawn first.
  if (!runtime::computeFacetView(g.facets[index], input, v.last)) v.last.visible = false;
  v.aids->update(index, v.last, input.viewer);

  const render::Viewport& vp = v.viewport;
  const float aspect = static_cast<float>(std::max(vp.width, 1U)) / static_cast<float>(std::max(vp.height, 1U));
  const Vec3 from =
      v.spec.from ? Vec3{(*v.spec.from)[0], (*v.spec.from)[1], (*v.spec.from)[2]} : runtime::CaveAids::kDefaultFrom;
  runtime::ViewTransforms t = v.aids->outsideView(input.worldFromCave, from, aspect);
  // The world as the facet views place it, then the aids over it (always in sight: a clear
  // depth buffer, so the world never hides the display's outline).
  t.model = show.position().global * show.position().local * runtime::viewNormalisation(show);
  if (adjust) adjust(t);
  render::ViewPass world;
  world.viewport = vp;
  renderer_.draw(show, t, world);
  t.model = input.worldFromCave;
  render::ViewPass overlay;
  overlay.viewport = vp;
  overlay.drawBackground = false;
  renderer_.draw(v.aids->show(), t, overlay);
}

void DisplayViews::drawViews(const runtime::Show& show, render::Size output,
                             const std::function<void(runtime::ViewTransforms&)>& adjust) {
  (void)output;
  for (View& v : views_) {
    const render::Viewport& vp = v.viewport;
    switch (v.spec.kind) {
      case ViewKind::kPlain: renderer_.drawShow(show, vp, adjust); break;
      case ViewKind::kStereo: {
        // One eye of the show's stereo pair, filling the view: a passive projector per eye.
        const float aspect = static_cast<float>(std::max(vp.width, 1U)) / static_cast<float>(std::max(vp.height, 1U));
        const float half = 0.5f * runtime::eyeSpacingInWindowUnits(show);
        runtime::ViewTransforms t = runtime::computeEyeView(show, aspect, v.spec.eye == Eye::kLeft ? -half : half);
        if (adjust) adjust(t);
        render::ViewPass pass;
        pass.viewport = vp;
        renderer_.draw(show, t, pass);
        break;
      }
      case ViewKind::kFacet: {
        if (!caveMode_) {
          renderer_.drawShow(show, vp, adjust);
          break;
        }
        const formats::CaveGeometry& g = *v.cave.geometry;
        const std::uint32_t index = v.cave.settings.facet < g.facets.size() ? v.cave.settings.facet : 0;
        render::FacetPass pass;
        pass.facet = &g.facets[index];
        pass.input = facetInput(v, show);
        pass.viewport = vp;
        using S = ViewSpec::Stereo;
        switch (v.spec.stereo) {
          case S::kShow:
            pass.stereo = show.global().stereo;
            pass.stereoMode = show.stereo().mode;
            break;
          case S::kOff: pass.stereo = false; break;
          case S::kAnaglyph: pass.stereo = true, pass.stereoMode = runtime::StereoMode::kAnaglyph; break;
          case S::kSideBySide: pass.stereo = true, pass.stereoMode = runtime::StereoMode::kSideBySide; break;
          case S::kTopBottom: pass.stereo = true, pass.stereoMode = runtime::StereoMode::kTopBottom; break;
        }
        pass.eyeSpacing = v.eyeSpacing >= 0 ? v.eyeSpacing : show.stereo().eyeSpacing;
        if (show.head().tracked) pass.eyeAxis = show.head().right;
        const auto r = facets_->draw(renderer_, show, pass, adjust);
        v.last = facets_->lastProjection();
        const bool empty = !r || !v.last.visible;
        if (empty != v.empty) noteEmpty(v, index, empty, r ? nullptr : &r.error(), pass.input.viewer);
        break;
      }
      case ViewKind::kAids: drawAids(v, show, adjust); break;
    }
  }
}

void DisplayViews::noteEmpty(View& v, std::uint32_t index, bool empty, const Error* error, const Vec3& at) {
  v.empty = empty;
  if (!empty) {
    v.emptyWhy.clear();
    log::info(kLogViews, "view '{}' draws again (facet {})", v.spec.name, index);
  } else {
    const formats::CaveFacet& f = v.cave.geometry->facets[index];
    const std::string facet =
        fmt::format("facet {} of {} (line {})", index, v.cave.geometry->path.filename().string(), f.line);
    if (error) {
      v.emptyWhy = fmt::format("{}: {}", facet, error->message());
    } else if (!f.facesInward) {
      // Thesis §4.2.1 and §4.4.1: the facet's front faces away from the viewer, so it is culled.
      v.emptyWhy = fmt::format(
          "{} faces away from the viewer: the display geometry is wound outward (its corners "
          "run clockwise seen from inside); set winding = \"outward\" (or \"auto\") in this "
          "view's [[views]] entry, or reverse the corners of the geometry's facets "
          "('basalt check' names them)",
          facet);
    } else {
      v.emptyWhy = fmt::format(
          "the viewer, at ({}, {}, {}) in the display geometry's units, is behind or on the plane "
          "of {}: it is outside the display; model the display around its origin, or move the "
          "viewer inside ([viewer] position, or the tracker)",
          at.x, at.y, at.z, facet);
    }
    log::warn(kLogViews, "view '{}' draws nothing (reported once): {}", v.spec.name, v.emptyWhy);
  }
  problems_.clear();
  for (const View& w : views_) {
    if (w.empty) problems_.push_back(fmt::format("view '{}' draws nothing: {}", w.spec.name, w.emptyWhy));
  }
  ++problemsVersion_;
}

bool DisplayViews::selectView(std::size_t index) {
  if (index >= views_.size() || views_[index].spec.kind != ViewKind::kFacet) return false;
  current_ = index;
  return true;
}

bool DisplayViews::applyKey(const Event& event) {
  if (current_ >= views_.size() || views_[current_].spec.kind != ViewKind::kFacet) return false;
  View& v = views_[current_];
  float spacing = v.eyeSpacing >= 0 ? v.eyeSpacing : 0.0f;
  const runtime::CaveKeyEffect effect = keys_.apply(event, v.cave.settings, *v.cave.geometry, spacing);
  if (effect == runtime::CaveKeyEffect::kEyeSpacing) v.eyeSpacing = spacing;
  return effect != runtime::CaveKeyEffect::kNone;
}

formats::CaveSettings* DisplayViews::calibration(std::size_t index) {
  if (index >= views_.size() || views_[index].spec.kind != ViewKind::kFacet) return nullptr;
  return &views_[index].cave.settings;
}

Result<std::string> DisplayViews::calibrate(std::string_view name, std::string_view statements, bool save) {
  const auto index = facetViewNamed(std::string(name));
  if (!index) {
    std::string names;
    for (const View& v : views_) {
      if (v.spec.kind == ViewKind::kFacet) names += (names.empty() ? "'" : ", '") + v.spec.name + "'";
    }
    if (names.empty()) return fail(Errc::kNotFound, "this show has no facet views to calibrate");
    return fail(Errc::kNotFound, fmt::format("no facet view '{}'; the facet views are {}", name, names));
  }
  View& v = views_[*index];
  std::string text(statements);
  std::replace(text.begin(), text.end(), ';', '\n');
  auto parsed =
      formats::parseCaveText(text, fmt::format("calibration of view '{}'", v.spec.name), v.cave.settings, true);
  if (!parsed) return std::unexpected(parsed.error());
  if (parsed->modelGiven) {
    return fail(Errc::kInvalidArgument,
                "the display geometry cannot change while the show plays: edit the cave file and reload");
  }
  if (auto problem = formats::caveSettingsProblem(parsed->settings, *v.cave.geometry)) {
    return fail(Errc::kInvalidArgument, std::move(*problem));
  }
  v.cave.settings = parsed->settings;
  log::info(kLogViews, "view '{}' calibrated: {}", v.spec.name, statements);
  if (save) {
    if (auto written = saveCalibration(*index); !written) return std::unexpected(written.error());
    log::info(kLogViews, "view '{}': calibration saved to {}", v.spec.name, calibrationFile(*index).string());
  }
  const formats::CaveSettings& c = v.cave.settings;
  return fmt::format("view '{}': facet[{}] side[{}] Xscale[{}] Yscale[{}] Xskew[{}] Yskew[{}] Zrotation[{}]{}",
                     v.spec.name, c.facet, c.side, c.xScale, c.yScale, c.xSkew, c.ySkew, c.zRotation,
                     save ? fmt::format(" (saved to {})", calibrationFile(*index).string()) : std::string());
}

std::filesystem::path DisplayViews::calibrationFile(std::size_t index) const {
  if (index >= views_.size() || views_[index].spec.kind != ViewKind::kFacet) return {};
  const View& v = views_[index];
  return savedCalibrations_.empty() ? v.cave.path : savedCalibrationFile(savedCalibrations_, v.spec.name);
}

Result<void> DisplayViews::saveCalibration(std::size_t index) const {
  if (index >= views_.size() || views_[index].spec.kind != ViewKind::kFacet) {
    return fail(Errc::kInvalidArgument, fmt::format("view {} is not a facet view", index));
  }
  const View& v = views_[index];
  if (savedCalibrations_.empty()) return formats::writeCave(v.cave.path, v.cave.settings);
  // A cave file of its own, complete: it names the show's geometry where it is.
  formats::CaveSettings settings = v.cave.settings;
  if (v.cave.geometry) settings.model = std::filesystem::absolute(v.cave.geometry->path).lexically_normal().string();
  return formats::writeCave(calibrationFile(index), settings);
}

const runtime::CaveAids* DisplayViews::aids(std::size_t index) const {
  if (index >= views_.size() || !views_[index].aids) return nullptr;
  return &*views_[index].aids;
}

const runtime::FacetProjection* DisplayViews::lastProjection(std::size_t index) const {
  if (index >= views_.size() || views_[index].spec.kind != ViewKind::kFacet) return nullptr;
  return &views_[index].last;
}

}  // namespace basalt::kiosk
