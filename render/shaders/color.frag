// Unlit geometry, fragment stage: the colour through the shared epilogue.

uniform vec4 uColor;

in vec4 vColor;

void main() {
  clipFragment();
  vec4 c = vColor.r < 0.0 ? uColor : vColor;
  c.rgb = atmosphere(c.rgb);
  writeColor(c);
}
