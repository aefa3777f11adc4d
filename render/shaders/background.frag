// Backgrounds (thesis §4.3.2, Performer's pfEarthSky): a flat image stretched over the viewport,
// a skybox from one 3 x 2 image, or the earth-sky model. Directions come from the view's inverse
// projection and rotation, so facets and stereo eyes see the same sky.

uniform int uMode;                 // 1 image, 2 skybox, 3 earth-sky
uniform mat4 uInverseViewRotationProjection;  // NDC to a world direction
uniform sampler2D uImage;
uniform vec2 uImageFlip;           // t' = y + x * t
uniform vec2 uAtlasTexel;          // 1 / skybox image size, for keeping samples inside a face

// Earth-sky colours and geometry.
uniform vec3 uSkyTop;
uniform vec3 uSkyBottom;
uniform vec3 uHorizon;
uniform vec3 uGroundFar;
uniform vec3 uGroundNear;
uniform vec3 uClear;
uniform float uHorizonAngle;  // radians
uniform int uEarthSkyMode;    // EarthSkyClear
uniform int uGroundVisible;   // 0 when the viewer is below the ground height

in vec2 vNdc;

// OpenGL cube-map face selection (ES 3.0 §3.8.10): face, then s and t in 0..1.
vec3 cubeFace(vec3 r) {
  vec3 a = abs(r);
  float face;
  float sc;
  float tc;
  float ma;
  if (a.x >= a.y && a.x >= a.z) {
    ma = a.x;
    face = r.x > 0.0 ? 0.0 : 1.0;
    sc = r.x > 0.0 ? -r.z : r.z;
    tc = -r.y;
  } else if (a.y >= a.z) {
    ma = a.y;
    face = r.y > 0.0 ? 2.0 : 3.0;
    sc = r.x;
    tc = r.y > 0.0 ? r.z : -r.z;
  } else {
    ma = a.z;
    face = r.z > 0.0 ? 4.0 : 5.0;
    sc = r.z > 0.0 ? r.x : -r.x;
    tc = -r.y;
  }
  return vec3(face, 0.5 * (sc / ma + 1.0), 0.5 * (tc / ma + 1.0));
}

vec3 earthSky(vec3 dir) {
  float elevation = asin(clamp(dir.y, -1.0, 1.0));
  float band = max(uHorizonAngle, 1e-4);
  const float kHalfPi = 1.5707963;
  if (elevation >= band) {
    return mix(uSkyBottom, uSkyTop, (elevation - band) / max(kHalfPi - band, 1e-4));
  }
  if (elevation >= 0.0) {
    if (uEarthSkyMode == 4 || uEarthSkyMode == 2 || uEarthSkyMode == 3) {
      return mix(uHorizon, uSkyBottom, elevation / band);
    }
    return uClear;
  }
  // Below the horizon.
  if (uEarthSkyMode == 3 && uGroundVisible == 1) {
    float below = -elevation;
    if (below < band) return mix(uHorizon, uGroundFar, below / band);
    return mix(uGroundFar, uGroundNear, (below - band) / max(kHalfPi - band, 1e-4));
  }
  if (uEarthSkyMode == 2 && -elevation < band) return mix(uHorizon, uClear, -elevation / band);
  if (uEarthSkyMode == 3) {
    // The viewer is under the ground: the sky continues downwards.
    return mix(uHorizon, uSkyBottom, min(-elevation / band, 1.0));
  }
  return uClear;
}

void main() {
  if (uMode == 1) {
    vec2 st = vNdc * 0.5 + 0.5;
    fragColor = vec4(texture(uImage, vec2(st.x, uImageFlip.y + uImageFlip.x * st.y)).rgb, 1.0);
    return;
  }
  vec4 far = uInverseViewRotationProjection * vec4(vNdc, 1.0, 1.0);
  vec4 near = uInverseViewRotationProjection * vec4(vNdc, -1.0, 1.0);
  vec3 dir = normalize(far.xyz / far.w - near.xyz / near.w);
  if (uMode == 2) {
    // Faces in the 3 x 2 image: -X, +Z, +X on top; -Y, +Y, -Z below.
    vec3 f = cubeFace(dir);
    const vec2 cells[6] = vec2[6](vec2(2.0, 0.0), vec2(0.0, 0.0), vec2(1.0, 1.0), vec2(0.0, 1.0),
                                  vec2(1.0, 0.0), vec2(2.0, 1.0));
    vec2 cell = cells[int(f.x)];
    vec2 inFace = clamp(f.yz, uAtlasTexel * vec2(1.5, 1.0), 1.0 - uAtlasTexel * vec2(1.5, 1.0));
    vec2 st = (cell + inFace) / vec2(3.0, 2.0);  // t from the image's top row
    fragColor = vec4(textureLod(uImage, vec2(st.x, uImageFlip.y > 0.5 ? st.y : 1.0 - st.y), 0.0).rgb, 1.0);
    return;
  }
  fragColor = vec4(earthSky(dir), 1.0);
}
