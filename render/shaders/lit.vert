#version 300 es
// Basalt's lit surface vertex stage: the XGL lighting model (XGL Programmer's Guide ch. 16)
// evaluated per vertex, for the front and the back side of each vertex. Per-facet illumination
// uses the same values through flat varyings (the provoking vertex carries the facet normal).
precision highp float;
precision highp int;

layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aNormal;
layout(location = 2) in vec4 aColor;

uniform mat4 uModel;
uniform mat4 uViewProjection;
uniform mat3 uNormalMatrix;
uniform vec3 uEye;           // world coordinates
uniform int uLit;            // 0: colour only (illumination none / interp colour)
uniform int uUseVertexColor; // 1: Od comes from the vertex colour

struct Surface {
  vec3 color;          // Od
  vec3 specularColor;  // Os
  float ka;
  float kd;
  float ks;
  float power;         // Se
  int components;      // bit 0 ambient, 1 diffuse, 2 specular
  float alpha;         // 1 - transparency
};
uniform Surface uFront;
uniform Surface uBack;

const int kMaxLights = 32;
uniform int uLightCount;
uniform vec4 uLightColor[kMaxLights];      // rgb colour, w: type (0 ambient 1 directional 2 positional 3 spot)
uniform vec4 uLightPosition[kMaxLights];   // xyz position, w: attenuation c1
uniform vec4 uLightDirection[kMaxLights];  // xyz unit direction of travel, w: attenuation c2
uniform vec2 uLightSpot[kMaxLights];       // x: cos(cut-off angle), y: exponent

out vec4 vFront;
out vec4 vBack;
flat out vec4 vFlatFront;
flat out vec4 vFlatBack;

vec3 illuminate(vec3 P, vec3 N, vec3 E, Surface s, vec3 Od) {
  vec3 sum = vec3(0.0);
  for (int i = 0; i < uLightCount; ++i) {
    int type = int(uLightColor[i].w);
    vec3 Lc = uLightColor[i].rgb;
    if (type == 0) {
      if ((s.components & 1) != 0) sum += s.ka * Od * Lc;
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
    if (NdotL <= 0.0) continue;  // negative dot products count as zero: no diffuse, no highlight
    vec3 c = vec3(0.0);
    if ((s.components & 2) != 0) c += s.kd * Od * Lc * NdotL;
    if ((s.components & 4) != 0) {
      vec3 R = 2.0 * NdotL * N - L;
      c += s.ks * s.specularColor * Lc * pow(max(dot(E, R), 0.0), s.power);
    }
    sum += attenuation * c;
  }
  return clamp(sum, 0.0, 1.0);
}

void main() {
  vec4 world = uModel * vec4(aPosition, 1.0);
  gl_Position = uViewProjection * world;
  vec3 P = world.xyz;
  vec3 N = normalize(uNormalMatrix * aNormal);
  vec3 E = normalize(uEye - P);
  vec3 frontOd = uUseVertexColor == 1 ? aColor.rgb : uFront.color;
  vec3 backOd = uUseVertexColor == 1 ? aColor.rgb : uBack.color;
  vec4 front;
  vec4 back;
  if (uLit == 1) {
    front = vec4(illuminate(P, N, E, uFront, frontOd), uFront.alpha);
    back = vec4(illuminate(P, -N, E, uBack, backOd), uBack.alpha);
  } else {
    front = vec4(frontOd, uFront.alpha);
    back = vec4(backOd, uBack.alpha);
  }
  vFront = front;
  vBack = back;
  vFlatFront = front;
  vFlatBack = back;
}
