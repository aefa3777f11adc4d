// Marker shapes in pixels around the vertex: dot, plus, asterisk, circle, cross (x), square,
// bowtie NE (two triangles meeting at the centre, opening to the north-east and south-west) and
// bowtie NW. Strokes are one pixel wide; the size is LAVA's scale factor in pixels.

uniform vec4 uColor;
uniform int uMarkerType;  // MarkerType, in LAVA's order
uniform float uPointSize;
uniform float uMarkerSize;
uniform int uAntialias;
uniform int uBlendToBackground;

in vec4 vColor;

float segmentDistance(vec2 p, vec2 a, vec2 b) {
  vec2 ab = b - a;
  float t = clamp(dot(p - a, ab) / max(dot(ab, ab), 1e-6), 0.0, 1.0);
  return length(p - a - t * ab);
}

// Signed distance to the marker's shape in pixels: strokes are lines of width one pixel.
float markerDistance(vec2 p, float r) {
  const float kStroke = 0.5;
  float plus = min(segmentDistance(p, vec2(-r, 0.0), vec2(r, 0.0)), segmentDistance(p, vec2(0.0, -r), vec2(0.0, r)));
  float d = r * 0.70710678;
  float cross = min(segmentDistance(p, vec2(-d, -d), vec2(d, d)), segmentDistance(p, vec2(-d, d), vec2(d, -d)));
  if (uMarkerType == 1) return plus - kStroke;
  if (uMarkerType == 2) return min(plus, cross) - kStroke;
  if (uMarkerType == 3) return abs(length(p) - r) - kStroke;
  if (uMarkerType == 4) return cross - kStroke;
  if (uMarkerType == 5) return abs(max(abs(p.x), abs(p.y)) - d) - kStroke;
  // Bowties: filled, the axis along the named diagonal.
  vec2 axis = uMarkerType == 6 ? vec2(0.70710678, 0.70710678) : vec2(-0.70710678, 0.70710678);
  float u = abs(dot(p, axis));
  float v = abs(dot(p, vec2(-axis.y, axis.x)));
  return max((v - u) * 0.70710678, u - r);
}

void main() {
  clipFragment();
  float coverage = 1.0;
  if (uMarkerType != 0) {
    vec2 p = (gl_PointCoord - 0.5) * uPointSize;
    p.y = -p.y;
    float r = max(uMarkerSize * 0.5 - 0.5, 0.5);
    float dist = markerDistance(p, r);
    if (uAntialias == 1) {
      coverage = clamp(0.5 - dist, 0.0, 1.0);
      if (coverage <= 0.0) discard;
    } else if (dist > 0.0) {
      discard;
    }
  }
  vec4 c = vColor.r < 0.0 ? uColor : vColor;
  c.rgb = atmosphere(c.rgb);
  c.a *= coverage;
  if (uBlendToBackground == 1) c = vec4(mix(uBackground.rgb, c.rgb, c.a), 1.0);
  writeColor(c);
}
