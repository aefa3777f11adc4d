#include "render/renderer.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>

#include <fmt/format.h>

#include "render/attribute_tables.h"
#include "render/facet_view.h"
#include "render/frame_block.h"
#include "render/gpu_mesh.h"
#include "render/shader_programs.h"
#include "runtime/log.h"

namespace basalt::render {

BASALT_LOG_CATEGORY(Render, "render");

using runtime::Color3;
using runtime::FaceCulling;
using runtime::Illumination;
using runtime::PartStyle;
using runtime::PrimType;
using runtime::Show;
using runtime::SurfaceAttributes;

namespace {

constexpr std::uint64_t kSweepEveryFrames = 600;
constexpr int kMaxVltmSegments = 32;

/// The part of `viewport` a pass's scissor leaves; an empty scissor leaves all of it.
Viewport scissorRect(const Viewport& viewport, const Viewport& scissor) {
  if (scissor.width == 0 || scissor.height == 0) return viewport;
  const std::int64_t x0 = std::max<std::int64_t>(viewport.x, scissor.x);
  const std::int64_t y0 = std::max<std::int64_t>(viewport.y, scissor.y);
  const std::int64_t x1 =
      std::min<std::int64_t>(std::int64_t{viewport.x} + viewport.width, std::int64_t{scissor.x} + scissor.width);
  const std::int64_t y1 =
      std::min<std::int64_t>(std::int64_t{viewport.y} + viewport.height, std::int64_t{scissor.y} + scissor.height);
  if (x1 <= x0 || y1 <= y0) return {viewport.x, viewport.y, 0, 0};
  return {static_cast<std::int32_t>(x0), static_cast<std::int32_t>(y0), static_cast<std::uint32_t>(x1 - x0),
          static_cast<std::uint32_t>(y1 - y0)};
}

const void* indexOffset(std::size_t bytes) { return reinterpret_cast<const void*>(bytes); }

std::array<float, 9> normalMatrix(const Mat4& model) {
  const Mat4 n = model.inverted().transposed();
  return {n(0, 0), n(1, 0), n(2, 0), n(0, 1), n(1, 1), n(2, 1), n(0, 2), n(1, 2), n(2, 2)};
}

Shading shadingFor(Illumination illumination) {
  switch (illumination) {
    case Illumination::kNone: return Shading::kUnlitFlat;
    case Illumination::kInterpColor: return Shading::kUnlitSmooth;
    case Illumination::kPerFacet: return Shading::kFacet;
    case Illumination::kPerVertex: return Shading::kVertex;
    case Illumination::kPerPixel: return Shading::kPixel;
  }
  return Shading::kVertex;
}

bool isLit(Illumination i) { return i != Illumination::kNone && i != Illumination::kInterpColor; }

/// Whether a surface takes its material colour from the vertices (XGL colour selectors).
bool usesVertexColor(const SurfaceAttributes& s, bool meshHasColors) {
  if (!meshHasColors) return false;
  switch (s.colorSelector) {
    case runtime::SurfaceColorSelector::kContext: return false;
    case runtime::SurfaceColorSelector::kFacet:
    case runtime::SurfaceColorSelector::kIllumIndependent: return true;
    case runtime::SurfaceColorSelector::kIllumDependent:
      return s.illumination == Illumination::kInterpColor || s.illumination == Illumination::kPerVertex ||
             s.illumination == Illumination::kPerPixel;
  }
  return false;
}

/// A floor of n x n squares over x, z in -1..1 at y = 0, facing +Y, with its grid lines as edges.
std::shared_ptr<runtime::Mesh> makeFloorMesh(int n) {
  auto mesh = std::make_shared<runtime::Mesh>();
  const auto side = static_cast<std::uint32_t>(n + 1);
  for (std::uint32_t j = 0; j < side; ++j) {
    for (std::uint32_t i = 0; i < side; ++i) {
      const float x = -1.0f + 2.0f * static_cast<float>(i) / static_cast<float>(n);
      const float z = -1.0f + 2.0f * static_cast<float>(j) / static_cast<float>(n);
      mesh->positions.push_back({x, 0, z});
      mesh->normals.push_back({0, 1, 0});
      mesh->texcoords.push_back({0.5f * (x + 1), 0.5f * (1 - z)});
    }
  }
  for (std::uint32_t j = 0; j + 1 < side; ++j) {
    for (std::uint32_t i = 0; i + 1 < side; ++i) {
      const std::uint32_t a = j * side + i, b = a + 1, c = a + side, d = c + 1;
      // Counter-clockwise seen from above (+Y).
      for (std::uint32_t v : {a, c, b, b, c, d}) mesh->triangles.push_back(v);
    }
  }
  for (std::uint32_t j = 0; j < side; ++j) {
    for (std::uint32_t i = 0; i + 1 < side; ++i) {
      mesh->edges.push_back(j * side + i);
      mesh->edges.push_back(j * side + i + 1);
      mesh->edges.push_back(i * side + j);
      mesh->edges.push_back((i + 1) * side + j);
    }
  }
  runtime::MeshPart part;
  part.name = "floor";
  part.triangleIndexCount = static_cast<std::uint32_t>(mesh->triangles.size());
  part.edgeIndexCount = static_cast<std::uint32_t>(mesh->edges.size());
  part.facetCount = static_cast<std::uint32_t>(n * n);
  mesh->parts.push_back(std::move(part));
  return mesh;
}

/// Line attributes as the draw needs them (from the lines or the edges group).
struct LineLook {
  Color3 color;
  Color3 altColor;
  float width = 1;
  runtime::LineStyle style = runtime::LineStyle::kSolid;
  runtime::LinePattern pattern = runtime::LinePattern::kDotted;
  runtime::Antialiasing antialiasing = runtime::Antialiasing::kOff;
  runtime::EndpointStyle endpoint = runtime::EndpointStyle::kButt;
  runtime::JoinStyle join = runtime::JoinStyle::kMiter;
  float miterLimit = 2;
  bool vertexColor = false;
  bool colorInterpolation = false;
  bool silhouette = false;
  float depthOffset = 0;
};

LineLook linesLook(const PartStyle& s, bool meshHasColors) {
  LineLook l;
  l.color = s.lines.color;
  l.altColor = s.lines.altColor;
  l.width = s.lines.width;
  l.style = s.lines.style;
  l.pattern = s.lines.pattern;
  l.antialiasing = s.lines.antialiasing;
  l.endpoint = s.lines.endpointStyle;
  l.join = s.lines.joinStyle;
  l.miterLimit = s.lines.miterLimit;
  l.vertexColor = meshHasColors && s.lines.colorSelector == runtime::ColorSelector::kVertex;
  l.colorInterpolation = s.lines.colorInterpolation;
  return l;
}

LineLook edgesLook(const PartStyle& s) {
  LineLook l;
  l.color = s.edges.color;
  l.altColor = s.edges.altColor;
  l.width = s.edges.width;
  l.style = s.edges.style;
  l.pattern = s.edges.pattern;
  l.antialiasing = s.edges.antialiasing;
  l.silhouette = s.edges.silhouette;
  // Software edges sit in front of the surface by the offset (a fraction of a percent of the
  // depth range per 0.1); XGL edges rely on the surface being pushed back instead.
  l.depthOffset = s.edges.show == runtime::EdgeMode::kSoftware ? s.edges.softwareOffset * 0.02f : 0.0f;
  return l;
}

}  // namespace

// ---------------------------------------------------------------------------------------------

struct Renderer::Impl {
  explicit Impl(Renderer& r, bool fetch) : self(r), programs(fetch) {}

