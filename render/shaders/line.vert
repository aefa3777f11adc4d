// Lines and edges that OpenGL ES lines cannot draw: wide lines with LAVA's endpoint styles (butt,
// square, round) and join styles (device, bevel, miter with its limit), patterned and
// alt-patterned lines, antialiased lines and silhouette edges. One instance per segment, expanded
// into a screen-space quad (vertices 0-5) and a bevel triangle at each end (6-8 and 9-11) that
// collapse when unused. Neighbouring segments (prev/next) share joins so that both compute the
// same corner points.

layout(location = 0) in vec3 aP0;
layout(location = 1) in vec3 aP1;
layout(location = 2) in vec4 aPrev;    // xyz: the far end of the segment joined at p0, w: 1 if any
layout(location = 3) in vec4 aNext;    // xyz: the far end of the segment joined at p1, w: 1 if any
layout(location = 4) in vec4 aC0;
layout(location = 5) in vec4 aC1;
layout(location = 6) in vec4 aFacetN0;  // normal of a facet this edge borders, w: 1 if any
layout(location = 7) in vec4 aFacetN1;  // the other facet, w: 1 if any (0: a boundary edge)

uniform mat4 uModel;
uniform mat3 uNormalMatrix;
uniform float uWidth;        // pixels
uniform int uCap;            // 0 butt, 1 square, 2 round
uniform int uJoin;           // 0 device (none), 1 bevel, 2 miter
uniform float uMiterLimit;
uniform int uAntialias;      // 1: soft edges (blended)
uniform int uSilhouette;     // 1: only edges between a front- and a back-facing facet
uniform float uDepthOffset;  // NDC depth moved towards the viewer (software edges)
uniform int uColorSource;    // 0: uColor, 1: the vertex colours
uniform int uColorInterp;    // 1: interpolate vertex colours along the segment

flat out vec4 vEnds;  // the segment's ends in viewport pixels
flat out vec4 vInfo;  // x: length in pixels, y: p0 joined, z: p1 joined
out vec4 vColor;

vec2 toPixels(vec4 clip) { return (clip.xy / clip.w * 0.5 + 0.5) * uViewport.zw; }

// The corner of this segment's quad at end E on side n (a unit normal of the segment), where u
// points from E into this segment and v from E into the joined segment (`joined` false: none).
vec2 corner(vec2 E, vec2 u, vec2 v, bool joined, vec2 n, float halfWidth, float extension) {
  if (!joined) return E + n * halfWidth - u * extension;
  if (uJoin == 0) return E + n * halfWidth;
  vec2 bisector = u + v;
  float bl = length(bisector);
  if (bl < 1e-3) return E + n * halfWidth;  // a straight continuation
  bisector /= bl;
  float k = dot(bisector, n);
  if (abs(k) < 1e-3) return E + n * halfWidth;
  bool outer = k < 0.0;
  float ratio = 1.0 / abs(k);
  if (outer && (uJoin == 1 || ratio > uMiterLimit)) return E + n * halfWidth;
  if (!outer && ratio > 4.0) return E + n * halfWidth;
  return E + bisector * (halfWidth / k);
}

