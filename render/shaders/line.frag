// Lines and edges, fragment stage: round ends, antialiased coverage, the line pattern (a
// repeating mask of up to 32 steps, each step a pixel times the line width), then the shared
// epilogue.

uniform vec4 uColor;
uniform vec4 uAltColor;
uniform int uStyle;          // 0 solid, 1 patterned, 2 alt patterned
uniform int uPatternMask;    // bit i: pixel i of the period is drawn
uniform int uPatternPeriod;  // 1..32
uniform float uPatternScale; // pixels per pattern bit
uniform float uWidth;
uniform int uCap;
uniform int uAntialias;
uniform int uBlendToBackground;  // antialiasing "blend to constant background"

flat in vec4 vEnds;
flat in vec4 vInfo;
in vec4 vColor;

void main() {
  clipFragment();
  vec2 p = gl_FragCoord.xy - uViewport.xy;
  vec2 s0 = vEnds.xy;
  vec2 s1 = vEnds.zw;
  float len = vInfo.x;
  vec2 dir = len > 1e-4 ? (s1 - s0) / len : vec2(1.0, 0.0);
  vec2 nrm = vec2(-dir.y, dir.x);
  float along = dot(p - s0, dir);
  float across = abs(dot(p - s0, nrm));
  float halfWidth = 0.5 * max(uWidth, 1.0);

  // Distance outside the line's shape, in pixels (<= 0 inside).
  float outside = across - halfWidth;
  bool free0 = vInfo.y < 0.5;
  bool free1 = vInfo.z < 0.5;
  if (uCap == 2 && ((along < 0.0 && free0) || (along > len && free1))) {
    vec2 centre = along < 0.0 ? s0 : s1;
    outside = length(p - centre) - halfWidth;
  } else if (uAntialias == 1) {
    float extension = uCap == 1 ? halfWidth : 0.0;
    if (free0) outside = max(outside, -(along + extension));
    if (free1) outside = max(outside, along - len - extension);
  }
  float coverage = 1.0;
  if (uAntialias == 1) {
    coverage = clamp(0.5 - outside, 0.0, 1.0);
  } else if (outside > 0.0) {
    discard;
  }
  if (coverage <= 0.0) discard;

  vec4 c = vColor.r < 0.0 ? uColor : vColor;
  if (uStyle != 0) {
    // Counted along the line's major screen axis, as OpenGL's line stipple counts it, so that
    // the pattern runs on across the joints of polylines and tessellated curves.
    float axis = abs(dir.x) >= abs(dir.y) ? p.x : p.y;
    int bit = int(floor((axis + 8192.0) / uPatternScale)) % uPatternPeriod;
    bool on = ((uPatternMask >> bit) & 1) != 0;
    if (!on) {
      if (uStyle == 1) discard;
      c = uAltColor;
    }
  }
  c.rgb = atmosphere(c.rgb);
  c.a *= coverage;
  if (uBlendToBackground == 1) c = vec4(mix(uBackground.rgb, c.rgb, c.a), 1.0);
  writeColor(c);
}