  /// Everything a part's draws share.
  struct PartDraw {
    const Show* show = nullptr;
    const runtime::SceneNode* node = nullptr;
    GpuMesh* gpu = nullptr;
    const runtime::MeshPart* meshPart = nullptr;
    const runtime::PartState* part = nullptr;
    const PartStyle* style = nullptr;
    Mat4 model;
    std::array<float, 9> normals{};
    RasterPath raster = RasterPath::kDirect;
    runtime::RasterOp rasterOp = runtime::RasterOp::kCopy;
  };

  struct BlendedItem {
    std::uint32_t node = 0;
    std::uint32_t part = 0;
    float distance = 0;
  };

  Renderer& self;
  ProgramCache programs;
  gl::Buffer frameUbo;
  FrameBlock block{};
  std::unordered_map<std::uint64_t, std::unique_ptr<GpuMesh>> meshes;
  std::uint64_t framesSinceSweep = 0;
  gl::VertexArray emptyVao;
  gl::Texture destination;
  Size destinationSize;
  std::shared_ptr<runtime::Mesh> floorMeshes[3];
  std::vector<BlendedItem> blended;
  std::vector<std::pair<std::string, std::string>> warned;  // (what, name) said once
  bool warnedRasterOp[16] = {};
  std::vector<std::uint8_t> readScratch;
  std::vector<std::uint32_t> accumulation;

  // The view being drawn.
  Viewport viewport;
  std::array<bool, 3> sceneMask{true, true, true};
  GLuint currentProgram = 0;

  GpuMesh& upload(const std::shared_ptr<const runtime::Mesh>& mesh) {
    auto it = meshes.find(mesh->id());
    if (it != meshes.end()) return *it->second;
    return *meshes.emplace(mesh->id(), GpuMesh::upload(mesh)).first->second;
  }

  void use(const LinkedProgram& p) {
    if (currentProgram != p.program.id()) {
      glUseProgram(p.program.id());
      currentProgram = p.program.id();
    }
  }

  /// Logs `message()` the first time (`kind`, `name`) comes up; allocates nothing afterwards.
  template <typename Message>
  void warnOnce(std::string_view kind, std::string_view name, Message&& message) {
    for (const auto& [k, n] : warned) {
      if (k == kind && n == name) return;
    }
    warned.emplace_back(std::string(kind), std::string(name));
    log::warn(kLogRender, "{}", message());
  }

  /// The texture `name` names, or null (warned once) when it is not loaded.
  const TextureView* texture(const std::string& name, std::string_view what, std::string_view owner) {
    if (name.empty()) return nullptr;
    const TextureView* view = self.textures_.find(name);
    if (!view || view->id == 0) {
      warnOnce(what, name, [&] {
        return fmt::format("{} '{}' of {} is not loaded; drawing without it (load it, or check the name)", what, name,
                           owner == "show" ? std::string("the show") : fmt::format("part '{}'", owner));
      });
      return nullptr;
    }
    return view;
  }

  /// The scene writes colour through the view's mask and never alpha: the background leaves the
  /// frame opaque, and snapshots stay opaque whatever transparency or antialiasing blends.
  void setColorMask(bool on) { glColorMask(on && sceneMask[0], on && sceneMask[1], on && sceneMask[2], GL_FALSE); }

  // ---- Raster operations ----

  RasterPath rasterPathFor(runtime::RasterOp op) {
    if (rasterOpIsDirect(op)) return RasterPath::kDirect;
    if (self.caps_.framebufferFetch) return RasterPath::kFetch;
    bool& said = warnedRasterOp[static_cast<std::size_t>(op)];
    if (!said) {
      said = true;
      log::warn(kLogRender,
                "render.raster_op = {} cannot be drawn exactly on this GPU (no framebuffer fetch): Basalt "
                "combines each part with a copy of the frame taken just before it, so where a part's own faces "
                "overlap they combine with what was behind the part rather than with each other",
                rasterOpName(op));
    }
    return RasterPath::kCopy;
  }

