#include "runtime/script/command_table.h"

#include <algorithm>
#include <cstring>
#include <unordered_map>
#include <vector>

#include <fmt/format.h>

#include "runtime/script/lexer.h"

namespace basalt::script {

using runtime::AttrId;
using runtime::Show;

namespace {

// ---- Choices, in the order of the attribute enums (runtime/show/attributes.h) ---------------

constexpr std::string_view kOffOn[] = {"off", "on"};
constexpr std::string_view kPrimTypes[] = {"wireframe", "markers", "solid"};
constexpr std::string_view kFaceCulling[] = {"off", "back", "front"};
constexpr std::string_view kRasterOps[] = {"clear",       "set",     "copy",  "copy_inv", "invert",     "and",
                                           "and_reverse", "and_inv", "nand",  "or",       "or_reverse", "or_inv",
                                           "nor",         "xor",     "equiv", "noop"};
constexpr std::string_view kMarkerTypes[] = {"dot",   "plus",   "asterisk",  "circle",
                                             "cross", "square", "bowtie_ne", "bowtie_nw"};
constexpr std::string_view kAntialiasing[] = {"off", "constant_bg", "arbitrary_bg"};
constexpr std::string_view kColorSelectors[] = {"context", "vertex"};
constexpr std::string_view kEndpoints[] = {"butt", "square", "round"};
constexpr std::string_view kJoins[] = {"device", "bevel", "miter"};
constexpr std::string_view kLineStyles[] = {"solid", "patterned", "alt_patterned"};
constexpr std::string_view kLinePatterns[] = {"dotted",     "dashed",   "dashed_dotted",   "cgm_dotted",
                                              "cgm_dashed", "dash_dot", "dash_dot_dotted", "long_dashed"};
constexpr std::string_view kFillStyles[] = {"solid", "hollow", "empty", "opaque_stipple", "stipple", "pattern"};
constexpr std::string_view kStipples[] = {"horizontal",  "vertical",     "diag_45",    "diag_135",
                                          "grid_r",      "grid_d",       "horiz_dbl",  "vert_dbl",
                                          "diag_45_dbl", "diag_135_dbl", "grid_r_dbl", "grid_d_dbl"};
constexpr std::string_view kSurfaceSelectors[] = {"context", "facet", "illum_dep", "illum_indep"};
constexpr std::string_view kIllumination[] = {"none", "interp_color", "per_facet", "per_vertex", "per_pixel"};
constexpr std::string_view kLightComponents[] = {"ambient", "diffuse", "specular"};
constexpr std::string_view kTranspMethods[] = {"none", "screen_door", "blended"};
constexpr std::string_view kTranspBlends[] = {"none", "arbitrary_bg", "constant_bg", "add_to_bg"};
constexpr std::string_view kEdgeModes[] = {"off", "on", "software"};
constexpr std::string_view kApproxMethods[] = {"const_param_subdiv_between_knots",
                                               "metric_wc",
                                               "metric_vdc",
                                               "metric_dc",
                                               "chordal_deviation_wc",
                                               "chordal_deviation_vdc",
                                               "chordal_deviation_dc",
                                               "relative_wc",
                                               "relative_vdc",
                                               "relative_dc"};
constexpr std::string_view kParamStyles[] = {"iso_curves", "show_tess", "incr_silh_tess"};
constexpr std::string_view kIsoPlacement[] = {"between_knots", "between_limits"};
constexpr std::string_view kTessellation[] = {"dynamic", "combine", "static"};
constexpr std::string_view kLightTypes[] = {"ambient", "directional", "positional", "spot"};
constexpr std::string_view kDepthCueModes[] = {"none", "linear", "scaled"};
constexpr std::string_view kTextureSources[] = {"off", "image", "video"};
constexpr std::string_view kTextureMethods[] = {"pixel", "vertex_level"};
constexpr std::string_view kTextureApprox[] = {"num_seg", "pixel_tol", "combined"};
constexpr std::string_view kAnnotationStyles[] = {"normal", "line"};
constexpr std::string_view kHorizontal[] = {"normal", "right", "left", "center"};
constexpr std::string_view kVertical[] = {"normal", "base", "bottom", "top", "half", "cap"};
constexpr std::string_view kTextPaths[] = {"right", "left", "up", "down"};
constexpr std::string_view kDeferral[] = {"asti", "asap"};
constexpr std::string_view kObjectCenters[] = {"use_slider", "plus_x", "minus_x", "plus_y",
                                               "minus_y",    "plus_z", "minus_z", "none"};
constexpr std::string_view kObjectScales[] = {"half_screen", "full_screen", "original"};
constexpr std::string_view kFloors[] = {"none", "single_square", "coarse_grid", "fine_grid"};
constexpr std::string_view kFloorPrims[] = {"solid", "wireframe"};

// ---- A small builder so that each command is one readable line -----------------------------

class Def {
 public:
  explicit Def(std::string_view name) { d_.name = name; }
  operator CommandDef() const { return d_; }  // NOLINT(google-explicit-constructor): table rows

  Def& part(AttrId attr) {
    d_.syntax = Syntax::kAssignment;
    d_.scope = Scope::kPart;
    d_.attr = attr;
    return *this;
  }
  Def& slot(SlotFn fn) {
    d_.syntax = Syntax::kAssignment;
    d_.slot = fn;
    return *this;
  }
  Def& assignment() {
    d_.syntax = Syntax::kAssignment;
    return *this;
  }
  Def& indexed(std::uint8_t count) {
    d_.scope = Scope::kIndexed;
    d_.indexCount = count;
    return *this;
  }
  Def& oneOf(std::span<const std::string_view> choices) {
    d_.kind = ValueKind::kEnum;
    d_.count = 1;
    d_.choices = choices;
    return *this;
  }
  Def& onOff() {
    d_.kind = ValueKind::kBool;
    d_.count = 1;
    d_.choices = kOffOn;
    return *this;
  }
  Def& flags(std::span<const std::string_view> choices) {
    d_.kind = ValueKind::kFlags;
    d_.count = 1;
    d_.choices = choices;
    return *this;
  }
  Def& floats(std::uint8_t count) {
    d_.kind = ValueKind::kFloat;
    d_.count = count;
    return *this;
  }
  Def& integer(double min, double max) {
    d_.kind = ValueKind::kInt;
    d_.count = 1;
    d_.min = min;
    d_.max = max;
    return *this;
  }
  Def& range(double min, double max) {
    d_.min = min;
    d_.max = max;
    return *this;
  }
  Def& rotation() {
    d_.noOpEquals = true;
    return *this;
  }
  Def& action(Action a) {
    d_.action = a;
    return *this;
  }
  Def& argument(ValueKind kind, bool optional = false) {
    d_.syntax = optional ? Syntax::kOptionalArgument : Syntax::kArgument;
    d_.kind = kind;
    d_.count = 1;
    return *this;
  }
  Def& axis(std::uint8_t a) {
    d_.axis = a;
    return *this;
  }
  Def& tv(TvOp op) {
    d_.action = Action::kTv;
    d_.tv = op;
    d_.origin = Origin::kBasalt;
    return *this;
  }
  Def& feature(Feature f) {
    d_.feature = f;
    return *this;
  }
  Def& menu() {
    d_.origin = Origin::kManualMenu;
    return *this;
  }
  Def& noEffect(std::string_view why) {
    d_.action = Action::kNoOp;
    d_.noEffect = why;
    return *this;
  }
  Def& doc(std::string_view summary) {
    d_.summary = summary;
    return *this;
  }

