// Cave files (thesis C.1) and the display geometry they name (§4.4.1). Everything here is all or
// nothing: a projection set up from half a calibration is worse than a clear error.

#include "runtime/formats/cave.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "runtime/formats/model.h"
#include "runtime/formats/polygon.h"

namespace basalt::formats {

namespace {

std::uint32_t col(std::size_t offset) { return static_cast<std::uint32_t>(offset) + 1; }

/// Fills a facet's plane and facing from its measured outline.
void setShape(CaveFacet& f, const PolygonShape& shape, const Vec3& displayCentre) {
  f.normal = shape.normal;
  f.planeOffset = shape.planeOffset;
  f.area = shape.area;
  f.longestSide = shape.longestSide;
  Vec3 centre{0, 0, 0};
  for (const Vec3& c : f.corners) centre += c;
  centre = centre / static_cast<float>(f.corners.size());
  f.facesInward = dot(f.normal, displayCentre - centre) > 0;
  // The viewer at the origin: its distance in front of the plane is dot(normal, 0) - offset.
  f.facesViewer = -f.planeOffset > kCaveViewerClearance;
}

/// "line 9", "lines 9-14" or "lines 9, 12 and 20" (the first eight, then how many more); the
/// same for facets.
std::string numberList(std::string_view one, std::string_view many, const std::vector<std::uint32_t>& lines) {
  if (lines.size() == 1) return fmt::format("{} {}", one, lines.front());
  bool consecutive = true;
  for (std::size_t i = 1; i < lines.size(); ++i) consecutive = consecutive && lines[i] == lines[i - 1] + 1;
  if (consecutive && lines.size() > 2) return fmt::format("{} {}-{}", many, lines.front(), lines.back());
  constexpr std::size_t kShown = 8;
  std::string out = fmt::format("{} ", many);
  const std::size_t shown = std::min(lines.size(), kShown);
  for (std::size_t i = 0; i < shown; ++i) {
    out += fmt::format("{}{}", i == 0 ? "" : (i + 1 == shown && shown == lines.size() ? " and " : ", "), lines[i]);
  }
  if (shown < lines.size()) out += fmt::format(" and {} more", lines.size() - shown);
  return out;
}

}  // namespace

Result<CaveParse> parseCaveText(std::string_view text, const std::string& name, CaveSettings start, bool modelKnown) {
  CaveParse out;
  out.settings = std::move(start);
  Diagnostics d(name, 0, false);
  LineReader lines(text);
  std::vector<StatementItem> items;
  while (auto raw = lines.next()) {
    std::string_view line = *raw;
    if (const auto hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
    // "model" takes the rest of the line as a file name, brackets and all ("model[x.obj]" and
    // "model x.obj" are both the thesis' form).
    const std::string_view content = trim(line);
    const std::string_view firstWord = content.substr(0, std::min(content.find_first_of(" \t["), content.size()));
    if (lowerAscii(firstWord) == "model") {
      const std::string where = d.where(lines.number(), col(static_cast<std::size_t>(content.data() - line.data())));
      std::string_view rest = trim(content.substr(firstWord.size()));
      if (rest.size() >= 2 && rest.front() == '[' && rest.back() == ']') rest = trim(rest.substr(1, rest.size() - 2));
      if (rest.empty()) return parseError(where, "'model' needs the name of the cave geometry's OBJ file");
      out.settings.model = std::string(rest);
      out.modelGiven = true;
      out.modelLine = lines.number();
      modelKnown = true;
      continue;
    }
    std::size_t errorAt = 0;
    if (!splitStatementItems(line, items, errorAt)) {
      return parseError(d.where(lines.number(), col(errorAt)), "'[' is not closed by ']'");
    }
    if (items.empty()) continue;
    const StatementItem& key = items[0];
    const std::string keyword = lowerAscii(key.name);
    const std::string where = d.where(lines.number(), col(key.offset));
    // Every other statement takes one number: "facet[3]" or "facet 3".
    std::string_view value;
    std::size_t valueAt = key.offset;
    if (key.bracketed) {
      if (key.args.size() != 1 || items.size() != 1) {
        return parseError(where, fmt::format("'{}' takes one value in brackets, as in {}[1]", key.name, key.name));
      }
      value = key.args[0];
      valueAt = static_cast<std::size_t>(value.data() - line.data());
    } else if (items.size() == 2 && !items[1].bracketed) {
      value = items[1].name;
      valueAt = items[1].offset;
    } else if (items.size() == 2 && items[1].bracketed && items[1].name.empty() && items[1].args.size() == 1) {
      value = items[1].args[0];
      valueAt = static_cast<std::size_t>(value.data() - line.data());
    } else {
      return parseError(where, fmt::format("'{}' takes one value, as in {}[1]", key.name, key.name));
    }
    const std::string valueWhere = d.where(lines.number(), col(valueAt));
    if (keyword == "facet" || keyword == "side") {
      std::int64_t n = 0;
      if (!parseInt(value, n) || n < 0 || n > 1000000) {
        return parseError(valueWhere, fmt::format("'{}' is not a {} index (0 or more)", value, keyword));
      }
      if (keyword == "facet") {
        out.settings.facet = static_cast<std::uint32_t>(n);
        out.facetLine = lines.number();
      } else {
        out.settings.side = static_cast<std::uint32_t>(n);
        out.sideLine = lines.number();
      }
      continue;
    }
    float v = 0;
    if (!parseFloat(value, v) || !std::isfinite(v)) {
      return parseError(valueWhere, fmt::format("'{}' is not a number", value));
    }
    if (keyword == "xscale" || keyword == "yscale") {
      if (!(v > 0)) return parseError(valueWhere, fmt::format("{} must be more than 0, not {}", key.name, value));
      (keyword == "xscale" ? out.settings.xScale : out.settings.yScale) = v;
    } else if (keyword == "xskew" || keyword == "yskew") {
      if (!(std::fabs(v) < 90)) {
        return parseError(valueWhere,
                          fmt::format("{} is an angle in degrees between -90 and 90, not {}", key.name, value));
      }
      (keyword == "xskew" ? out.settings.xSkew : out.settings.ySkew) = v;
    } else if (keyword == "zrotation") {
      if (!modelKnown) {
        return parseError(where, "Zrotation cannot be set before a model is named; put the 'model' line first");
      }
      out.settings.zRotation = v;
    } else {
      return parseError(where, fmt::format("'{}' is not a cave statement (model, facet, side, Xscale, Yscale, Xskew, "
                                           "Yskew, Zrotation)",
                                           key.name));
    }
  }
  return out;
}

Result<CaveGeometry> parseCaveGeometry(std::string_view text, const std::string& name, const LoadOptions& options,
                                       std::vector<Diagnostic>& warnings) {
  Diagnostics d(name, options.limits.maxWarnings, options.logWarnings);
  auto decoded = decodeText(std::string(text), d);
  if (!decoded) return std::unexpected(decoded.error());
  CaveGeometry geometry;
  geometry.path = name;
  std::vector<Vec3> positions;
  std::vector<std::uint32_t> ignoredLines;
  LineReader lines(*decoded);
  while (auto raw = lines.next()) {
    std::string_view line = *raw;
    if (const auto hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
    const auto tokens = splitBlanks(line);
    if (tokens.empty()) continue;
    const auto at = [&](std::string_view t) { return col(static_cast<std::size_t>(t.data() - line.data())); };
    if (tokens[0] == "v") {
      if (positions.size() >= options.limits.maxVertices) {
        return fail(Errc::kResourceExhausted, "too many vertices for a cave geometry", d.where(lines.number()));
      }
      float v[3];
      if (tokens.size() < 4) return parseError(d.where(lines.number(), at(tokens[0])), "a vertex needs x y z");
      for (int i = 0; i < 3; ++i) {
        if (!parseFloat(tokens[static_cast<std::size_t>(i) + 1], v[i]) || !std::isfinite(v[i])) {
          return parseError(d.where(lines.number(), at(tokens[static_cast<std::size_t>(i) + 1])),
                            fmt::format("'{}' is not a finite number", tokens[static_cast<std::size_t>(i) + 1]));
        }
      }
      positions.push_back({v[0], v[1], v[2]});
    } else if (tokens[0] == "f") {
      const auto index = geometry.facets.size();
      if (index >= options.limits.maxElements) {
        return fail(Errc::kResourceExhausted, "too many facets for a cave geometry", d.where(lines.number()));
      }
      CaveFacet facet;
      facet.line = lines.number();
      for (std::size_t i = 1; i < tokens.size(); ++i) {
        const std::string_view t = tokens[i];
        const std::string_view first = t.substr(0, t.find('/'));
        std::int64_t raw64 = 0;
        const std::int64_t count = static_cast<std::int64_t>(positions.size());
        if (!parseInt(first, raw64) || raw64 == 0 || raw64 > count || raw64 < -count) {
          return parseError(
              d.where(lines.number(), at(t)),
              fmt::format("facet {}: '{}' is not a vertex index (1 to {}, or -1 back)", index, t, positions.size()));
        }
        if (facet.corners.size() >= options.limits.maxFaceCorners) {
          return parseError(d.where(lines.number(), at(t)), fmt::format("facet {} has too many corners", index));
        }
        facet.corners.push_back(positions[static_cast<std::size_t>(raw64 > 0 ? raw64 - 1 : count + raw64)]);
      }
      geometry.facets.push_back(std::move(facet));
    } else {
      ignoredLines.push_back(lines.number());
    }
  }
  if (geometry.facets.empty()) {
    return parseError(name, "the cave geometry has no facets ('f' lines); it must be the display's polyhedron");
  }
  Vec3 sum{0, 0, 0};
  std::size_t corners = 0;
  for (const CaveFacet& f : geometry.facets) {
    for (const Vec3& c : f.corners) sum += c;
    corners += f.corners.size();
  }
  geometry.center = sum / static_cast<float>(std::max<std::size_t>(corners, 1));
  for (std::size_t i = 0; i < geometry.facets.size(); ++i) {
    CaveFacet& f = geometry.facets[i];
    const std::string where = d.where(f.line);
    if (f.corners.size() < 3) {
      return parseError(where, fmt::format("facet {} has {} corners; a facet needs at least 3", i, f.corners.size()));
    }
    const PolygonShape shape = measurePolygon(f.corners);
    if (shape.degenerate) {
      return parseError(where, fmt::format("facet {} has no area (its corners are on one line or the same point)", i));
    }
    if (shape.maxPlaneDistance > kCavePlanarTolerance * shape.diameter) {
      return parseError(where, fmt::format("facet {} is not flat: a corner is {:.4g} off its plane (more than {:.3g} "
                                           "of its size {:.4g}); cave facets must be planar",
                                           i, shape.maxPlaneDistance, kCavePlanarTolerance, shape.diameter));
    }
    if (shape.reflexCorner >= 0) {
      return parseError(where, fmt::format("facet {} is not convex: its outline turns the other way at corner {} "
                                           "(number {} on its 'f' line); cave facets must be convex",
                                           i, shape.reflexCorner, shape.reflexCorner + 1));
    }
    setShape(f, shape, geometry.center);
  }
  if (!ignoredLines.empty()) {
    d.warn(ignoredLines.front(), 0,
           fmt::format("{} statements other than 'v' and 'f' were ignored (a cave geometry uses only its vertices "
                       "and faces)",
                       ignoredLines.size()));
  }
  for (Diagnostic& w : d.finish()) warnings.push_back(std::move(w));
  return geometry;
}

Result<CaveGeometry> loadCaveGeometry(const std::filesystem::path& path, const LoadOptions& options,
                                      std::vector<Diagnostic>& warnings) {
  auto bytes = readFileBytes(path, options.limits.maxFileBytes);
  if (!bytes) return std::unexpected(bytes.error());
  auto geometry = parseCaveGeometry(*bytes, path.string(), options, warnings);
  if (geometry) geometry->path = path;
  return geometry;
}

Result<LoadedCave> loadCave(const std::filesystem::path& path, const LoadedCave* previous, const LoadOptions& options) {
  auto bytes = readFileBytes(path, options.limits.maxFileBytes);
  if (!bytes) return std::unexpected(bytes.error());
  Diagnostics d(path.string(), options.limits.maxWarnings, options.logWarnings);
  auto text = decodeText(std::move(*bytes), d);
  if (!text) return std::unexpected(text.error());
  const std::string ext = lowerAscii(path.extension().string());
  if (ext != ".cave") d.warn(0, 0, "cave files should end in .cave (thesis C.1); read anyway");
  LoadedCave cave;
  if (previous) {
    cave.settings = previous->settings;
    cave.geometry = previous->geometry;
  }
  auto parsed = parseCaveText(*text, path.string(), cave.settings, cave.geometry != nullptr);
  if (!parsed) return std::unexpected(parsed.error());
  cave.settings = parsed->settings;
  cave.path = path;
  std::vector<Diagnostic> warnings = d.finish();
  if (parsed->modelGiven) {
    const ResolvedPath model = resolveReferencedFile(cave.settings.model, path.parent_path(), options.searchPaths);
    if (!model.found) {
      return fail(
          Errc::kNotFound,
          fmt::format("the cave geometry '{}' was not found (looked for {})", cave.settings.model, model.path.string()),
          d.where(parsed->modelLine));
    }
    auto geometry = loadCaveGeometry(model.path, options, warnings);
    if (!geometry) {
      return std::unexpected(geometry.error().withContext(
          fmt::format("the cave geometry named on line {} of {}", parsed->modelLine, path.string())));
    }
    cave.geometry = std::make_shared<const CaveGeometry>(std::move(*geometry));
  }
  if (cave.geometry) {
    bool sideWrong = false;
    if (auto problem = caveSettingsProblem(cave.settings, *cave.geometry, &sideWrong)) {
      return fail(Errc::kInvalidArgument, std::move(*problem),
                  d.where(sideWrong && parsed->sideLine ? parsed->sideLine : parsed->facetLine));
    }
  } else if (parsed->facetLine || parsed->sideLine) {
    warnings.push_back({path.string(),
                        "facet and side are set before any model was named; they are checked when "
                        "one is"});
  }
  cave.warnings = std::move(warnings);
  return cave;
}

CaveGeometry windFacets(const CaveGeometry& geometry, FacetWinding winding) {
  CaveGeometry out = geometry;
  if (winding == FacetWinding::kInward) return out;
  for (CaveFacet& f : out.facets) {
    if (winding == FacetWinding::kAuto && f.facesViewer) continue;
    std::reverse(f.corners.begin(), f.corners.end());
    setShape(f, measurePolygon(f.corners), out.center);
  }
  return out;
}

std::optional<Diagnostic> caveFacingProblem(const CaveGeometry& geometry, FacetWinding winding) {
  const CaveGeometry wound = windFacets(geometry, winding);
  // Thesis §4.2.1: a face is seen from its front when its corners run counter-clockwise from the
  // viewer, i.e. when the viewer is on the side its normal points to; §4.4.3: the viewer stands
  // at the geometry's origin. A facet seen from behind is culled: its view draws nothing.
  std::vector<std::uint32_t> outward, outwardLines, behind, behindLines;
  for (std::size_t i = 0; i < wound.facets.size(); ++i) {
    const CaveFacet& f = wound.facets[i];
    if (f.facesViewer) continue;
    // Facing away from the display's centre too: wound the other way. Facing the centre (or the
    // centre on its plane, a display of one facet): the viewer is outside the display.
    Vec3 centroid{0, 0, 0};
    for (const Vec3& c : f.corners) centroid += c;
    centroid = centroid / static_cast<float>(f.corners.size());
    const bool woundOutward = dot(f.normal, wound.center - centroid) < 0;
    (woundOutward ? outward : behind).push_back(static_cast<std::uint32_t>(i));
    (woundOutward ? outwardLines : behindLines).push_back(f.line);
  }
  const std::size_t n = wound.facets.size();
  const std::string file = geometry.path.string();
  if (!outward.empty()) {
    const std::string where = fmt::format("{}:{}", file, outwardLines.front());
    if (outward.size() == n && winding == FacetWinding::kOutward) {
      return Diagnostic{where, fmt::format("winding = \"outward\" turns every facet round, but the {} facets of this "
                                           "geometry face the viewer as written ({}): it is wound inward, as the "
                                           "thesis wants; remove winding from the facet view or set it to \"inward\"",
                                           n, numberList("line", "lines", outwardLines))};
    }
    if (outward.size() == n) {
      return Diagnostic{
          where, fmt::format("{} away from the viewer ({}): the geometry is wound outward, as modelling "
                             "tools export it (each facet's corners run clockwise seen from inside; the thesis' facets "
                             "face inward, counter-clockwise), so every view of it draws nothing. Fix: add "
                             "winding = \"outward\" to the facet view in the show's manifest, or reverse the order of "
                             "the corners on each 'f' line",
                             n == 1 ? std::string("its one facet faces") : fmt::format("all {} facets face", n),
                             numberList("line", "lines", outwardLines))};
    }
    return Diagnostic{where,
                      fmt::format("{} of {} {} away from the viewer ({}): wound outward (corners clockwise seen "
                                  "from inside), so {} draw nothing. Fix: add winding = \"auto\" to the facet "
                                  "view in the show's manifest, which turns each facet to face the viewer, or "
                                  "reverse the order of the corners on {}",
                                  numberList("facet", "facets", outward), n, outward.size() == 1 ? "faces" : "face",
                                  numberList("line", "lines", outwardLines),
                                  outward.size() == 1 ? "its view would" : "their views would",
                                  outward.size() == 1 ? "that line" : "those lines")};
  }
  if (behind.empty()) return std::nullopt;
  return Diagnostic{
      fmt::format("{}:{}", file, behindLines.front()),
      fmt::format("the viewer, at the geometry's origin, is behind or on the plane of {} ({}), which "
                  "{} the display's inside: the origin is not inside the display, so {} draw nothing. "
                  "Fix: model the display around its origin (the thesis' viewer stands there)",
                  numberList("facet", "facets", behind), numberList("line", "lines", behindLines),
                  behind.size() == 1 ? "faces" : "face", behind.size() == 1 ? "its view would" : "their views would")};
}

std::optional<std::string> caveSettingsProblem(const CaveSettings& settings, const CaveGeometry& geometry,
                                               bool* sideWrong) {
  if (sideWrong) *sideWrong = false;
  const auto& facets = geometry.facets;
  if (settings.facet >= facets.size()) {
    return fmt::format("facet {} does not exist: the geometry {} has facets 0 to {}", settings.facet,
                       geometry.path.string(), facets.size() - 1);
  }
  const std::size_t sides = facets[settings.facet].corners.size();
  if (settings.side >= sides) {
    if (sideWrong) *sideWrong = true;
    return fmt::format("side {} does not exist: facet {} has sides 0 to {}", settings.side, settings.facet, sides - 1);
  }
  return std::nullopt;
}

std::string formatCave(const CaveSettings& s) {
  std::string out = "# Cave written by Basalt (thesis appendix C.1)\n";
  if (!s.model.empty()) {
    // A name that is itself in brackets keeps them inside the thesis' bracket form.
    const bool bracketed = s.model.front() == '[' && s.model.back() == ']';
    out += bracketed ? fmt::format("model[{}]\n", s.model) : fmt::format("model {}\n", s.model);
  }
  out += fmt::format("facet[{}]\nside[{}]\nXscale[{}]\nYscale[{}]\nXskew[{}]\nYskew[{}]\n", s.facet, s.side, s.xScale,
                     s.yScale, s.xSkew, s.ySkew);
  // Zrotation may only follow a model.
  if (!s.model.empty()) out += fmt::format("Zrotation[{}]\n", s.zRotation);
  return out;
}

Result<void> writeCave(const std::filesystem::path& path, const CaveSettings& settings) {
  if (settings.model.empty() && settings.zRotation != 0) {
    return fail(Errc::kInvalidArgument, "a cave file cannot hold Zrotation without a model", path.string());
  }
  return writeTextFile(path, formatCave(settings));
}

}  // namespace basalt::formats
