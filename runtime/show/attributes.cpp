#include "runtime/show/attributes.h"

#include <cmath>
#include <cstring>
#include <type_traits>

namespace basalt::runtime {

static_assert(std::is_trivially_copyable_v<PartStyle>, "PartStyle must stay trivially copyable");
static_assert(std::is_standard_layout_v<PartStyle>, "the field table uses offsetof");

namespace {

// offsetof with a nested designator is supported by GCC and Clang for standard-layout types.
#define BASALT_NESTED(id, name, group, field)                                                   \
  AttrField {                                                                                   \
    AttrId::id, name, offsetof(PartStyle, group) + offsetof(decltype(PartStyle::group), field), \
        sizeof(decltype(PartStyle::group)::field)                                               \
  }

constexpr AttrField kFields[] = {
    BASALT_NESTED(kRenderPrimType, "render.prim_type", render, primType),
    BASALT_NESTED(kRenderFaceCulling, "render.face_culling", render, faceCulling),
    BASALT_NESTED(kRenderFaceDist, "render.face_dist", render, faceDistinguishing),
    BASALT_NESTED(kRenderRasterOp, "render.raster_op", render, rasterOp),
    BASALT_NESTED(kRenderHlhsrMode, "render.hlhsr_mode", render, hiddenSurfaceRemoval),
    BASALT_NESTED(kMarkersType, "markers.marker_type", markers, type),
    BASALT_NESTED(kMarkersColor, "markers.marker_color", markers, color),
    BASALT_NESTED(kMarkersAntialiasing, "markers.antialiasing", markers, antialiasing),
    BASALT_NESTED(kMarkersScaleFactor, "markers.scale_factor", markers, scaleFactor),
    BASALT_NESTED(kMarkersColorSelector, "markers.color_selector", markers, colorSelector),
    BASALT_NESTED(kLinesColor, "lines.line_color", lines, color),
    BASALT_NESTED(kLinesAntialiasing, "lines.antialiasing", lines, antialiasing),
    BASALT_NESTED(kLinesWidth, "lines.line_width", lines, width),
    BASALT_NESTED(kLinesEndpointStyle, "lines.endpoint_style", lines, endpointStyle),
    BASALT_NESTED(kLinesJoinStyle, "lines.join_style", lines, joinStyle),
    BASALT_NESTED(kLinesMiterLimit, "lines.miter_limit", lines, miterLimit),
    BASALT_NESTED(kLinesStyle, "lines.line_style", lines, style),
    BASALT_NESTED(kLinesPattern, "lines.line_pattern", lines, pattern),
    BASALT_NESTED(kLinesAltColor, "lines.alt_line_color", lines, altColor),
    BASALT_NESTED(kLinesColorSelector, "lines.color_selector", lines, colorSelector),
    BASALT_NESTED(kLinesColorInterp, "lines.color_interp", lines, colorInterpolation),
    BASALT_NESTED(kFrontColor, "front_surf.color", front, color),
    BASALT_NESTED(kFrontFillStyle, "front_surf.fill_style", front, fillStyle),
    BASALT_NESTED(kFrontStipplePattern, "front_surf.stipple_pattern", front, stipplePattern),
    BASALT_NESTED(kFrontColorSelector, "front_surf.color_selector", front, colorSelector),
    BASALT_NESTED(kFrontIllum, "front_surf.illum", front, illumination),
    BASALT_NESTED(kFrontLightComponent, "front_surf.light_component", front, lightComponents),
    BASALT_NESTED(kFrontAmbient, "front_surf.ambient", front, ambient),
    BASALT_NESTED(kFrontDiffuse, "front_surf.diffuse", front, diffuse),
    BASALT_NESTED(kFrontSpecular, "front_surf.specular", front, specular),
    BASALT_NESTED(kFrontSpecularColor, "front_surf.specular_color", front, specularColor),
    BASALT_NESTED(kFrontSpecularPower, "front_surf.specular_power", front, specularPower),
    BASALT_NESTED(kFrontTranspMethod, "front_surf.transp_method", front, transparencyMethod),
    BASALT_NESTED(kFrontTranspBlendEq, "front_surf.transp_blend_eq", front, transparencyBlend),
    BASALT_NESTED(kFrontTransparency, "front_surf.transparency", front, transparency),
    BASALT_NESTED(kBackColor, "back_surf.color", back, color),
    BASALT_NESTED(kBackFillStyle, "back_surf.fill_style", back, fillStyle),
    BASALT_NESTED(kBackStipplePattern, "back_surf.stipple_pattern", back, stipplePattern),
    BASALT_NESTED(kBackColorSelector, "back_surf.color_selector", back, colorSelector),
    BASALT_NESTED(kBackIllum, "back_surf.illum", back, illumination),
    BASALT_NESTED(kBackLightComponent, "back_surf.light_component", back, lightComponents),
    BASALT_NESTED(kBackAmbient, "back_surf.ambient", back, ambient),
    BASALT_NESTED(kBackDiffuse, "back_surf.diffuse", back, diffuse),
    BASALT_NESTED(kBackSpecular, "back_surf.specular", back, specular),
    BASALT_NESTED(kBackSpecularColor, "back_surf.specular_color", back, specularColor),
    BASALT_NESTED(kBackSpecularPower, "back_surf.specular_power", back, specularPower),
    BASALT_NESTED(kBackTranspMethod, "back_surf.transp_method", back, transparencyMethod),
    BASALT_NESTED(kBackTranspBlendEq, "back_surf.transp_blend_eq", back, transparencyBlend),
    BASALT_NESTED(kBackTransparency, "back_surf.transparency", back, transparency),
    BASALT_NESTED(kEdgesShow, "edges.show_edges", edges, show),
    BASALT_NESTED(kEdgesColor, "edges.edge_color", edges, color),
    BASALT_NESTED(kEdgesAntialiasing, "edges.antialiasing", edges, antialiasing),
    BASALT_NESTED(kEdgesWidth, "edges.edge_width", edges, width),
    BASALT_NESTED(kEdgesStyle, "edges.edge_style", edges, style),
    BASALT_NESTED(kEdgesPattern, "edges.edge_pattern", edges, pattern),
    BASALT_NESTED(kEdgesAltColor, "edges.alt_edge_color", edges, altColor),
    BASALT_NESTED(kEdgesSilhouette, "edges.silhouette", edges, silhouette),
    BASALT_NESTED(kEdgesSwOffset, "edges.sw_offset", edges, softwareOffset),
    BASALT_NESTED(kNurbsApproxMethod, "nurbs.approx_method", nurbs, approxMethod),
    BASALT_NESTED(kNurbsApproxValU, "nurbs.approx_val_u", nurbs, approxValueU),
    BASALT_NESTED(kNurbsApproxValV, "nurbs.approx_val_v", nurbs, approxValueV),
    BASALT_NESTED(kNurbsParamStyle, "nurbs.param_style", nurbs, paramStyle),
    BASALT_NESTED(kNurbsIsoCurvePlacement, "nurbs.iso_curve_placement", nurbs, isoCurvePlacement),
    BASALT_NESTED(kNurbsIsoCurvesU, "nurbs.iso_curves_u", nurbs, isoCurvesU),
    BASALT_NESTED(kNurbsIsoCurvesV, "nurbs.iso_curves_v", nurbs, isoCurvesV),
    BASALT_NESTED(kNurbsTessellation, "nurbs.tessellation", nurbs, tessellation),
    BASALT_NESTED(kFrontEmission, "front_surf.emission", front, emission),
    BASALT_NESTED(kFrontAmbientColor, "front_surf.ambient_color", front, ambientColor),
    BASALT_NESTED(kBackEmission, "back_surf.emission", back, emission),
    BASALT_NESTED(kBackAmbientColor, "back_surf.ambient_color", back, ambientColor),
};
#undef BASALT_NESTED

static_assert(std::size(kFields) == kAttrCount, "one AttrField per AttrId");

constexpr bool fieldsInIdOrder() {
  for (std::size_t i = 0; i < std::size(kFields); ++i) {
    if (static_cast<std::size_t>(kFields[i].id) != i) return false;
  }
  return true;
}
static_assert(fieldsInIdOrder(), "kFields must be listed in AttrId order");

}  // namespace

std::span<const AttrField> attrFields() { return kFields; }

const AttrField& attrField(AttrId id) { return kFields[static_cast<std::size_t>(id)]; }

void copyAttr(AttrId id, const PartStyle& from, PartStyle& to) {
  const AttrField& f = attrField(id);
  std::memcpy(reinterpret_cast<std::byte*>(&to) + f.offset, reinterpret_cast<const std::byte*>(&from) + f.offset,
              f.size);
}

PartStyle resolveStyle(const PartStyle& global, const PartStyle& own, const AttrMask& mask) {
  if (mask.none()) return global;
  PartStyle out = global;
  for (std::size_t i = 0; i < kAttrCount; ++i) {
    if (mask.test(i)) copyAttr(static_cast<AttrId>(i), own, out);
  }
  return out;
}

std::array<Light, kMaxLights> defaultLights() {
  std::array<Light, kMaxLights> lights{};
  // Light 0: ambient, white, on.
  lights[0].on = true;
  lights[0].type = LightType::kAmbient;
  lights[0].color = {1, 1, 1};
  // Lights 1 and 2: directional and on; a key light from upper right front, a dimmer fill from
  // the left, so that three faces of the start-up cube read differently.
  lights[1].on = true;
  lights[1].type = LightType::kDirectional;
  lights[1].color = {1, 1, 1};
  lights[1].direction = normalize(Vec3{-0.5f, -0.6f, -1.0f});
  lights[2].on = true;
  lights[2].type = LightType::kDirectional;
  lights[2].color = {0.5f, 0.5f, 0.5f};
  lights[2].direction = normalize(Vec3{1.0f, -0.2f, -0.5f});
  // Light 3: spot, off, above and in front, aimed at the origin.
  lights[3].type = LightType::kSpot;
  lights[3].position = {0, 2, 2};
  lights[3].direction = normalize(Vec3{0, -1, -1});
  lights[3].angle = 0.5f;
  lights[3].exponent = 10.0f;
  // Light 4: positional, off.
  lights[4].type = LightType::kPositional;
  lights[4].position = {2, 2, 2};
  // Lights 5..31: directional, off, colours around the hue circle, directions around the view.
  for (std::size_t i = 5; i < kMaxLights; ++i) {
    const float t = static_cast<float>(i - 5) / static_cast<float>(kMaxLights - 5);
    const float hue = t * 6.0f;
    const float x = 1.0f - std::fabs(std::fmod(hue, 2.0f) - 1.0f);
    Color3 c{};
    switch (static_cast<int>(hue)) {
      case 0: c = {1, x, 0}; break;
      case 1: c = {x, 1, 0}; break;
      case 2: c = {0, 1, x}; break;
      case 3: c = {0, x, 1}; break;
      case 4: c = {x, 0, 1}; break;
      default: c = {1, 0, x}; break;
    }
    const float angle = t * 2.0f * 3.14159265f;
    lights[i].type = LightType::kDirectional;
    lights[i].color = c;
    lights[i].direction = normalize(Vec3{std::cos(angle), std::sin(angle), -1.5f});
  }
  return lights;
}

std::array<ClipPlane, kMaxClipPlanes> ModelClipping::defaultClipPlanes() {
  // Each default plane passes near the centre with a different normal, so that enabling one
  // more plane visibly cuts most objects (as the manual asks).
  std::array<ClipPlane, kMaxClipPlanes> planes{};
  const Vec3 normals[6] = {{-1, 0, 0}, {0, -1, 0}, {0, 0, -1}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (std::size_t i = 0; i < kMaxClipPlanes; ++i) {
    const Vec3 n = i < 6 ? normals[i] : normalize(Vec3{std::cos(float(i)), std::sin(float(i)), 0.5f});
    planes[i].normal = n;
    planes[i].point = n * -0.25f;  // keep the part behind the plane's normal side beyond 0.25
  }
  return planes;
}

}  // namespace basalt::runtime
