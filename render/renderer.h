#pragma once

/// \file
/// \brief Draws a Show with OpenGL ES 3: LAVA's per-part attributes under the XGL lights, with
/// depth cue, fog, model clipping, backgrounds, the floor and its shadow, textures, anaglyph
/// stereo and jittered snapshots.

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "render/gl.h"
#include "render/output.h"
#include "render/texture_registry.h"
#include "runtime/error.h"
#include "runtime/image.h"
#include "runtime/show/show.h"

namespace basalt::render {

/// \brief What draw() drew (LAVA's performance meter counts, §9), plus the draw calls.
struct DrawCounts {
  std::uint64_t triangles = 0;
  std::uint64_t lines = 0;
  std::uint64_t points = 0;
  std::uint64_t parts = 0;
  std::uint64_t facets = 0;
  std::uint64_t drawCalls = 0;
};

/// \brief A rectangle of the bound framebuffer, in pixels from its lower-left corner.
struct Viewport {
  std::int32_t x = 0;
  std::int32_t y = 0;
  std::uint32_t width = 0;
  std::uint32_t height = 0;
};

/// \brief How one view is drawn into the framebuffer. Several views may share a frame (facets,
/// stereo eyes): each brings its own viewport, masks and jitter; nothing carries over between
/// them but what is in the framebuffer.
struct ViewPass {
  Viewport viewport;
  bool drawBackground = true;  ///< clear to the background (colour, image, skybox or earth-sky)
  bool clearDepth = true;      ///< start with an empty depth (and stencil) buffer
  /// Which colour channels the scene writes (the background is always drawn in full):
  /// the anaglyph's left eye writes red only, the right eye green and blue.
  std::array<bool, 3> colorMask{true, true, true};
  Vec2 jitter{0, 0};  ///< sub-pixel offset of the whole view, in pixels (stochastic passes)
  /// Where in the viewport the view may draw, in window pixels (a facet's bounding box: the
  /// border covers the rest); empty: the whole viewport. The clears still cover the whole
  /// viewport, so outside it the view leaves the background's clear colour (Renderer::clearColor).
  Viewport scissor;
};

/// \brief What the renderer found out about the GL it runs on.
struct RendererCapabilities {
  bool framebufferFetch = false;  ///< GL_EXT_shader_framebuffer_fetch: exact raster operations
  bool stencil = false;           ///< a stencil buffer for the fake shadow
  float maxPointSize = 1;
  std::string description;  ///< GL_RENDERER, GL_VERSION
};

struct RendererOptions {
  /// Use framebuffer fetch for raster operations where the GL offers it (tests turn it off to
  /// exercise the copy path).
  bool allowFramebufferFetch = true;
};

/// \brief Draws Shows into the bound framebuffer.
///
/// Threading: created, used and destroyed on the thread whose EGL context is current. GPU
/// buffers for a mesh and shader variants are made the first time they are needed and kept, so
/// drawing an unchanged show allocates nothing.
class Renderer {
 public:
  /// \brief Compiles the shaders; needs a current OpenGL ES 3 context, with the framebuffer it
  /// will draw into bound (its stencil buffer, if any, is what the fake shadow uses).
  static Result<std::unique_ptr<Renderer>> create(const RendererOptions& options = {});
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  /// \brief Clears to the show's background and draws every selected part of every node,
  /// seen through `view`, into a viewport of `viewport` pixels at the origin.
  void draw(const runtime::Show& show, const runtime::ViewTransforms& view, Size viewport);
  /// \brief Draws one view as `pass` says.
  void draw(const runtime::Show& show, const runtime::ViewTransforms& view, const ViewPass& pass);
  /// \brief The show as its settings ask: LAVA's view fitted to the viewport or a scene seen
  /// from its own camera (runtime::computeView), in the scene's own viewport rectangle within
  /// `viewport` when it gives one (the rest of the viewport is cleared to the background), in
  /// stereo when `global().stereo` is on. What the frame loop calls. `adjust`, when given, may
  /// change each computed view before it is drawn (a script's sub-pixel jitter).
  void drawShow(const runtime::Show& show, const Viewport& viewport,
                const std::function<void(runtime::ViewTransforms&)>& adjust = {});
  /// \brief Thesis §5.1 anaglyph: the background once, then the scene for the left eye in red
  /// and for the right eye in green and blue.
  void drawAnaglyph(const runtime::Show& show, const runtime::ViewTransforms& left,
                    const runtime::ViewTransforms& right, const Viewport& viewport);
  /// \brief LAVA's "Stochastic" snapshot (§6.2.1): the show drawn `passes` times (at most 8)
  /// with LAVA's sub-pixel jitter offsets and averaged into `out` (RGBA8, top row first).
  [[nodiscard]] Result<void> drawStochastic(const runtime::Show& show, const Viewport& viewport, Image& out,
                                            int passes = 8);

  /// \brief Counts of the last draw() (one view).
  [[nodiscard]] const DrawCounts& lastCounts() const { return counts_; }
  /// \brief Counts summed over every draw since the last call (one frame, all its views), for
  /// the performance meter.
  runtime::FrameCounts takeFrameCounts();
  /// \brief How many meshes have GPU buffers now: one per distinct Mesh drawn lately, however
  /// many nodes instance it (what the instancing tests and the status figures read).
  [[nodiscard]] std::size_t gpuMeshCount() const;
  /// \brief The textures parts can name (image files and streams).
  TextureRegistry& textures() { return textures_; }
  [[nodiscard]] const RendererCapabilities& capabilities() const { return caps_; }

  /// \brief LAVA's eight jitter offsets, in pixels (-0.5..0.5), in the order passes use them.
  static const std::array<Vec2, 8>& jitterOffsets();
  /// \brief The colour a view of `show` is cleared to before anything is drawn: the background
  /// colour, or the earth-sky's clear colour when it only clears.
  [[nodiscard]] static runtime::Color3 clearColor(const runtime::Show& show);

 private:
  struct Impl;
  Renderer();
  std::unique_ptr<Impl> impl_;
  DrawCounts counts_;
  runtime::FrameCounts frameCounts_;
  RendererCapabilities caps_;
  TextureRegistry textures_;
};

}  // namespace basalt::render
