// Shared by every Basalt program (after `#version`, extensions and the variant's #defines):
// the per-view Frame block, XGL lighting, and the fragment epilogue that applies model
// clipping, depth cueing, fog and the raster operation.
//
// Variant switches (#define): STAGE_VERTEX or STAGE_FRAGMENT; CLIP (model clipping planes);
// DEPTH_CUE; FOG; RASTER_FETCH (raster op read from the framebuffer: exact) or RASTER_COPY
// (raster op read from a copy of the frame taken before the draw).
precision highp float;
precision highp int;

// Everything that belongs to one view: written once per Renderer::draw() into a uniform buffer
// that every program shares (binding point 0).
layout(std140) uniform Frame {
  mat4 uViewProjection;
  mat4 uView;
  vec4 uEye;        // xyz: eye in world coordinates
  vec4 uViewport;   // x, y, width, height in pixels
  vec4 uDepth;      // x: near, y: far (eye-space depth of the projection's planes)
  vec4 uDepthCue;   // x: mode (0 none, 1 linear, 2 scaled), y: front plane, z: back plane
  vec4 uDepthCueScale;  // x: scale at the front plane, y: scale at the back plane
  vec4 uDepthCueColor;
  vec4 uFog;        // x: mode (0 none, 1 linear, 2 exp, 3 exp2), y: start, z: end, w: density
  vec4 uFogColor;
  vec4 uBackground; // the background colour (opaque stipple, blending to a constant background)
  ivec4 uCounts;    // x: lights switched on, y: model clipping planes
  vec4 uLightColor[32];      // rgb colour, w: type (0 ambient, 1 directional, 2 positional, 3 spot)
  vec4 uLightPosition[32];   // xyz position, w: attenuation c1
  vec4 uLightDirection[32];  // xyz unit direction the light travels, w: attenuation c2
  vec4 uLightSpot[32];       // x: cos(spot angle), y: spot exponent
  vec4 uLightAmbient[32];    // rgb: the light's ambient colour (an ambient light's Lc)
  vec4 uLightSpecular[32];   // rgb: the light's specular colour (Lc unless the light has its own)
  vec4 uClipPlane[16];       // xyz: unit normal towards what is kept, w: -dot(normal, point)
};

#ifdef STAGE_VERTEX
#define VARYING out
#else
#define VARYING in
#endif

// XGL surface attributes (XGL Programmer's Guide ch. 16, table 16-4).
struct Surface {
  vec3 color;          // Od when the colour comes from the context
  vec3 specularColor;  // Os
  float ka;
  float kd;
  float ks;
  float power;         // Se
  int components;      // bit 0 ambient, 1 diffuse, 2 specular
  float alpha;         // 1 - transparency
  vec3 emission;       // thesis §4.2.4: emitted whatever the lights (XGL: black)
  vec3 ambientColor;   // the ambient reflectance's colour when ambientOwn is 1
  int ambientOwn;      // 0: the ambient term reflects Od (XGL); 1: ambientColor (thesis)
};

// The XGL reflection model summed over every light that is on, clamped to 1 per channel, with
// the thesis' (OpenGL's) additions: the material's emission first, and each light's own ambient
// colour, attenuated like its other terms. P: point, N: unit normal, E: unit vector to the eye,
// all in world coordinates. A light behind the surface (N.L <= 0) gives no diffuse and no
// highlight.
vec3 illuminate(vec3 P, vec3 N, vec3 E, Surface s, vec3 Od) {
  vec3 sum = s.emission;
  vec3 Oa = s.ambientOwn == 1 ? s.ambientColor : Od;
  for (int i = 0; i < uCounts.x; ++i) {
    vec4 colorType = uLightColor[i];
    vec3 Lc = colorType.rgb;
    int type = int(colorType.w);
    vec3 ambient = (s.components & 1) != 0 ? s.ka * Oa * uLightAmbient[i].rgb : vec3(0.0);
    if (type == 0) {
      sum += ambient;
      continue;
    }
    vec3 L;
    float attenuation = 1.0;
    if (type == 1) {
      L = -uLightDirection[i].xyz;
    } else {
      vec3 toLight = uLightPosition[i].xyz - P;
      float d = length(toLight);
      L = toLight / max(d, 1e-6);
      attenuation = 1.0 / max(uLightPosition[i].w + uLightDirection[i].w * d, 1e-6);
      if (type == 3) {
        float c = dot(-L, uLightDirection[i].xyz);
        attenuation = c < uLightSpot[i].x ? 0.0 : attenuation * pow(max(c, 0.0), uLightSpot[i].y);
      }
    }
    float NdotL = dot(N, L);
    vec3 c = ambient;
    if (NdotL > 0.0) {
      if ((s.components & 2) != 0) c += s.kd * Od * Lc * NdotL;
      if ((s.components & 4) != 0) {
        vec3 R = 2.0 * NdotL * N - L;
        c += s.ks * s.specularColor * uLightSpecular[i].rgb * pow(max(dot(E, R), 0.0), s.power);
      }
    }
    sum += attenuation * c;
  }
  return clamp(sum, 0.0, 1.0);
}

