// Surfaces, fragment stage: the side's colour (interpolated, flat or lit here), the colour map
// and reflection map (modulating, as OpenGL's default texture environment does), LAVA's fill
// styles and screen-door transparency (FILL_EFFECTS), then the shared epilogue.

uniform Surface uFront;
uniform Surface uBack;
uniform int uBackLit;

#if defined(SHADE_FACET) || defined(SHADE_UNLIT_FLAT)
flat in vec4 vFront;
#ifdef TWO_SIDED
flat in vec4 vBack;
#endif
#elif defined(SHADE_VERTEX) || defined(SHADE_UNLIT_SMOOTH)
in vec4 vFront;
#ifdef TWO_SIDED
in vec4 vBack;
#endif
#else
in vec3 vWorld;
in vec3 vNormal;
in vec4 vColor;
#endif

#ifdef TEXTURE
in vec2 vTexcoord;
uniform sampler2D uColorMap;
uniform int uTextureMode;    // 0: the part's coordinates; 1: fill style "pattern", tiled on the screen
uniform vec2 uTextureSize;   // in texels
uniform vec2 uTexcoordFlip;
#endif
#ifdef SPHERE_MAP
in vec3 vEyePosition;
in vec3 vEyeNormal;
uniform sampler2D uReflectionMap;
#endif

#ifdef FILL_EFFECTS
uniform int uStipple;      // XGL stipple pattern 0..11, -1 for none
uniform int uOpaqueStipple;  // 1: unset stipple pixels take the background colour
uniform int uScreenDoor;   // 1: screen-door transparency at the side's transparency
#endif
uniform int uBlendToBackground;  // 1: transparency blends with the constant background here

#ifdef FILL_EFFECTS
// LAVA's twelve stipple patterns on an 8-pixel cell (4 for the double-density ones):
// horizontal, vertical, 45 and 135 degree lines, and the rectilinear and diagonal grids.
bool stippleSet(int pattern, ivec2 q) {
  int cell = pattern >= 6 ? 4 : 8;
  int kind = pattern >= 6 ? pattern - 6 : pattern;
  int x = q.x + 4096;
  int y = q.y + 4096;
  bool horizontal = (y % cell) == 0;
  bool vertical = (x % cell) == 0;
  bool diag45 = ((x - y + 8192) % cell) == 0;
  bool diag135 = ((x + y) % cell) == 0;
  if (kind == 0) return horizontal;
  if (kind == 1) return vertical;
  if (kind == 2) return diag45;
  if (kind == 3) return diag135;
  if (kind == 4) return horizontal || vertical;
  return diag45 || diag135;
}

// An ordered 4 x 4 dither: the fraction of pixels kept is 1 - transparency.
float screenDoorThreshold(ivec2 q) {
  const int bayer[16] = int[16](0, 8, 2, 10, 12, 4, 14, 6, 3, 11, 1, 9, 15, 7, 13, 5);
  int i = (q.y & 3) * 4 + (q.x & 3);
  return (float(bayer[i]) + 0.5) / 16.0;
}
#endif

void main() {
  clipFragment();
#ifdef TWO_SIDED
  bool front = gl_FrontFacing;
#else
  bool front = true;
#endif

#if defined(SHADE_FACET) || defined(SHADE_UNLIT_FLAT) || defined(SHADE_VERTEX) || defined(SHADE_UNLIT_SMOOTH)
#ifdef TWO_SIDED
  vec4 c = front ? vFront : vBack;
#else
  vec4 c = vFront;
#endif
#else
  vec3 N = normalize(vNormal);
  vec3 E = normalize(uEye.xyz - vWorld);
  vec4 c;
  if (front) {
    vec3 Od = vColor.r < 0.0 ? uFront.color : vColor.rgb;
    c = vec4(illuminate(vWorld, N, E, uFront, Od), uFront.alpha);
  } else {
    vec3 Od = vColor.r < 0.0 ? uBack.color : vColor.rgb;
    c = vec4(uBackLit == 1 ? illuminate(vWorld, -N, E, uBack, Od) : Od, uBack.alpha);
  }
#endif

  ivec2 pixel = ivec2(gl_FragCoord.xy - uViewport.xy);
#ifdef TEXTURE
  vec4 texel;
  if (uTextureMode == 1) {
    vec2 st = (vec2(pixel) + 0.5) / uTextureSize;
    texel = texture(uColorMap, vec2(st.x, uTexcoordFlip.y + uTexcoordFlip.x * st.y));
  } else {
    texel = texture(uColorMap, vTexcoord);
  }
  c *= texel;
#endif
#ifdef SPHERE_MAP
  // OpenGL's sphere-map coordinates from the eye-space reflection vector.
  vec3 u = normalize(vEyePosition);
  vec3 n = normalize(vEyeNormal);
  if (!front) n = -n;
  vec3 r = reflect(u, n);
  float m = 2.0 * sqrt(r.x * r.x + r.y * r.y + (r.z + 1.0) * (r.z + 1.0));
  vec2 sphere = vec2(r.x / m + 0.5, r.y / m + 0.5);
  c.rgb *= texture(uReflectionMap, vec2(sphere.x, 1.0 - sphere.y)).rgb;
#endif

#ifdef FILL_EFFECTS
  if (uStipple >= 0 && !stippleSet(uStipple, pixel)) {
    if (uOpaqueStipple == 0) discard;
    c = vec4(uBackground.rgb, c.a);
  }
  if (uScreenDoor == 1 && screenDoorThreshold(pixel) < 1.0 - c.a) discard;
#endif

  c.rgb = atmosphere(c.rgb);
  if (uBlendToBackground == 1) c = vec4(mix(uBackground.rgb, c.rgb, c.a), 1.0);
  writeColor(c);
}
