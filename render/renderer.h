#pragma once

/// \file
/// \brief Draws a Show with OpenGL ES 3: LAVA's per-part attributes under the XGL lights.

#include <cstdint>
#include <memory>
#include <unordered_map>

#include "render/gl.h"
#include "render/output.h"
#include "render/texture_registry.h"
#include "runtime/error.h"
#include "runtime/show/show.h"

namespace basalt::render {

/// \brief What one draw() drew (LAVA's performance meter counts, §9).
struct DrawCounts {
  std::uint64_t triangles = 0;
  std::uint64_t lines = 0;
  std::uint64_t points = 0;
  std::uint64_t parts = 0;
  std::uint64_t facets = 0;
  std::uint64_t drawCalls = 0;
};

/// \brief Draws Shows into the bound framebuffer.
///
/// Threading: created, used and destroyed on the thread whose EGL context is current; GPU
/// buffers for a mesh are made the first time the mesh is drawn and kept while it lives, so
/// drawing an unchanged show allocates nothing.
class Renderer {
 public:
  /// \brief Compiles the shaders; needs a current OpenGL ES 3 context.
  static Result<std::unique_ptr<Renderer>> create();
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  /// \brief Clears to the show's background and draws every selected part of every node,
  /// seen through `view`, into a viewport of `viewport` pixels.
  void draw(const runtime::Show& show, const runtime::ViewTransforms& view, Size viewport);
  [[nodiscard]] const DrawCounts& lastCounts() const { return counts_; }
  /// \brief The textures parts can name (image files and streams).
  TextureRegistry& textures() { return textures_; }

 private:
  struct GpuMesh;
  struct LitUniforms;
  struct ColorUniforms;
  Renderer();
  GpuMesh& upload(const std::shared_ptr<const runtime::Mesh>& mesh);
  void drawNode(const runtime::Show& show, const runtime::SceneNode& node, const Mat4& model,
                const runtime::ViewTransforms& view);
  void setLights(const runtime::Show& show);
  void sweepMeshCache();

  gl::Program lit_;
  gl::Program color_;
  std::unique_ptr<LitUniforms> litUniforms_;
  std::unique_ptr<ColorUniforms> colorUniforms_;
  std::unordered_map<std::uint64_t, std::unique_ptr<GpuMesh>> meshes_;
  std::uint64_t framesSinceSweep_ = 0;
  DrawCounts counts_;
  TextureRegistry textures_;
};

}  // namespace basalt::render