  /// Sets blending and masks for the raster op; before a copy-path draw, copies the viewport.
  void beginRaster(const PartDraw& d) {
    if (d.raster == RasterPath::kCopy) {
      const Size size{viewport.width, viewport.height};
      if (!destination || destinationSize != size) {
        destination = gl::Texture::create();
        glActiveTexture(GL_TEXTURE0 + kUnitDestination);
        glBindTexture(GL_TEXTURE_2D, destination.id());
        glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGB8, static_cast<GLsizei>(size.width), static_cast<GLsizei>(size.height));
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        destinationSize = size;
      }
      glActiveTexture(GL_TEXTURE0 + kUnitDestination);
      glBindTexture(GL_TEXTURE_2D, destination.id());
      glCopyTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, viewport.x, viewport.y, static_cast<GLsizei>(viewport.width),
                          static_cast<GLsizei>(viewport.height));
    }
    if (d.rasterOp == runtime::RasterOp::kNoop) setColorMask(false);
    if (d.rasterOp == runtime::RasterOp::kInvert && d.raster == RasterPath::kDirect) {
      glEnable(GL_BLEND);
      glBlendFunc(GL_ONE_MINUS_DST_COLOR, GL_ZERO);
    }
  }

  void endRaster(const PartDraw& d) {
    if (d.rasterOp == runtime::RasterOp::kNoop) setColorMask(true);
    if (d.rasterOp == runtime::RasterOp::kInvert && d.raster == RasterPath::kDirect) glDisable(GL_BLEND);
  }

  VariantKey effectsKey(ProgramKind kind, const Show& show, bool modelGeometry, const PartDraw* d) const {
    VariantKey k;
    k.kind = kind;
    k.clip = modelGeometry && show.modelClipping().numPlanes > 0;
    k.depthCue = show.depthCue().mode != runtime::DepthCueMode::kNone;
    k.fog = show.fog().mode != runtime::FogMode::kNone;
    if (d) k.raster = d->raster;
    return k;
  }

  // ---- Uniform helpers ----

  static void setSurface(const ProgramUniforms::SurfaceLocations& u, const SurfaceAttributes& s, Color3 colour,
                         float alpha) {
    glUniform3f(u.color, colour.r, colour.g, colour.b);
    glUniform3f(u.specularColor, s.specularColor.r, s.specularColor.g, s.specularColor.b);
    glUniform1f(u.ka, s.ambient);
    glUniform1f(u.kd, s.diffuse);
    glUniform1f(u.ks, s.specular);
    glUniform1f(u.power, s.specularPower);
    glUniform1i(u.components, s.lightComponents);
    glUniform1f(u.alpha, alpha);
    glUniform3f(u.emission, s.emission.r, s.emission.g, s.emission.b);
    glUniform3f(u.ambientColor, s.ambientColor.color.r, s.ambientColor.color.g, s.ambientColor.color.b);
    glUniform1i(u.ambientOwn, s.ambientColor.own ? 1 : 0);
  }

  static void setModel(const ProgramUniforms& u, const Mat4& model, const std::array<float, 9>& normals) {
    glUniformMatrix4fv(u.model, 1, GL_FALSE, model.data());
    glUniformMatrix3fv(u.normalMatrix, 1, GL_FALSE, normals.data());
  }

  static void bindTexture(GLint unit, const TextureView& view) {
    glActiveTexture(static_cast<GLenum>(GL_TEXTURE0 + unit));
    glBindTexture(GL_TEXTURE_2D, view.id);
  }

  static std::array<float, 2> flipOf(const TextureView* view) {
    // Texture rows run top to bottom unless the owner says otherwise: t' = y + x t.
    if (view && view->bottomUp) return {1.0f, 0.0f};
    return {-1.0f, 1.0f};
  }

  // ---- Surfaces ----

  struct SurfaceLook {
    bool screenDoor = false;
    bool blendToBackground = false;
    float frontAlpha = 1;
    float backAlpha = 1;
  };

  void drawSurface(const PartDraw& d, const SurfaceLook& look) {
    const Show& show = *d.show;
    const PartStyle& style = *d.style;
    const runtime::MeshPart& mp = *d.meshPart;
    GpuMesh& gpu = *d.gpu;
    const SurfaceAttributes& front = style.front;
    const bool faceDist = style.render.faceDistinguishing;
    const SurfaceAttributes& back = faceDist ? style.back : style.front;

    VariantKey key = effectsKey(ProgramKind::kSurface, show, true, &d);
    key.shading = shadingFor(front.illumination);
    key.twoSided = faceDist && style.render.faceCulling != FaceCulling::kBack;

    const bool texturing = show.texture().source != runtime::TextureSource::kOff;
    const TextureView* video =
        show.texture().source == runtime::TextureSource::kVideo ? self.textures_.find(kVideoTexture) : nullptr;
    const TextureView* colorMap =
        video ? video : (texturing ? texture(d.part->texture, "texture", d.part->name) : nullptr);
    const TextureView* reflection =
        texturing ? texture(d.part->reflectionTexture, "reflection map", d.part->name) : nullptr;
    const bool patternFill = front.fillStyle == runtime::FillStyle::kPattern;
    if (patternFill && !colorMap) {
      warnOnce("pattern fill", d.part->name, [&] {
        return fmt::format("part '{}' has fill style 'pattern' but no texture to tile; drawing it solid", d.part->name);
      });
    }
    const bool vltm = colorMap && !patternFill && show.texture().method == runtime::TextureMethod::kVertexLevel;
    const bool stipple =
        front.fillStyle == runtime::FillStyle::kStipple || front.fillStyle == runtime::FillStyle::kOpaqueStipple;
    key.fillEffects = stipple || look.screenDoor;
    if (vltm) {
      key.kind = ProgramKind::kVltm;
      key.shading = Shading::kVertex;
    } else {
      key.texture = colorMap != nullptr;
      key.sphereMap = reflection != nullptr;
    }
    const LinkedProgram* program = programs.get(key);
    if (!program) return;
    use(*program);
    const ProgramUniforms& u = program->u;
    setModel(u, d.model, d.normals);
    setSurface(u.front, front, front.color, look.frontAlpha);
    setSurface(u.back, back, back.color, look.backAlpha);
    const bool vertexColor = usesVertexColor(front, gpu.hasColors());
    glUniform1i(u.colorSource, vertexColor ? 1 : 0);
    glUniform1i(u.backLit, isLit(back.illumination) ? 1 : 0);
    glUniform1i(u.frontLit, isLit(front.illumination) ? 1 : 0);
    glUniform1i(u.rasterOp, static_cast<GLint>(d.rasterOp));
    glUniform1i(u.blendToBackground, look.blendToBackground ? 1 : 0);
    const auto flip = flipOf(colorMap);
    glUniform2f(u.texcoordFlip, flip[0], flip[1]);
    if (colorMap) {
      bindTexture(kUnitColorMap, *colorMap);
      glUniform1i(u.textureMode, patternFill ? 1 : 0);
      glUniform2f(u.textureSize, static_cast<float>(std::max(colorMap->size.width, 1U)),
                  static_cast<float>(std::max(colorMap->size.height, 1U)));
      glUniform1i(u.textured, 1);
    }
    if (reflection) bindTexture(kUnitReflection, *reflection);
    if (key.fillEffects) {
      glUniform1i(u.stipple, stipple ? static_cast<GLint>(front.stipplePattern) : -1);
      glUniform1i(u.opaqueStipple, front.fillStyle == runtime::FillStyle::kOpaqueStipple ? 1 : 0);
      glUniform1i(u.screenDoor, look.screenDoor ? 1 : 0);
    }

    beginRaster(d);
    const auto triangles = static_cast<GLsizei>(mp.triangleIndexCount);
    if (vltm) {
      const runtime::TextureSettings& ts = show.texture();
      const int segments = vltmSegments(d, ts);
      glUniform1i(u.maxSegments, segments);
      glUniform1i(u.approx, static_cast<GLint>(ts.approx));
      glUniform1i(u.subsegments, std::max(ts.subsegments, 1));
      glUniform1f(u.pixelTolerance, static_cast<float>(std::max(ts.pixelTolerance, 1)));
      glBindVertexArray(gpu.vltmVao());
      gpu.bindVltm(mp.firstTriangleIndex / 3);
      glDrawArraysInstanced(GL_TRIANGLES, 0, 3 * segments * segments, triangles / 3);
    } else if (key.shading == Shading::kFacet) {
      glUniform1i(u.facetStream, 1);
      glBindVertexArray(gpu.facetVao());
      glDrawArrays(GL_TRIANGLES, static_cast<GLint>(mp.firstTriangleIndex), triangles);
    } else {
      glUniform1i(u.facetStream, 0);
      glBindVertexArray(gpu.indexedVao());
      glDrawElements(GL_TRIANGLES, triangles, GL_UNSIGNED_INT,
                     indexOffset(std::size_t{mp.firstTriangleIndex} * sizeof(std::uint32_t)));
    }
    endRaster(d);
    ++self.counts_.drawCalls;
  }

  /// The largest subdivision a VLTM draw of this part needs.
  int vltmSegments(const PartDraw& d, const runtime::TextureSettings& ts) const {
    int m = std::max(ts.subsegments, 1);
    if (ts.approx != runtime::TextureApprox::kNumSegments) {
      // Pixels per object unit at the part's nearest possible depth bounds the longest side.
      const GpuPart& gp = d.gpu->parts()[static_cast<std::size_t>(d.meshPart - d.node->mesh->parts.data())];
      const float scale = length(d.model.transformDirection({1, 0, 0}));
      const float projected = gp.longestEdge * scale;
      const Vec4 clipCentre = viewProjection * (d.model * Vec4{gp.centre.x, gp.centre.y, gp.centre.z, 1});
      const float w = std::max(clipCentre.w - gp.longestEdge * scale, 1e-3f);
      const float pixels = projected * std::abs(viewProjection(1, 1)) * 0.5f * static_cast<float>(viewport.height) / w;
      const int byTolerance = static_cast<int>(std::ceil(pixels / static_cast<float>(std::max(ts.pixelTolerance, 1))));
      m = ts.approx == runtime::TextureApprox::kPixelTolerance ? byTolerance : std::max(m, byTolerance);
    }
    return std::clamp(m, 1, kMaxVltmSegments);
  }

  // ---- Lines, edges, markers ----

  /// Draws the part's polygon edges (`edges`) or its lines with `look`, in `colorSource` order.
  void drawLines(const PartDraw& d, bool edges, const LineLook& look) {
    const runtime::MeshPart& mp = *d.meshPart;
    const std::uint32_t first = edges ? mp.firstEdgeIndex : mp.firstLineIndex;
    const std::uint32_t count = edges ? mp.edgeIndexCount : mp.lineIndexCount;
    if (count < 2) return;
    const Show& show = *d.show;
    const bool patterned = look.style != runtime::LineStyle::kSolid;
    const bool aa = look.antialiasing != runtime::Antialiasing::kOff;
    const bool thin = look.width <= 1.0f && !patterned && !aa && !look.silhouette;
    const bool blend = look.antialiasing == runtime::Antialiasing::kArbitraryBackground;

    if (thin) {
      const LinkedProgram* program = programs.get(effectsKey(ProgramKind::kColor, show, true, &d));
      if (!program) return;
      use(*program);
      const ProgramUniforms& u = program->u;
      glUniformMatrix4fv(u.model, 1, GL_FALSE, d.model.data());
      glUniform4f(u.color, look.color.r, look.color.g, look.color.b, 1);
      glUniform1i(u.colorSource, look.vertexColor ? 1 : 0);
      glUniform1f(u.depthOffset, look.depthOffset);
      glUniform1i(u.rasterOp, static_cast<GLint>(d.rasterOp));
      glBindVertexArray(d.gpu->indexedVao());
      beginRaster(d);
      glDrawElements(GL_LINES, static_cast<GLsizei>(count), GL_UNSIGNED_INT,
                     indexOffset((edges ? d.gpu->edgeOffset() : d.gpu->lineOffset()) +
                                 std::size_t{first} * sizeof(std::uint32_t)));
      endRaster(d);
    } else {
      const LinkedProgram* program = programs.get(effectsKey(ProgramKind::kLine, show, true, &d));
      if (!program) return;
      use(*program);
      const ProgramUniforms& u = program->u;
      setModel(u, d.model, d.normals);
      glUniform4f(u.color, look.color.r, look.color.g, look.color.b, 1);
      glUniform4f(u.altColor, look.altColor.r, look.altColor.g, look.altColor.b, 1);
      glUniform1i(u.style, static_cast<GLint>(look.style));
      const LinePatternMask mask = linePatternMask(look.pattern);
      glUniform1i(u.patternMask, static_cast<GLint>(mask.mask));
      glUniform1i(u.patternPeriod, mask.period);
      glUniform1f(u.patternScale, std::max(look.width, 1.0f));
      glUniform1f(u.width, look.width);
      glUniform1i(u.cap, static_cast<GLint>(look.endpoint));
      glUniform1i(u.join, static_cast<GLint>(look.join));
      glUniform1f(u.miterLimit, look.miterLimit);
      glUniform1i(u.antialias, aa ? 1 : 0);
      glUniform1i(u.blendToBackground, look.antialiasing == runtime::Antialiasing::kConstantBackground ? 1 : 0);
      glUniform1i(u.silhouette, look.silhouette ? 1 : 0);
      glUniform1f(u.depthOffset, look.depthOffset);
      glUniform1i(u.colorSource, look.vertexColor ? 1 : 0);
      glUniform1i(u.colorInterp, look.colorInterpolation ? 1 : 0);
      glUniform1i(u.rasterOp, static_cast<GLint>(d.rasterOp));
      glBindVertexArray(d.gpu->segmentVao(edges));
      d.gpu->bindSegments(edges, first / 2);
      if (blend) {
        glEnable(GL_BLEND);
        glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
      }
      beginRaster(d);
      glDrawArraysInstanced(GL_TRIANGLES, 0, 12, static_cast<GLsizei>(count / 2));
      endRaster(d);
      if (blend) glDisable(GL_BLEND);
    }
    ++self.counts_.drawCalls;
    self.counts_.lines += count / 2;
  }

  void drawMarkers(const PartDraw& d, std::size_t indexByteOffset, std::uint32_t count) {
    if (count == 0) return;
    const runtime::MarkerAttributes& m = d.style->markers;
    const LinkedProgram* program = programs.get(effectsKey(ProgramKind::kMarker, *d.show, true, &d));
    if (!program) return;
    use(*program);
    const ProgramUniforms& u = program->u;
    const bool aa = m.antialiasing != runtime::Antialiasing::kOff;
    const bool dot = m.type == runtime::MarkerType::kDot;
    const float size = dot ? 1.0f : std::max(m.scaleFactor, 1.0f);
    const float sprite = std::min(dot ? 1.0f : std::ceil(size) + (aa ? 2.0f : 0.0f), self.caps_.maxPointSize);
    glUniformMatrix4fv(u.model, 1, GL_FALSE, d.model.data());
    glUniform4f(u.color, m.color.r, m.color.g, m.color.b, 1);
    glUniform1i(u.colorSource, m.colorSelector == runtime::ColorSelector::kVertex && d.gpu->hasColors() ? 1 : 0);
    glUniform1i(u.markerType, static_cast<GLint>(m.type));
    glUniform1f(u.pointSize, sprite);
    glUniform1f(u.markerSize, size);
    glUniform1i(u.antialias, aa ? 1 : 0);
    glUniform1i(u.blendToBackground, m.antialiasing == runtime::Antialiasing::kConstantBackground ? 1 : 0);
    glUniform1i(u.rasterOp, static_cast<GLint>(d.rasterOp));
    const bool blend = m.antialiasing == runtime::Antialiasing::kArbitraryBackground;
    if (blend) {
      glEnable(GL_BLEND);
      glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    }
    glBindVertexArray(d.gpu->indexedVao());
    beginRaster(d);
    glDrawElements(GL_POINTS, static_cast<GLsizei>(count), GL_UNSIGNED_INT, indexOffset(indexByteOffset));
    endRaster(d);
    if (blend) glDisable(GL_BLEND);
    ++self.counts_.drawCalls;
    self.counts_.points += count;
  }

  // ---- Parts ----

  void setDepthAndCulling(const PartStyle& style) {
    if (style.render.hiddenSurfaceRemoval) {
      glEnable(GL_DEPTH_TEST);
      glDepthFunc(GL_LEQUAL);
    } else {
      glDisable(GL_DEPTH_TEST);
    }
    switch (style.render.faceCulling) {
      case FaceCulling::kOff: glDisable(GL_CULL_FACE); break;
      case FaceCulling::kBack:
        glEnable(GL_CULL_FACE);
        glCullFace(GL_BACK);
        break;
      case FaceCulling::kFront:
        glEnable(GL_CULL_FACE);
        glCullFace(GL_FRONT);
        break;
    }
  }

  bool deferredBlend(const PartStyle& style) const {
    const SurfaceAttributes& f = style.front;
    return style.render.primType == PrimType::kSolid && f.transparencyMethod == runtime::TransparencyMethod::kBlended &&
           (f.transparencyBlend == runtime::TransparencyBlend::kArbitraryBackground ||
            f.transparencyBlend == runtime::TransparencyBlend::kAddToBackground);
  }

  SurfaceLook lookFor(const PartStyle& style) const {
    SurfaceLook look;
    const SurfaceAttributes& f = style.front;
    const SurfaceAttributes& b = style.render.faceDistinguishing ? style.back : style.front;
    if (f.transparencyMethod == runtime::TransparencyMethod::kNone) return look;
    if (f.transparencyMethod == runtime::TransparencyMethod::kBlended &&
        f.transparencyBlend == runtime::TransparencyBlend::kNone) {
      return look;
    }
    look.frontAlpha = std::clamp(1.0f - f.transparency, 0.0f, 1.0f);
    look.backAlpha = std::clamp(1.0f - b.transparency, 0.0f, 1.0f);
    look.screenDoor = f.transparencyMethod == runtime::TransparencyMethod::kScreenDoor;
    look.blendToBackground = f.transparencyMethod == runtime::TransparencyMethod::kBlended &&
                             f.transparencyBlend == runtime::TransparencyBlend::kConstantBackground;
    return look;
  }

  /// Draws one part's opaque work; returns true when its surface waits for the blended pass.
  bool drawPart(PartDraw& d) {
    const PartStyle& style = *d.style;
    const runtime::MeshPart& mp = *d.meshPart;
    d.rasterOp = style.render.rasterOp;
    d.raster = rasterPathFor(d.rasterOp);
    setDepthAndCulling(style);
    ++self.counts_.parts;
    bool deferred = false;

    switch (style.render.primType) {
      case PrimType::kSolid: {
        const runtime::FillStyle fill = style.front.fillStyle;
        const bool xglEdges = style.edges.show == runtime::EdgeMode::kOn;
        if (fill == runtime::FillStyle::kHollow) {
          LineLook outline;
          outline.color = style.front.color;
          drawLines(d, true, outline);
        } else if (fill != runtime::FillStyle::kEmpty && mp.triangleIndexCount > 0) {
          if (deferredBlend(style)) {
            deferred = true;
          } else {
            if (xglEdges) {
              glEnable(GL_POLYGON_OFFSET_FILL);
              glPolygonOffset(1.0f, 1.0f);
            }
            drawSurface(d, lookFor(style));
            if (xglEdges) glDisable(GL_POLYGON_OFFSET_FILL);
          }
          self.counts_.triangles += mp.triangleIndexCount / 3;
          self.counts_.facets += mp.facetCount;
        }
        if (style.edges.show != runtime::EdgeMode::kOff) {
          glDisable(GL_CULL_FACE);
          drawLines(d, true, edgesLook(style));
          setDepthAndCulling(style);
        }
        break;
      }
      case PrimType::kWireframe: drawLines(d, true, linesLook(style, d.gpu->hasColors())); break;
      case PrimType::kMarkers: {
        const GpuPart& gp = d.gpu->parts()[static_cast<std::size_t>(&mp - d.node->mesh->parts.data())];
        drawMarkers(d, d.gpu->markerOffset() + std::size_t{gp.firstMarkerIndex} * sizeof(std::uint32_t),
                    gp.markerIndexCount);
        break;
      }
    }
    // A part's own lines and points are drawn whatever its primitive type.
    if (mp.lineIndexCount > 0) drawLines(d, false, linesLook(style, d.gpu->hasColors()));
    if (mp.pointIndexCount > 0) {
      drawMarkers(d, d.gpu->pointOffset() + std::size_t{mp.firstPointIndex} * sizeof(std::uint32_t),
                  mp.pointIndexCount);
    }
    return deferred;
  }

  void drawBlendedPart(PartDraw& d) {
    const PartStyle& style = *d.style;
    d.rasterOp = style.render.rasterOp;
    d.raster = rasterPathFor(d.rasterOp);
    setDepthAndCulling(style);
    glEnable(GL_BLEND);
    if (style.front.transparencyBlend == runtime::TransparencyBlend::kAddToBackground) {
      glBlendFunc(GL_SRC_ALPHA, GL_ONE);
    } else {
      glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    }
    glDepthMask(GL_FALSE);
    const SurfaceLook look = lookFor(style);
    if (style.render.faceCulling == FaceCulling::kOff) {
      // Far faces first, then near ones: right for convex parts, better than index order for any.
      glEnable(GL_CULL_FACE);
      glCullFace(GL_FRONT);
      drawSurface(d, look);
      glCullFace(GL_BACK);
      drawSurface(d, look);
      glDisable(GL_CULL_FACE);
    } else {
      drawSurface(d, look);
    }
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
  }

  PartDraw partDraw(const Show& show, std::uint32_t nodeIndex, std::uint32_t partIndex, const Mat4& model,
                    const std::array<float, 9>& normals) {
    const runtime::SceneNode& node = show.nodes()[nodeIndex];
    PartDraw d;
    d.show = &show;
    d.node = &node;
    d.gpu = &upload(node.mesh);
    d.meshPart = &node.mesh->parts[partIndex];
    const runtime::PartId id = node.partIds[partIndex];
    d.part = &show.part(id);
    d.style = &show.resolvedStyle(id);
    d.model = model;
    d.normals = normals;
    return d;
  }

  // ---- Background, floor, shadow ----

  /// Clears the viewport to the background's clear colour, then draws an image, skybox or
  /// earth-sky background inside `clip`.
  void drawBackground(const Show& show, const runtime::ViewTransforms& view, const Mat4& projection,
                      const Viewport& clip) {
    const runtime::BackgroundKind kind = show.backgroundKind();
    const runtime::EarthSky& sky = show.earthSky();
    const Color3 clear = Renderer::clearColor(show);
    const bool earthSkyClearOnly =
        sky.mode == runtime::EarthSkyClear::kFast || sky.mode == runtime::EarthSkyClear::kTag;
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glClearColor(clear.r, clear.g, clear.b, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    glScissor(clip.x, clip.y, static_cast<GLsizei>(clip.width), static_cast<GLsizei>(clip.height));

    int mode = 0;
    const TextureView* image = nullptr;
    if (kind == runtime::BackgroundKind::kImage || kind == runtime::BackgroundKind::kSkybox) {
      image = texture(show.backgroundImage(), kind == runtime::BackgroundKind::kImage ? "background image" : "skybox",
                      "show");
      if (image) mode = kind == runtime::BackgroundKind::kImage ? 1 : 2;
    } else if (kind == runtime::BackgroundKind::kEarthSky && !earthSkyClearOnly) {
      mode = 3;
    }
    if (mode == 0) return;
    const LinkedProgram* program = programs.get(VariantKey{ProgramKind::kBackground});
    if (!program) return;
    use(*program);
    const ProgramUniforms& u = program->u;
    glUniform1i(u.mode, mode);
    Mat4 rotation = view.view;
    rotation(0, 3) = rotation(1, 3) = rotation(2, 3) = 0;
    const Mat4 inverse = (projection * rotation).inverted();
    glUniformMatrix4fv(u.inverseViewRotationProjection, 1, GL_FALSE, inverse.data());
    if (image) {
      bindTexture(kUnitBackground, *image);
      const auto flip = flipOf(image);
      glUniform2f(u.imageFlip, flip[0], flip[1]);
      glUniform2f(u.atlasTexel, 1.0f / static_cast<float>(std::max(image->size.width, 1U)),
                  1.0f / static_cast<float>(std::max(image->size.height, 1U)));
    }
    auto colour = [](GLint at, const Color3& c) { glUniform3f(at, c.r, c.g, c.b); };
    colour(u.skyTop, sky.skyTop);
    colour(u.skyBottom, sky.skyBottom);
    colour(u.horizon, sky.horizon);
    colour(u.groundFar, sky.groundFar);
    colour(u.groundNear, sky.groundNear);
    colour(u.clear, sky.clear);
    glUniform1f(u.horizonAngle, radians(std::clamp(sky.horizonAngle, 0.01f, 89.0f)));
    glUniform1i(u.earthSkyMode, static_cast<GLint>(sky.mode));
    glUniform1i(u.groundVisible, view.eye.y >= sky.groundHeight ? 1 : 0);
    glDisable(GL_DEPTH_TEST);
    glDepthMask(GL_FALSE);
    glDisable(GL_CULL_FACE);
    glBindVertexArray(emptyVao.id());
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glDepthMask(GL_TRUE);
    ++self.counts_.drawCalls;
  }

  void drawFloor(const Show& show) {
    const runtime::Environment& env = show.environment();
    if (env.floor == runtime::FloorKind::kNone) return;
    const int kindIndex = static_cast<int>(env.floor) - 1;
    auto& mesh = floorMeshes[kindIndex];
    if (!mesh) mesh = makeFloorMesh(kindIndex == 0 ? 1 : (kindIndex == 1 ? 8 : 32));
    GpuMesh& gpu = upload(mesh);
    const runtime::FloorGeometry geometry = runtime::computeFloor(show);
    const std::array<float, 9> normals = normalMatrix(geometry.floor);
    const bool solid = env.floorPrimType == runtime::FloorPrimType::kSolid;
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LEQUAL);
    glDisable(GL_CULL_FACE);

    auto drawFloorOnce = [&](float darkness) {
      const Color3 c{env.floorColor.r * darkness, env.floorColor.g * darkness, env.floorColor.b * darkness};
      if (solid) {
        VariantKey key = effectsKey(ProgramKind::kSurface, show, false, nullptr);
        key.shading = Shading::kVertex;
        const LinkedProgram* program = programs.get(key);
        if (!program) return;
        use(*program);
        const ProgramUniforms& u = program->u;
        setModel(u, geometry.floor, normals);
        SurfaceAttributes matte;
        matte.specular = 0;  // a matte floor, so that the shadow darkens it exactly
        setSurface(u.front, matte, c, 1);
        setSurface(u.back, matte, c, 1);
        glUniform1i(u.colorSource, 0);
        glUniform1i(u.rasterOp, static_cast<GLint>(runtime::RasterOp::kCopy));
        glUniform1i(u.blendToBackground, 0);
        glBindVertexArray(gpu.indexedVao());
        glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(mesh->triangles.size()), GL_UNSIGNED_INT, nullptr);
      } else {
        const LinkedProgram* program = programs.get(effectsKey(ProgramKind::kColor, show, false, nullptr));
        if (!program) return;
        use(*program);
        const ProgramUniforms& u = program->u;
        glUniformMatrix4fv(u.model, 1, GL_FALSE, geometry.floor.data());
        glUniform4f(u.color, c.r, c.g, c.b, 1);
        glUniform1i(u.colorSource, 0);
        glUniform1f(u.depthOffset, 0);
        glUniform1i(u.rasterOp, static_cast<GLint>(runtime::RasterOp::kCopy));
        glBindVertexArray(gpu.indexedVao());
        glDrawElements(GL_LINES, static_cast<GLsizei>(mesh->edges.size()), GL_UNSIGNED_INT,
                       indexOffset(gpu.edgeOffset()));
      }
      ++self.counts_.drawCalls;
    };
    drawFloorOnce(1.0f);
    if (!env.shadow) return;

    // LAVA's fake shadow: the object squashed onto the floor. With a stencil buffer, it marks
    // where the floor is drawn again at the shadow's darkness; without one, it is drawn flat.
    const LinkedProgram* shadowProgram = programs.get(effectsKey(ProgramKind::kColor, show, false, nullptr));
    if (!shadowProgram) return;
    const float darkness = std::clamp(env.shadowDarkness, 0.0f, 1.0f);
    const bool stencil = self.caps_.stencil;
    glDisable(GL_DEPTH_TEST);
    glDepthMask(GL_FALSE);
    if (stencil) {
      glEnable(GL_STENCIL_TEST);
      glStencilFunc(GL_ALWAYS, 1, 0xFF);
      glStencilOp(GL_KEEP, GL_KEEP, GL_REPLACE);
      glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    }
    use(*shadowProgram);
    const ProgramUniforms& su = shadowProgram->u;
    const Color3 flat{env.floorColor.r * darkness, env.floorColor.g * darkness, env.floorColor.b * darkness};
    glUniform4f(su.color, flat.r, flat.g, flat.b, 1);
    glUniform1i(su.colorSource, 0);
    glUniform1f(su.depthOffset, 0);
    glUniform1i(su.rasterOp, static_cast<GLint>(runtime::RasterOp::kCopy));
    const auto& nodes = show.nodes();
    for (std::uint32_t i = 0; i < nodes.size(); ++i) {
      const runtime::SceneNode& node = nodes[i];
      if (!node.visible || !node.mesh) continue;
      GpuMesh& objectGpu = upload(node.mesh);
      const Mat4 squashed = geometry.shadow * show.worldTransform(i);
      glUniformMatrix4fv(su.model, 1, GL_FALSE, squashed.data());
      glBindVertexArray(objectGpu.indexedVao());
      for (std::size_t p = 0; p < node.mesh->parts.size(); ++p) {
        const runtime::MeshPart& mp = node.mesh->parts[p];
        if (!show.part(node.partIds[p]).selected || mp.triangleIndexCount == 0) continue;
        glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(mp.triangleIndexCount), GL_UNSIGNED_INT,
                       indexOffset(std::size_t{mp.firstTriangleIndex} * sizeof(std::uint32_t)));
        ++self.counts_.drawCalls;
      }
    }
    if (stencil) {
      setColorMask(true);
      glStencilFunc(GL_EQUAL, 1, 0xFF);
      glStencilOp(GL_KEEP, GL_KEEP, GL_KEEP);
      drawFloorOnce(darkness);
      glDisable(GL_STENCIL_TEST);
    }
    glDepthMask(GL_TRUE);
    glEnable(GL_DEPTH_TEST);
  }

  // ---- One view ----

  Mat4 viewProjection;

  void drawView(const Show& show, const runtime::ViewTransforms& view, const ViewPass& pass) {
    viewport = pass.viewport;
    sceneMask = pass.colorMask;
    currentProgram = 0;
    const auto w = static_cast<GLsizei>(viewport.width), h = static_cast<GLsizei>(viewport.height);
    glViewport(viewport.x, viewport.y, w, h);
    glEnable(GL_SCISSOR_TEST);
    const Viewport clip = scissorRect(viewport, pass.scissor);
    glScissor(viewport.x, viewport.y, w, h);

    Mat4 projection = view.projection;
    if (pass.jitter.x != 0 || pass.jitter.y != 0) {
      const float jx = 2.0f * pass.jitter.x / static_cast<float>(std::max(viewport.width, 1U));
      const float jy = 2.0f * pass.jitter.y / static_cast<float>(std::max(viewport.height, 1U));
      projection = Mat4::translation({jx, jy, 0}) * projection;
    }
    viewProjection = projection * view.view;
    const float rect[4] = {static_cast<float>(viewport.x), static_cast<float>(viewport.y), static_cast<float>(w),
                           static_cast<float>(h)};
    fillFrameBlock(block, show, view, viewProjection, rect);
    glBindBufferBase(GL_UNIFORM_BUFFER, kFrameBlockBinding, frameUbo.id());
    glBufferSubData(GL_UNIFORM_BUFFER, 0, sizeof(FrameBlock), &block);

    glDisable(GL_BLEND);
    glDisable(GL_POLYGON_OFFSET_FILL);
    glDepthMask(GL_TRUE);
    // The clears cover the whole viewport (a scissored clear is a drawn quad on Mesa, slower
    // than a whole one); what is drawn after them stays inside the pass's scissor.
    if (pass.clearDepth) {
      glClearDepthf(1.0f);
      glClearStencil(0);
      glClear(GL_DEPTH_BUFFER_BIT | (self.caps_.stencil ? GL_STENCIL_BUFFER_BIT : 0));
    }
    if (pass.drawBackground) drawBackground(show, view, projection, clip);
    setColorMask(true);
    glScissor(clip.x, clip.y, static_cast<GLsizei>(clip.width), static_cast<GLsizei>(clip.height));
    drawFloor(show);

    blended.clear();
    const auto& nodes = show.nodes();
    for (std::uint32_t i = 0; i < nodes.size(); ++i) {
      const runtime::SceneNode& node = nodes[i];
      if (!node.visible || !node.mesh) continue;
      const Mat4 model = view.model * show.worldTransform(i);
      const std::array<float, 9> normals = normalMatrix(model);
      for (std::uint32_t p = 0; p < node.mesh->parts.size() && p < node.partIds.size(); ++p) {
        if (!show.part(node.partIds[p]).selected) continue;
        PartDraw d = partDraw(show, i, p, model, normals);
        if (drawPart(d)) {
          const GpuPart& gp = d.gpu->parts()[p];
          const Vec3 centre = model.transformPoint(gp.centre);
          blended.push_back({i, p, length(centre - view.eye)});
        }
      }
    }
    if (!blended.empty()) {
      std::sort(blended.begin(), blended.end(),
                [](const BlendedItem& a, const BlendedItem& b) { return a.distance > b.distance; });
      for (const BlendedItem& item : blended) {
        const Mat4 model = view.model * show.worldTransform(item.node);
        PartDraw d = partDraw(show, item.node, item.part, model, normalMatrix(model));
        drawBlendedPart(d);
      }
    }

    glBindVertexArray(0);
    glDisable(GL_SCISSOR_TEST);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glDisable(GL_POLYGON_OFFSET_FILL);
    glDepthMask(GL_TRUE);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glActiveTexture(GL_TEXTURE0);
    if (++framesSinceSweep >= kSweepEveryFrames) {
      framesSinceSweep = 0;
      // Erasing frees GPU buffers of meshes no longer in any Show; iteration allocates nothing.
      std::erase_if(meshes, [](const auto& entry) { return !entry.second->alive(); });
    }
  }
};

