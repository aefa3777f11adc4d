#include "render/facet_view.h"

#include <GLES3/gl3.h>

#include <algorithm>
#include <cmath>

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

namespace {

/// One half-plane a x + b y + c >= 0 (inside the facet), in normalised device coordinates.
struct HalfPlane {
  float a = 0, b = 0, c = 0;
  [[nodiscard]] float at(const Vec2& p) const { return a * p.x + b * p.y + c; }
};

/// The piece of the rectangle `box` (x0, y0, x1, y1 in normalised device coordinates) outside
/// one half-plane (where it is below zero), clipped by Sutherland and Hodgman's rule: the four
/// corners give at most five.
std::size_t outsidePiece(const HalfPlane& h, const std::array<float, 4>& box, std::array<Vec2, 5>& piece) {
  const std::array<Vec2, 4> corners = {Vec2{box[0], box[1]}, Vec2{box[2], box[1]}, Vec2{box[2], box[3]},
                                       Vec2{box[0], box[3]}};
  std::size_t n = 0;
  for (std::size_t i = 0; i < corners.size(); ++i) {
    const Vec2& p = corners[i];
    const Vec2& q = corners[(i + 1) % corners.size()];
    const float hp = h.at(p), hq = h.at(q);
    if (hp <= 0) piece[n++] = p;
    if ((hp < 0 && hq > 0) || (hp > 0 && hq < 0)) {
      const float t = hp / (hp - hq);
      piece[n++] = Vec2{p.x + (q.x - p.x) * t, p.y + (q.y - p.y) * t};
    }
  }
  return n;
}

/// The pixels of `viewport` a convex outline (in normalised device coordinates) can touch, a
/// pixel wider on each side than its bounding box; an outline that is not one: the viewport.
Viewport outlineBounds(std::span<const Vec2> outline, const Viewport& viewport) {
  if (outline.size() < 3) return viewport;
  float x0 = 1, y0 = 1, x1 = -1, y1 = -1;
  for (const Vec2& p : outline) {
    x0 = std::min(x0, p.x), y0 = std::min(y0, p.y);
    x1 = std::max(x1, p.x), y1 = std::max(y1, p.y);
  }
  x0 = std::max(x0, -1.0f), y0 = std::max(y0, -1.0f);
  x1 = std::min(x1, 1.0f), y1 = std::min(y1, 1.0f);
  if (x1 <= x0 || y1 <= y0) return {viewport.x, viewport.y, 1, 1};
  const auto w = static_cast<float>(viewport.width), h = static_cast<float>(viewport.height);
  const auto left = static_cast<std::int64_t>(std::floor((x0 + 1) * 0.5f * w)) - 1;
  const auto bottom = static_cast<std::int64_t>(std::floor((y0 + 1) * 0.5f * h)) - 1;
  const auto right = static_cast<std::int64_t>(std::ceil((x1 + 1) * 0.5f * w)) + 1;
  const auto top = static_cast<std::int64_t>(std::ceil((y1 + 1) * 0.5f * h)) + 1;
  const std::int64_t cl = std::clamp<std::int64_t>(left, 0, viewport.width);
  const std::int64_t cb = std::clamp<std::int64_t>(bottom, 0, viewport.height);
  const std::int64_t cr = std::clamp<std::int64_t>(right, cl, viewport.width);
  const std::int64_t ct = std::clamp<std::int64_t>(top, cb, viewport.height);
  return {viewport.x + static_cast<std::int32_t>(cl), viewport.y + static_cast<std::int32_t>(cb),
          static_cast<std::uint32_t>(cr - cl), static_cast<std::uint32_t>(ct - cb)};
}

/// The smallest rectangle holding both.
Viewport boundsUnion(const Viewport& a, const Viewport& b) {
  if (a.width == 0 || a.height == 0) return b;
  if (b.width == 0 || b.height == 0) return a;
  const std::int64_t x0 = std::min(a.x, b.x), y0 = std::min(a.y, b.y);
  const std::int64_t x1 = std::max(std::int64_t{a.x} + a.width, std::int64_t{b.x} + b.width);
  const std::int64_t y1 = std::max(std::int64_t{a.y} + a.height, std::int64_t{b.y} + b.height);
  return {static_cast<std::int32_t>(x0), static_cast<std::int32_t>(y0), static_cast<std::uint32_t>(x1 - x0),
          static_cast<std::uint32_t>(y1 - y0)};
}

}  // namespace

