#pragma once

/// \file
/// \brief Video as textures: a stream's frames (movie, camera, capture card) uploaded plane by
/// plane as they come and converted to RGBA in a shader, once per new frame however many parts
/// show it; and the Zoom picture (LAVA §7.1, §4.3), a stream drawn flat over the scene.

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "render/gl.h"
#include "render/output.h"
#include "render/texture_registry.h"
#include "runtime/error.h"
#include "runtime/frame.h"
#include "runtime/image.h"

namespace basalt::render {

/// \brief How a frame reached the GPU.
enum class UploadPath : std::uint8_t {
  kNone,          ///< nothing uploaded yet (the fallback shows)
  kPlanes,        ///< CPU planes uploaded as textures, converted in the shader
  kDmabufImport,  ///< dmabuf planes imported as EGL images (no copy), converted in the shader
};

std::string_view uploadPathName(UploadPath path);

/// \brief How uploaded 4:2:0 planes (I420, YV12, NV12, NV21) become the RGBA texture.
enum class ConversionPass : std::uint8_t {
  kPerPixel,  ///< one fragment a pixel into the texture (yuv.frag): what a GPU does best
  kPacked,    ///< eight pixels a fragment into integer targets, copied into the texture through a
              ///< pixel buffer (yuv_packed.frag): a third of the CPU time on a software renderer
};

class PictureOverlay;
struct PictureRect;

/// \brief One stream's RGBA texture, registered in a TextureRegistry under the stream's name.
///
/// Threading: the frame loop's thread with the GL context current. update() never blocks and,
/// once the planes and target exist for a size, allocates nothing.
class StreamTexture {
 public:
  /// \brief Compiles the conversion shader; needs a current OpenGL ES 3 context. `name` is the
  /// texture name parts use (`PartState::texture`).
  [[nodiscard]] static Result<std::unique_ptr<StreamTexture>> create(std::string name);
  ~StreamTexture();
  StreamTexture(const StreamTexture&) = delete;
  StreamTexture& operator=(const StreamTexture&) = delete;

  /// \brief Shows `frame` if it is new (an empty ref or the frame already shown changes
  /// nothing). Returns true when the texture changed. Leaves the GL framebuffer, viewport and
  /// program bindings as it found them... except the framebuffer: callers bind theirs after.
  [[nodiscard]] Result<bool> update(const FrameRef& frame);
  /// \brief Fills the texture with the fallback colour (the source failed or is absent).
  void showFallback();
  /// \brief The fallback colour (RGBA 0..1); default dark grey.
  void setFallbackColor(float r, float g, float b);
  [[nodiscard]] bool showingFallback() const { return fallback_; }
  /// \brief Flips the picture left-right from the next frame on (a camera asked to mirror
  /// that cannot flip in the device: VideoSource::mirrorInRenderer()). The frame on the texture
  /// is converted again at its next update().
  void setMirror(bool mirror);
  [[nodiscard]] bool mirror() const { return mirror_; }

  /// \brief Registers (or refreshes) the texture under name() in `registry`.
  void publish(TextureRegistry& registry) const;
  [[nodiscard]] const std::string& name() const { return name_; }
  [[nodiscard]] const TextureView& view() const { return view_; }
  [[nodiscard]] UploadPath uploadPath() const { return path_; }
  /// \brief One line for logs and the status server: path, format, size and colorimetry.
  [[nodiscard]] std::string describe() const;
  /// \brief YUV-to-RGB conversions run (one per new frame).
  [[nodiscard]] std::uint64_t conversions() const { return conversions_; }
  /// \brief The pass 4:2:0 frames take from the next update() on. The default is kPacked on a
  /// software renderer (llvmpipe, softpipe, SwiftShader) and kPerPixel on a GPU. Frames the
  /// packed pass cannot take (odd heights, rows that are not whole 32-bit words, imported
  /// dmabufs, a mirrored stream) take the per-pixel pass.
  void setConversionPass(ConversionPass pass) { conversionPass_ = pass; }
  [[nodiscard]] ConversionPass conversionPass() const { return conversionPass_; }
  /// \brief Whether the frame shown went through the packed pass.
  [[nodiscard]] bool packedConversion() const { return uploaded_.packed; }
  /// \brief Whether this EGL display can import dmabufs (EGL_EXT_image_dma_buf_import).
  [[nodiscard]] bool dmabufImportOffered() const { return dmabufOffered_; }

  /// \brief Reads the RGBA texture back, top row first (tests and snapshots).
  [[nodiscard]] Result<void> readPixels(Image& out);