 private:
  CommandDef d_;
};

// Storage of global-only settings. `i` is the light or clip-plane index for indexed commands.
#define BASALT_SLOT(expr) ([](Show& s, int i) -> void* { return (void)i, static_cast<void*>(&(expr)); })
#define BASALT_LIGHT(field) BASALT_SLOT(s.lights()[static_cast<std::size_t>(i)].field)
#define BASALT_PLANE(field) BASALT_SLOT(s.modelClipping().planes[static_cast<std::size_t>(i)].field)

constexpr auto kLights = static_cast<std::uint8_t>(runtime::kMaxLights);
constexpr auto kPlanes = static_cast<std::uint8_t>(runtime::kMaxClipPlanes);
constexpr double kIntMax = 2147483647.0;

/// The per-part groups of both surfaces: identical except for the attribute ids.
struct SurfaceIds {
  AttrId color, fill, stipple, selector, illum, components, ambient, diffuse, specular, specularColor, power;
};

void addSurface(std::vector<CommandDef>& t, const char* const names[11], const SurfaceIds& ids) {
  t.push_back(Def(names[0]).part(ids.color).floats(3).doc("surface colour, red green blue"));
  t.push_back(
      Def(names[1]).part(ids.fill).oneOf(kFillStyles).feature(Feature::kFillStyle).doc("how solids are filled"));
  t.push_back(Def(names[2])
                  .part(ids.stipple)
                  .oneOf(kStipples)
                  .feature(Feature::kFillStyle)
                  .doc("pattern of the stipple fills"));
  t.push_back(Def(names[3])
                  .part(ids.selector)
                  .oneOf(kSurfaceSelectors)
                  .feature(Feature::kColorSelector)
                  .doc("where the surface colour comes from"));
  t.push_back(
      Def(names[4])
          .part(ids.illum)
          .oneOf(kIllumination)
          .doc("illumination: none, vertex colours, flat (per facet), Gouraud (per vertex); per_pixel is Basalt's"));
  t.push_back(Def(names[5])
                  .part(ids.components)
                  .flags(kLightComponents)
                  .doc("which light components are used: zero or more of the three"));
  t.push_back(Def(names[6]).part(ids.ambient).floats(1).doc("ambient reflection coefficient"));
  t.push_back(Def(names[7]).part(ids.diffuse).floats(1).doc("diffuse reflection coefficient"));
  t.push_back(Def(names[8]).part(ids.specular).floats(1).doc("specular reflection coefficient"));
  t.push_back(Def(names[9]).part(ids.specularColor).floats(3).doc("colour of the specular highlight"));
  t.push_back(Def(names[10]).part(ids.power).floats(1).doc("specular power: larger is a smaller highlight"));
}

std::vector<CommandDef> buildTable() {
  std::vector<CommandDef> t;
  t.reserve(200);

  // Part selection.
  t.push_back(Def("part.select").argument(ValueKind::kPartName).action(Action::kPartSelect).doc("display a part"));
  t.push_back(Def("part.deselect").argument(ValueKind::kPartName).action(Action::kPartDeselect).doc("hide a part"));
  t.push_back(Def("part.select_all").action(Action::kSelectAll).doc("display every part"));
  t.push_back(Def("part.deselect_all").action(Action::kDeselectAll).doc("hide every part"));

  // Render options.
  t.push_back(Def("render.prim_type")
                  .part(AttrId::kRenderPrimType)
                  .oneOf(kPrimTypes)
                  .doc("draw as wireframe, markers at the vertices, or solid"));
  t.push_back(Def("render.face_culling")
                  .part(AttrId::kRenderFaceCulling)
                  .oneOf(kFaceCulling)
                  .doc("faces not drawn: none, back faces or front faces"));
  t.push_back(
      Def("render.face_dist").part(AttrId::kRenderFaceDist).onOff().doc("back faces use the back_surf attributes"));
  t.push_back(Def("render.raster_op")
                  .part(AttrId::kRenderRasterOp)
                  .oneOf(kRasterOps)
                  .feature(Feature::kRasterOp)
                  .doc("raster operation with the picture below"));
  t.push_back(Def("render.hlhsr_mode")
                  .part(AttrId::kRenderHlhsrMode)
                  .onOff()
                  .doc("hidden line and hidden surface removal (the depth test)"));

  // Markers.
  t.push_back(Def("markers.marker_type")
                  .part(AttrId::kMarkersType)
                  .oneOf(kMarkerTypes)
                  .feature(Feature::kMarkerShapes)
                  .doc("the marker drawn at each vertex"));
  t.push_back(Def("markers.marker_color").part(AttrId::kMarkersColor).floats(3).doc("marker colour, red green blue"));
  t.push_back(Def("markers.antialiasing")
                  .part(AttrId::kMarkersAntialiasing)
                  .oneOf(kAntialiasing)
                  .feature(Feature::kAntialiasing)
                  .doc("marker antialiasing"));
  t.push_back(Def("markers.scale_factor")
                  .part(AttrId::kMarkersScaleFactor)
                  .floats(1)
                  .range(0, kIntMax)
                  .doc("marker size in pixels (not for dots)"));
  t.push_back(Def("markers.color_selector")
                  .part(AttrId::kMarkersColorSelector)
                  .oneOf(kColorSelectors)
                  .feature(Feature::kColorSelector)
                  .doc("markers in the part colour or the vertex colour"));

  // Lines.
  t.push_back(Def("lines.line_color").part(AttrId::kLinesColor).floats(3).doc("line colour, red green blue"));
  t.push_back(Def("lines.antialiasing")
                  .part(AttrId::kLinesAntialiasing)
                  .oneOf(kAntialiasing)
                  .feature(Feature::kAntialiasing)
                  .doc("line antialiasing"));
  t.push_back(
      Def("lines.line_width").part(AttrId::kLinesWidth).floats(1).range(0, kIntMax).doc("line width in pixels"));
  t.push_back(Def("lines.endpoint_style")
                  .part(AttrId::kLinesEndpointStyle)
                  .oneOf(kEndpoints)
                  .feature(Feature::kLineStyle)
                  .doc("ends of wide lines"));
  t.push_back(Def("lines.join_style")
                  .part(AttrId::kLinesJoinStyle)
                  .oneOf(kJoins)
                  .feature(Feature::kLineStyle)
                  .doc("joins of wide lines"));
  t.push_back(Def("lines.miter_limit")
                  .part(AttrId::kLinesMiterLimit)
                  .floats(1)
                  .feature(Feature::kLineStyle)
                  .doc("miter limit of mitered joins"));
  t.push_back(Def("lines.line_style")
                  .part(AttrId::kLinesStyle)
                  .oneOf(kLineStyles)
                  .feature(Feature::kLineStyle)
                  .doc("solid, patterned, or patterned in two colours"));
  t.push_back(Def("lines.line_pattern")
                  .part(AttrId::kLinesPattern)
                  .oneOf(kLinePatterns)
                  .feature(Feature::kLineStyle)
                  .doc("pattern of patterned lines"));
  t.push_back(Def("lines.alt_line_color")
                  .part(AttrId::kLinesAltColor)
                  .floats(3)
                  .feature(Feature::kLineStyle)
                  .doc("second colour of alt_patterned lines"));
  t.push_back(Def("lines.color_selector")
                  .part(AttrId::kLinesColorSelector)
                  .oneOf(kColorSelectors)
                  .feature(Feature::kColorSelector)
                  .doc("lines in the part colour or the vertex colours"));
  t.push_back(Def("lines.color_interp")
                  .part(AttrId::kLinesColorInterp)
                  .onOff()
                  .feature(Feature::kColorInterpolation)
                  .doc("interpolate vertex colours along lines"));

  // Front and back surfaces.
  static const char* const kFront[] = {
      "front_surf.color",    "front_surf.fill_style",      "front_surf.stipple_pattern", "front_surf.color_selector",
      "front_surf.illum",    "front_surf.light_component", "front_surf.ambient",         "front_surf.diffuse",
      "front_surf.specular", "front_surf.specular_color",  "front_surf.specular_power"};
  addSurface(t, kFront,
             {AttrId::kFrontColor, AttrId::kFrontFillStyle, AttrId::kFrontStipplePattern, AttrId::kFrontColorSelector,
              AttrId::kFrontIllum, AttrId::kFrontLightComponent, AttrId::kFrontAmbient, AttrId::kFrontDiffuse,
              AttrId::kFrontSpecular, AttrId::kFrontSpecularColor, AttrId::kFrontSpecularPower});
  t.push_back(Def("front_surf.transp_method")
                  .part(AttrId::kFrontTranspMethod)
                  .oneOf(kTranspMethods)
                  .feature(Feature::kTransparency)
                  .doc("transparency method (back faces use the front's)"));
  t.push_back(Def("front_surf.transp_blend_eq")
                  .part(AttrId::kFrontTranspBlendEq)
                  .oneOf(kTranspBlends)
                  .feature(Feature::kTransparency)
                  .doc("blending of blended transparency"));
  t.push_back(Def("front_surf.transparency")
                  .part(AttrId::kFrontTransparency)
                  .floats(1)
                  .range(0, 1)
                  .feature(Feature::kTransparency)
                  .doc("0 opaque to 1 fully transparent"));
  static const char* const kBack[] = {
      "back_surf.color",    "back_surf.fill_style",      "back_surf.stipple_pattern", "back_surf.color_selector",
      "back_surf.illum",    "back_surf.light_component", "back_surf.ambient",         "back_surf.diffuse",
      "back_surf.specular", "back_surf.specular_color",  "back_surf.specular_power"};
  addSurface(t, kBack,
             {AttrId::kBackColor, AttrId::kBackFillStyle, AttrId::kBackStipplePattern, AttrId::kBackColorSelector,
              AttrId::kBackIllum, AttrId::kBackLightComponent, AttrId::kBackAmbient, AttrId::kBackDiffuse,
              AttrId::kBackSpecular, AttrId::kBackSpecularColor, AttrId::kBackSpecularPower});

  // Edges.
  t.push_back(Def("edges.show_edges")
                  .part(AttrId::kEdgesShow)
                  .oneOf(kEdgeModes)
                  .feature(Feature::kEdges)
                  .doc("draw polygon edges over solids (software: LAVA's menu choice)"));
  t.push_back(Def("edges.edge_color")
                  .part(AttrId::kEdgesColor)
                  .floats(3)
                  .feature(Feature::kEdges)
                  .doc("edge colour, red green blue"));
  t.push_back(Def("edges.antialiasing")
                  .part(AttrId::kEdgesAntialiasing)
                  .oneOf(kAntialiasing)
                  .feature(Feature::kEdges)
                  .doc("edge antialiasing"));
  t.push_back(Def("edges.edge_width")
                  .part(AttrId::kEdgesWidth)
                  .floats(1)
                  .range(0, kIntMax)
                  .feature(Feature::kEdges)
                  .doc("edge width in pixels"));
  t.push_back(Def("edges.edge_style")
                  .part(AttrId::kEdgesStyle)
                  .oneOf(kLineStyles)
                  .feature(Feature::kEdges)
                  .doc("solid, patterned, or patterned in two colours"));
  t.push_back(Def("edges.edge_pattern")
                  .part(AttrId::kEdgesPattern)
                  .oneOf(kLinePatterns)
                  .feature(Feature::kEdges)
                  .doc("pattern of patterned edges"));
  t.push_back(Def("edges.alt_edge_color")
                  .part(AttrId::kEdgesAltColor)
                  .floats(3)
                  .feature(Feature::kEdges)
                  .doc("second colour of alt_patterned edges"));
  t.push_back(
      Def("edges.silhouette").part(AttrId::kEdgesSilhouette).onOff().feature(Feature::kEdges).doc("silhouette edges"));
  t.push_back(Def("edges.sw_offset")
                  .part(AttrId::kEdgesSwOffset)
                  .floats(1)
                  .feature(Feature::kEdges)
                  .menu()
                  .doc("depth offset of software edges"));

  // NURBS.
  t.push_back(Def("nurbs.approx_method")
                  .part(AttrId::kNurbsApproxMethod)
                  .oneOf(kApproxMethods)
                  .feature(Feature::kNurbs)
                  .doc("how NURBS are tessellated"));
  t.push_back(Def("nurbs.approx_val_u")
                  .part(AttrId::kNurbsApproxValU)
                  .floats(1)
                  .feature(Feature::kNurbs)
                  .doc("approximation value in U"));
  t.push_back(Def("nurbs.approx_val_v")
                  .part(AttrId::kNurbsApproxValV)
                  .floats(1)
                  .feature(Feature::kNurbs)
                  .doc("approximation value in V"));
  t.push_back(Def("nurbs.param_style")
                  .part(AttrId::kNurbsParamStyle)
                  .flags(kParamStyles)
                  .feature(Feature::kNurbs)
                  .doc("zero or more of the three"));
  t.push_back(Def("nurbs.iso_curve_placement")
                  .part(AttrId::kNurbsIsoCurvePlacement)
                  .oneOf(kIsoPlacement)
                  .feature(Feature::kNurbs)
                  .doc("iso curves between knots or limits"));
  t.push_back(Def("nurbs.iso_curves_u")
                  .part(AttrId::kNurbsIsoCurvesU)
                  .integer(0, kIntMax)
                  .feature(Feature::kNurbs)
                  .doc("iso curves in U"));
  t.push_back(Def("nurbs.iso_curves_v")
                  .part(AttrId::kNurbsIsoCurvesV)
                  .integer(0, kIntMax)
                  .feature(Feature::kNurbs)
                  .doc("iso curves in V"));
  t.push_back(Def("nurbs.tessellation")
                  .part(AttrId::kNurbsTessellation)
                  .oneOf(kTessellation)
                  .feature(Feature::kNurbs)
                  .menu()
                  .doc("tessellation method"));

  // Picking (global only from here on).
  t.push_back(Def("picking.picking")
                  .slot(BASALT_SLOT(s.picking().enabled))
                  .onOff()
                  .feature(Feature::kPicking)
                  .doc("pick parts or facets with the pointer"));
  t.push_back(Def("picking.part_highlight_color")
                  .slot(BASALT_SLOT(s.picking().partHighlight))
                  .floats(3)
                  .feature(Feature::kPicking)
                  .doc("colour of picked parts"));
  t.push_back(Def("picking.facet_highlight_color")
                  .slot(BASALT_SLOT(s.picking().facetHighlight))
                  .floats(3)
                  .feature(Feature::kPicking)
                  .doc("colour of picked facets"));
  t.push_back(Def("picking.pick_aperture")
                  .slot(BASALT_SLOT(s.picking().aperture))
                  .integer(0, 4096)
                  .feature(Feature::kPicking)
                  .doc("pixels around the pointer that pick"));

  // Lighting.
  t.push_back(Def("lighting.switch").slot(BASALT_LIGHT(on)).indexed(kLights).onOff().doc("light N on or off"));
  t.push_back(Def("lighting.type").slot(BASALT_LIGHT(type)).indexed(kLights).oneOf(kLightTypes).doc("kind of light N"));
  t.push_back(Def("lighting.color").slot(BASALT_LIGHT(color)).indexed(kLights).floats(3).doc("colour of light N"));
  t.push_back(Def("lighting.direction")
                  .slot(BASALT_LIGHT(direction))
                  .indexed(kLights)
                  .floats(3)
                  .doc("direction light N travels (directional and spot)"));
  t.push_back(Def("lighting.position")
                  .slot(BASALT_LIGHT(position))
                  .indexed(kLights)
                  .floats(3)
                  .doc("position of light N (positional and spot)"));
  t.push_back(Def("lighting.atten_1")
                  .slot(BASALT_LIGHT(attenuation1))
                  .indexed(kLights)
                  .floats(1)
                  .doc("constant attenuation coefficient"));
  t.push_back(Def("lighting.atten_2")
                  .slot(BASALT_LIGHT(attenuation2))
                  .indexed(kLights)
                  .floats(1)
                  .doc("distance attenuation coefficient"));
  t.push_back(
      Def("lighting.angle").slot(BASALT_LIGHT(angle)).indexed(kLights).floats(1).doc("spot cut-off angle, radians"));
  t.push_back(Def("lighting.exponent")
                  .slot(BASALT_LIGHT(exponent))
                  .indexed(kLights)
                  .floats(1)
                  .doc("spot concentration exponent"));

  // Depth cue.
  t.push_back(Def("depth_cue.mode")
                  .slot(BASALT_SLOT(s.depthCue().mode))
                  .oneOf(kDepthCueModes)
                  .feature(Feature::kDepthCue)
                  .doc("depth cueing: none, linear or scaled"));
  t.push_back(Def("depth_cue.color")
                  .slot(BASALT_SLOT(s.depthCue().color))
                  .floats(3)
                  .feature(Feature::kDepthCue)
                  .doc("colour far objects fade to"));
  t.push_back(Def("depth_cue.front_ref_plane")
                  .slot(BASALT_SLOT(s.depthCue().frontRefPlane))
                  .floats(1)
                  .feature(Feature::kDepthCue)
                  .doc("front reference plane (above the back one)"));
  t.push_back(Def("depth_cue.back_ref_plane")
                  .slot(BASALT_SLOT(s.depthCue().backRefPlane))
                  .floats(1)
                  .feature(Feature::kDepthCue)
                  .doc("back reference plane"));
  t.push_back(Def("depth_cue.max_scale")
                  .slot(BASALT_SLOT(s.depthCue().maxScale))
                  .floats(1)
                  .feature(Feature::kDepthCue)
                  .doc("object colour fraction at the front plane"));
  t.push_back(Def("depth_cue.min_scale")
                  .slot(BASALT_SLOT(s.depthCue().minScale))
                  .floats(1)
                  .feature(Feature::kDepthCue)
                  .doc("object colour fraction at the back plane"));
  t.push_back(Def("depth_cue.use_bg_color")
                  .slot(BASALT_SLOT(s.depthCue().useBackgroundColor))
                  .onOff()
                  .feature(Feature::kDepthCue)
                  .menu()
                  .doc("fade to the background colour instead"));

  // Texture.
  t.push_back(Def("texture.switch")
                  .slot(BASALT_SLOT(s.texture().source))
                  .oneOf(kTextureSources)
                  .feature(Feature::kTexture)
                  .doc("texture source: off, an image or video"));
  t.push_back(Def("texture.binding")
                  .noEffect("Basalt binds textures to parts automatically, as LAVA did")
                  .doc("performs texture binding"));
  t.push_back(Def("texture.approx")
                  .slot(BASALT_SLOT(s.texture().approx))
                  .oneOf(kTextureApprox)
                  .feature(Feature::kTexture)
                  .doc("vertex-level subdivision criterion"));
  t.push_back(Def("texture.subseg")
                  .slot(BASALT_SLOT(s.texture().subsegments))
                  .integer(0, kIntMax)
                  .feature(Feature::kTexture)
                  .doc("subsegments for num_seg"));
  t.push_back(Def("texture.pixel_tol")
                  .slot(BASALT_SLOT(s.texture().pixelTolerance))
                  .integer(0, kIntMax)
                  .feature(Feature::kTexture)
                  .doc("pixel tolerance for pixel_tol"));
  t.push_back(Def("texture.tau_func")
                  .slot(BASALT_SLOT(s.texture().tauFunction))
                  .integer(-kIntMax, kIntMax)
                  .feature(Feature::kTexture)
                  .doc("digital filter of vertex-level texturing"));
  t.push_back(Def("texture.update")
                  .noEffect("Basalt applies texture settings at once; no update is needed before draw")
                  .doc("updates all texture parameters"));
  t.push_back(Def("texture.method")
                  .slot(BASALT_SLOT(s.texture().method))
                  .oneOf(kTextureMethods)
                  .feature(Feature::kTexture)
                  .menu()
                  .doc("pixel-accurate or vertex-level texturing"));

  // Model clipping.
  t.push_back(Def("model_clipping.num_planes")
                  .slot(BASALT_SLOT(s.modelClipping().numPlanes))
                  .integer(0, kPlanes)
                  .feature(Feature::kModelClipping)
                  .doc("how many clip planes are on"));
  t.push_back(Def("model_clipping.coord")
                  .slot(BASALT_PLANE(point))
                  .indexed(kPlanes)
                  .floats(3)
                  .feature(Feature::kModelClipping)
                  .doc("a point on clip plane N"));
  t.push_back(Def("model_clipping.normal")
                  .slot(BASALT_PLANE(normal))
                  .indexed(kPlanes)
                  .floats(3)
                  .feature(Feature::kModelClipping)
                  .doc("normal of plane N, towards what is kept"));

  // Annotation.
  t.push_back(Def("annotation.show")
                  .slot(BASALT_SLOT(s.annotation().show))
                  .onOff()
                  .feature(Feature::kAnnotation)
                  .doc("label parts with their names"));
  t.push_back(Def("annotation.antialiasing")
                  .slot(BASALT_SLOT(s.annotation().antialiasing))
                  .oneOf(kAntialiasing)
                  .feature(Feature::kAnnotation)
                  .doc("annotation antialiasing"));
  t.push_back(Def("annotation.char_height")
                  .slot(BASALT_SLOT(s.annotation().charHeight))
                  .floats(1)
                  .feature(Feature::kAnnotation)
                  .doc("text height"));
  t.push_back(Def("annotation.slant_angle")
                  .slot(BASALT_SLOT(s.annotation().slantAngle))
                  .floats(1)
                  .feature(Feature::kAnnotation)
                  .doc("slant of the characters"));
  t.push_back(Def("annotation.up_vector")
                  .slot(BASALT_SLOT(s.annotation().upVector))
                  .floats(2)
                  .feature(Feature::kAnnotation)
                  .doc("text up direction, x y"));
  t.push_back(Def("annotation.color")
                  .slot(BASALT_SLOT(s.annotation().color))
                  .floats(3)
                  .feature(Feature::kAnnotation)
                  .doc("text colour"));
  t.push_back(Def("annotation.style")
                  .slot(BASALT_SLOT(s.annotation().style))
                  .oneOf(kAnnotationStyles)
                  .feature(Feature::kAnnotation)
                  .doc("line: draw a line from the text to the part"));
  t.push_back(Def("annotation.pointer_length")
                  .slot(BASALT_SLOT(s.annotation().pointerLength))
                  .floats(1)
                  .feature(Feature::kAnnotation)
                  .doc("distance of the text from the part"));
  t.push_back(Def("annotation.horiz_alignment")
                  .slot(BASALT_SLOT(s.annotation().horizontal))
                  .oneOf(kHorizontal)
                  .feature(Feature::kAnnotation)
                  .doc("horizontal alignment"));
  t.push_back(Def("annotation.vert_alignment")
                  .slot(BASALT_SLOT(s.annotation().vertical))
                  .oneOf(kVertical)
                  .feature(Feature::kAnnotation)
                  .doc("vertical alignment"));
  t.push_back(Def("annotation.text_path")
                  .slot(BASALT_SLOT(s.annotation().textPath))
                  .oneOf(kTextPaths)
                  .feature(Feature::kAnnotation)
                  .doc("direction the text runs"));

  // Global settings.
  t.push_back(
      Def("global.background_color").slot(BASALT_SLOT(s.global().background)).floats(3).doc("background colour"));
  t.push_back(Def("global.deferral_mode")
                  .slot(BASALT_SLOT(s.global().deferral))
                  .oneOf(kDeferral)
                  .doc("XGL's drawing deferral (stored; OpenGL ES defers as it needs)"));
  t.push_back(Def("global.double_buffered")
                  .slot(BASALT_SLOT(s.global().doubleBuffered))
                  .onOff()
                  .feature(Feature::kSingleBuffering)
                  .doc("double buffering"));
  t.push_back(
      Def("global.stereo_mode").slot(BASALT_SLOT(s.global().stereo)).onOff().feature(Feature::kStereo).doc("stereo"));
  t.push_back(Def("global.reset_attr")
                  .action(Action::kResetGlobalSettings)
                  .doc("global settings back to their defaults (parts keep theirs)"));

  // Motion.
  t.push_back(Def("motion.reset_transforms")
                  .action(Action::kResetTransforms)
                  .doc("global and local matrices to identity; motion goes on"));
  t.push_back(Def("motion.stop").action(Action::kMotionStop).doc("stop all motion"));
  t.push_back(
      Def("motion.start").action(Action::kMotionStart).doc("run motion for num_frames frames (0: until stopped)"));
  t.push_back(Def("motion.num_frames")
                  .slot(BASALT_SLOT(s.motion().numFrames))
                  .integer(0, kIntMax)
                  .doc("frames motion.start runs"));
  t.push_back(Def("motion.global_x_rotate")
                  .slot(BASALT_SLOT(s.motion().globalRotate.x))
                  .floats(1)
                  .rotation()
                  .doc("degrees per frame about X, global matrix"));
  t.push_back(Def("motion.global_y_rotate")
                  .slot(BASALT_SLOT(s.motion().globalRotate.y))
                  .floats(1)
                  .rotation()
                  .doc("degrees per frame about Y, global matrix"));
  t.push_back(Def("motion.global_z_rotate")
                  .slot(BASALT_SLOT(s.motion().globalRotate.z))
                  .floats(1)
                  .rotation()
                  .doc("degrees per frame about Z, global matrix"));
  t.push_back(Def("motion.global_scale")
                  .slot(BASALT_SLOT(s.motion().globalScale))
                  .floats(1)
                  .doc("scale per frame, global matrix"));
  t.push_back(Def("motion.global_free_run").action(Action::kGlobalFreeRun).doc("update the global matrix every frame"));
  t.push_back(Def("motion.global_stop").action(Action::kGlobalStop).doc("stop updating the global matrix"));
  t.push_back(Def("motion.local_x_rotate")
                  .slot(BASALT_SLOT(s.motion().localRotate.x))
                  .floats(1)
                  .rotation()
                  .doc("degrees per frame about X, local matrix"));
  t.push_back(Def("motion.local_y_rotate")
                  .slot(BASALT_SLOT(s.motion().localRotate.y))
                  .floats(1)
                  .rotation()
                  .doc("degrees per frame about Y, local matrix"));
  t.push_back(Def("motion.local_z_rotate")
                  .slot(BASALT_SLOT(s.motion().localRotate.z))
                  .floats(1)
                  .rotation()
                  .doc("degrees per frame about Z, local matrix"));
  t.push_back(Def("motion.local_scale")
                  .slot(BASALT_SLOT(s.motion().localScale))
                  .floats(1)
                  .menu()
                  .doc("scale per frame, local matrix"));
  t.push_back(Def("motion.local_free_run").action(Action::kLocalFreeRun).doc("update the local matrix every frame"));
  t.push_back(Def("motion.local_stop").action(Action::kLocalStop).doc("stop updating the local matrix"));

  // View.
  t.push_back(Def("view.center_x")
                  .slot(BASALT_SLOT(s.view().center.x))
                  .floats(1)
                  .doc("object centre X (object_center = use_slider)"));
  t.push_back(Def("view.center_y").slot(BASALT_SLOT(s.view().center.y)).floats(1).doc("object centre Y"));
  t.push_back(Def("view.center_z").slot(BASALT_SLOT(s.view().center.z)).floats(1).doc("object centre Z"));
  t.push_back(Def("view.object_center")
                  .slot(BASALT_SLOT(s.view().objectCenter))
                  .oneOf(kObjectCenters)
                  .doc("how the object is centred"));
  t.push_back(Def("view.object_scale")
                  .slot(BASALT_SLOT(s.view().objectScale))
                  .oneOf(kObjectScales)
                  .doc("fit the window, half of it, or original size"));
  t.push_back(Def("view.view_scale").slot(BASALT_SLOT(s.view().viewScale)).floats(1).doc("scale of the whole picture"));
  t.push_back(
      Def("view.z_clip_scale").slot(BASALT_SLOT(s.view().zClipScale)).floats(1).doc("depth range around the object"));
  t.push_back(Def("view.perspective")
                  .slot(BASALT_SLOT(s.view().perspective))
                  .floats(1)
                  .doc("eye distance in window units (0: orthographic)"));

  // Environment.
  t.push_back(Def("env.floor")
                  .slot(BASALT_SLOT(s.environment().floor))
                  .oneOf(kFloors)
                  .feature(Feature::kFloor)
                  .doc("a floor under the object"));
  t.push_back(Def("env.floor_color")
                  .slot(BASALT_SLOT(s.environment().floorColor))
                  .floats(3)
                  .feature(Feature::kFloor)
                  .doc("floor colour"));
  t.push_back(Def("env.floor_prim_type")
                  .slot(BASALT_SLOT(s.environment().floorPrimType))
                  .oneOf(kFloorPrims)
                  .feature(Feature::kFloor)
                  .doc("solid or wireframe floor"));
  t.push_back(Def("env.floor_position")
                  .slot(BASALT_SLOT(s.environment().floorPosition))
                  .floats(1)
                  .feature(Feature::kFloor)
                  .doc("floor height; 0 touches the object"));
  t.push_back(Def("env.shadow")
                  .slot(BASALT_SLOT(s.environment().shadow))
                  .onOff()
                  .feature(Feature::kShadow)
                  .doc("fake shadow on the floor"));
  t.push_back(Def("env.shadow_darkness")
                  .slot(BASALT_SLOT(s.environment().shadowDarkness))
                  .floats(1)
                  .feature(Feature::kShadow)
                  .doc("fraction of the floor colour in the shadow"));

  // Position: moves applied once per command (in loops: once per pass).
  t.push_back(
      Def("position.reset_transforms").action(Action::kResetTransforms).doc("local and global matrices to identity"));
  static const std::string_view kAxes[3][4] = {{"position.local_x_translate", "position.local_x_rotate",
                                                "position.global_x_translate", "position.global_x_rotate"},
                                               {"position.local_y_translate", "position.local_y_rotate",
                                                "position.global_y_translate", "position.global_y_rotate"},
                                               {"position.local_z_translate", "position.local_z_rotate",
                                                "position.global_z_translate", "position.global_z_rotate"}};
  t.push_back(Def("position.local_scale")
                  .assignment()
                  .floats(1)
                  .action(Action::kScaleLocal)
                  .doc("scale the local matrix by the value"));
  for (std::uint8_t a = 0; a < 3; ++a) {
    t.push_back(Def(kAxes[a][0])
                    .assignment()
                    .floats(1)
                    .action(Action::kTranslateLocal)
                    .axis(a)
                    .doc("move along the object's own axis"));
  }
  for (std::uint8_t a = 0; a < 3; ++a) {
    t.push_back(Def(kAxes[a][1])
                    .assignment()
                    .floats(1)
                    .rotation()
                    .action(Action::kRotateLocal)
                    .axis(a)
                    .doc("turn about the object's own axis, degrees"));
  }
  t.push_back(Def("position.global_scale")
                  .assignment()
                  .floats(1)
                  .action(Action::kScaleGlobal)
                  .doc("scale the global matrix by the value"));
  for (std::uint8_t a = 0; a < 3; ++a) {
    t.push_back(Def(kAxes[a][2])
                    .assignment()
                    .floats(1)
                    .action(Action::kTranslateGlobal)
                    .axis(a)
                    .doc("move along the world axis"));
  }
  for (std::uint8_t a = 0; a < 3; ++a) {
    t.push_back(Def(kAxes[a][3])
                    .assignment()
                    .floats(1)
                    .rotation()
                    .action(Action::kRotateGlobal)
                    .axis(a)
                    .doc("turn about the world axis, degrees"));
  }
  t.push_back(Def("position.local_matrix")
                  .slot(BASALT_SLOT(s.position().local.m))
                  .floats(16)
                  .doc("the local matrix, 16 numbers as Save Model writes them"));
  t.push_back(Def("position.global_matrix")
                  .slot(BASALT_SLOT(s.position().global.m))
                  .floats(16)
                  .doc("the global matrix, 16 numbers"));
  t.push_back(Def("position.view_matrix")
                  .slot(BASALT_SLOT(s.position().view.m))
                  .floats(16)
                  .feature(Feature::kViewMatrix)
                  .doc("the view matrix, 16 numbers (stored; the view comes from view.*)"));

  // Other commands.
  t.push_back(Def("obj_colors.part_color")
                  .part(AttrId::kFrontColor)
                  .floats(3)
                  .action(Action::kPartColor)
                  .doc("front surface, line and marker colour at once"));
  t.push_back(Def("load_object")
                  .argument(ValueKind::kFile)
                  .action(Action::kLoadObject)
                  .doc("load a 3D object; all attributes are reset"));
  t.push_back(Def("load_color_cube")
                  .action(Action::kLoadColorCube)
                  .menu()
                  .doc("LAVA's start-up colour cube; all attributes are reset"));
  t.push_back(Def("load_texture")
                  .argument(ValueKind::kFile)
                  .action(Action::kLoadTexture)
                  .doc("load an image and map it on the displayed parts"));
  t.push_back(Def("draw").action(Action::kDraw).doc("end the frame: the picture is drawn"));
  t.push_back(Def("draw_no_clear")
                  .action(Action::kDrawNoClear)
                  .feature(Feature::kDrawNoClear)
                  .doc("end the frame without clearing the picture"));
  t.push_back(Def("no_final_move")
                  .action(Action::kNoFinalMove)
                  .feature(Feature::kNoFinalMove)
                  .doc("no redraw when the script ends"));
  t.push_back(Def("update_menus").noEffect("Basalt has no menus to update").doc("update LAVA's menus"));
  t.push_back(Def("loop")
                  .argument(ValueKind::kInt)
                  .range(0, kIntMax)
                  .action(Action::kLoop)
                  .doc("repeat the lines up to end_loop N times (loops nest)"));
  t.push_back(Def("end_loop").action(Action::kEndLoop).doc("end of a loop"));
  t.push_back(Def("quit").action(Action::kQuit).doc("end the program (when the script was given on the command line)"));
  t.push_back(Def("save_image")
                  .argument(ValueKind::kFile, true)
                  .action(Action::kSaveImage)
                  .doc("write the current picture: ras.im32, or the name given, in the output folder"));
  t.push_back(Def("jitter")
                  .argument(ValueKind::kInt)
                  .range(1, 256)
                  .action(Action::kJitter)
                  .doc("repeat the lines up to end_jitter N times with sub-pixel offsets, averaging the passes"));
  t.push_back(Def("end_jitter").action(Action::kEndJitter).doc("end of a jitter loop"));
  t.push_back(Def("jitter_offset")
                  .assignment()
                  .floats(2)
                  .action(Action::kJitterOffset)
                  .doc("extra sub-pixel offset of the picture, x y in pixels"));

  // The VCR remote and the camera (LAVA §7), named in LAVA's style.
  t.push_back(Def("tv.movie").tv(TvOp::kMovie).argument(ValueKind::kFile).assignment().doc("load a movie"));
  t.push_back(Def("tv.unload").tv(TvOp::kUnload).doc("unload the movie"));
  t.push_back(Def("tv.play").tv(TvOp::kPlay).doc("play"));
  t.push_back(Def("tv.pause").tv(TvOp::kPause).doc("pause on the current frame"));
  t.push_back(Def("tv.stop").tv(TvOp::kStop).doc("stop"));
  t.push_back(Def("tv.step_forward").tv(TvOp::kStepForward).doc("one frame on"));
  t.push_back(Def("tv.step_reverse").tv(TvOp::kStepReverse).doc("one frame back"));
  t.push_back(Def("tv.rewind").tv(TvOp::kRewind).doc("back to the first frame"));
  t.push_back(Def("tv.fast_forward").tv(TvOp::kFastForward).doc("ten frames on"));
  t.push_back(Def("tv.shuttle")
                  .assignment()
                  .integer(-kIntMax, kIntMax)
                  .tv(TvOp::kShuttle)
                  .doc("N frames on, or back when negative"));
  t.push_back(Def("tv.repeat").assignment().onOff().tv(TvOp::kRepeat).doc("loop the movie"));
  t.push_back(Def("tv.camera")
                  .assignment()
                  .onOff()
                  .tv(TvOp::kCamera)
                  .doc("the live camera on or off: the camera of basalt run --camera, else the manifest's first"));
  return t;
}

#undef BASALT_SLOT
#undef BASALT_LIGHT
#undef BASALT_PLANE

constexpr CommandAlias kAliases[] = {
    {"render.hlshr_mode", "render.hlhsr_mode", "the manual's list spells it so; the menu says HLHSR"},
};

struct Index {
  std::vector<CommandDef> table = buildTable();
  std::unordered_map<std::string_view, std::uint16_t> byName;
  std::vector<std::string_view> names;  // every spelling, for suggestions
  Index() {
    for (std::size_t i = 0; i < table.size(); ++i) {
      byName.emplace(table[i].name, static_cast<std::uint16_t>(i));
      names.push_back(table[i].name);
    }
    for (const CommandAlias& a : kAliases) {
      byName.emplace(a.alias, byName.at(a.name));
      names.push_back(a.alias);
    }
  }
};

const Index& index() {
  static const Index kIndex;
  return kIndex;
}

/// Optimal string alignment distance, without case.
std::size_t editDistance(std::string_view a, std::string_view b) {
  const std::size_t n = a.size();
  const std::size_t m = b.size();
  std::vector<std::size_t> prev2(m + 1), prev(m + 1), cur(m + 1);
  for (std::size_t j = 0; j <= m; ++j) prev[j] = j;
  auto lo = [](char c) { return (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c; };
  for (std::size_t i = 1; i <= n; ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= m; ++j) {
      const std::size_t cost = lo(a[i - 1]) == lo(b[j - 1]) ? 0 : 1;
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + cost});
      if (i > 1 && j > 1 && lo(a[i - 1]) == lo(b[j - 2]) && lo(a[i - 2]) == lo(b[j - 1])) {
        cur[j] = std::min(cur[j], prev2[j - 2] + 1);
      }
    }
    std::swap(prev2, prev);
    std::swap(prev, cur);
  }
  return prev[m];
}