// ---------------------------------------------------------------------------------------------

Renderer::Renderer() = default;

Renderer::~Renderer() = default;

std::size_t Renderer::gpuMeshCount() const { return impl_->meshes.size(); }

Result<std::unique_ptr<Renderer>> Renderer::create(const RendererOptions& options) {
  std::unique_ptr<Renderer> r(new Renderer);
  bool fetch = false;
  GLint extensionCount = 0;
  glGetIntegerv(GL_NUM_EXTENSIONS, &extensionCount);
  for (GLint i = 0; i < extensionCount; ++i) {
    const auto* name = reinterpret_cast<const char*>(glGetStringi(GL_EXTENSIONS, static_cast<GLuint>(i)));
    if (name && std::string_view(name) == "GL_EXT_shader_framebuffer_fetch") fetch = true;
  }
  r->caps_.framebufferFetch = options.allowFramebufferFetch && fetch;
  GLint stencilBits = 0;
  GLint framebuffer = 0;
  glGetIntegerv(GL_FRAMEBUFFER_BINDING, &framebuffer);
  if (framebuffer != 0) {
    glGetFramebufferAttachmentParameteriv(GL_FRAMEBUFFER, GL_STENCIL_ATTACHMENT, GL_FRAMEBUFFER_ATTACHMENT_STENCIL_SIZE,
                                          &stencilBits);
  } else {
    glGetFramebufferAttachmentParameteriv(GL_FRAMEBUFFER, GL_STENCIL, GL_FRAMEBUFFER_ATTACHMENT_STENCIL_SIZE,
                                          &stencilBits);
  }
  gl::drainErrors();  // a framebuffer without a stencil attachment answers with an error
  r->caps_.stencil = stencilBits > 0;
  GLfloat pointRange[2] = {1, 1};
  glGetFloatv(GL_ALIASED_POINT_SIZE_RANGE, pointRange);
  r->caps_.maxPointSize = std::max(pointRange[1], 1.0f);
  r->caps_.description = gl::rendererDescription();

  r->impl_ = std::make_unique<Impl>(*r, r->caps_.framebufferFetch);
  Impl& impl = *r->impl_;
  impl.frameUbo = gl::Buffer::create();
  glBindBuffer(GL_UNIFORM_BUFFER, impl.frameUbo.id());
  glBufferData(GL_UNIFORM_BUFFER, sizeof(FrameBlock), nullptr, GL_DYNAMIC_DRAW);
  glBindBuffer(GL_UNIFORM_BUFFER, 0);
  impl.emptyVao = gl::VertexArray::create();
  impl.blended.reserve(64);

  // The variants every show needs: a broken shader fails here, not in the middle of a show.
  VariantKey facet{ProgramKind::kSurface, Shading::kFacet};
  VariantKey vertex{ProgramKind::kSurface, Shading::kVertex};
  for (const VariantKey& key : {facet, vertex, VariantKey{ProgramKind::kColor}, VariantKey{ProgramKind::kLine},
                                VariantKey{ProgramKind::kMarker}, VariantKey{ProgramKind::kBackground}}) {
    auto built = impl.programs.build(key);
    if (!built) return std::unexpected(built.error());
  }
  glUseProgram(0);
  if (const GLenum e = gl::drainErrors(); e != GL_NO_ERROR) {
    return fail(Errc::kInternal, fmt::format("setting up the renderer: {}", gl::errorName(e)));
  }
  return r;
}

