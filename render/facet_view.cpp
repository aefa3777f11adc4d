#include "render/facet_view.h"

#include <GLES3/gl3.h>

#include "embedded/render_shaders.h"
#include "render/gl.h"

namespace basalt::render {

std::array<Viewport, 2> stereoViewports(const Viewport& v, runtime::StereoMode mode) {
  switch (mode) {
    case runtime::StereoMode::kSideBySide: {
      const std::uint32_t left = v.width / 2;
      return {Viewport{v.x, v.y, left, v.height},
              Viewport{v.x + static_cast<std::int32_t>(left), v.y, v.width - left, v.height}};
    }
    case runtime::StereoMode::kTopBottom: {
      const std::uint32_t bottom = v.height / 2;
      // GL's y runs up: the top half (the left eye) starts at y + bottom.
      return {Viewport{v.x, v.y + static_cast<std::int32_t>(bottom), v.width, v.height - bottom},
              Viewport{v.x, v.y, v.width, bottom}};
    }
    case runtime::StereoMode::kAnaglyph: break;
  }
  return {v, v};
}

struct BorderMask::Gpu {
  gl::Program program;
  gl::VertexArray vao;
  GLint rect = -1, viewportRect = -1, edges = -1, edgeCount = -1;
  std::array<float, kMaxCorners * 3> edgeValues{};
};

BorderMask::BorderMask() = default;
BorderMask::~BorderMask() = default;

Result<std::unique_ptr<BorderMask>> BorderMask::create() {
  auto program = gl::buildProgram(shaders::kQuadVert, shaders::kBorderFrag, "facet border");
  if (!program) return std::unexpected(program.error());
  std::unique_ptr<BorderMask> mask(new BorderMask);
  mask->gpu_ = std::make_unique<Gpu>();
  Gpu& g = *mask->gpu_;
  g.program = std::move(*program);
  g.vao = gl::VertexArray::create();
  const GLuint p = g.program.id();
  g.rect = glGetUniformLocation(p, "uRect");
  g.viewportRect = glGetUniformLocation(p, "uViewportRect");
  g.edges = glGetUniformLocation(p, "uEdges");
  g.edgeCount = glGetUniformLocation(p, "uEdgeCount");
  return mask;
}

void BorderMask::draw(std::span<const Vec2> polygon, const Viewport& viewport, const std::array<bool, 3>& colorMask) {
  if (viewport.width == 0 || viewport.height == 0) return;
  Gpu& g = *gpu_;
  const std::size_t n = polygon.size() >= 3 && polygon.size() <= kMaxCorners ? polygon.size() : 0;
  // Signed area: the half-planes face the inside whichever way the outline runs (the rear
  // projection flip reverses it).
  float area = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2& a = polygon[i];
    const Vec2& b = polygon[(i + 1) % n];
    area += a.x * b.y - b.x * a.y;
  }
  const float sign = area >= 0 ? 1.0f : -1.0f;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2& a = polygon[i];
    const Vec2& b = polygon[(i + 1) % n];
    // Inside is to the left of a->b for a counter-clockwise outline: -(b-a).y x + (b-a).x y + c.
    const float nx = -(b.y - a.y) * sign, ny = (b.x - a.x) * sign;
    g.edgeValues[i * 3] = nx;
    g.edgeValues[i * 3 + 1] = ny;
    g.edgeValues[i * 3 + 2] = -(nx * a.x + ny * a.y);
  }
  // No outline (degenerate): one half-plane nothing satisfies, so the whole viewport goes black.
  GLint count = static_cast<GLint>(n);
  if (n == 0) {
    g.edgeValues[0] = 0, g.edgeValues[1] = 0, g.edgeValues[2] = -1;
    count = 1;
  }
  glViewport(viewport.x, viewport.y, static_cast<GLsizei>(viewport.width), static_cast<GLsizei>(viewport.height));
  glEnable(GL_SCISSOR_TEST);
  glScissor(viewport.x, viewport.y, static_cast<GLsizei>(viewport.width), static_cast<GLsizei>(viewport.height));
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  glDisable(GL_STENCIL_TEST);
  glColorMask(colorMask[0] ? GL_TRUE : GL_FALSE, colorMask[1] ? GL_TRUE : GL_FALSE, colorMask[2] ? GL_TRUE : GL_FALSE,
              GL_FALSE);
  glUseProgram(g.program.id());
  glUniform4f(g.rect, -1, -1, 1, 1);
  glUniform4f(g.viewportRect, static_cast<float>(viewport.x), static_cast<float>(viewport.y),
              static_cast<float>(viewport.width), static_cast<float>(viewport.height));
  glUniform3fv(g.edges, count, g.edgeValues.data());
  glUniform1i(g.edgeCount, count);
  glBindVertexArray(g.vao.id());
  glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
  glBindVertexArray(0);
  glUseProgram(0);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glDisable(GL_SCISSOR_TEST);
}