/// True when `word`'s attribute (after the dot) is a whole word of `candidate`'s attribute in
/// the same group: "lines.width" for "lines.line_width".
bool sameGroupPartialName(std::string_view word, std::string_view candidate) {
  const auto wd = word.find('.');
  const auto cd = candidate.find('.');
  if (wd == std::string_view::npos || cd == std::string_view::npos) return false;
  if (!equalsIgnoreCase(word.substr(0, wd), candidate.substr(0, cd))) return false;
  const std::string w = toLower(word.substr(wd + 1));
  const std::string_view c = candidate.substr(cd + 1);
  if (w.size() < 3) return false;
  const auto at = c.find(w);
  if (at == std::string_view::npos) return false;
  const bool startsWord = at == 0 || c[at - 1] == '_';
  const bool endsWord = at + w.size() == c.size() || c[at + w.size()] == '_';
  return startsWord && endsWord;
}

}  // namespace

std::string_view featureName(Feature feature) {
  switch (feature) {
    case Feature::kRendered: return "this";
    case Feature::kRasterOp: return "raster operations";
    case Feature::kMarkerShapes: return "marker shapes other than dots (they are drawn as squares)";
    case Feature::kAntialiasing: return "antialiasing";
    case Feature::kColorSelector: return "colour selectors";
    case Feature::kLineStyle: return "line styles, patterns, ends and joins";
    case Feature::kColorInterpolation: return "line colour interpolation";
    case Feature::kFillStyle: return "fill styles and stipple patterns";
    case Feature::kTransparency: return "transparency";
    case Feature::kEdges: return "edges";
    case Feature::kNurbs: return "NURBS";
    case Feature::kPicking: return "picking";
    case Feature::kDepthCue: return "depth cueing";
    case Feature::kTexture: return "texture mapping";
    case Feature::kModelClipping: return "model clipping";
    case Feature::kAnnotation: return "annotation";
    case Feature::kSingleBuffering: return "single-buffered drawing (Basalt always double-buffers)";
    case Feature::kStereo: return "stereo";
    case Feature::kFloor: return "the floor";
    case Feature::kShadow: return "the fake shadow";
    case Feature::kViewMatrix: return "view matrices (the view comes from the view.* settings)";
    case Feature::kDrawNoClear: return "drawing without clearing (every frame is cleared)";
    case Feature::kNoFinalMove: return "no_final_move (the show goes on drawing after the script ends)";
    case Feature::kJitterDisplay:
      return "showing the averaged jitter picture on screen (save_image writes it; the screen shows the last pass)";
    case Feature::kCount: break;
  }
  return "this feature";
}