void Renderer::draw(const Show& show, const runtime::ViewTransforms& view, Size viewport) {
  ViewPass pass;
  pass.viewport = {0, 0, viewport.width, viewport.height};
  draw(show, view, pass);
}

void Renderer::draw(const Show& show, const runtime::ViewTransforms& view, const ViewPass& pass) {
  counts_ = {};
  if (pass.viewport.width == 0 || pass.viewport.height == 0) return;
  impl_->drawView(show, view, pass);
  frameCounts_.triangles += counts_.triangles;
  frameCounts_.lines += counts_.lines;
  frameCounts_.points += counts_.points;
  frameCounts_.parts += counts_.parts;
  frameCounts_.facets += counts_.facets;
}

runtime::Color3 Renderer::clearColor(const Show& show) {
  const runtime::EarthSky& sky = show.earthSky();
  const bool earthSkyClearOnly = sky.mode == runtime::EarthSkyClear::kFast || sky.mode == runtime::EarthSkyClear::kTag;
  return show.backgroundKind() == runtime::BackgroundKind::kEarthSky && earthSkyClearOnly ? sky.clear
                                                                                          : show.global().background;
}

namespace {

/// A scene's own viewport (thesis §4.3.4 and C.3, `viewport position[x,y] resolution[w,h]`:
/// glViewport's rectangle, in pixels from the bottom left of the view it is drawn in). The view's
/// clip space is squeezed into that rectangle and drawing is scissored to it; the view's clears
/// still cover the whole view, as the thesis' glClear covers the whole window.
struct SceneRectangle {
  bool used = false;
  float aspect = 1;  ///< the rectangle's
  Mat4 place;        ///< clip space of the rectangle to clip space of the view
  Viewport scissor;  ///< the rectangle within the view, in window pixels
};

SceneRectangle sceneRectangle(const Show& show, const Viewport& view) {
  SceneRectangle r;
  const runtime::Viewer& c = show.viewer();
  if (c.framing != runtime::Framing::kScene || c.viewportWidth <= 0 || c.viewportHeight <= 0) return r;
  const auto vw = static_cast<float>(std::max(view.width, 1U)), vh = static_cast<float>(std::max(view.height, 1U));
  const auto x = static_cast<float>(c.viewportX), y = static_cast<float>(c.viewportY);
  const auto w = static_cast<float>(c.viewportWidth), h = static_cast<float>(c.viewportHeight);
  r.used = true;
  r.aspect = w / h;
  r.place = Mat4::translation({(2 * x + w) / vw - 1, (2 * y + h) / vh - 1, 0}) * Mat4::scaling({w / vw, h / vh, 1});
  const std::int64_t x0 = std::clamp<std::int64_t>(c.viewportX, 0, view.width);
  const std::int64_t y0 = std::clamp<std::int64_t>(c.viewportY, 0, view.height);
  const std::int64_t x1 = std::clamp<std::int64_t>(std::int64_t{c.viewportX} + c.viewportWidth, 0, view.width);
  const std::int64_t y1 = std::clamp<std::int64_t>(std::int64_t{c.viewportY} + c.viewportHeight, 0, view.height);
  if (x1 <= x0 || y1 <= y0) {
    // Off the view: a scissor beside it draws nothing (an empty one would mean the whole view).
    r.scissor = {view.x - 2, view.y - 2, 1, 1};
  } else {
    r.scissor = {view.x + static_cast<std::int32_t>(x0), view.y + static_cast<std::int32_t>(y0),
                 static_cast<std::uint32_t>(x1 - x0), static_cast<std::uint32_t>(y1 - y0)};
  }
  return r;
}

}  // namespace

