#version 300 es
// The Zoom picture: a stream's RGBA texture drawn flat over the scene.
precision highp float;

uniform sampler2D uPicture;
uniform float uOpacity;

in vec2 vUv;
out vec4 fragColor;

void main() { fragColor = vec4(texture(uPicture, vUv).rgb, uOpacity); }