std::span<const CommandDef> commands() { return index().table; }

const CommandDef* findCommand(std::string_view name) {
  const Index& idx = index();
  auto it = idx.byName.find(name);
  if (it == idx.byName.end()) {
    const std::string lower = toLower(name);
    it = idx.byName.find(lower);
    if (it == idx.byName.end()) return nullptr;
  }
  return &idx.table[it->second];
}

std::uint16_t commandIndex(const CommandDef& def) { return static_cast<std::uint16_t>(&def - index().table.data()); }

std::span<const CommandAlias> commandAliases() { return kAliases; }

std::optional<std::string_view> closestMatch(std::string_view word, std::span<const std::string_view> candidates) {
  if (word.empty() || word.size() > kMaxSuggestedLength) return std::nullopt;
  const std::size_t limit = word.size() <= 4 ? 1 : (word.size() <= 9 ? 2 : 3);
  std::optional<std::string_view> best;
  std::size_t bestDistance = SIZE_MAX;
  for (std::string_view c : candidates) {
    if (c.size() > kMaxSuggestedLength) continue;
    // The distance is at least the difference in length: skip those that cannot be close (a
    // partial attribute name is longer than the word by design).
    const std::size_t apart = c.size() > word.size() ? c.size() - word.size() : word.size() - c.size();
    if (apart > limit && !sameGroupPartialName(word, c)) continue;
    const std::size_t d = editDistance(word, c);
    const bool close = d <= limit || sameGroupPartialName(word, c);
    if (close && d < bestDistance) {
      best = c;
      bestDistance = d;
    }
  }
  if (bestDistance == 0) return std::nullopt;  // the same word (another case): not a misspelling
  return best;
}