void Renderer::drawShow(const Show& show, const Viewport& viewport,
                        const std::function<void(runtime::ViewTransforms&)>& adjust) {
  const SceneRectangle rect = sceneRectangle(show, viewport);
  const float aspect =
      rect.used ? rect.aspect
                : static_cast<float>(std::max(viewport.width, 1U)) / static_cast<float>(std::max(viewport.height, 1U));
  auto adjusted = [&adjust, &rect](runtime::ViewTransforms view) {
    if (adjust) adjust(view);
    if (rect.used) view.projection = rect.place * view.projection;
    return view;
  };
  if (show.global().stereo) {
    const float half = 0.5f * runtime::eyeSpacingInWindowUnits(show);
    const runtime::ViewTransforms left = adjusted(runtime::computeEyeView(show, aspect, -half));
    const runtime::ViewTransforms right = adjusted(runtime::computeEyeView(show, aspect, half));
    if (show.stereo().mode == runtime::StereoMode::kAnaglyph && !rect.used) {
      drawAnaglyph(show, left, right, viewport);
      return;
    }
    if (show.stereo().mode == runtime::StereoMode::kAnaglyph) {
      ViewPass leftEye;
      leftEye.viewport = viewport;
      leftEye.scissor = rect.scissor;
      leftEye.colorMask = {true, false, false};
      draw(show, left, leftEye);
      ViewPass rightEye = leftEye;
      rightEye.drawBackground = false;
      rightEye.colorMask = {false, true, true};
      draw(show, right, rightEye);
      return;
    }
    // Passive stereo: each eye squeezed into its half at the whole viewport's aspect ratio.
    const std::array<Viewport, 2> eyes = stereoViewports(viewport, show.stereo().mode);
    ViewPass pass;
    pass.viewport = eyes[0];
    pass.scissor = rect.used ? sceneRectangle(show, eyes[0]).scissor : Viewport{};
    draw(show, left, pass);
    pass.viewport = eyes[1];
    pass.scissor = rect.used ? sceneRectangle(show, eyes[1]).scissor : Viewport{};
    draw(show, right, pass);
    return;
  }
  ViewPass pass;
  pass.viewport = viewport;
  pass.scissor = rect.scissor;
  draw(show, adjusted(runtime::computeView(show, aspect)), pass);
}

