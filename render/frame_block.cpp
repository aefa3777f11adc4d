#include "render/frame_block.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace basalt::render {

using runtime::Show;

DepthRange depthRangeOf(const Mat4& p) {
  DepthRange r;
  const float a = p(2, 2), b = p(2, 3);
  if (std::fabs(p(3, 2) + 1.0f) < 1e-6f && std::fabs(p(3, 3)) < 1e-6f) {
    // Perspective: a = -(f + n) / (f - n), b = -2 f n / (f - n).
    if (std::fabs(a - 1.0f) > 1e-12f && std::fabs(a + 1.0f) > 1e-12f) {
      r.zNear = b / (a - 1.0f);
      r.zFar = b / (a + 1.0f);
    }
  } else if (std::fabs(a) > 1e-12f) {
    // Orthographic: a = -2 / (f - n), b = -(f + n) / (f - n).
    r.zNear = (b + 1.0f) / a;
    r.zFar = (b - 1.0f) / a;
  }
  if (!(r.zFar > r.zNear)) r = DepthRange{};
  return r;
}

namespace {

void put(float (&out)[4], float x, float y, float z, float w) {
  out[0] = x;
  out[1] = y;
  out[2] = z;
  out[3] = w;
}
void put(float (&out)[4], const runtime::Color3& c) { put(out, c.r, c.g, c.b, 1.0f); }

}  // namespace

void fillFrameBlock(FrameBlock& block, const Show& show, const runtime::ViewTransforms& view,
                    const Mat4& viewProjection, const float (&viewport)[4]) {
  std::memcpy(block.viewProjection, viewProjection.data(), sizeof block.viewProjection);
  std::memcpy(block.view, view.view.data(), sizeof block.view);
  put(block.eye, view.eye.x, view.eye.y, view.eye.z, 1.0f);
  std::memcpy(block.viewport, viewport, sizeof block.viewport);
  const DepthRange range = depthRangeOf(view.projection);
  put(block.depth, range.zNear, range.zFar, 0, 0);

  const runtime::DepthCue& dc = show.depthCue();
  put(block.depthCue, static_cast<float>(dc.mode), dc.frontRefPlane, dc.backRefPlane, 0);
  put(block.depthCueScale, dc.maxScale, dc.minScale, 0, 0);
  put(block.depthCueColor, dc.useBackgroundColor ? show.global().background : dc.color);

  // Scene units reach the world through the model matrix: one scene unit is `scale` world units.
  const float scale = runtime::uniformScale(view.model);
  const bool usableScale = scale > 0 && std::isfinite(scale);
  const runtime::Fog& fog = show.fog();
  const bool sceneFog = fog.units == runtime::Units::kScene && usableScale;
  put(block.fog, static_cast<float>(fog.mode), sceneFog ? fog.start * scale : fog.start,
      sceneFog ? fog.end * scale : fog.end, sceneFog ? fog.density / scale : fog.density);
  put(block.fogColor, fog.color);
  put(block.background, show.global().background);

  int lights = 0;
  for (const runtime::Light& l : show.lights()) {
    if (!l.on) continue;
    const auto i = static_cast<std::size_t>(lights++);
    const bool scene = l.units == runtime::Units::kScene && usableScale;
    const Vec3 d = normalize(scene ? view.model.transformDirection(l.direction) : l.direction);
    const Vec3 p = scene ? view.model.transformPoint(l.position) : l.position;
    const float c2 = scene ? l.attenuation2 / scale : l.attenuation2;
    // XGL's ambient light is all ambient; the others carry Lc into the diffuse and highlight.
    const bool ambientType = l.type == runtime::LightType::kAmbient;
    const runtime::Color3 diffuse = ambientType ? runtime::Color3{0, 0, 0} : l.color;
    const runtime::Color3 ambient =
        ambientType ? runtime::Color3{l.color.r + l.ambient.r, l.color.g + l.ambient.g, l.color.b + l.ambient.b}
                    : l.ambient;
    const runtime::Color3 specular = ambientType ? runtime::Color3{0, 0, 0} : (l.ownSpecular ? l.specular : l.color);
    put(block.lightColor[i], diffuse.r, diffuse.g, diffuse.b, static_cast<float>(l.type));
    put(block.lightPosition[i], p.x, p.y, p.z, l.attenuation1);
    put(block.lightDirection[i], d.x, d.y, d.z, c2);
    put(block.lightSpot[i], std::cos(l.angle), l.exponent, 0, 0);
    put(block.lightAmbient[i], ambient.r, ambient.g, ambient.b, 0);
    put(block.lightSpecular[i], specular.r, specular.g, specular.b, 0);
  }

  // Clipping planes are given in the object's normalised coordinates (they turn with it):
  // carried into the world by the global and local matrices.
  const runtime::ModelClipping& clip = show.modelClipping();
  const int planes = std::clamp(clip.numPlanes, 0, static_cast<int>(runtime::kMaxClipPlanes));
  const Mat4 toWorld = show.position().global * show.position().local;
  const Mat4 normalToWorld = toWorld.inverted().transposed();
  for (int i = 0; i < planes; ++i) {
    const runtime::ClipPlane& plane = clip.planes[static_cast<std::size_t>(i)];
    const Vec3 p = toWorld.transformPoint(plane.point);
    const Vec3 n = normalize(normalToWorld.transformDirection(plane.normal));
    put(block.clipPlane[static_cast<std::size_t>(i)], n.x, n.y, n.z, -dot(n, p));
  }
  block.counts[0] = lights;
  block.counts[1] = planes;
  block.counts[2] = 0;
  block.counts[3] = 0;
}

}  // namespace basalt::render