std::optional<std::string_view> suggestCommand(std::string_view name) { return closestMatch(name, index().names); }

std::string CommandDef::valueForm() const {
  switch (kind) {
    case ValueKind::kNone: return "";
    case ValueKind::kBool:
    case ValueKind::kEnum: {
      std::string s;
      for (std::size_t i = 0; i < choices.size(); ++i) s += fmt::format("{}{}", i ? " | " : "", choices[i]);
      return s;
    }
    case ValueKind::kFlags: {
      std::string s;
      for (std::size_t i = 0; i < choices.size(); ++i) s += fmt::format("{}[{}]", i ? " " : "", choices[i]);
      return s;
    }
    case ValueKind::kFloat: {
      std::string s;
      for (std::uint8_t i = 0; i < count; ++i) s += i ? " <float>" : "<float>";
      return count == 16 ? std::string("<16 floats>") : s;
    }
    case ValueKind::kInt: return "<int>";
    case ValueKind::kFile: return "\"file\"";
    case ValueKind::kPartName: return "\"part name\"";
  }
  return "";
}

std::string CommandDef::form() const {
  std::string s(name);
  switch (syntax) {
    case Syntax::kAction: return s;
    case Syntax::kArgument: return s + " " + valueForm();
    case Syntax::kOptionalArgument: return s + " [" + valueForm() + "]";
    case Syntax::kAssignment: break;
  }
  if (scope == Scope::kPart) s += " [\"part name\"]";
  if (scope == Scope::kIndexed) s += " [N]";
  s += " = " + valueForm();
  return s;
}

