#version 300 es
// The border of a facet view: black, in the channels the colour mask lets through.
precision mediump float;

out vec4 fragColor;

void main() { fragColor = vec4(0.0, 0.0, 0.0, 1.0); }
