#pragma once

/// \file
/// \brief Cave files (`.cave`, thesis appendix C.1) and cave geometry (§4.4.1): which display
/// geometry a node projects onto, which facet and side, and the output's scale, skew and
/// rotation. The geometry is an OBJ file whose faces are the display's facets; each must be a
/// flat convex polygon, and loading says which one is not.
///
/// Cave files calibrate hardware, so they are all or nothing: any error rejects the file, and
/// the settings in force stay as they were.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/formats/text.h"
#include "runtime/math.h"

namespace basalt::formats {

/// \brief The settings of a cave file, with the thesis' defaults.
struct CaveSettings {
  std::string model;        ///< `model file.obj` as written (relative to the cave file's folder)
  std::uint32_t facet = 0;  ///< `facet[n]`: the facet this node shows
  std::uint32_t side = 0;   ///< `side[n]`: which side of the facet is at the bottom (0 = its longest side)
  float xScale = 1.0f;      ///< `Xscale[f]`: horizontal field-of-view scale
  float yScale = 1.0f;      ///< `Yscale[f]`
  float xSkew = 0.0f;       ///< `Xskew[f]`: degrees of horizontal skew
  float ySkew = 0.0f;       ///< `Yskew[f]`
  float zRotation = 0.0f;   ///< `Zrotation[f]`: degrees about the line of sight
  friend bool operator==(const CaveSettings&, const CaveSettings&) = default;
};

/// \brief One facet of the display: a flat convex polygon (validated on load).
struct CaveFacet {
  std::vector<Vec3> corners;  ///< in the file's order (counter-clockwise seen from its front)
  Vec3 normal{0, 0, 1};       ///< unit normal; the facet's front faces along it
  float planeOffset = 0;      ///< the facet's plane: dot(normal, p) == planeOffset
  float area = 0;
  std::uint32_t longestSide = 0;  ///< side i runs from corner i to corner i+1
  bool facesInward = true;        ///< its front faces the inside of the display (as the thesis wants)
  /// The thesis' default viewer, the geometry's origin (§4.4.3), is in front of its plane, so it
  /// sees the facet's front (§4.2.1): only then does a view of the facet draw anything.
  bool facesViewer = true;
  std::uint32_t line = 0;  ///< its `f` line in the geometry file
};

/// \brief A display's geometry: the facets in file order (facet 0 is the first `f`).
struct CaveGeometry {
  std::filesystem::path path;
  std::vector<CaveFacet> facets;
  Vec3 center{0, 0, 0};  ///< mean of the facets' corners: inside a convex display
};

/// \brief A cave as the latest cave file left it.
struct LoadedCave {
  std::filesystem::path path;  ///< the cave file read last
  CaveSettings settings;
  std::shared_ptr<const CaveGeometry> geometry;  ///< null until a cave file names a model
  std::vector<Diagnostic> warnings;
};

/// \brief How far in front of a facet's plane (cave units) the viewer must be to see it: the
/// facet projection's own test (runtime/facet_projection.cpp).
inline constexpr float kCaveViewerClearance = 1e-6f;

/// \brief How a display geometry's facets are wound, as a facet view says (`winding` in a
/// manifest's `[[views]]`).
enum class FacetWinding : std::uint8_t {
  kInward,   ///< as the thesis wants (§4.4.1): every facet used as written
  kOutward,  ///< the usual export of modelling tools: every facet is turned round
  kAuto,     ///< each facet whose front the viewer cannot see is turned round
};

/// \brief The geometry with its facets turned as `winding` says: a turned facet has its corners
/// in the reverse order, so its normal, plane, longest side and facing are those of the same
/// polygon wound the other way (turning a reversed copy of a file gives back the file's facets).
[[nodiscard]] CaveGeometry windFacets(const CaveGeometry& geometry, FacetWinding winding);

/// \brief What is wrong with the way `geometry`'s facets face the viewer once `winding` is
/// applied, as one warning for the whole geometry (it names the facets and their `f` lines and
/// says how to fix it), or nothing when every facet's front faces the viewer.
[[nodiscard]] std::optional<Diagnostic> caveFacingProblem(const CaveGeometry& geometry, FacetWinding winding);

/// \brief Tolerance of the flatness check: corners may be this fraction of the facet's size
/// off its plane.
inline constexpr float kCavePlanarTolerance = 1e-3f;

/// \brief Parses cave-file text over `start` (the settings in force). `modelKnown` says whether
/// a model was named before (Zrotation needs one). `modelLine` gets the line of a `model`
/// statement, `facetLine`/`sideLine` those of facet and side (0 when absent).
struct CaveParse {
  CaveSettings settings;
  bool modelGiven = false;
  std::uint32_t modelLine = 0, facetLine = 0, sideLine = 0;
};
[[nodiscard]] Result<CaveParse> parseCaveText(std::string_view text, const std::string& name, CaveSettings start,
                                              bool modelKnown);

/// \brief Reads the facets of a cave geometry OBJ (only `v` and `f` are used, as the thesis
/// says) and validates each: at least 3 corners, an area, flat within kCavePlanarTolerance,
/// convex. The error names the facet, its line and what is wrong.
[[nodiscard]] Result<CaveGeometry> parseCaveGeometry(std::string_view text, const std::string& name,
                                                     const LoadOptions& options, std::vector<Diagnostic>& warnings);
[[nodiscard]] Result<CaveGeometry> loadCaveGeometry(const std::filesystem::path& path, const LoadOptions& options,
                                                    std::vector<Diagnostic>& warnings);

/// \brief Reads a cave file over `previous` (cave files may be read in succession: each changes
/// what it names). A named model is loaded and validated; the facet and side must exist on it.
[[nodiscard]] Result<LoadedCave> loadCave(const std::filesystem::path& path, const LoadedCave* previous = nullptr,
                                          const LoadOptions& options = {});

/// \brief Why `settings` do not fit `geometry` (a facet or a side that does not exist), or
/// nothing when they do. `sideWrong`, when given, says whether it is the side (else the facet).
/// What loading a cave file and calibrating a view live both check.
std::optional<std::string> caveSettingsProblem(const CaveSettings& settings, const CaveGeometry& geometry,
                                               bool* sideWrong = nullptr);

/// \brief Cave-file text for `settings` (every setting, in the thesis' bracket form).
std::string formatCave(const CaveSettings& settings);
[[nodiscard]] Result<void> writeCave(const std::filesystem::path& path, const CaveSettings& settings);

}  // namespace basalt::formats
