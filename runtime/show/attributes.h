#pragma once

/// \file
/// \brief LAVA's attribute model (LAVA manual §6.1, §10): the per-part attribute groups that may
/// be set globally or per part, and the global-only settings. Defaults are the manual's; where
/// the manual is silent the default is Basalt's and is marked so.

#include <array>
#include <bitset>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "runtime/math.h"

namespace basalt::runtime {

struct Color3 {
  float r = 0, g = 0, b = 0;
  friend bool operator==(const Color3&, const Color3&) = default;
};

// ---- Per-part groups ------------------------------------------------------------------------

enum class PrimType : std::uint8_t { kWireframe, kMarkers, kSolid };
enum class FaceCulling : std::uint8_t { kOff, kBack, kFront };
/// \brief XGL raster operations (LAVA `render.raster_op`), in the script's order.
enum class RasterOp : std::uint8_t {
  kClear,
  kSet,
  kCopy,
  kCopyInverted,
  kInvert,
  kAnd,
  kAndReverse,
  kAndInverted,
  kNand,
  kOr,
  kOrReverse,
  kOrInverted,
  kNor,
  kXor,
  kEquiv,
  kNoop
};
enum class Antialiasing : std::uint8_t { kOff, kConstantBackground, kArbitraryBackground };
enum class ColorSelector : std::uint8_t { kContext, kVertex };

struct RenderOptions {
  PrimType primType = PrimType::kSolid;         // "Default is Solid"
  FaceCulling faceCulling = FaceCulling::kOff;  // "Default is Off"
  bool faceDistinguishing = false;              // "Default is Off"
  RasterOp rasterOp = RasterOp::kCopy;          // "Default is Copy"
  bool hiddenSurfaceRemoval = true;             // HLHSR "Default is on"
  friend bool operator==(const RenderOptions&, const RenderOptions&) = default;
};

enum class MarkerType : std::uint8_t { kDot, kPlus, kAsterisk, kCircle, kCross, kSquare, kBowtieNE, kBowtieNW };

struct MarkerAttributes {
  MarkerType type = MarkerType::kDot;  // "Default is Dot"
  Color3 color{0, 1, 0};               // "Default is green"
  Antialiasing antialiasing = Antialiasing::kOff;
  float scaleFactor = 10.0f;  // "Default is 10.0"
  ColorSelector colorSelector = ColorSelector::kContext;
  friend bool operator==(const MarkerAttributes&, const MarkerAttributes&) = default;
};

enum class EndpointStyle : std::uint8_t { kButt, kSquare, kRound };
enum class JoinStyle : std::uint8_t { kDevice, kBevel, kMiter };
enum class LineStyle : std::uint8_t { kSolid, kPatterned, kAltPatterned };
enum class LinePattern : std::uint8_t {
  kDotted,
  kDashed,
  kDashedDotted,
  kCgmDotted,
  kCgmDashed,
  kDashDot,
  kDashDotDotted,
  kLongDashed
};

struct LineAttributes {
  Color3 color{0, 1, 0};  // "Default is green"
  Antialiasing antialiasing = Antialiasing::kOff;
  float width = 1.0f;                                  // "Default is 1.0 pixel wide"
  EndpointStyle endpointStyle = EndpointStyle::kButt;  // "Default is Butt"
  JoinStyle joinStyle = JoinStyle::kMiter;             // "Default is Mitered"
  float miterLimit = 2.0f;                             // "Default is 2.0"
  LineStyle style = LineStyle::kSolid;                 // "Default is <Solid>"
  LinePattern pattern = LinePattern::kDotted;          // "Default is Dotted"
  Color3 altColor{1, 1, 1};                            // "The default is white"
  ColorSelector colorSelector = ColorSelector::kContext;
  bool colorInterpolation = false;  // "Default is OFF"
  friend bool operator==(const LineAttributes&, const LineAttributes&) = default;
};

enum class FillStyle : std::uint8_t { kSolid, kHollow, kEmpty, kOpaqueStipple, kStipple, kPattern };
enum class StipplePattern : std::uint8_t {
  kHorizontal,
  kVertical,
  kDiag45,
  kDiag135,
  kGridR,
  kGridD,
  kHorizDbl,
  kVertDbl,
  kDiag45Dbl,
  kDiag135Dbl,
  kGridRDbl,
  kGridDDbl
};
enum class SurfaceColorSelector : std::uint8_t { kContext, kFacet, kIllumDependent, kIllumIndependent };
/// \brief XGL illumination types; kPerPixel is Basalt's quality option beyond XGL.
enum class Illumination : std::uint8_t { kNone, kInterpColor, kPerFacet, kPerVertex, kPerPixel };
enum class TransparencyMethod : std::uint8_t { kNone, kScreenDoor, kBlended };
enum class TransparencyBlend : std::uint8_t { kNone, kArbitraryBackground, kConstantBackground, kAddToBackground };

/// \brief Which light components are used (`front_surf.light_component`), a bit set.
enum LightComponent : std::uint8_t { kLightAmbient = 1, kLightDiffuse = 2, kLightSpecular = 4 };

struct SurfaceAttributes {
  Color3 color{1, 1, 1};                                                          // "Default is white"
  FillStyle fillStyle = FillStyle::kSolid;                                        // "Default is <Solid>"
  StipplePattern stipplePattern = StipplePattern::kHorizontal;                    // Basalt default (manual silent)
  SurfaceColorSelector colorSelector = SurfaceColorSelector::kIllumIndependent;   // manual default
  Illumination illumination = Illumination::kPerFacet;                            // "Default is Per Facet"
  std::uint8_t lightComponents = kLightAmbient | kLightDiffuse | kLightSpecular;  // "all on"
  float ambient = 0.2f;                                                           // manual defaults: 0.2, 0.8, 1.0
  float diffuse = 0.8f;
  float specular = 1.0f;
  Color3 specularColor{1, 1, 1};                                      // "Default color is white"
  float specularPower = 20.0f;                                        // "Default is 20.0"
  TransparencyMethod transparencyMethod = TransparencyMethod::kNone;  // "None ... default"
  TransparencyBlend transparencyBlend = TransparencyBlend::kNone;     // "None ... (default)"
  float transparency = 0.0f;                                          // 0 opaque .. 1 fully transparent
  /// Thesis §4.2.4 (OpenGL materials), beyond XGL: the colour the surface emits whatever the
  /// lights, added before them. XGL surfaces emit nothing, so black unless a scene sets it.
  Color3 emission{0, 0, 0};
  /// Thesis §4.2.4: the material's own ambient colour. When `own` is false (XGL, LAVA) the
  /// ambient term reflects the surface colour Od; when true it reflects `color` instead, so a
  /// scene's ambient and diffuse colours stay independent.
  struct AmbientColor {
    bool own = false;
    Color3 color{0, 0, 0};
    friend bool operator==(const AmbientColor&, const AmbientColor&) = default;
  } ambientColor;
  friend bool operator==(const SurfaceAttributes&, const SurfaceAttributes&) = default;
};

/// \brief `edges.show_edges`: the script accepts off/on; the menu also offers XGL and software.
enum class EdgeMode : std::uint8_t { kOff, kOn, kSoftware };

struct EdgeAttributes {
  EdgeMode show = EdgeMode::kOff;  // "Default is <OFF>"
  Color3 color{0, 0, 0};           // "Default is black"
  Antialiasing antialiasing = Antialiasing::kOff;
  float width = 1.0f;                          // "Default is 1.0"
  LineStyle style = LineStyle::kSolid;         // "Default is <Solid>"
  LinePattern pattern = LinePattern::kDotted;  // "Default is <Dotted>"
  Color3 altColor{1, 1, 1};                    // "Default is white"
  bool silhouette = false;                     // "Default is OFF"
  float softwareOffset = 0.1f;                 // "The default value is 0.1"
  friend bool operator==(const EdgeAttributes&, const EdgeAttributes&) = default;
};

enum class NurbsApproxMethod : std::uint8_t {
  kConstParamSubdivBetweenKnots,
  kMetricWc,
  kMetricVdc,
  kMetricDc,
  kChordalDeviationWc,
  kChordalDeviationVdc,
  kChordalDeviationDc,
  kRelativeWc,
  kRelativeVdc,
  kRelativeDc
};
enum NurbsParamStyle : std::uint8_t { kNurbsIsoCurves = 1, kNurbsShowTess = 2, kNurbsIncrSilhTess = 4 };
enum class IsoCurvePlacement : std::uint8_t { kBetweenKnots, kBetweenLimits };
enum class NurbsTessellation : std::uint8_t { kDynamic, kCombine, kStatic };

struct NurbsAttributes {
  NurbsApproxMethod approxMethod = NurbsApproxMethod::kConstParamSubdivBetweenKnots;  // manual
  float approxValueU = 1.0f;                                                          // Basalt default (manual silent)
  float approxValueV = 1.0f;                                                          // Basalt default (manual silent)
  std::uint8_t paramStyle = 0;  // Basalt default: none of the three
  IsoCurvePlacement isoCurvePlacement = IsoCurvePlacement::kBetweenKnots;
  std::int32_t isoCurvesU = 1;  // Basalt default (manual silent)
  std::int32_t isoCurvesV = 1;
  NurbsTessellation tessellation = NurbsTessellation::kDynamic;  // "Default is <Dynamic>"
  friend bool operator==(const NurbsAttributes&, const NurbsAttributes&) = default;
};

/// \brief Every attribute that may be set per part. Trivially copyable: resolution copies the
/// part's own fields over the global ones.
struct PartStyle {
  RenderOptions render;
  MarkerAttributes markers;
  LineAttributes lines;
  SurfaceAttributes front;
  SurfaceAttributes back;
  EdgeAttributes edges;
  NurbsAttributes nurbs;
  friend bool operator==(const PartStyle&, const PartStyle&) = default;
};

/// \brief One id per field of PartStyle: a part's override mask has one bit per id.
enum class AttrId : std::uint16_t {
  kRenderPrimType,
  kRenderFaceCulling,
  kRenderFaceDist,
  kRenderRasterOp,
  kRenderHlhsrMode,
  kMarkersType,
  kMarkersColor,
  kMarkersAntialiasing,
  kMarkersScaleFactor,
  kMarkersColorSelector,
  kLinesColor,
  kLinesAntialiasing,
  kLinesWidth,
  kLinesEndpointStyle,
  kLinesJoinStyle,
  kLinesMiterLimit,
  kLinesStyle,
  kLinesPattern,
  kLinesAltColor,
  kLinesColorSelector,
  kLinesColorInterp,
  kFrontColor,
  kFrontFillStyle,
  kFrontStipplePattern,
  kFrontColorSelector,
  kFrontIllum,
  kFrontLightComponent,
  kFrontAmbient,
  kFrontDiffuse,
  kFrontSpecular,
  kFrontSpecularColor,
  kFrontSpecularPower,
  kFrontTranspMethod,
  kFrontTranspBlendEq,
  kFrontTransparency,
  kBackColor,
  kBackFillStyle,
  kBackStipplePattern,
  kBackColorSelector,
  kBackIllum,
  kBackLightComponent,
  kBackAmbient,
  kBackDiffuse,
  kBackSpecular,
  kBackSpecularColor,
  kBackSpecularPower,
  kBackTranspMethod,
  kBackTranspBlendEq,
  kBackTransparency,
  kEdgesShow,
  kEdgesColor,
  kEdgesAntialiasing,
  kEdgesWidth,
  kEdgesStyle,
  kEdgesPattern,
  kEdgesAltColor,
  kEdgesSilhouette,
  kEdgesSwOffset,
  kNurbsApproxMethod,
  kNurbsApproxValU,
  kNurbsApproxValV,
  kNurbsParamStyle,
  kNurbsIsoCurvePlacement,
  kNurbsIsoCurvesU,
  kNurbsIsoCurvesV,
  kNurbsTessellation,
  // Thesis materials a scene (or Basalt) sets; LAVA's script has no command for them.
  kFrontEmission,
  kFrontAmbientColor,
  kBackEmission,
  kBackAmbientColor,
  kCount
};
inline constexpr std::size_t kAttrCount = static_cast<std::size_t>(AttrId::kCount);
using AttrMask = std::bitset<kAttrCount>;

/// \brief Where one per-part attribute lives inside PartStyle, and its script name.
struct AttrField {
  AttrId id;
  std::string_view name;  ///< the script's name, e.g. "render.prim_type"
  std::size_t offset;     ///< byte offset in PartStyle
  std::size_t size;       ///< byte size of the field
};

/// \brief The field table, indexed by AttrId.
std::span<const AttrField> attrFields();
const AttrField& attrField(AttrId id);
/// \brief Copies attribute `id` from `from` into `to`.
void copyAttr(AttrId id, const PartStyle& from, PartStyle& to);
/// \brief `global` with every field set in `mask` taken from `own`.
PartStyle resolveStyle(const PartStyle& global, const PartStyle& own, const AttrMask& mask);

// ---- Global-only settings -------------------------------------------------------------------

enum class LightType : std::uint8_t { kAmbient, kDirectional, kPositional, kSpot };

/// \brief The units a light's position and attenuation, fog's distances or the stereo eye
/// spacing are given in: LAVA's window units (the object normalised into -1..1, the eye
/// `view.perspective` away), or the scene's own units (a `.sce` file's coordinates, before
/// Basalt fits the scene to the window): the renderer carries the second through the model
/// matrix so that they keep their meaning at any fit.
enum class Units : std::uint8_t { kWindow, kScene };

/// \brief One of the 32 lights (LAVA "Lighting", XGL chapter 16). Directions point the way the
/// light travels; angles are in radians, as LAVA's menu takes them.
///
/// `color` is XGL's light colour Lc: the ambient colour of an ambient light, the diffuse and
/// specular colour of the others. A scene's light (thesis §4.2.4, E.3) has three colours of its
/// own: `ambient` (added, attenuated, whatever the light's type) and, with `ownSpecular`,
/// `specular` instead of Lc in the highlight. LAVA's lights have neither.
struct Light {
  bool on = false;  // "Default is OFF" (lights 0-2 are on)
  LightType type = LightType::kDirectional;
  Color3 color{1, 1, 1};
  Color3 ambient{0, 0, 0};   // thesis: the light's ambient colour (LAVA: none)
  Color3 specular{1, 1, 1};  // thesis: the light's specular colour, used when ownSpecular
  bool ownSpecular = false;
  Units units = Units::kWindow;  // of position and attenuation2
  Vec3 direction{0, 0, -1};
  Vec3 position{0, 0, 1};
  float attenuation1 = 1.0f;  // c1 in A = 1/(c1 + c2 d)
  float attenuation2 = 0.0f;  // c2
  float angle = 0.5f;         // spot cut-off, radians
  float exponent = 1.0f;      // spot concentration
  friend bool operator==(const Light&, const Light&) = default;
};
inline constexpr std::size_t kMaxLights = 32;

/// \brief LAVA's default lights: 0 ambient, 1 and 2 directional and on, 3 spot, 4 positional,
/// the rest directional in varying colours and directions, off.
std::array<Light, kMaxLights> defaultLights();

enum class DepthCueMode : std::uint8_t { kNone, kLinear, kScaled };

struct DepthCue {
  DepthCueMode mode = DepthCueMode::kNone;  // "Default is None"
  Color3 color{0, 0, 0};                    // "Default is black"
  float frontRefPlane = 0.2f;               // "Default is 0.2"
  float backRefPlane = -0.2f;               // "Default is -0.2"
  float maxScale = 1.0f;                    // "Default is 1.0"
  float minScale = 0.1f;                    // "Default is 0.1"
  bool useBackgroundColor = false;          // Basalt default (manual silent)
  friend bool operator==(const DepthCue&, const DepthCue&) = default;
};

enum class FogMode : std::uint8_t { kNone, kLinear, kExp, kExp2 };

/// \brief Thesis §4.3.3 fog, OpenGL's fog functions on the eye-space depth z of each pixel (in
/// `units`: window units, where the eye sits `view.perspective` from the object's centre, or,
/// for a scene's fog, the scene's own units):
/// linear f = (end - z) / (end - start), exp f = e^(-density z), exp2 f = e^(-(density z)^2),
/// f clamped to 0..1, and the colour f C + (1 - f) fog colour. Fog is off unless `mode` says so;
/// the thesis gives no defaults for the rest (Basalt defaults, chosen to fog the far half of
/// the default view).
struct Fog {
  FogMode mode = FogMode::kNone;
  Units units = Units::kWindow;  // of start, end and density (a scene's fog: kScene)
  Color3 color{0.5f, 0.5f, 0.5f};
  float start = 1.0f;
  float end = 10.0f;
  float density = 0.1f;
  friend bool operator==(const Fog&, const Fog&) = default;
};

enum class TextureSource : std::uint8_t { kOff, kImage, kVideo };
enum class TextureMethod : std::uint8_t { kPixel, kVertexLevel };
enum class TextureApprox : std::uint8_t { kNumSegments, kPixelTolerance, kCombined };

/// \brief LAVA "Texture Mapping" (§6.2.2). `source` switches texturing as a whole: a part that
/// names a texture (`PartState::texture`) shows it unless the source is kOff. Image files and
/// streams (movies, cameras) both reach the renderer through its texture registry, so kImage and
/// kVideo draw the same way; the distinction is kept for the script and Save Model.
struct TextureSettings {
  TextureSource source = TextureSource::kImage;  // Basalt default (manual silent): parts show their textures
  TextureMethod method = TextureMethod::kPixel;  // Basalt default (manual silent)
  TextureApprox approx = TextureApprox::kNumSegments;
  std::int32_t subsegments = 1;     // VLTM "Num Segments": each triangle side cut into this many parts
  std::int32_t pixelTolerance = 7;  // VLTM "Pixel Tolerance": longest sub-triangle side, in pixels
  std::int32_t tauFunction = 0;
  friend bool operator==(const TextureSettings&, const TextureSettings&) = default;
};

struct ClipPlane {
  Vec3 point;
  Vec3 normal{0, 0, 1};
  friend bool operator==(const ClipPlane&, const ClipPlane&) = default;
};
inline constexpr std::size_t kMaxClipPlanes = 16;

struct ModelClipping {
  std::int32_t numPlanes = 0;  // "Default is 0"
  /// "the default values for each plane is unique such that adding a plane is visible"
  std::array<ClipPlane, kMaxClipPlanes> planes = defaultClipPlanes();
  static std::array<ClipPlane, kMaxClipPlanes> defaultClipPlanes();
  friend bool operator==(const ModelClipping&, const ModelClipping&) = default;
};

enum class AnnotationStyle : std::uint8_t { kNormal, kLine };
enum class HorizontalAlignment : std::uint8_t { kNormal, kRight, kLeft, kCenter };
enum class VerticalAlignment : std::uint8_t { kNormal, kBase, kBottom, kTop, kHalf, kCap };
enum class TextPath : std::uint8_t { kRight, kLeft, kUp, kDown };

struct Annotation {
  bool show = false;  // "Default is OFF"
  Antialiasing antialiasing = Antialiasing::kOff;
  float charHeight = 0.05f;                        // "Default is 0.05"
  float slantAngle = 0.0f;                         // "straight up (0.0)"
  Vec2 upVector{0, 1};                             // "(0.0 1.0)"
  Color3 color{0, 1, 0};                           // "Default is green"
  AnnotationStyle style = AnnotationStyle::kLine;  // "Default is Line"
  float pointerLength = 1.0f;                      // "Default is 1.0"
  HorizontalAlignment horizontal = HorizontalAlignment::kNormal;
  VerticalAlignment vertical = VerticalAlignment::kNormal;
  TextPath textPath = TextPath::kRight;
  friend bool operator==(const Annotation&, const Annotation&) = default;
};

struct Picking {
  bool enabled = false;            // "Default is <OFF>"
  Color3 partHighlight{1, 1, 0};   // Basalt default (manual silent)
  Color3 facetHighlight{1, 0, 1};  // Basalt default (manual silent)
  std::int32_t aperture = 3;       // Basalt default (manual silent)
  friend bool operator==(const Picking&, const Picking&) = default;
};

enum class DeferralMode : std::uint8_t { kAsti, kAsap };

/// \brief How `global.stereo_mode = on` is shown. With no stereo display the object "gets drawn
/// twice into the same buffer" (LAVA §6.1): Basalt draws a red/cyan anaglyph (thesis §5.1).
/// Passive projectors take the two eyes side by side (left eye on the left) or top and bottom
/// (left eye on top), each squeezed into half the output (the frame-compatible formats).
enum class StereoMode : std::uint8_t { kAnaglyph, kSideBySide, kTopBottom };

/// \brief Thesis §5.1 stereo: two eyes `eyeSpacing` apart (thesis C.3 `eyespacing`, default
/// 0.04), left eye red, right eye cyan, converging on the object's centre plane.
struct StereoSettings {
  StereoMode mode = StereoMode::kAnaglyph;
  float eyeSpacing = 0.04f;  // thesis C.3 default, in `units`
  Units units = Units::kWindow;
  friend bool operator==(const StereoSettings&, const StereoSettings&) = default;
};

struct GlobalSettings {
  Color3 background{0, 0, 0};                   // "Default color is black"
  DeferralMode deferral = DeferralMode::kAsti;  // "Default is ASTI"
  bool doubleBuffered = true;                   // double buffering is always available
  bool stereo = false;
  friend bool operator==(const GlobalSettings&, const GlobalSettings&) = default;
};

/// \brief Automatic motion (LAVA "Motion" menu): per-frame rotations in degrees and a scale,
/// applied to the global and local matrices while free run is on.
struct Motion {
  Vec3 globalRotate{0, 0, 0};
  float globalScale = 1.0f;
  Vec3 localRotate{0, 0, 0};
  float localScale = 1.0f;
  bool globalFreeRun = false;
  bool localFreeRun = false;
  std::int32_t numFrames = 0;    // frames to run after motion.start; 0 = until stopped
  std::int32_t framesLeft = -1;  // counting down after start; -1 = not counting
  friend bool operator==(const Motion&, const Motion&) = default;
};

/// \brief The object's placement: LAVA's global and local modelling matrices (model = global *
/// local) and the view matrix that `position.view_matrix` restores.
struct Position {
  Mat4 global;
  Mat4 local;
  Mat4 view;
  friend bool operator==(const Position&, const Position&) = default;
};

enum class ObjectCenter : std::uint8_t { kUseSlider, kPlusX, kMinusX, kPlusY, kMinusY, kPlusZ, kMinusZ, kNone };
enum class ObjectScale : std::uint8_t { kHalfScreen, kFullScreen, kOriginal };

/// \brief LAVA's "View" menu. The object is centred and scaled into window bounds -1..1, then
/// seen from `perspective` units away on +Z (0 = orthographic).
struct ViewSettings {
  Vec3 center{0, 0, 0};                                // the centre used with kUseSlider, in object coordinates
  ObjectCenter objectCenter = ObjectCenter::kNone;     // Basalt default: the bounding-box centre
  ObjectScale objectScale = ObjectScale::kFullScreen;  // Basalt default (manual silent)
  float viewScale = 1.0f;
  float zClipScale = 2.0f;   // Basalt default: near/far at distance +- 2
  float perspective = 4.0f;  // Basalt default: eye 4 window units away
  friend bool operator==(const ViewSettings&, const ViewSettings&) = default;
};

/// \brief LAVA's floors: one square, or a grid of 8 x 8 (coarse) or 32 x 32 (fine) lit squares.
enum class FloorKind : std::uint8_t { kNone, kSingleSquare, kCoarseGrid, kFineGrid };
enum class FloorPrimType : std::uint8_t { kSolid, kWireframe };

/// \brief LAVA "Environment": the floor and its fake shadow. The floor is horizontal in the
/// global frame (it turns with the global matrix, the object turns on it with the local one),
/// centred under the object, four object radii wide; the shadow is the object squashed onto it.
struct Environment {
  FloorKind floor = FloorKind::kNone;
  Color3 floorColor{0.5f, 0.5f, 0.5f};  // Basalt default (manual silent)
  FloorPrimType floorPrimType = FloorPrimType::kSolid;
  float floorPosition = 0.0f;   // window units above the object's lowest point; 0 touches it
  bool shadow = false;          // "only available when a floor is drawn"
  float shadowDarkness = 0.5f;  // shadow colour = this fraction of the lit floor colour; Basalt default
  friend bool operator==(const Environment&, const Environment&) = default;
};

/// \brief What is drawn behind the scene (thesis §4.3.2, Performer's pfEarthSky): the
/// background colour; a flat image (`Show::backgroundImage()`, a texture name) stretched over the
/// view; a skybox from one 3 x 2 image of six 90-degree views (-X, +Z, +X on the top row, -Y,
/// +Y, -Z below; each face in the OpenGL cube-map orientation that skybox sets are made in);
/// or the earth-sky model.
enum class BackgroundKind : std::uint8_t { kColor, kImage, kSkybox, kEarthSky };
/// \brief pfESkyMode: kFast and kTag clear to the clear colour; kSky draws the sky and the
/// horizon band on both sides of the horizon, the clear colour below it; kSkyGround draws sky,
/// horizon and ground; kSkyClear draws the sky down to the horizon and the clear colour below.
enum class EarthSkyClear : std::uint8_t { kFast, kTag, kSky, kSkyGround, kSkyClear };

/// \brief Performer's pfEarthSky (Performer chapter 6, table 6-2 defaults). Up is world +Y; the
/// sky shades from `skyBottom` at `horizonAngle` degrees above the horizon to `skyTop` at the
/// zenith, the horizon colour fills the band between, and the ground runs from `groundFar` at the
/// horizon to `groundNear` straight down. A viewer below `groundHeight` sees no ground.
struct EarthSky {
  EarthSkyClear mode = EarthSkyClear::kFast;
  Color3 skyTop{0.0f, 0.0f, 0.44f};
  Color3 skyBottom{0.0f, 0.4f, 0.7f};
  Color3 horizon{0.8f, 0.8f, 1.0f};
  float horizonAngle = 10.0f;  // degrees
  float groundHeight = 0.0f;
  Color3 groundFar{0.4f, 0.2f, 0.0f};
  Color3 groundNear{0.5f, 0.3f, 0.0f};
  Color3 clear{0, 0, 0};
  friend bool operator==(const EarthSky&, const EarthSky&) = default;
};

}  // namespace basalt::runtime