#ifdef CLIP
VARYING vec3 vClipPosition;  // world position, tested against the clipping planes
#endif
#if defined(DEPTH_CUE) || defined(FOG)
VARYING float vEyeDepth;  // distance in front of the eye along the view axis
#endif

#ifdef STAGE_VERTEX
// Fills the varyings the fragment epilogue needs from a world position.
void passEffects(vec3 world) {
#ifdef CLIP
  vClipPosition = world;
#endif
#if defined(DEPTH_CUE) || defined(FOG)
  vEyeDepth = -(uView * vec4(world, 1.0)).z;
#endif
}
#endif

#ifdef STAGE_FRAGMENT

#ifdef RASTER_FETCH
inout highp vec4 fragColor;
#else
out highp vec4 fragColor;
#endif
#ifdef RASTER_COPY
uniform highp sampler2D uDestination;  // the viewport as it was before this draw
#endif
uniform int uRasterOp;  // RasterOp, in LAVA's order

// Discards fragments on the clipped side of any model clipping plane.
void clipFragment() {
#ifdef CLIP
  for (int i = 0; i < uCounts.y; ++i) {
    if (dot(uClipPlane[i].xyz, vClipPosition) + uClipPlane[i].w < 0.0) discard;
  }
#endif
}

// XGL depth cueing (linear or scaled between the reference planes), then OpenGL fog.
vec3 atmosphere(vec3 c) {
#if defined(DEPTH_CUE) || defined(FOG)
  float depth = vEyeDepth;
#endif
#ifdef DEPTH_CUE
  int dcMode = int(uDepthCue.x);
  if (dcMode != 0) {
    // z in VDC: +1 at the near plane, -1 at the far plane, linear in eye depth.
    float zv = (uDepth.x + uDepth.y - 2.0 * depth) / (uDepth.y - uDepth.x);
    float s;
    if (dcMode == 1) {
      float z = clamp((1.0 - zv) * 0.5, 0.0, 1.0);  // 0 at the front, 1 at the back
      s = 1.0 - z;
    } else {
      float front = uDepthCue.y;
      float back = uDepthCue.z;
      if (zv >= front) {
        s = uDepthCueScale.x;
      } else if (zv <= back) {
        s = uDepthCueScale.y;
      } else {
        s = mix(uDepthCueScale.y, uDepthCueScale.x, (zv - back) / (front - back));
      }
    }
    c = s * c + (1.0 - s) * uDepthCueColor.rgb;
  }
#endif
#ifdef FOG
  int fogMode = int(uFog.x);
  if (fogMode != 0) {
    float f;
    if (fogMode == 1) {
      f = (uFog.z - depth) / (uFog.z - uFog.y);
    } else if (fogMode == 2) {
      f = exp(-uFog.w * depth);
    } else {
      float dz = uFog.w * depth;
      f = exp(-dz * dz);
    }
    f = clamp(f, 0.0, 1.0);
    c = f * c + (1.0 - f) * uFogColor.rgb;
  }
#endif
  return c;
}

#if defined(RASTER_FETCH) || defined(RASTER_COPY)
// XGL/X11 raster operations on 8-bit channels.
uvec3 rasterOp(int op, uvec3 s, uvec3 d) {
  uvec3 m = uvec3(255u);
  switch (op) {
    case 0: return uvec3(0u);
    case 1: return m;
    case 2: return s;
    case 3: return ~s & m;
    case 4: return ~d & m;
    case 5: return s & d;
    case 6: return s & ~d & m;
    case 7: return ~s & d & m;
    case 8: return ~(s & d) & m;
    case 9: return s | d;
    case 10: return (s | ~d) & m;
    case 11: return (~s | d) & m;
    case 12: return ~(s | d) & m;
    case 13: return s ^ d;
    case 14: return ~(s ^ d) & m;
    default: return d;
  }
}
#endif

// Writes the final colour through the raster operation.
void writeColor(vec4 c) {
#if defined(RASTER_FETCH) || defined(RASTER_COPY)
#ifdef RASTER_FETCH
  vec3 dst = fragColor.rgb;
#else
  vec3 dst = texelFetch(uDestination, ivec2(gl_FragCoord.xy - uViewport.xy), 0).rgb;
#endif
  uvec3 s = uvec3(clamp(c.rgb, 0.0, 1.0) * 255.0 + 0.5);
  uvec3 d = uvec3(clamp(dst, 0.0, 1.0) * 255.0 + 0.5);
  fragColor = vec4(vec3(rasterOp(uRasterOp, s, d)) / 255.0, 1.0);
#else
  if (uRasterOp == 0) {
    fragColor = vec4(0.0, 0.0, 0.0, 1.0);
  } else if (uRasterOp == 1) {
    fragColor = vec4(1.0);
  } else if (uRasterOp == 4) {
    fragColor = vec4(1.0);  // blended as ONE_MINUS_DST_COLOR, ZERO: the destination inverted
  } else if (uRasterOp == 3) {
    fragColor = vec4((255.0 - floor(clamp(c.rgb, 0.0, 1.0) * 255.0 + 0.5)) / 255.0, c.a);
  } else {
    fragColor = c;
  }
#endif
}

#endif  // STAGE_FRAGMENT
