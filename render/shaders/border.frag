#version 300 es
// The border of a facet view (thesis §4.4.5): every pixel of the viewport outside the facet's
// convex outline is black. The outline is given as half-planes in normalised device
// coordinates (a x + b y + c >= 0 inside); pixels inside all of them are left alone.
precision highp float;

uniform vec4 uViewportRect;  // x, y, width, height in window pixels
uniform vec3 uEdges[64];
uniform int uEdgeCount;

out vec4 fragColor;

void main() {
  vec2 ndc = (gl_FragCoord.xy - uViewportRect.xy) / uViewportRect.zw * 2.0 - 1.0;
  bool inside = true;
  for (int i = 0; i < uEdgeCount; ++i) {
    if (dot(uEdges[i], vec3(ndc, 1.0)) < 0.0) {
      inside = false;
      break;
    }
  }
  if (inside) discard;
  fragColor = vec4(0.0, 0.0, 0.0, 1.0);
}
