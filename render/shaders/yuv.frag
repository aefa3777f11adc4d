#version 300 es
// YUV (or RGB) planes as the decoder or camera made them -> RGBA, once per new video frame.
// The matrix and offsets carry the stream's colorimetry (BT.601/709/2020, limited/full range).
// StreamTexture compiles one variant per layout (LAYOUT is defined in front of this text), so
// that no pixel pays for a branch: software renderers run every branch of a shader.
precision highp float;
precision highp int;

#define LAYOUT_RGBA 0
#define LAYOUT_BGRA 1
#define LAYOUT_GRAY 2
#define LAYOUT_THREE_PLANES 3  // I420 (U then V) and YV12 (bound swapped)
#define LAYOUT_NV12 4
#define LAYOUT_NV21 5
#define LAYOUT_YUYV 6  // Y0 U Y1 V: one RGBA texel holds two pixels
#define LAYOUT_UYVY 7  // U Y0 V Y1

uniform sampler2D uPlane0;  // Y (R8), packed 4:2:2 (RGBA8) or RGB(A)
uniform sampler2D uPlane1;  // U (R8) or interleaved UV (RG8)
uniform sampler2D uPlane2;  // V (R8)
// rgb = y * uYCoef + u * uUCoef + v * uVCoef + uBias: the matrix columns with the range and the
// offsets folded in (three multiply-adds; the RGBA8 target clamps).
uniform vec3 uYCoef;
uniform vec3 uUCoef;
uniform vec3 uVCoef;
uniform vec3 uBias;
// Chroma texture coordinates from luma ones: (width / (2 * chroma width), same for height), so
// that a pixel's chroma sample is the one sited with its top-left luma sample, odd sizes too.
uniform vec2 uChromaScale;
// 0, or the frame's width to mirror it left-right (a camera that cannot flip in the device).
uniform int uMirrorWidth;

in vec2 vUv;
out vec4 fragColor;

vec3 toRgb(vec3 yuv) { return yuv.x * uYCoef + yuv.y * uUCoef + yuv.z * uVCoef + uBias; }

void main() {
  // The target has the frame's size: every sample is a texel fetch (no filtering), chroma at
  // half resolution: 4:2:0 chroma sited with its top-left luma sample.
  // Layouts read through texture() are mirrored by the quad (uFlipX); those fetched by the
  // fragment's position here.
  vec2 uv = vUv;
#if LAYOUT <= LAYOUT_GRAY || LAYOUT >= LAYOUT_YUYV
  ivec2 px = ivec2(gl_FragCoord.xy);
  if (uMirrorWidth > 0) px.x = uMirrorWidth - 1 - px.x;
#endif
#if LAYOUT == LAYOUT_RGBA
  fragColor = vec4(texelFetch(uPlane0, px, 0).rgb, 1.0);
#elif LAYOUT == LAYOUT_BGRA
  fragColor = vec4(texelFetch(uPlane0, px, 0).bgr, 1.0);
#elif LAYOUT == LAYOUT_GRAY
  fragColor = vec4(vec3(texelFetch(uPlane0, px, 0).r), 1.0);
#elif LAYOUT == LAYOUT_THREE_PLANES
  // Planar layouts sample with texture() at texel centres (nearest): the same texels as
  // texelFetch, but software renderers (llvmpipe) take their fast 8-bit path for it, which
  // costs about half as much per pixel as texelFetch's gather.
  vec2 c = uv * uChromaScale;
  fragColor = vec4(toRgb(vec3(texture(uPlane0, uv).r, texture(uPlane1, c).r, texture(uPlane2, c).r)), 1.0);
#elif LAYOUT == LAYOUT_NV12
  fragColor = vec4(toRgb(vec3(texture(uPlane0, uv).r, texture(uPlane1, uv * uChromaScale).rg)), 1.0);
#elif LAYOUT == LAYOUT_NV21
  fragColor = vec4(toRgb(vec3(texture(uPlane0, uv).r, texture(uPlane1, uv * uChromaScale).gr)), 1.0);
#else
  vec4 t = texelFetch(uPlane0, ivec2(px.x >> 1, px.y), 0);
  bool odd = (px.x & 1) == 1;
#if LAYOUT == LAYOUT_YUYV
  vec3 yuv = vec3(odd ? t.b : t.r, t.g, t.a);
#else
  vec3 yuv = vec3(odd ? t.a : t.g, t.r, t.b);
#endif
  fragColor = vec4(toRgb(yuv), 1.0);
#endif
}