void Renderer::drawAnaglyph(const Show& show, const runtime::ViewTransforms& left, const runtime::ViewTransforms& right,
                            const Viewport& viewport) {
  ViewPass leftEye;
  leftEye.viewport = viewport;
  leftEye.colorMask = {true, false, false};
  draw(show, left, leftEye);
  ViewPass rightEye;
  rightEye.viewport = viewport;
  rightEye.drawBackground = false;
  rightEye.colorMask = {false, true, true};
  draw(show, right, rightEye);
}

const std::array<Vec2, 8>& Renderer::jitterOffsets() {
  // The eight-sample jitter table of the OpenGL Programming Guide's accumulation-buffer
  // anti-aliasing, centred on the pixel.
  static const std::array<Vec2, 8> offsets = {
      Vec2{0.5625f - 0.5f, 0.4375f - 0.5f}, Vec2{0.0625f - 0.5f, 0.9375f - 0.5f}, Vec2{0.3125f - 0.5f, 0.6875f - 0.5f},
      Vec2{0.6875f - 0.5f, 0.8125f - 0.5f}, Vec2{0.8125f - 0.5f, 0.1875f - 0.5f}, Vec2{0.9375f - 0.5f, 0.5625f - 0.5f},
      Vec2{0.4375f - 0.5f, 0.0625f - 0.5f}, Vec2{0.1875f - 0.5f, 0.3125f - 0.5f}};
  return offsets;
}

