// What is drawn behind the scene: one triangle that covers the viewport.

out vec2 vNdc;

void main() {
  vec2 corner = vec2(float((gl_VertexID & 1) << 2) - 1.0, float((gl_VertexID & 2) << 1) - 1.0);
  vNdc = corner;
  gl_Position = vec4(corner, 1.0, 1.0);
}
