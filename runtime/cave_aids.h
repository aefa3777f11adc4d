#pragma once

/// \file
/// \brief The thesis' visual aids (§4.4.6): the display geometry seen from outside, for checking
/// a set-up. Draws the geometry as a wireframe, the current facet filled, the facet's inward
/// normal, a cone for the viewer looking along its line of sight, and the vectors of the
/// thesis' update method (the collision point on the facet plane, the line of sight to it, and
/// the viewport's up and right on the facet). Pure geometry: the aids are a Show of their own
/// that the renderer draws over the world, seen from a camera outside the display.

#include <memory>

#include "runtime/error.h"
#include "runtime/facet_projection.h"
#include "runtime/formats/cave.h"
#include "runtime/math.h"
#include "runtime/show/show.h"

namespace basalt::runtime {

/// \brief The aids of one display geometry, built once and moved each frame.
///
/// The Show's nodes are in cave coordinates: draw it with `worldFromCave` as the view's model.
/// Node and part names, for tests and for a script that wants to restyle them: "cave" (the
/// wireframe, part "cave"), "facets" (one filled part per facet, "facet N", only the current one
/// displayed), "normal", "viewer", "line of sight", "up", "right" and "collision" (a marker).
/// update() changes node transforms and part selection only, so a steady show allocates nothing.
class CaveAids {
 public:
  /// \brief Builds the aids' geometry for `geometry` (which must have at least one facet).
  [[nodiscard]] static Result<CaveAids> create(std::shared_ptr<const formats::CaveGeometry> geometry);

  /// \brief Places the aids for facet `facet` as `projection` (computed for that facet, viewer
  /// at `viewer` in cave coordinates) sees it. An invisible projection (the viewer behind the
  /// facet) hides the vectors and keeps the facet, its normal and the viewer.
  void update(std::uint32_t facet, const FacetProjection& projection, const Vec3& viewer);

  /// \brief What to draw: every aid as a part of this Show.
  [[nodiscard]] const Show& show() const { return show_; }
  [[nodiscard]] std::uint32_t currentFacet() const { return current_; }
  /// \brief The radius of the sphere around the geometry's centre that holds every corner.
  [[nodiscard]] float radius() const { return radius_; }
  [[nodiscard]] const formats::CaveGeometry& geometry() const { return *geometry_; }

  /// \brief A camera outside the display: from the geometry's centre `from` (a direction in
  /// cave coordinates) far enough that the whole geometry fits the view at `aspect` (width /
  /// height), looking at the centre with cave +Y up. `model` is left at the identity; the
  /// caller sets it (the show's model for the world, `worldFromCave` for the aids).
  [[nodiscard]] ViewTransforms outsideView(const Mat4& worldFromCave, const Vec3& from, float aspect) const;

  /// \brief The default direction the outside camera looks from: front, right and above.
  static constexpr Vec3 kDefaultFrom{1.0f, 0.8f, 1.6f};

 private:
  CaveAids() = default;

  std::shared_ptr<const formats::CaveGeometry> geometry_;
  Show show_;
  float radius_ = 1.0f;
  std::uint32_t current_ = 0;
  std::vector<PartId> facetParts_;
  NodeId normal_ = 0, viewer_ = 0, sight_ = 0, up_ = 0, right_ = 0, collision_ = 0;
};

}  // namespace basalt::runtime