void* globalStorage(const CommandDef& def, runtime::Show& show, runtime::PartStyle& style, int index) {
  if (def.action != Action::kStore && def.action != Action::kPartColor) return nullptr;
  if (def.attr != AttrId::kCount) {
    return reinterpret_cast<std::byte*>(&style) + runtime::attrField(def.attr).offset;
  }
  if (def.slot) return def.slot(show, index);
  return nullptr;
}

std::size_t valueBytes(const CommandDef& def) {
  switch (def.kind) {
    case ValueKind::kBool:
    case ValueKind::kEnum:
    case ValueKind::kFlags: return 1;
    case ValueKind::kFloat: return sizeof(float) * def.count;
    case ValueKind::kInt: return sizeof(std::int32_t);
    default: return 0;
  }
}

std::string formatValue(const CommandDef& def, const void* storage) {
  switch (def.kind) {
    case ValueKind::kBool: {
      bool b = false;
      std::memcpy(&b, storage, 1);
      return b ? "on" : "off";
    }
    case ValueKind::kEnum: {
      std::uint8_t v = 0;
      std::memcpy(&v, storage, 1);
      return v < def.choices.size() ? std::string(def.choices[v]) : fmt::format("{}", v);
    }
    case ValueKind::kFlags: {
      std::uint8_t v = 0;
      std::memcpy(&v, storage, 1);
      std::string s;
      for (std::size_t i = 0; i < def.choices.size(); ++i) {
        if (v & (1u << i)) s += fmt::format("{}{}", s.empty() ? "" : " ", def.choices[i]);
      }
      return s;
    }
    case ValueKind::kFloat: {
      std::string s;
      for (std::uint8_t i = 0; i < def.count; ++i) {
        float f = 0;
        std::memcpy(&f, static_cast<const std::byte*>(storage) + i * sizeof(float), sizeof f);
        // fmt writes the shortest text that reads back as the same float.
        s += fmt::format("{}{}", i ? " " : "", f);
      }
      return s;
    }
    case ValueKind::kInt: {
      std::int32_t v = 0;
      std::memcpy(&v, storage, sizeof v);
      return fmt::format("{}", v);
    }
    default: return "";
  }
}

}  // namespace basalt::script
