#version 300 es
// The border of a facet view (thesis §4.4.5) as geometry: the pieces of the viewport outside
// the facet's outline, in normalised device coordinates.
precision highp float;

layout(location = 0) in vec2 aPosition;

void main() { gl_Position = vec4(aPosition, 0.0, 1.0); }
