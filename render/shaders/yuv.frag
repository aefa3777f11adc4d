#version 300 es
// YUV (or RGB) planes as the decoder or camera made them -> RGBA, once per new video frame.
// The matrix and offsets carry the stream's colorimetry (BT.601/709/2020, limited/full range).
precision highp float;
precision highp int;

uniform sampler2D uPlane0;  // Y (R8), packed 4:2:2 (RGBA8, 2 pixels per texel) or RGB(A)
uniform sampler2D uPlane1;  // U (R8) or interleaved UV (RG8)
uniform sampler2D uPlane2;  // V (R8)
uniform int uLayout;        // see StreamTexture::Layout
uniform mat3 uYuvToRgb;
uniform vec3 uOffset;       // subtracted from (Y, U, V) before the matrix

in vec2 vUv;
out vec4 fragColor;

vec3 toRgb(vec3 yuv) { return clamp(uYuvToRgb * (yuv - uOffset), 0.0, 1.0); }

void main() {
  if (uLayout == 0) {  // RGBA
    fragColor = vec4(texture(uPlane0, vUv).rgb, 1.0);
  } else if (uLayout == 1) {  // BGRA
    fragColor = vec4(texture(uPlane0, vUv).bgr, 1.0);
  } else if (uLayout == 2) {  // GRAY8
    fragColor = vec4(vec3(texture(uPlane0, vUv).r), 1.0);
  } else if (uLayout == 3) {  // three planes: I420 (U then V) and YV12 (bound swapped)
    vec3 yuv = vec3(texture(uPlane0, vUv).r, texture(uPlane1, vUv).r, texture(uPlane2, vUv).r);
    fragColor = vec4(toRgb(yuv), 1.0);
  } else if (uLayout == 4 || uLayout == 5) {  // NV12 (UV) and NV21 (VU)
    vec2 c = texture(uPlane1, vUv).rg;
    vec3 yuv = vec3(texture(uPlane0, vUv).r, uLayout == 4 ? c : c.yx);
    fragColor = vec4(toRgb(yuv), 1.0);
  } else {  // 6: YUYV (Y0 U Y1 V), 7: UYVY (U Y0 V Y1); one texel holds two pixels
    ivec2 size = textureSize(uPlane0, 0);
    int x = int(gl_FragCoord.x);
    vec4 t = texelFetch(uPlane0, ivec2(min(x / 2, size.x - 1), int(gl_FragCoord.y)), 0);
    bool odd = (x & 1) == 1;
    vec3 yuv = uLayout == 6 ? vec3(odd ? t.b : t.r, t.g, t.a) : vec3(odd ? t.a : t.g, t.r, t.b);
    fragColor = vec4(toRgb(yuv), 1.0);
  }
}
