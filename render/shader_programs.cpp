#include "render/shader_programs.h"

#include <algorithm>

#include <fmt/format.h>

#include "embedded/render_shaders.h"
#include "runtime/log.h"

namespace basalt::render {

BASALT_LOG_CATEGORY(RenderPrograms, "render");

std::uint32_t VariantKey::packed() const {
  std::uint32_t bits = static_cast<std::uint32_t>(kind);
  bits |= static_cast<std::uint32_t>(shading) << 3;
  bits |= static_cast<std::uint32_t>(twoSided) << 6;
  bits |= static_cast<std::uint32_t>(texture) << 7;
  bits |= static_cast<std::uint32_t>(sphereMap) << 8;
  bits |= static_cast<std::uint32_t>(clip) << 9;
  bits |= static_cast<std::uint32_t>(depthCue) << 10;
  bits |= static_cast<std::uint32_t>(fog) << 11;
  bits |= static_cast<std::uint32_t>(raster) << 12;
  bits |= static_cast<std::uint32_t>(fillEffects) << 14;
  return bits;
}

namespace {

std::string_view shadingDefine(Shading s) {
  switch (s) {
    case Shading::kUnlitFlat: return "SHADE_UNLIT_FLAT";
    case Shading::kUnlitSmooth: return "SHADE_UNLIT_SMOOTH";
    case Shading::kFacet: return "SHADE_FACET";
    case Shading::kVertex: return "SHADE_VERTEX";
    case Shading::kPixel: return "SHADE_PIXEL";
  }
  return "SHADE_VERTEX";
}

std::string_view stageBody(ProgramKind kind, bool vertexStage) {
  switch (kind) {
    case ProgramKind::kSurface: return vertexStage ? shaders::kSurfaceVert : shaders::kSurfaceFrag;
    case ProgramKind::kVltm: return vertexStage ? shaders::kVltmVert : shaders::kSurfaceFrag;
    case ProgramKind::kLine: return vertexStage ? shaders::kLineVert : shaders::kLineFrag;
    case ProgramKind::kMarker: return vertexStage ? shaders::kMarkerVert : shaders::kMarkerFrag;
    case ProgramKind::kColor: return vertexStage ? shaders::kColorVert : shaders::kColorFrag;
    case ProgramKind::kBackground: return vertexStage ? shaders::kBackgroundVert : shaders::kBackgroundFrag;
  }
  return {};
}

std::string_view kindName(ProgramKind kind) {
  switch (kind) {
    case ProgramKind::kSurface: return "surface";
    case ProgramKind::kVltm: return "vltm";
    case ProgramKind::kLine: return "line";
    case ProgramKind::kMarker: return "marker";
    case ProgramKind::kColor: return "color";
    case ProgramKind::kBackground: return "background";
  }
  return "?";
}

void locate(GLuint p, ProgramUniforms& u) {
  auto at = [p](const char* name) { return glGetUniformLocation(p, name); };
  auto surface = [&](const char* prefix, ProgramUniforms::SurfaceLocations& s) {
    auto field = [&](const char* f) { return at(fmt::format("{}.{}", prefix, f).c_str()); };
    s = {field("color"),    field("specularColor"), field("ka"),         field("kd"),
         field("ks"),       field("power"),         field("components"), field("alpha"),
         field("emission"), field("ambientColor"),  field("ambientOwn")};
  };
  u.model = at("uModel");
  u.normalMatrix = at("uNormalMatrix");
  u.colorSource = at("uColorSource");
  u.backLit = at("uBackLit");
  u.frontLit = at("uFrontLit");
  u.texcoordFlip = at("uTexcoordFlip");
  u.facetStream = at("uFacetStream");
  surface("uFront", u.front);
  surface("uBack", u.back);
  u.textureMode = at("uTextureMode");
  u.textureSize = at("uTextureSize");
  u.stipple = at("uStipple");
  u.opaqueStipple = at("uOpaqueStipple");
  u.screenDoor = at("uScreenDoor");
  u.blendToBackground = at("uBlendToBackground");
  u.rasterOp = at("uRasterOp");
  u.textured = at("uTextured");
  u.maxSegments = at("uMaxSegments");
  u.approx = at("uApprox");
  u.subsegments = at("uSubsegments");
  u.pixelTolerance = at("uPixelTolerance");
  u.color = at("uColor");
  u.altColor = at("uAltColor");
  u.style = at("uStyle");
  u.patternMask = at("uPatternMask");
  u.patternPeriod = at("uPatternPeriod");
  u.patternScale = at("uPatternScale");
  u.width = at("uWidth");
  u.cap = at("uCap");
  u.join = at("uJoin");
  u.miterLimit = at("uMiterLimit");
  u.antialias = at("uAntialias");
  u.silhouette = at("uSilhouette");
  u.depthOffset = at("uDepthOffset");
  u.colorInterp = at("uColorInterp");
  u.pointSize = at("uPointSize");
  u.markerType = at("uMarkerType");
  u.markerSize = at("uMarkerSize");
  u.mode = at("uMode");
  u.inverseViewRotationProjection = at("uInverseViewRotationProjection");
  u.imageFlip = at("uImageFlip");
  u.atlasTexel = at("uAtlasTexel");
  u.skyTop = at("uSkyTop");
  u.skyBottom = at("uSkyBottom");
  u.horizon = at("uHorizon");
  u.groundFar = at("uGroundFar");
  u.groundNear = at("uGroundNear");
  u.clear = at("uClear");
  u.horizonAngle = at("uHorizonAngle");
  u.earthSkyMode = at("uEarthSkyMode");
  u.groundVisible = at("uGroundVisible");
}

}  // namespace

std::string assembleShader(const VariantKey& key, bool vertexStage) {
  std::string s = "#version 300 es\n";
  if (!vertexStage && key.raster == RasterPath::kFetch) s += "#extension GL_EXT_shader_framebuffer_fetch : require\n";
  s += vertexStage ? "#define STAGE_VERTEX 1\n" : "#define STAGE_FRAGMENT 1\n";
  auto define = [&s](std::string_view name) { s += fmt::format("#define {} 1\n", name); };
  if (key.kind == ProgramKind::kSurface) define(shadingDefine(key.shading));
  if (key.kind == ProgramKind::kVltm) define("SHADE_VERTEX");
  if (key.twoSided) define("TWO_SIDED");
  if (key.texture) define("TEXTURE");
  if (key.sphereMap) define("SPHERE_MAP");
  if (key.clip) define("CLIP");
  if (key.depthCue) define("DEPTH_CUE");
  if (key.fog) define("FOG");
  if (key.raster == RasterPath::kFetch) define("RASTER_FETCH");
  if (key.raster == RasterPath::kCopy) define("RASTER_COPY");
  if (key.fillEffects) define("FILL_EFFECTS");
  s += shaders::kCommonGlsl;
  s += "\n#line 1 1\n";
  s += stageBody(key.kind, vertexStage);
  return s;
}

Result<const LinkedProgram*> ProgramCache::build(const VariantKey& key) {
  if (key.raster == RasterPath::kFetch && !framebufferFetch_) {
    return fail(Errc::kUnsupported, "framebuffer fetch is not available for raster operations");
  }
  const std::string label = fmt::format("{} variant {:#x}", kindName(key.kind), key.packed());
  auto program = gl::buildProgram(assembleShader(key, true), assembleShader(key, false), label);
  if (!program) return std::unexpected(program.error());
  auto linked = std::make_unique<LinkedProgram>();
  linked->key = key;
  linked->program = std::move(*program);
  const GLuint id = linked->program.id();
  const GLuint block = glGetUniformBlockIndex(id, "Frame");
  if (block != GL_INVALID_INDEX) glUniformBlockBinding(id, block, kFrameBlockBinding);
  locate(id, linked->u);
  glUseProgram(id);
  glUniform1i(glGetUniformLocation(id, "uColorMap"), kUnitColorMap);
  glUniform1i(glGetUniformLocation(id, "uReflectionMap"), kUnitReflection);
  glUniform1i(glGetUniformLocation(id, "uDestination"), kUnitDestination);
  glUniform1i(glGetUniformLocation(id, "uImage"), kUnitBackground);
  if (const GLenum e = gl::drainErrors(); e != GL_NO_ERROR) {
    return fail(Errc::kInternal, fmt::format("setting up {}: {}", label, gl::errorName(e)));
  }
  programs_.push_back(std::move(linked));
  return programs_.back().get();
}

const LinkedProgram* ProgramCache::get(const VariantKey& key) {
  for (const auto& p : programs_) {
    if (p->key == key) return p.get();
  }
  const std::uint32_t packed = key.packed();
  if (std::find(failed_.begin(), failed_.end(), packed) != failed_.end()) return nullptr;
  auto built = build(key);
  if (!built) {
    log::error(kLogRenderPrograms, "a shader variant does not build; parts that need it are not drawn: {}",
               built.error().describe());
    failed_.push_back(packed);
    return nullptr;
  }
  return *built;
}

}  // namespace basalt::render
