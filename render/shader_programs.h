#pragma once

/// \file
/// \brief The renderer's programs and their variants (private to render/).
///
/// Each program is assembled from `common.glsl` and its own stages, with #defines for the
/// features a draw needs (the lighting location, two-sided lighting, textures, clipping, depth
/// cue, fog, the raster-op path, fill effects). Variants are compiled the first time a draw
/// needs them and kept, so a steady frame compiles and allocates nothing; the common ones are
/// compiled up front so that a broken shader fails Renderer::create().

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "render/gl.h"
#include "runtime/error.h"

namespace basalt::render {

enum class ProgramKind : std::uint8_t { kSurface, kVltm, kLine, kMarker, kColor, kBackground };

/// \brief Where a surface's light is computed (XGL illumination types, plus per pixel).
enum class Shading : std::uint8_t { kUnlitFlat, kUnlitSmooth, kFacet, kVertex, kPixel };

/// \brief How the raster operation reaches the destination: in the shader and fixed-function
/// state alone (copy, clear, set, copy inverted, invert, no-op), by framebuffer fetch (exact), or
/// from a copy of the viewport taken before the draw (exact unless a draw overlaps itself).
enum class RasterPath : std::uint8_t { kDirect, kFetch, kCopy };

/// \brief Everything that selects a variant, packed for lookup.
struct VariantKey {
  ProgramKind kind = ProgramKind::kSurface;
  Shading shading = Shading::kVertex;
  bool twoSided = false;
  bool texture = false;
  bool sphereMap = false;
  bool clip = false;
  bool depthCue = false;
  bool fog = false;
  RasterPath raster = RasterPath::kDirect;
  bool fillEffects = false;

  [[nodiscard]] std::uint32_t packed() const;
  friend bool operator==(const VariantKey&, const VariantKey&) = default;
};

/// \brief Uniform locations of one linked variant (-1 where the variant lacks the uniform, which
/// glUniform* ignores).
struct ProgramUniforms {
  struct SurfaceLocations {
    GLint color = -1, specularColor = -1, ka = -1, kd = -1, ks = -1, power = -1, components = -1, alpha = -1;
    GLint emission = -1, ambientColor = -1, ambientOwn = -1;
  };
  GLint model = -1, normalMatrix = -1, colorSource = -1, backLit = -1, frontLit = -1, texcoordFlip = -1;
  GLint facetStream = -1;
  SurfaceLocations front, back;
  GLint textureMode = -1, textureSize = -1, stipple = -1, opaqueStipple = -1, screenDoor = -1;
  GLint blendToBackground = -1, rasterOp = -1;
  // VLTM
  GLint textured = -1, maxSegments = -1, approx = -1, subsegments = -1, pixelTolerance = -1;
  // Lines and markers
  GLint color = -1, altColor = -1, style = -1, patternMask = -1, patternPeriod = -1, patternScale = -1;
  GLint width = -1, cap = -1, join = -1, miterLimit = -1, antialias = -1, silhouette = -1, depthOffset = -1;
  GLint colorInterp = -1, pointSize = -1, markerType = -1, markerSize = -1;
  // Background
  GLint mode = -1, inverseViewRotationProjection = -1, imageFlip = -1, atlasTexel = -1;
  GLint skyTop = -1, skyBottom = -1, horizon = -1, groundFar = -1, groundNear = -1, clear = -1;
  GLint horizonAngle = -1, earthSkyMode = -1, groundVisible = -1;
};

/// \brief Texture units the programs sample, fixed at link time.
enum TextureUnit : GLint { kUnitColorMap = 0, kUnitReflection = 1, kUnitDestination = 2, kUnitBackground = 3 };

/// \brief The binding point of the per-view `Frame` uniform block.
inline constexpr GLuint kFrameBlockBinding = 0;

struct LinkedProgram {
  VariantKey key;
  gl::Program program;
  ProgramUniforms u;
};

/// \brief Compiles and keeps program variants.
class ProgramCache {
 public:
  /// \brief `framebufferFetch`: whether RasterPath::kFetch variants may be built.
  explicit ProgramCache(bool framebufferFetch) : framebufferFetch_(framebufferFetch) {}

  /// \brief The variant for `key`, compiled on first use; null when it does not compile (the
  /// error was logged once; the draw is skipped).
  const LinkedProgram* get(const VariantKey& key);
  /// \brief Compiles `key` now, returning the compiler's error.
  Result<const LinkedProgram*> build(const VariantKey& key);
  [[nodiscard]] std::size_t size() const { return programs_.size(); }

 private:
  bool framebufferFetch_;
  std::vector<std::unique_ptr<LinkedProgram>> programs_;
  std::vector<std::uint32_t> failed_;
};

/// \brief The full source of one stage of a variant (exposed for tests and error messages).
std::string assembleShader(const VariantKey& key, bool vertexStage);

}  // namespace basalt::render
