// LAVA's markers (XGL's predefined marker types) at vertices: one point sprite each, the shape
// drawn by the fragment stage.

layout(location = 0) in vec3 aPosition;
layout(location = 2) in vec4 aColor;

uniform mat4 uModel;
uniform float uPointSize;  // sprite size in pixels (the marker size, plus a pixel each side to antialias)
uniform int uColorSource;

out vec4 vColor;

void main() {
  vec4 world = uModel * vec4(aPosition, 1.0);
  gl_Position = uViewProjection * world;
  gl_PointSize = uPointSize;
  passEffects(world.xyz);
  vColor = uColorSource == 1 ? aColor : vec4(-1.0);
}
