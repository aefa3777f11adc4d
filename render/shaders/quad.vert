#version 300 es
// A rectangle from four vertices made from gl_VertexID (no buffers): the YUV conversion pass
// covers its whole target; the Zoom picture covers uRect (in normalised device coordinates).
precision highp float;

uniform vec4 uRect;  // x0, y0, x1, y1 in NDC
uniform bool uFlipY; // sample the texture upside down (its rows run top to bottom)
uniform bool uFlipX; // sample it mirrored left-right (texel centres still land on texel centres)

out vec2 vUv;

void main() {
  vec2 corner = vec2(float(gl_VertexID & 1), float((gl_VertexID >> 1) & 1));
  vUv = vec2(uFlipX ? 1.0 - corner.x : corner.x, uFlipY ? 1.0 - corner.y : corner.y);
  gl_Position = vec4(mix(uRect.xy, uRect.zw, corner), 0.0, 1.0);
}
