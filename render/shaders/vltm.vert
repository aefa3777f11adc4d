// Vertex-level texture mapping (LAVA Appendix 1, Kamen): the texture is sampled only at
// vertices and Gouraud-interpolated inside, each triangle cut into m x m sub-triangles (each side
// in m equal parts) until that is good enough. One instance per triangle; gl_VertexID walks the
// sub-triangles row by row. m is the same for every triangle ("Num Segments"), or chosen per
// triangle so that no side is longer than the pixel tolerance on the screen, or the finer of
// the two ("Combined"); the draw is sized for the largest m, and the rest collapse.
// The fragment stage is surface.frag with SHADE_VERTEX.

layout(location = 0) in vec3 aP0;
layout(location = 1) in vec3 aP1;
layout(location = 2) in vec3 aP2;
layout(location = 3) in vec3 aN0;
layout(location = 4) in vec3 aN1;
layout(location = 5) in vec3 aN2;
layout(location = 6) in vec2 aT0;
layout(location = 7) in vec2 aT1;
layout(location = 8) in vec2 aT2;
layout(location = 9) in vec4 aC0;
layout(location = 10) in vec4 aC1;
layout(location = 11) in vec4 aC2;

uniform mat4 uModel;
uniform mat3 uNormalMatrix;
uniform Surface uFront;
uniform Surface uBack;
uniform int uColorSource;
uniform int uBackLit;
uniform int uFrontLit;
uniform vec2 uTexcoordFlip;
uniform sampler2D uColorMap;
uniform int uTextured;
uniform int uMaxSegments;   // the m the draw was sized for
uniform int uApprox;        // 0: num segments, 1: pixel tolerance, 2: combined
uniform int uSubsegments;
uniform float uPixelTolerance;

out vec4 vFront;
#ifdef TWO_SIDED
out vec4 vBack;
#endif

vec2 toPixels(vec3 p) {
  vec4 clip = uViewProjection * (uModel * vec4(p, 1.0));
  return (clip.xy / max(clip.w, 1e-6) * 0.5 + 0.5) * uViewport.zw;
}

void main() {
  int m = uSubsegments;
  if (uApprox != 0) {
    vec2 s0 = toPixels(aP0), s1 = toPixels(aP1), s2 = toPixels(aP2);
    float longest = max(length(s1 - s0), max(length(s2 - s1), length(s0 - s2)));
    int byTolerance = int(ceil(longest / max(uPixelTolerance, 0.5)));
    m = uApprox == 1 ? byTolerance : max(m, byTolerance);
  }
  m = clamp(m, 1, uMaxSegments);

  int k = gl_VertexID / 3;
  int corner = gl_VertexID - k * 3;
  if (k >= m * m) {
    gl_Position = vec4(0.0);  // an unused sub-triangle: w = 0 is clipped away
    vFront = vec4(0.0);
#ifdef TWO_SIDED
    vBack = vec4(0.0);
#endif
    return;
  }
  int r = int(sqrt(float(k)));
  if (r * r > k) r -= 1;
  if ((r + 1) * (r + 1) <= k) r += 1;
  int j = k - r * r;
  int c = j / 2;
  ivec2 ab;  // lattice point: a rows down from vertex 0, b steps towards vertex 2
  if ((j & 1) == 0) {
    ab = corner == 0 ? ivec2(r, c) : (corner == 1 ? ivec2(r + 1, c) : ivec2(r + 1, c + 1));
  } else {
    ab = corner == 0 ? ivec2(r, c) : (corner == 1 ? ivec2(r + 1, c + 1) : ivec2(r, c + 1));
  }
  float fm = float(m);
  vec3 w = vec3(1.0 - float(ab.x) / fm, float(ab.x - ab.y) / fm, float(ab.y) / fm);

  vec3 P = w.x * aP0 + w.y * aP1 + w.z * aP2;
  vec3 n = w.x * aN0 + w.y * aN1 + w.z * aN2;
  vec2 t = w.x * aT0 + w.y * aT1 + w.z * aT2;
  vec4 vc = w.x * aC0 + w.y * aC1 + w.z * aC2;

  vec4 world = uModel * vec4(P, 1.0);
  gl_Position = uViewProjection * world;
  passEffects(world.xyz);
  vec3 N = normalize(uNormalMatrix * n);
  vec3 E = normalize(uEye.xyz - world.xyz);
  vec4 texel = vec4(1.0);
  if (uTextured == 1) texel = textureLod(uColorMap, vec2(t.x, uTexcoordFlip.y + uTexcoordFlip.x * t.y), 0.0);

  vec3 frontOd = uColorSource == 1 ? vc.rgb : uFront.color;
  vec3 front = uFrontLit == 1 ? illuminate(world.xyz, N, E, uFront, frontOd) : frontOd;
  vFront = vec4(front, uFront.alpha) * texel;
#ifdef TWO_SIDED
  vec3 backOd = uColorSource == 1 ? vc.rgb : uBack.color;
  vec3 back = uBackLit == 1 ? illuminate(world.xyz, -N, E, uBack, backOd) : backOd;
  vBack = vec4(back, uBack.alpha) * texel;
#endif
}
