#pragma once

/// \file
/// \brief The per-view uniform block (private to render/): the std140 mirror of `Frame` in
/// shaders/common.glsl, filled from a Show and a view once per Renderer::draw().

#include <cstdint>

#include "runtime/show/show.h"

namespace basalt::render {

struct FrameBlock {
  float viewProjection[16];
  float view[16];
  float eye[4];
  float viewport[4];
  float depth[4];
  float depthCue[4];
  float depthCueScale[4];
  float depthCueColor[4];
  float fog[4];
  float fogColor[4];
  float background[4];
  std::int32_t counts[4];
  float lightColor[32][4];
  float lightPosition[32][4];
  float lightDirection[32][4];
  float lightSpot[32][4];
  float lightAmbient[32][4];
  float lightSpecular[32][4];
  float clipPlane[16][4];
};
static_assert(sizeof(FrameBlock) == 2 * 64 + 10 * 16 + 6 * 32 * 16 + 16 * 16, "std140 layout of Frame");

/// \brief Near and far eye-space depths of a perspective or orthographic projection matrix.
struct DepthRange {
  float zNear = 0.1f;
  float zFar = 100.0f;
};
DepthRange depthRangeOf(const Mat4& projection);

/// \brief Fills the block for one view. Lights and fog in scene units are carried into the
/// renderer's world through `view.model` (positions and directions moved with it, distances
/// scaled by its scale), so that they keep the meaning the scene gave them. `viewProjection` includes any jitter;
/// `viewport` is x, y, width, height in pixels.
void fillFrameBlock(FrameBlock& block, const runtime::Show& show, const runtime::ViewTransforms& view,
                    const Mat4& viewProjection, const float (&viewport)[4]);

}  // namespace basalt::render
