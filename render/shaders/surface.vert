// Surfaces: XGL illumination of LAVA's front and back surface attributes.
//
// One shading #define picks where the light is computed (XGL "Illumination and Shading"):
//   SHADE_UNLIT_FLAT    illumination none: the material colour, one per facet
//   SHADE_UNLIT_SMOOTH  interpolated colour: vertex colours interpolated, no light
//   SHADE_FACET         per facet: one lighting calculation per polygon, at its first corner,
//                       with the polygon's normal (drawn from the de-indexed facet stream, whose
//                       vertices all carry both)
//   SHADE_VERTEX        per vertex (Gouraud): light at each vertex, colours interpolated
//   SHADE_PIXEL         per pixel: normals interpolated, light at each pixel (beyond XGL)
// TWO_SIDED lights back faces with the back surface and the normal reversed (face
// distinguishing); without it both sides take the front surface's colour. TEXTURE and
// SPHERE_MAP pass what the fragment stage samples.

layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aNormal;  // the facet normal in the facet stream
layout(location = 2) in vec4 aColor;   // vertex colour (facet colour in the facet stream)
layout(location = 3) in vec2 aTexcoord;
layout(location = 4) in vec3 aFacetPoint;  // the facet stream: the polygon's lit corner

uniform mat4 uModel;
uniform mat3 uNormalMatrix;
uniform Surface uFront;
uniform Surface uBack;
uniform int uColorSource;  // 0: the surface colour, 1: the vertex (or facet) colour
uniform int uBackLit;      // 1: light back faces (TWO_SIDED)
uniform vec2 uTexcoordFlip;  // t' = y + x * t: images are stored top row first
uniform int uFacetStream;    // 1: drawing the de-indexed facet stream

#if defined(SHADE_FACET) || defined(SHADE_UNLIT_FLAT)
flat out vec4 vFront;
#ifdef TWO_SIDED
flat out vec4 vBack;
#endif
#elif defined(SHADE_VERTEX) || defined(SHADE_UNLIT_SMOOTH)
out vec4 vFront;
#ifdef TWO_SIDED
out vec4 vBack;
#endif
#else
out vec3 vWorld;
out vec3 vNormal;
out vec4 vColor;  // Od, and the alpha of the front surface
#endif
#ifdef TEXTURE
out vec2 vTexcoord;
#endif
#ifdef SPHERE_MAP
out vec3 vEyePosition;
out vec3 vEyeNormal;
#endif

void main() {
  vec4 world = uModel * vec4(aPosition, 1.0);
  gl_Position = uViewProjection * world;
  passEffects(world.xyz);
  vec3 N = normalize(uNormalMatrix * aNormal);
  vec3 frontOd = uColorSource == 1 ? aColor.rgb : uFront.color;
#ifdef TWO_SIDED
  vec3 backOd = uColorSource == 1 ? aColor.rgb : uBack.color;
#endif

#if defined(SHADE_UNLIT_FLAT) || defined(SHADE_UNLIT_SMOOTH)
  vFront = vec4(frontOd, uFront.alpha);
#ifdef TWO_SIDED
  vBack = vec4(backOd, uBack.alpha);
#endif
#elif defined(SHADE_FACET) || defined(SHADE_VERTEX)
#ifdef SHADE_FACET
  // GLES takes a flat value from the last vertex of each triangle: in the facet stream (three
  // vertices per triangle, in order) light only that one, at the polygon's lit corner, so that
  // every triangle of a polygon gets the same colour.
  bool provoking = uFacetStream == 0 || (gl_VertexID % 3) == 2;
  vec3 litPoint = uFacetStream == 1 ? (uModel * vec4(aFacetPoint, 1.0)).xyz : world.xyz;
#else
  bool provoking = true;
  vec3 litPoint = world.xyz;
#endif
  vec3 E = normalize(uEye.xyz - litPoint);
  vFront = vec4(0.0, 0.0, 0.0, uFront.alpha);
#ifdef TWO_SIDED
  vBack = vec4(0.0, 0.0, 0.0, uBack.alpha);
#endif
  if (provoking) {
    vFront.rgb = illuminate(litPoint, N, E, uFront, frontOd);
#ifdef TWO_SIDED
    vBack.rgb = uBackLit == 1 ? illuminate(litPoint, -N, E, uBack, backOd) : backOd;
#endif
  }
#else
  vWorld = world.xyz;
  vNormal = N;
  vColor = vec4(uColorSource == 1 ? aColor.rgb : vec3(-1.0), uFront.alpha);
#endif

#ifdef TEXTURE
  vTexcoord = vec2(aTexcoord.x, uTexcoordFlip.y + uTexcoordFlip.x * aTexcoord.y);
#endif
#ifdef SPHERE_MAP
  vEyePosition = (uView * world).xyz;
  vEyeNormal = mat3(uView) * N;
#endif
}
