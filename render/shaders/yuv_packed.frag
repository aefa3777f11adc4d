#version 300 es
// 4:2:0 planes -> RGBA, eight pixels a fragment: four across, two rows down (the two rows that
// share a chroma row). For software renderers (llvmpipe), where a fragment's fixed cost and its
// texture fetches outweigh the arithmetic: a quarter of the fetches and an eighth of the
// fragments of yuv.frag. The planes arrive as R32UI textures, four 8-bit samples a texel; the
// fragment writes its pixels as packed RGBA8 words to two RGBA32UI targets (even and odd rows),
// which StreamTexture copies into the RGBA texture through a pixel buffer, bottom row first.
// StreamTexture compiles one variant per layout (LAYOUT is defined in front of this text).
precision highp float;
precision highp int;

#define LAYOUT_THREE_PLANES 3  // I420 (U then V) and YV12 (bound swapped)
#define LAYOUT_NV12 4
#define LAYOUT_NV21 5

uniform highp usampler2D uPlane0;  // Y: four samples a texel
uniform highp usampler2D uPlane1;  // U: four samples a texel; or UV pairs: two pairs a texel
uniform highp usampler2D uPlane2;  // V: four samples a texel
// As in yuv.frag: rgb = y * uYCoef + u * uUCoef + v * uVCoef + uBias.
uniform vec3 uYCoef;
uniform vec3 uUCoef;
uniform vec3 uVCoef;
uniform vec3 uBias;
uniform int uHeight;  // the frame's height (even)

layout(location = 0) out uvec4 oEven;  // target row 2k
layout(location = 1) out uvec4 oOdd;   // target row 2k + 1

vec4 samples(uint word) {
  return vec4(uvec4(word, word >> 8u, word >> 16u, word >> 24u) & 255u) * (1.0 / 255.0);
}

uint rgba(vec3 rgb) {
  uvec3 c = uvec3(clamp(rgb, 0.0, 1.0) * 255.0 + 0.5);
  return c.r | (c.g << 8u) | (c.b << 16u) | 0xff000000u;
}

uvec4 row(vec4 y, vec3 chroma0, vec3 chroma1) {
  return uvec4(rgba(y.x * uYCoef + chroma0), rgba(y.y * uYCoef + chroma0), rgba(y.z * uYCoef + chroma1),
               rgba(y.w * uYCoef + chroma1));
}

void main() {
  ivec2 g = ivec2(gl_FragCoord.xy);
  // Target rows 2k and 2k + 1 are the frame's rows H-1-2k and H-2-2k (bottom row first): the
  // pair of frame rows from `top`, which share chroma row top / 2.
  int top = uHeight - 2 - 2 * g.y;
  vec4 upper = samples(texelFetch(uPlane0, ivec2(g.x, top), 0).r);
  vec4 lower = samples(texelFetch(uPlane0, ivec2(g.x, top + 1), 0).r);
  int chromaRow = top >> 1;
#if LAYOUT == LAYOUT_THREE_PLANES
  // A chroma texel covers eight pixels: this fragment's four use its low or high half.
  uint shift = uint(g.x & 1) * 16u;
  vec2 u = samples(texelFetch(uPlane1, ivec2(g.x >> 1, chromaRow), 0).r >> shift).xy;
  vec2 v = samples(texelFetch(uPlane2, ivec2(g.x >> 1, chromaRow), 0).r >> shift).xy;
#else
  vec4 pairs = samples(texelFetch(uPlane1, ivec2(g.x, chromaRow), 0).r);
#if LAYOUT == LAYOUT_NV12
  vec2 u = pairs.xz, v = pairs.yw;
#else
  vec2 u = pairs.yw, v = pairs.xz;
#endif
#endif
  vec3 chroma0 = u.x * uUCoef + v.x * uVCoef + uBias;
  vec3 chroma1 = u.y * uUCoef + v.y * uVCoef + uBias;
  oEven = row(lower, chroma0, chroma1);
  oOdd = row(upper, chroma0, chroma1);
}