struct BorderMask::Gpu {
  gl::Program program;
  gl::VertexArray vao;
  gl::Buffer vertices;
  /// Up to three triangles a half-plane, two floats a corner.
  static constexpr std::size_t kMaxFloats = kMaxCorners * 9 * 2;
  std::array<float, kMaxFloats> values{};
};

BorderMask::BorderMask() = default;
BorderMask::~BorderMask() = default;

Result<std::unique_ptr<BorderMask>> BorderMask::create() {
  auto program = gl::buildProgram(shaders::kBorderVert, shaders::kBorderFrag, "facet border");
  if (!program) return std::unexpected(program.error());
  std::unique_ptr<BorderMask> mask(new BorderMask);
  mask->gpu_ = std::make_unique<Gpu>();
  Gpu& g = *mask->gpu_;
  g.program = std::move(*program);
  g.vao = gl::VertexArray::create();
  g.vertices = gl::Buffer::create();
  glBindVertexArray(g.vao.id());
  glBindBuffer(GL_ARRAY_BUFFER, g.vertices.id());
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(sizeof(g.values)), nullptr, GL_STREAM_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 0, nullptr);
  glBindVertexArray(0);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  return mask;
}

void BorderMask::draw(std::span<const Vec2> polygon, const Viewport& viewport, const std::array<bool, 3>& colorMask,
                      const Viewport& within) {
  if (viewport.width == 0 || viewport.height == 0) return;
  // The rectangle the pieces cover, in normalised device coordinates: the viewport, or the part
  // of it the caller says is not black yet.
  std::array<float, 4> box = {-1, -1, 1, 1};
  if (within.width > 0 && within.height > 0) {
    const auto w = static_cast<float>(viewport.width), h = static_cast<float>(viewport.height);
    box = {
        std::max(-1.0f, static_cast<float>(within.x - viewport.x) / w * 2 - 1),
        std::max(-1.0f, static_cast<float>(within.y - viewport.y) / h * 2 - 1),
        std::min(1.0f, static_cast<float>(within.x - viewport.x + static_cast<std::int64_t>(within.width)) / w * 2 - 1),
        std::min(1.0f,
                 static_cast<float>(within.y - viewport.y + static_cast<std::int64_t>(within.height)) / h * 2 - 1)};
  }
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
  // The border is the union of the pieces of the viewport outside each edge's half-plane: drawn
  // as triangles, it costs only the border's pixels (a full-viewport pass testing every pixel
  // against every edge cost more than the scene itself on a software GL). The pieces overlap
  // near the corners, so no pixel outside the outline can fall between two of them.
  const float onEdge = 0.125f / static_cast<float>(std::max(viewport.width, viewport.height));
  std::size_t floats = 0;
  const auto addPiece = [&g, &floats, &box](const HalfPlane& h) {
    std::array<Vec2, 5> piece{};
    const std::size_t corners = outsidePiece(h, box, piece);
    for (std::size_t k = 1; k + 1 < corners; ++k) {
      for (const Vec2& p : {piece[0], piece[k], piece[k + 1]}) {
        g.values[floats++] = p.x;
        g.values[floats++] = p.y;
      }
    }
  };
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2& a = polygon[i];
    const Vec2& b = polygon[(i + 1) % n];
    // Inside is to the left of a->b for a counter-clockwise outline: -(b-a).y x + (b-a).x y + c.
    // A pixel whose centre lies on the outline belongs to the facet: each piece starts a
    // sixteenth of a pixel beyond the edge (finer than the rasteriser's snapping can tell).
    const float nx = -(b.y - a.y) * sign, ny = (b.x - a.x) * sign;
    addPiece(HalfPlane{nx, ny, -(nx * a.x + ny * a.y) + onEdge * std::hypot(nx, ny)});
  }
  // No outline (degenerate): one half-plane nothing satisfies, so the whole viewport goes black.
  if (n == 0) addPiece(HalfPlane{0, 0, -1});
  if (floats == 0) return;  // the outline covers the whole viewport
  glViewport(viewport.x, viewport.y, static_cast<GLsizei>(viewport.width), static_cast<GLsizei>(viewport.height));
  glEnable(GL_SCISSOR_TEST);
  glScissor(viewport.x, viewport.y, static_cast<GLsizei>(viewport.width), static_cast<GLsizei>(viewport.height));
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  glDisable(GL_STENCIL_TEST);
  // Alpha is written (opaque, as the background leaves it) when every colour is: a masked
  // channel makes a software GL read each pixel back before it writes it.
  const bool all = colorMask[0] && colorMask[1] && colorMask[2];
  glColorMask(colorMask[0] ? GL_TRUE : GL_FALSE, colorMask[1] ? GL_TRUE : GL_FALSE, colorMask[2] ? GL_TRUE : GL_FALSE,
              all ? GL_TRUE : GL_FALSE);
  glUseProgram(g.program.id());
  glBindBuffer(GL_ARRAY_BUFFER, g.vertices.id());
  glBufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(floats * sizeof(float)), g.values.data());
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  glBindVertexArray(g.vao.id());
  glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(floats / 2));
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
  // Outside its scissor a view leaves the clear colour: when that is black, the border need
  // only cover the outline's box (the whole viewport otherwise, and for anaglyph eyes, whose
  // channels share one clear).
  const runtime::Color3 clear = Renderer::clearColor(show);
  const bool clearIsBlack = clear.r <= 0 && clear.g <= 0 && clear.b <= 0;
  auto drawEye = [&](const runtime::FacetProjection& p, const ViewPass& viewPass) {
    runtime::ViewTransforms t{model, p.view, p.projection, p.eye};
    if (adjust) adjust(t);
    renderer.draw(show, t, viewPass);
    const bool boxOnly =
        clearIsBlack && viewPass.drawBackground && !(pass.stereo && pass.stereoMode == runtime::StereoMode::kAnaglyph);
    mask_->draw(p.border, viewPass.viewport, viewPass.colorMask, boxOnly ? viewPass.scissor : Viewport{});
  };
  if (!pass.stereo) {
    ViewPass viewPass;
    viewPass.viewport = vp;
    viewPass.scissor = outlineBounds(head_.border, vp);
    drawEye(head_, viewPass);
    return {};
  }
  // Thesis §4.4.3: for stereo the viewer position is offset for each eye, along the view's right
  // (or a tracked head's right: the eyes are where the head is turned).
  const std::array<Viewport, 2> eyeViewports = stereoViewports(vp, pass.stereoMode);
  std::array<bool, 2> shown{};
  for (std::size_t eye = 0; eye < 2; ++eye) {
    runtime::FacetViewInput eyeInput = input;
    const float offset = (eye == 0 ? -0.5f : 0.5f) * pass.eyeSpacing;
    const Vec3 axis = pass.eyeAxis == Vec3{} ? head_.right : pass.eyeAxis;
    eyeInput.viewer = input.viewer + axis * offset;
    auto r = runtime::computeFacetView(*pass.facet, eyeInput, eyes_[eye]);
    shown[eye] = r && eyes_[eye].visible;
  }
  for (std::size_t eye = 0; eye < 2; ++eye) {
    ViewPass viewPass;
    viewPass.viewport = eyeViewports[eye];
    viewPass.scissor = outlineBounds(eyes_[eye].border, viewPass.viewport);
    if (pass.stereoMode == runtime::StereoMode::kAnaglyph) {
      viewPass.colorMask = eye == 0 ? std::array<bool, 3>{true, false, false} : std::array<bool, 3>{false, true, true};
      viewPass.drawBackground = eye == 0;
      // The left eye clears the background for both: it covers both eyes' outlines.
      if (eye == 0 && shown[1]) {
        viewPass.scissor = shown[0] ? boundsUnion(viewPass.scissor, outlineBounds(eyes_[1].border, vp)) : Viewport{};
      }
    }
    if (!shown[eye]) {
      mask_->draw({}, viewPass.viewport, viewPass.colorMask);
      continue;
    }
    drawEye(eyes_[eye], viewPass);
  }
  return {};
}

}  // namespace basalt::render
