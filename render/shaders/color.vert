#version 300 es
// Unlit geometry in one colour: wireframe lines, edges and markers.
precision highp float;

layout(location = 0) in vec3 aPosition;

uniform mat4 uModel;
uniform mat4 uViewProjection;
uniform float uPointSize;

void main() {
  gl_Position = uViewProjection * uModel * vec4(aPosition, 1.0);
  gl_PointSize = uPointSize;
}
