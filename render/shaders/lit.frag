#version 300 es
// Picks the front or back colour of a lit surface, smooth (per vertex) or flat (per facet).
precision highp float;
precision highp int;

in vec4 vFront;
in vec4 vBack;
flat in vec4 vFlatFront;
flat in vec4 vFlatBack;

uniform int uFlat;

out vec4 fragColor;

void main() {
  if (uFlat == 1) {
    fragColor = gl_FrontFacing ? vFlatFront : vFlatBack;
  } else {
    fragColor = gl_FrontFacing ? vFront : vBack;
  }
}