void main() {
  int vertex = gl_VertexID;
  vec4 w0 = uModel * vec4(aP0, 1.0);
  vec4 w1 = uModel * vec4(aP1, 1.0);
  vec4 c0 = uViewProjection * w0;
  vec4 c1 = uViewProjection * w1;
  // Keep both ends in front of the eye: move an end that is behind it along the segment.
  const float kNear = 1e-5;
  if (c0.w < kNear && c1.w < kNear) {
    gl_Position = vec4(0.0);
    return;
  }
  if (c0.w < kNear) c0 = mix(c0, c1, (kNear - c0.w) / (c1.w - c0.w));
  if (c1.w < kNear) c1 = mix(c1, c0, (kNear - c1.w) / (c0.w - c1.w));

  if (uSilhouette == 1 && aFacetN0.w > 0.0) {
    vec3 middle = 0.5 * (w0.xyz + w1.xyz);
    vec3 toEye = uEye.xyz - middle;
    bool facing0 = dot(uNormalMatrix * aFacetN0.xyz, toEye) > 0.0;
    bool facing1 = dot(uNormalMatrix * aFacetN1.xyz, toEye) > 0.0;
    if (aFacetN1.w > 0.0 && facing0 == facing1) {
      gl_Position = vec4(0.0);
      return;
    }
  }

  vec2 s0 = toPixels(c0);
  vec2 s1 = toPixels(c1);
  vec2 d = s1 - s0;
  float len = length(d);
  vec2 dir = len > 1e-4 ? d / len : vec2(1.0, 0.0);
  vec2 nrm = vec2(-dir.y, dir.x);
  float pad = uAntialias == 1 ? 1.0 : 0.0;
  float halfWidth = 0.5 * max(uWidth, 1.0) + pad;
  float extension = (uCap == 0 ? 0.0 : 0.5 * max(uWidth, 1.0)) + pad;

  bool joined0 = aPrev.w > 0.0 && uJoin != 0;
  bool joined1 = aNext.w > 0.0 && uJoin != 0;
  vec2 v0 = dir;
  vec2 v1 = -dir;
  if (joined0) {
    vec4 cp = uViewProjection * (uModel * vec4(aPrev.xyz, 1.0));
    vec2 to = cp.w > kNear ? toPixels(cp) - s0 : vec2(0.0);
    joined0 = length(to) > 1e-4;
    v0 = joined0 ? normalize(to) : dir;
  }
  if (joined1) {
    vec4 cn = uViewProjection * (uModel * vec4(aNext.xyz, 1.0));
    vec2 to = cn.w > kNear ? toPixels(cn) - s1 : vec2(0.0);
    joined1 = length(to) > 1e-4;
    v1 = joined1 ? normalize(to) : -dir;
  }

  int end;  // which end the vertex belongs to
  vec2 p;
  if (vertex < 6) {
    // Two triangles: (A+, A-, B+), (B+, A-, B-).
    const int ends[6] = int[6](0, 0, 1, 1, 0, 1);
    const float sides[6] = float[6](1.0, -1.0, 1.0, 1.0, -1.0, -1.0);
    end = ends[vertex];
    float side = sides[vertex];
    p = end == 0 ? corner(s0, dir, v0, joined0, nrm * side, halfWidth, extension)
                 : corner(s1, -dir, v1, joined1, nrm * side, halfWidth, extension);
  } else {
    // The half bevel at one end: (E, this segment's outer corner, the middle of both outer corners).
    end = vertex < 9 ? 0 : 1;
    int which = vertex - (end == 0 ? 6 : 9);
    vec2 E = end == 0 ? s0 : s1;
    vec2 u = end == 0 ? dir : -dir;
    vec2 v = end == 0 ? v0 : v1;
    bool joined = end == 0 ? joined0 : joined1;
    float ratio = 0.0;
    vec2 bisector = u + v;
    bool bevel = joined && length(bisector) > 1e-3;
    if (bevel) {
      bisector = normalize(bisector);
      ratio = 1.0 / max(abs(dot(bisector, nrm)), 1e-6);
      bevel = uJoin == 1 || ratio > uMiterLimit;
    }
    if (!bevel) {
      gl_Position = vec4(0.0);
      return;
    }
    vec2 outerThis = dot(nrm, v) > 0.0 ? -nrm : nrm;
    vec2 outerOther = normalize(-(u - dot(u, v) * v));
    if (which == 0) {
      // The apex is this segment's inner corner, which both segments share, so that the two half
      // bevels and the two quads leave no gap around the joint.
      p = corner(E, u, v, true, -outerThis, halfWidth, extension);
    } else if (which == 1) {
      p = E + outerThis * halfWidth;
    } else {
      p = E + 0.5 * (outerThis + outerOther) * halfWidth;
    }
  }

  vec4 clip = end == 0 ? c0 : c1;
  gl_Position = vec4((p / uViewport.zw * 2.0 - 1.0) * clip.w, clip.z - uDepthOffset * clip.w, clip.w);
  passEffects(end == 0 ? w0.xyz : w1.xyz);
  vEnds = vec4(s0, s1);
  vInfo = vec4(len, joined0 ? 1.0 : 0.0, joined1 ? 1.0 : 0.0, 0.0);
  vec4 vertexColor = uColorInterp == 1 ? (end == 0 ? aC0 : aC1) : aC0;
  vColor = uColorSource == 1 ? vertexColor : vec4(-1.0);
}