  /// \brief For a stream shown only as a picture (the Zoom picture, never on a part): planar
  /// frames (I420, YV12, NV12, NV21) are then not converted at update(), but drawn straight from
  /// their planes by drawPicture(), one pass instead of two. readPixels() converts on demand;
  /// view() keeps the last frame converted, so a picture-only stream is not for parts. Off by
  /// default.
  void setPictureOnly(bool pictureOnly);
  [[nodiscard]] bool pictureOnly() const { return pictureOnly_; }
  /// \brief Draws the frame shown into the bound framebuffer of `viewport` size at `rect`: from
  /// its planes in one pass when it can (a picture-only stream, a planar frame, opaque), else
  /// the RGBA texture through `overlay`. Nothing while the fallback shows.
  void drawPicture(PictureOverlay& overlay, const PictureRect& rect, Size viewport, float opacity = 1.0f);
  /// \brief Pictures drawn straight from the planes (the one-pass path), for tests and figures.
  [[nodiscard]] std::uint64_t directPictures() const { return directPictures_; }
  /// \brief Opaque pictures at the texture's own size, copied into the output by a framebuffer
  /// blit instead of drawn (straight for a bottom-up texture, flipped for a top-down one).
  [[nodiscard]] std::uint64_t blitPictures() const { return blitPictures_; }

 private:
  struct Gpu;
  explicit StreamTexture(std::string name);
  Result<void> ensureTarget(std::uint32_t width, std::uint32_t height);
  Result<void> uploadPlanes(const Frame& frame, bool packed);
  Result<void> importDmabuf(const Frame& frame);
  Result<void> uploadRgba(const Frame& frame);
  /// What the planes on the GPU hold: enough to convert or draw them after the frame is gone.
  struct Uploaded {
    PixelFormat format = PixelFormat::kUnknown;
    std::uint32_t width = 0, height = 0;
    Colorimetry colorimetry{};
    bool packed = false;  // as the packed pass takes them (R32UI planes)
  };
  Result<void> convert(const Uploaded& planes);
  Result<void> convertPacked(const Uploaded& planes);
  Result<void> ensurePackedTarget(std::uint32_t quads, std::uint32_t rowPairs);
  /// Draws the quad with the planes bound to units 0-2 (U always on 1), the conversion program
  /// in use with its uniforms set; leaves nothing bound.
  void drawFromPlanes(PixelFormat format);
  bool blitPicture(const PictureRect& rect, Size viewport);
  /// Runs the conversion program over the planes into the bound framebuffer: the whole of it
  /// (`ndc` -1..1, into the target) or a picture rectangle (flipped: frames are top row first).
  Result<void> drawPlanes(const Uploaded& planes, const std::array<float, 4>& ndc, bool flip);
  /// The view with the target holding the current frame (converts a picture-only frame).
  Result<void> ensureConverted();

  std::string name_;
  std::unique_ptr<Gpu> gpu_;
  TextureView view_;
  UploadPath path_ = UploadPath::kNone;
  PixelFormat format_ = PixelFormat::kUnknown;
  Colorimetry colorimetry_{};
  const Frame* shown_ = nullptr;  // identity of the frame on the texture (never dereferenced)
  std::uint64_t shownSequence_ = 0;
  std::int64_t shownPts_ = -1;
  std::uint64_t conversions_ = 0;
  bool fallback_ = true;
  bool dmabufOffered_ = false;
  bool mirror_ = false;
  bool pictureOnly_ = false;
  bool converted_ = true;  // the target holds the current frame (false: only its planes do)
  Uploaded uploaded_;
  std::uint64_t directPictures_ = 0;
  std::uint64_t blitPictures_ = 0;
  ConversionPass conversionPass_ = ConversionPass::kPerPixel;
  bool packedShown_ = false;  // what the last log line said
  float fallbackColor_[3] = {0.12f, 0.12f, 0.12f};
};

/// \brief Where the Zoom picture sits, in output pixels from the top-left corner.
struct PictureRect {
  float x = 0;
  float y = 0;
  float width = 0;
  float height = 0;
};

/// \brief Draws textures flat over the scene: LAVA's Zoom picture of a movie ("1/2x", "1x",
/// "2x", or any size), movable (Shift + drag in LAVA §4.3; `move()` here).
class PictureOverlay {
 public:
  [[nodiscard]] static Result<std::unique_ptr<PictureOverlay>> create();
  ~PictureOverlay();
  PictureOverlay(const PictureOverlay&) = delete;
  PictureOverlay& operator=(const PictureOverlay&) = delete;

  /// \brief Draws `texture` into the bound framebuffer of `viewport` size at `rect`.
  void draw(const TextureView& texture, const PictureRect& rect, Size viewport, float opacity = 1.0f);

 private:
  struct Gpu;
  PictureOverlay();
  std::unique_ptr<Gpu> gpu_;
};

}  // namespace basalt::render