FacetRenderer::~FacetRenderer() = default;

Result<std::unique_ptr<FacetRenderer>> FacetRenderer::create() {
  auto mask = BorderMask::create();
  if (!mask) return std::unexpected(mask.error());
  std::unique_ptr<FacetRenderer> r(new FacetRenderer);
  r->mask_ = std::move(*mask);
  return r;
}

Result<void> FacetRenderer::draw(Renderer& renderer, const runtime::Show& show, const FacetPass& pass,
                                 const std::function<void(runtime::ViewTransforms&)>& adjust) {
  const Viewport& vp = pass.viewport;
  if (vp.width == 0 || vp.height == 0 || pass.facet == nullptr) return {};
  runtime::FacetViewInput input = pass.input;
  input.aspect = static_cast<float>(vp.width) / static_cast<float>(vp.height);
  auto head = runtime::computeFacetView(*pass.facet, input, head_);
  if (!head || !head_.visible) {
    mask_->draw({}, vp);
    if (!head) return std::unexpected(head.error());
    return {};
  }
  const Mat4 model = show.position().global * show.position().local * runtime::viewNormalisation(show);
  auto drawEye = [&](const runtime::FacetProjection& p, const ViewPass& viewPass) {
    runtime::ViewTransforms t{model, p.view, p.projection, p.eye};
    if (adjust) adjust(t);
    renderer.draw(show, t, viewPass);
    mask_->draw(p.border, viewPass.viewport, viewPass.colorMask);
  };
  if (!pass.stereo) {
    ViewPass viewPass;
    viewPass.viewport = vp;
    drawEye(head_, viewPass);
    return {};
  }
  // Thesis §4.4.3: for stereo the viewer position is offset for each eye, along the view's right.
  const std::array<Viewport, 2> eyeViewports = stereoViewports(vp, pass.stereoMode);
  for (std::size_t eye = 0; eye < 2; ++eye) {
    runtime::FacetViewInput eyeInput = input;
    const float offset = (eye == 0 ? -0.5f : 0.5f) * pass.eyeSpacing;
    eyeInput.viewer = input.viewer + head_.right * offset;
    auto r = runtime::computeFacetView(*pass.facet, eyeInput, eyes_[eye]);
    ViewPass viewPass;
    viewPass.viewport = eyeViewports[eye];
    if (pass.stereoMode == runtime::StereoMode::kAnaglyph) {
      viewPass.colorMask = eye == 0 ? std::array<bool, 3>{true, false, false} : std::array<bool, 3>{false, true, true};
      viewPass.drawBackground = eye == 0;
    }
    if (!r || !eyes_[eye].visible) {
      mask_->draw({}, viewPass.viewport, viewPass.colorMask);
      continue;
    }
    drawEye(eyes_[eye], viewPass);
  }
  return {};
}

}  // namespace basalt::render
