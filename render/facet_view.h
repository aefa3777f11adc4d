#pragma once

/// \file
/// \brief Facet views (thesis §4.4): the show seen through one facet of a polyhedral display,
/// with everything outside the facet black (the border approach of §4.4.5), in mono or in any
/// stereo layout; and the stereo layouts for plain views. The projection math is
/// `runtime/facet_projection.h`; this file draws it.

#include <array>
#include <functional>
#include <memory>
#include <span>

#include "render/renderer.h"
#include "runtime/facet_projection.h"

namespace basalt::render {

/// \brief The two eyes' viewports of a stereo layout: side by side (left eye left), top and
/// bottom (left eye on top), or both the whole viewport (anaglyph).
std::array<Viewport, 2> stereoViewports(const Viewport& viewport, runtime::StereoMode mode);

/// \brief Blackens every pixel of a viewport outside a convex polygon given in normalised
/// device coordinates (at most kMaxCorners corners, either winding).
class BorderMask {
 public:
  static constexpr std::size_t kMaxCorners = 64;
  [[nodiscard]] static Result<std::unique_ptr<BorderMask>> create();
  ~BorderMask();
  BorderMask(const BorderMask&) = delete;
  BorderMask& operator=(const BorderMask&) = delete;

  /// \brief Draws the black border into the channels `colorMask` allows (an anaglyph eye's); a
  /// polygon with fewer than 3 corners blackens the viewport. With `within` (window pixels) only
  /// that part of the viewport is covered: the caller knows the rest is black already.
  void draw(std::span<const Vec2> polygon, const Viewport& viewport,
            const std::array<bool, 3>& colorMask = {true, true, true}, const Viewport& within = {});

 private:
  struct Gpu;
  BorderMask();
  std::unique_ptr<Gpu> gpu_;
};

/// \brief How one facet view is drawn this frame.
struct FacetPass {
  const formats::CaveFacet* facet = nullptr;
  runtime::FacetViewInput input;  ///< viewer = the head (between the eyes); aspect is set here
  Viewport viewport;
  bool stereo = false;
  runtime::StereoMode stereoMode = runtime::StereoMode::kAnaglyph;
  float eyeSpacing = 0.0f;  ///< distance between the eyes, in cave units, along the view's right
  /// The head's right vector (cave axes, unit), along which the eyes sit: a tracked head's. Zero:
  /// the view's right, as the thesis places the eyes for a viewer who faces each facet.
  Vec3 eyeAxis;
};

/// \brief Draws facet views: each a Renderer::draw with the facet's view and projection, then
/// the border. Owns the border program; reuses its projections' storage, so a steady show
/// allocates nothing.
///
/// Threading: the GL thread, like the Renderer.
class FacetRenderer {
 public:
  [[nodiscard]] static Result<std::unique_ptr<FacetRenderer>> create();
  ~FacetRenderer();
  FacetRenderer(const FacetRenderer&) = delete;
  FacetRenderer& operator=(const FacetRenderer&) = delete;

  /// \brief Draws `show` through the pass's facet. `adjust` may change each eye's view before
  /// it is drawn (a script's jitter). A degenerate facet or a viewer behind it leaves a black
  /// viewport (the error comes back once, for the caller to report).
  Result<void> draw(Renderer& renderer, const runtime::Show& show, const FacetPass& pass,
                    const std::function<void(runtime::ViewTransforms&)>& adjust = {});

  /// \brief The projection of the last draw's head position (for the visual aids and tests).
  [[nodiscard]] const runtime::FacetProjection& lastProjection() const { return head_; }

 private:
  FacetRenderer() = default;
  std::unique_ptr<BorderMask> mask_;
  runtime::FacetProjection head_;
  std::array<runtime::FacetProjection, 2> eyes_;
};

}  // namespace basalt::render