Result<void> Renderer::drawStochastic(const Show& show, const Viewport& viewport, Image& out, int passes) {
  passes = std::clamp(passes, 1, 8);
  const std::size_t pixels = std::size_t{viewport.width} * viewport.height;
  if (pixels == 0) return fail(Errc::kInvalidArgument, "a stochastic snapshot needs a viewport with pixels");
  std::vector<std::uint8_t>& scratch = impl_->readScratch;
  std::vector<std::uint32_t>& sum = impl_->accumulation;
  scratch.resize(pixels * 4);
  sum.assign(pixels * 4, 0);
  const float aspect = static_cast<float>(viewport.width) / static_cast<float>(viewport.height);
  const runtime::ViewTransforms view = runtime::computeView(show, aspect);
  for (int i = 0; i < passes; ++i) {
    ViewPass pass;
    pass.viewport = viewport;
    pass.jitter = jitterOffsets()[static_cast<std::size_t>(i)];
    if (show.global().stereo) {
      const float half = 0.5f * runtime::eyeSpacingInWindowUnits(show);
      ViewPass right = pass;
      pass.colorMask = {true, false, false};
      draw(show, runtime::computeEyeView(show, aspect, -half), pass);
      right.drawBackground = false;
      right.colorMask = {false, true, true};
      draw(show, runtime::computeEyeView(show, aspect, half), right);
    } else {
      draw(show, view, pass);
    }
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(viewport.x, viewport.y, static_cast<GLsizei>(viewport.width), static_cast<GLsizei>(viewport.height),
                 GL_RGBA, GL_UNSIGNED_BYTE, scratch.data());
    if (const GLenum e = gl::drainErrors(); e != GL_NO_ERROR) {
      return fail(Errc::kIo, fmt::format("reading a stochastic pass back failed: {}", gl::errorName(e)));
    }
    for (std::size_t k = 0; k < scratch.size(); ++k) sum[k] += scratch[k];
  }
  if (out.width != viewport.width || out.height != viewport.height || out.channels != 4 ||
      out.type != ChannelType::kU8) {
    out = Image::make(viewport.width, viewport.height, 4);
  }
  const auto n = static_cast<std::uint32_t>(passes);
  const std::size_t row = std::size_t{viewport.width} * 4;
  for (std::uint32_t y = 0; y < viewport.height; ++y) {
    const std::uint32_t* from = sum.data() + row * (viewport.height - 1 - y);  // GL rows run bottom up
    std::uint8_t* to = out.row(y);
    for (std::size_t k = 0; k < row; ++k) to[k] = static_cast<std::uint8_t>((from[k] + n / 2) / n);
  }
  return {};
}

runtime::FrameCounts Renderer::takeFrameCounts() {
  const runtime::FrameCounts c = frameCounts_;
  frameCounts_ = {};
  return c;
}

}  // namespace basalt::render
