// Unlit geometry in one colour (or its vertex colours): one-pixel solid lines, hollow fill, the
// fake shadow's stencil pass.

layout(location = 0) in vec3 aPosition;
layout(location = 2) in vec4 aColor;

uniform mat4 uModel;
uniform int uColorSource;     // 0: uColor, 1: the vertex colours
uniform float uDepthOffset;   // NDC depth moved towards the viewer (software edges)

out vec4 vColor;

void main() {
  vec4 world = uModel * vec4(aPosition, 1.0);
  vec4 clip = uViewProjection * world;
  clip.z -= uDepthOffset * clip.w;
  gl_Position = clip;
  passEffects(world.xyz);
  vColor = uColorSource == 1 ? aColor : vec4(-1.0);
}
