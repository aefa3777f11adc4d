// Stream textures: video frames to RGBA textures on the GPU, with no CPU colour conversion.
//
// Serves: every FrameSource (movies, cameras, capture cards). CPU frames are uploaded plane by
// plane in the layout they come in (I420, YV12, NV12, NV21, YUYV, UYVY, RGBA, BGRA, GRAY8) and
// converted by one full-target draw with the stream's colorimetry; on a software renderer 4:2:0
// frames take the packed pass (eight pixels a fragment, copied into the texture through a pixel
// buffer, bottom row first). Opaque pictures at the texture's size are blitted. Frames backed
// by dmabufs are imported as EGL images where the display offers EGL_EXT_image_dma_buf_import
// (Mesa's surfaceless llvmpipe does not; then the frame must also be mapped, and is uploaded).
// Limits: no mipmaps (a video texture is sampled linearly); MJPEG must be decoded first
// (media::MjpegDecoder). Configuration: none; the path taken is logged once per stream.

#include "render/stream_texture.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GLES2/gl2ext.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <utility>

#include <fmt/format.h>

#include "embedded/render_shaders.h"
#include "render/egl.h"
#include "runtime/log.h"

namespace basalt::render {

BASALT_LOG_CATEGORY(Render, "render");

std::string_view uploadPathName(UploadPath path) {
  switch (path) {
    case UploadPath::kNone: return "none";
    case UploadPath::kPlanes: return "planes uploaded, converted in the shader";
    case UploadPath::kDmabufImport: return "dmabuf imported, converted in the shader";
  }
  return "none";
}

namespace {

// Layouts the conversion shader knows (yuv.frag's uLayout).
enum Layout : int { kRgba = 0, kBgra = 1, kGray = 2, kThreePlanes = 3, kNv12 = 4, kNv21 = 5, kYuyv = 6, kUyvy = 7 };

int layoutOf(PixelFormat f) {
  switch (f) {
    case PixelFormat::kRgba8: return kRgba;
    case PixelFormat::kBgra8: return kBgra;
    case PixelFormat::kGray8: return kGray;
    case PixelFormat::kI420:
    case PixelFormat::kYv12: return kThreePlanes;
    case PixelFormat::kNv12: return kNv12;
    case PixelFormat::kNv21: return kNv21;
    case PixelFormat::kYuyv: return kYuyv;
    case PixelFormat::kUyvy: return kUyvy;
    default: return -1;
  }
}

struct PlaneFormat {
  GLenum internal;
  GLenum format;
  std::uint32_t bytesPerTexel;
  std::uint32_t width;
  std::uint32_t height;
  GLenum type = GL_UNSIGNED_BYTE;
};

/// The texture each plane of `frame` goes into.
int planeFormats(const Frame& frame, std::array<PlaneFormat, 3>& out) {
  const std::uint32_t w = frame.width, h = frame.height, cw = (w + 1) / 2, ch = (h + 1) / 2;
  switch (frame.format) {
    case PixelFormat::kRgba8:
    case PixelFormat::kBgra8: out[0] = {GL_RGBA8, GL_RGBA, 4, w, h}; return 1;
    case PixelFormat::kGray8: out[0] = {GL_R8, GL_RED, 1, w, h}; return 1;
    case PixelFormat::kI420:
    case PixelFormat::kYv12:
      out[0] = {GL_R8, GL_RED, 1, w, h};
      out[1] = {GL_R8, GL_RED, 1, cw, ch};
      out[2] = {GL_R8, GL_RED, 1, cw, ch};
      return 3;
    case PixelFormat::kNv12:
    case PixelFormat::kNv21:
      out[0] = {GL_R8, GL_RED, 1, w, h};
      out[1] = {GL_RG8, GL_RG, 2, cw, ch};
      return 2;
    case PixelFormat::kYuyv:
    case PixelFormat::kUyvy: out[0] = {GL_RGBA8, GL_RGBA, 4, cw, h}; return 1;
    default: return 0;
  }
}

/// The textures of a 4:2:0 frame for the packed pass (yuv_packed.frag): every plane as R32UI,
/// four 8-bit samples a texel, rows read a whole texel further than the picture where its width
/// is not a multiple of four. 0 when the frame cannot take it: another layout, an odd height (the
/// pass pairs rows that share chroma), or rows too short, unaligned or a stride that is not a
/// whole number of texels.
int packedPlaneFormats(const Frame& frame, std::array<PlaneFormat, 3>& out) {
  const bool threePlanes = frame.format == PixelFormat::kI420 || frame.format == PixelFormat::kYv12;
  const bool twoPlanes = frame.format == PixelFormat::kNv12 || frame.format == PixelFormat::kNv21;
  if ((!threePlanes && !twoPlanes) || frame.height % 2 != 0 || frame.width == 0) return 0;
  const std::uint32_t quads = (frame.width + 3) / 4;  // fragments across: four pixels each
  const std::uint32_t chromaRows = frame.height / 2;
  out[0] = {GL_R32UI, GL_RED_INTEGER, 4, quads, frame.height, GL_UNSIGNED_INT};
  // Three planes: a chroma texel holds four samples, eight pixels; two: two UV pairs, four pixels.
  const std::uint32_t chromaTexels = threePlanes ? (quads + 1) / 2 : quads;
  out[1] = {GL_R32UI, GL_RED_INTEGER, 4, chromaTexels, chromaRows, GL_UNSIGNED_INT};
  out[2] = out[1];
  const int count = threePlanes ? 3 : 2;
  if (frame.planeCount < count) return 0;
  for (int i = 0; i < count; ++i) {
    const Plane& p = frame.planes[static_cast<std::size_t>(i)];
    const PlaneFormat& pf = out[static_cast<std::size_t>(i)];
    if (!p.data || reinterpret_cast<std::uintptr_t>(p.data) % 4 != 0 || p.stride % 4 != 0 || p.stride < pf.width * 4) {
      return 0;
    }
  }
  return count;
}

/// Column-major YUV->RGB matrix and offsets for the shader, range folded in.
void colorMatrix(const Colorimetry& c, std::array<float, 9>& m, std::array<float, 3>& offset) {
  float kr = 0.299f, kb = 0.114f;  // BT.601
  if (c.matrix == Colorimetry::Matrix::kBt709) {
    kr = 0.2126f;
    kb = 0.0722f;
  } else if (c.matrix == Colorimetry::Matrix::kBt2020) {
    kr = 0.2627f;
    kb = 0.0593f;
  }
  const float kg = 1.0f - kr - kb;
  const bool limited = c.range == Colorimetry::Range::kLimited;
  const float ys = limited ? 255.0f / 219.0f : 1.0f;
  const float cs = limited ? 255.0f / 224.0f : 1.0f;
  const float rv = 2.0f * (1.0f - kr) * cs;
  const float bu = 2.0f * (1.0f - kb) * cs;
  const float gu = -2.0f * (1.0f - kb) * kb / kg * cs;
  const float gv = -2.0f * (1.0f - kr) * kr / kg * cs;
  // Columns: Y, U, V contributions to (R, G, B).
  m = {ys, ys, ys, 0.0f, gu, bu, rv, gv, 0.0f};
  offset = {limited ? 16.0f / 255.0f : 0.0f, 128.0f / 255.0f, 128.0f / 255.0f};
}

std::string_view matrixName(const Colorimetry& c) {
  switch (c.matrix) {
    case Colorimetry::Matrix::kBt709: return "BT.709";
    case Colorimetry::Matrix::kBt2020: return "BT.2020";
    default: return "BT.601";
  }
}

void setSampling(GLenum filter) {
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, static_cast<GLint>(filter));
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, static_cast<GLint>(filter));
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
}

/// The program the current EGL context keeps under `key` (compiled once for every stream texture
/// and picture drawing in it), made by `build` (which also sets its sampler units) the first
/// time. Where no context is known, `owned` keeps the one built.
template <typename Build>
Result<GLuint> keptProgram(const std::string& key, gl::Program& owned, Build&& build) {
  EglContext* context = EglContext::current();
  if (const GLuint kept = context ? context->keptProgram(key) : 0; kept != 0) return kept;
  Result<gl::Program> program = std::forward<Build>(build)();
  if (!program) return std::unexpected(program.error());
  if (context) return context->keepProgram(key, std::move(*program));
  owned = std::move(*program);
  return owned.id();
}

/// The conversion program for one layout: the current EGL context's copy (compiled once for all
/// the stream textures drawing in it), or one of its own where none is known.
struct ConversionProgram {
  GLuint program = 0;
  gl::Program owned;
  GLint yCoef = -1, uCoef = -1, vCoef = -1, bias = -1, rect = -1, flip = -1, flipX = -1, chromaScale = -1,
        mirrorWidth = -1, height = -1;
};

/// yuv.frag (or yuv_packed.frag) with LAYOUT defined: one program per layout, so no pixel runs
/// a branch.
Result<ConversionProgram> buildConversion(int layout, bool packed = false) {
  ConversionProgram c;
  auto kept = keptProgram(
      fmt::format("stream_texture.yuv.{}{}", layout, packed ? ".packed" : ""), c.owned, [&]() -> Result<gl::Program> {
        std::string_view text = packed ? shaders::kYuvPackedFrag : shaders::kYuvFrag;
        const auto firstLine = text.find('\n');
        const std::string source =
            fmt::format("{}\n#define LAYOUT {}\n{}", text.substr(0, firstLine), layout, text.substr(firstLine + 1));
        auto program = gl::buildProgram(shaders::kQuadVert, source,
                                        fmt::format("yuv layout {}{}", layout, packed ? " (packed)" : ""));
        if (!program) return program;
        glUseProgram(program->id());
        for (int unit = 0; unit < 3; ++unit) {
          glUniform1i(glGetUniformLocation(program->id(), fmt::format("uPlane{}", unit).c_str()), unit);
        }
        glUseProgram(0);
        return program;
      });
  if (!kept) return std::unexpected(kept.error());
  c.program = *kept;
  const GLuint p = c.program;
  c.yCoef = glGetUniformLocation(p, "uYCoef");
  c.uCoef = glGetUniformLocation(p, "uUCoef");
  c.vCoef = glGetUniformLocation(p, "uVCoef");
  c.bias = glGetUniformLocation(p, "uBias");
  c.rect = glGetUniformLocation(p, "uRect");
  c.flip = glGetUniformLocation(p, "uFlipY");
  c.flipX = glGetUniformLocation(p, "uFlipX");
  c.chromaScale = glGetUniformLocation(p, "uChromaScale");
  c.mirrorWidth = glGetUniformLocation(p, "uMirrorWidth");
  c.height = glGetUniformLocation(p, "uHeight");
  return c;
}

/// The stream's colorimetry into a conversion program's uniforms (the program in use).
void setColourUniforms(const ConversionProgram& c, const Colorimetry& colorimetry) {
  std::array<float, 9> m{};
  std::array<float, 3> offset{};
  colorMatrix(colorimetry, m, offset);
  // Columns of m are the Y, U and V contributions; the bias is -m * offset.
  glUniform3f(c.yCoef, m[0], m[1], m[2]);
  glUniform3f(c.uCoef, m[3], m[4], m[5]);
  glUniform3f(c.vCoef, m[6], m[7], m[8]);
  glUniform3f(c.bias, -(m[0] * offset[0] + m[3] * offset[1] + m[6] * offset[2]),
              -(m[1] * offset[0] + m[4] * offset[1] + m[7] * offset[2]),
              -(m[2] * offset[0] + m[5] * offset[1] + m[8] * offset[2]));
}

/// Whether the current context renders in software (Mesa's llvmpipe or softpipe, SwiftShader).
bool softwareRenderer() {
  const auto* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  if (!renderer) return false;
  const std::string_view r(renderer);
  return r.find("llvmpipe") != std::string_view::npos || r.find("softpipe") != std::string_view::npos ||
         r.find("SwiftShader") != std::string_view::npos;
}

}  // namespace

struct StreamTexture::Gpu {
  std::array<ConversionProgram, 8> programs;        // by layout, built on first use
  std::array<ConversionProgram, 8> packedPrograms;  // yuv_packed.frag, by layout (4:2:0 ones)
  gl::VertexArray vao;                              // attributeless draws still need a bound VAO in ES 3
  std::array<gl::Texture, 3> planes;
  std::array<PlaneFormat, 3> planeFormat{};
  int planeCount = 0;
  gl::Texture target;
  gl::Framebuffer fbo;
  std::uint32_t width = 0, height = 0;
  // The packed pass: even and odd target rows as RGBA32UI (a texel: four packed RGBA8 pixels),
  // and the pixel buffer they are copied through into `target`.
  std::array<gl::Texture, 2> packedRows;
  gl::Framebuffer packedFbo;
  gl::Buffer packedPixels;
  std::uint32_t packedWidth = 0, packedHeight = 0;
  PFNGLEGLIMAGETARGETTEXTURE2DOESPROC imageTargetTexture = nullptr;
  PFNEGLCREATEIMAGEKHRPROC createImage = nullptr;
  PFNEGLDESTROYIMAGEKHRPROC destroyImage = nullptr;
};

StreamTexture::StreamTexture(std::string name) : name_(std::move(name)), gpu_(std::make_unique<Gpu>()) {}

StreamTexture::~StreamTexture() = default;

Result<std::unique_ptr<StreamTexture>> StreamTexture::create(std::string name) {
  std::unique_ptr<StreamTexture> s(new StreamTexture(std::move(name)));
  Gpu& g = *s->gpu_;
  // The common decoder layout is built now, for the pass this renderer takes, so that a broken
  // shader fails at start-up.
  const bool packed = softwareRenderer();
  s->conversionPass_ = packed ? ConversionPass::kPacked : ConversionPass::kPerPixel;
  auto i420 = buildConversion(kThreePlanes, packed);
  if (!i420) return std::unexpected(i420.error());
  (packed ? g.packedPrograms : g.programs)[kThreePlanes] = std::move(*i420);
  g.vao = gl::VertexArray::create();
  const EGLDisplay display = eglGetCurrentDisplay();
  const char* extensions = display != EGL_NO_DISPLAY ? eglQueryString(display, EGL_EXTENSIONS) : nullptr;
  s->dmabufOffered_ = extensions && extensionListHas(extensions, "EGL_EXT_image_dma_buf_import");
  if (s->dmabufOffered_) {
    g.imageTargetTexture =
        reinterpret_cast<PFNGLEGLIMAGETARGETTEXTURE2DOESPROC>(eglGetProcAddress("glEGLImageTargetTexture2DOES"));
    g.createImage = reinterpret_cast<PFNEGLCREATEIMAGEKHRPROC>(eglGetProcAddress("eglCreateImageKHR"));
    g.destroyImage = reinterpret_cast<PFNEGLDESTROYIMAGEKHRPROC>(eglGetProcAddress("eglDestroyImageKHR"));
    if (!g.imageTargetTexture || !g.createImage || !g.destroyImage) s->dmabufOffered_ = false;
  }
  if (auto r = s->ensureTarget(16, 16); !r) return std::unexpected(r.error());
  s->showFallback();
  if (const GLenum e = gl::drainErrors(); e != GL_NO_ERROR) {
    return fail(Errc::kInternal, fmt::format("setting up stream texture '{}': {}", s->name_, gl::errorName(e)));
  }
  return s;
}

Result<void> StreamTexture::ensureTarget(std::uint32_t width, std::uint32_t height) {
  Gpu& g = *gpu_;
  if (g.target && g.width == width && g.height == height) return {};
  GLint maxSize = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &maxSize);
  if (width == 0 || height == 0 || width > static_cast<std::uint32_t>(maxSize) ||
      height > static_cast<std::uint32_t>(maxSize)) {
    return fail(Errc::kUnsupported, fmt::format("stream '{}': a {}x{} frame is beyond this renderer's limit of {}",
                                                name_, width, height, maxSize));
  }
  g.target = gl::Texture::create();
  glBindTexture(GL_TEXTURE_2D, g.target.id());
  glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA8, static_cast<GLsizei>(width), static_cast<GLsizei>(height));
  setSampling(GL_LINEAR);
  glBindTexture(GL_TEXTURE_2D, 0);
  g.fbo = gl::Framebuffer::create();
  glBindFramebuffer(GL_FRAMEBUFFER, g.fbo.id());
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, g.target.id(), 0);
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    return fail(Errc::kUnavailable, fmt::format("stream '{}': cannot render into an RGBA texture (0x{:x})", name_,
                                                static_cast<unsigned>(status)));
  }
  g.width = width;
  g.height = height;
  view_.id = g.target.id();
  view_.size = {width, height};
  view_.hasAlpha = false;
  ++view_.generation;
  return {};
}

void StreamTexture::setFallbackColor(float r, float g, float b) {
  fallbackColor_[0] = r;
  fallbackColor_[1] = g;
  fallbackColor_[2] = b;
  if (fallback_) showFallback();
}

void StreamTexture::showFallback() {
  Gpu& g = *gpu_;
  glBindFramebuffer(GL_FRAMEBUFFER, g.fbo.id());
  glViewport(0, 0, static_cast<GLsizei>(g.width), static_cast<GLsizei>(g.height));
  glClearColor(fallbackColor_[0], fallbackColor_[1], fallbackColor_[2], 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  if (!fallback_) ++view_.generation;
  fallback_ = true;
  shown_ = nullptr;
  shownPts_ = -1;
}

Result<void> StreamTexture::uploadPlanes(const Frame& frame, bool packed) {
  Gpu& g = *gpu_;
  std::array<PlaneFormat, 3> formats{};
  const int count = packed ? packedPlaneFormats(frame, formats) : planeFormats(frame, formats);
  if (count == 0 || frame.planeCount < count) {
    return fail(Errc::kUnsupported, fmt::format("stream '{}': {} frames cannot be shown (decode MJPEG first)", name_,
                                                pixelFormatName(frame.format)));
  }
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  for (int i = 0; i < count; ++i) {
    const auto idx = static_cast<std::size_t>(i);
    const PlaneFormat& pf = formats[idx];
    const Plane& plane = frame.planes[idx];
    if (!plane.data) return fail(Errc::kUnsupported, fmt::format("stream '{}': plane {} is not mapped", name_, i));
    const PlaneFormat& old = g.planeFormat[idx];
    if (!g.planes[idx] || old.width != pf.width || old.height != pf.height || old.internal != pf.internal) {
      g.planes[idx] = gl::Texture::create();
      glBindTexture(GL_TEXTURE_2D, g.planes[idx].id());
      glTexStorage2D(GL_TEXTURE_2D, 1, pf.internal, static_cast<GLsizei>(pf.width), static_cast<GLsizei>(pf.height));
      // Sampled at texel centres, texel by texel (the shader sites chroma with its top-left
      // luma sample); nearest keeps a software renderer's sampling to a plain load.
      setSampling(GL_NEAREST);
      g.planeFormat[idx] = pf;
    } else {
      glBindTexture(GL_TEXTURE_2D, g.planes[idx].id());
    }
    if (plane.stride % pf.bytesPerTexel == 0) {
      glPixelStorei(GL_UNPACK_ROW_LENGTH, static_cast<GLint>(plane.stride / pf.bytesPerTexel));
      glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, static_cast<GLsizei>(pf.width), static_cast<GLsizei>(pf.height),
                      pf.format, pf.type, plane.data);
    } else {
      // A stride that is not a whole number of texels: row by row.
      glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
      for (std::uint32_t y = 0; y < pf.height; ++y) {
        glTexSubImage2D(GL_TEXTURE_2D, 0, 0, static_cast<GLint>(y), static_cast<GLsizei>(pf.width), 1, pf.format,
                        pf.type, plane.data + std::size_t{plane.stride} * y);
      }
    }
  }
  glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  glBindTexture(GL_TEXTURE_2D, 0);
  g.planeCount = count;
  return {};
}

Result<void> StreamTexture::uploadRgba(const Frame& frame) {
  const Plane& plane = frame.planes[0];
  if (!plane.data || plane.stride % 4 != 0) {
    return fail(Errc::kUnsupported, fmt::format("stream '{}': an RGBA frame without mapped rows", name_));
  }
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, static_cast<GLint>(plane.stride / 4));
  glBindTexture(GL_TEXTURE_2D, gpu_->target.id());
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, static_cast<GLsizei>(frame.width), static_cast<GLsizei>(frame.height),
                  GL_RGBA, GL_UNSIGNED_BYTE, plane.data);
  glBindTexture(GL_TEXTURE_2D, 0);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  return {};
}

Result<void> StreamTexture::importDmabuf(const Frame& frame) {
  // Planes are imported as separate R8/RG88 images (what Mesa and most drivers take) and run
  // through the same conversion shader as uploaded planes.
  Gpu& g = *gpu_;
  std::array<PlaneFormat, 3> formats{};
  const int count = planeFormats(frame, formats);
  if (count == 0) return fail(Errc::kUnsupported, "no dmabuf layout for this format");
  const EGLDisplay display = eglGetCurrentDisplay();
  for (int i = 0; i < count; ++i) {
    const auto idx = static_cast<std::size_t>(i);
    const PlaneFormat& pf = formats[idx];
    const Plane& plane = frame.planes[idx];
    EGLint fourcc = 0;
    switch (pf.bytesPerTexel) {
      case 1: fourcc = 0x20203852; break;   // DRM_FORMAT_R8
      case 2: fourcc = 0x38384752; break;   // DRM_FORMAT_GR88
      default: fourcc = 0x34324241; break;  // DRM_FORMAT_ABGR8888: R G B A in memory
    }
    const EGLint attributes[] = {EGL_WIDTH,
                                 static_cast<EGLint>(pf.width),
                                 EGL_HEIGHT,
                                 static_cast<EGLint>(pf.height),
                                 EGL_LINUX_DRM_FOURCC_EXT,
                                 fourcc,
                                 EGL_DMA_BUF_PLANE0_FD_EXT,
                                 plane.dmabufFd,
                                 EGL_DMA_BUF_PLANE0_OFFSET_EXT,
                                 static_cast<EGLint>(plane.offset),
                                 EGL_DMA_BUF_PLANE0_PITCH_EXT,
                                 static_cast<EGLint>(plane.stride),
                                 EGL_NONE};
    EGLImageKHR image = g.createImage(display, EGL_NO_CONTEXT, EGL_LINUX_DMA_BUF_EXT, nullptr, attributes);
    if (image == EGL_NO_IMAGE_KHR) {
      return fail(Errc::kUnsupported, fmt::format("EGL refused the dmabuf ({})", eglErrorName(eglGetError())));
    }
    g.planes[idx] = gl::Texture::create();
    glBindTexture(GL_TEXTURE_2D, g.planes[idx].id());
    g.imageTargetTexture(GL_TEXTURE_2D, image);
    setSampling(frame.format == PixelFormat::kYuyv || frame.format == PixelFormat::kUyvy ? GL_NEAREST : GL_LINEAR);
    g.planeFormat[idx] = PlaneFormat{};  // imported: re-created on the next upload
    g.destroyImage(display, image);      // the texture keeps the storage
  }
  glBindTexture(GL_TEXTURE_2D, 0);
  g.planeCount = count;
  return {};
}

Result<void> StreamTexture::convert(const Uploaded& planes) {
  if (planes.packed) return convertPacked(planes);
  Gpu& g = *gpu_;
  glBindFramebuffer(GL_FRAMEBUFFER, g.fbo.id());
  glViewport(0, 0, static_cast<GLsizei>(g.width), static_cast<GLsizei>(g.height));
  auto drawn = drawPlanes(planes, {-1.0f, -1.0f, 1.0f, 1.0f}, false);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  if (drawn) {
    converted_ = true;
    view_.bottomUp = false;
  }
  return drawn;
}

Result<void> StreamTexture::ensurePackedTarget(std::uint32_t quads, std::uint32_t rowPairs) {
  Gpu& g = *gpu_;
  if (g.packedFbo && g.packedWidth == quads && g.packedHeight == rowPairs) return {};
  g.packedFbo = gl::Framebuffer::create();
  glBindFramebuffer(GL_FRAMEBUFFER, g.packedFbo.id());
  for (std::size_t i = 0; i < g.packedRows.size(); ++i) {
    g.packedRows[i] = gl::Texture::create();
    glBindTexture(GL_TEXTURE_2D, g.packedRows[i].id());
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32UI, static_cast<GLsizei>(quads), static_cast<GLsizei>(rowPairs));
    setSampling(GL_NEAREST);
    glFramebufferTexture2D(GL_FRAMEBUFFER, static_cast<GLenum>(GL_COLOR_ATTACHMENT0 + i), GL_TEXTURE_2D,
                           g.packedRows[i].id(), 0);
  }
  glBindTexture(GL_TEXTURE_2D, 0);
  const std::array<GLenum, 2> buffers = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
  glDrawBuffers(2, buffers.data());
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    g.packedFbo.reset();
    return fail(Errc::kUnavailable, fmt::format("stream '{}': cannot render into RGBA32UI textures (0x{:x})", name_,
                                                static_cast<unsigned>(status)));
  }
  g.packedPixels = gl::Buffer::create();
  glBindBuffer(GL_PIXEL_PACK_BUFFER, g.packedPixels.id());
  glBufferData(GL_PIXEL_PACK_BUFFER, static_cast<GLsizeiptr>(std::size_t{quads} * 16 * rowPairs * 2), nullptr,
               GL_STREAM_COPY);
  glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
  g.packedWidth = quads;
  g.packedHeight = rowPairs;
  return {};
}

Result<void> StreamTexture::convertPacked(const Uploaded& planes) {
  Gpu& g = *gpu_;
  const int layout = layoutOf(planes.format);
  ConversionProgram& c = g.packedPrograms[static_cast<std::size_t>(layout)];
  if (!c.program) {
    auto built = buildConversion(layout, true);
    if (!built) return std::unexpected(built.error());
    c = std::move(*built);
  }
  const std::uint32_t quads = (planes.width + 3) / 4, rowPairs = planes.height / 2;
  if (auto r = ensurePackedTarget(quads, rowPairs); !r) return r;
  glBindFramebuffer(GL_FRAMEBUFFER, g.packedFbo.id());
  glViewport(0, 0, static_cast<GLsizei>(quads), static_cast<GLsizei>(rowPairs));
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  glUseProgram(c.program);
  setColourUniforms(c, planes.colorimetry);
  glUniform4f(c.rect, -1.0f, -1.0f, 1.0f, 1.0f);
  glUniform1i(c.flip, 0);
  glUniform1i(c.flipX, 0);
  glUniform1i(c.height, static_cast<GLint>(planes.height));
  drawFromPlanes(planes.format);
  // Even and odd rows into one pixel buffer, interleaved (each read skips the other's rows);
  // then into the RGBA texture as the bytes they are. Both copies stay on the GPU's side.
  const std::size_t rowBytes = std::size_t{quads} * 16;
  glBindBuffer(GL_PIXEL_PACK_BUFFER, g.packedPixels.id());
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glPixelStorei(GL_PACK_ROW_LENGTH, static_cast<GLint>(quads * 2));
  for (std::size_t i = 0; i < g.packedRows.size(); ++i) {
    glReadBuffer(static_cast<GLenum>(GL_COLOR_ATTACHMENT0 + i));
    glReadPixels(0, 0, static_cast<GLsizei>(quads), static_cast<GLsizei>(rowPairs), GL_RGBA_INTEGER, GL_UNSIGNED_INT,
                 reinterpret_cast<void*>(i * rowBytes));  // NOLINT(performance-no-int-to-ptr): a buffer offset
  }
  glPixelStorei(GL_PACK_ROW_LENGTH, 0);
  glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, g.packedPixels.id());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, static_cast<GLint>(quads * 4));
  glBindTexture(GL_TEXTURE_2D, g.target.id());
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, static_cast<GLsizei>(planes.width), static_cast<GLsizei>(planes.height),
                  GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
  glBindTexture(GL_TEXTURE_2D, 0);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
  converted_ = true;
  view_.bottomUp = true;
  return {};
}

void StreamTexture::drawFromPlanes(PixelFormat format) {
  // YV12 stores V before U: bind the planes so that unit 1 is always U.
  const bool swapUv = format == PixelFormat::kYv12;
  for (int i = 0; i < 3; ++i) {
    int source = i;
    if (swapUv && i > 0) source = 3 - i;
    glActiveTexture(static_cast<GLenum>(GL_TEXTURE0 + i));
    glBindTexture(GL_TEXTURE_2D, source < gpu_->planeCount ? gpu_->planes[static_cast<std::size_t>(source)].id() : 0);
  }
  glBindVertexArray(gpu_->vao.id());
  glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
  glBindVertexArray(0);
  for (int i = 2; i >= 0; --i) {
    glActiveTexture(static_cast<GLenum>(GL_TEXTURE0 + i));
    glBindTexture(GL_TEXTURE_2D, 0);
  }
  glUseProgram(0);
}

Result<void> StreamTexture::drawPlanes(const Uploaded& planes, const std::array<float, 4>& ndc, bool flip) {
  Gpu& g = *gpu_;
  const int layout = layoutOf(planes.format);
  ConversionProgram& c = g.programs[static_cast<std::size_t>(layout)];
  if (!c.program) {
    auto built = buildConversion(layout);
    if (!built) return std::unexpected(built.error());
    c = std::move(*built);
  }
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  glUseProgram(c.program);
  setColourUniforms(c, planes.colorimetry);
  glUniform4f(c.rect, ndc[0], ndc[1], ndc[2], ndc[3]);
  glUniform1i(c.flip, flip ? 1 : 0);
  if (c.chromaScale >= 0) {
    const std::uint32_t cw = (planes.width + 1) / 2, ch = (planes.height + 1) / 2;
    glUniform2f(c.chromaScale, static_cast<float>(planes.width) / static_cast<float>(2 * cw),
                static_cast<float>(planes.height) / static_cast<float>(2 * ch));
  }
  // Mirrored: the target's left column is the frame's right one (the quad mirrors what is
  // sampled through coordinates, the shader what is fetched by position).
  glUniform1i(c.flipX, mirror_ ? 1 : 0);
  glUniform1i(c.mirrorWidth, mirror_ ? static_cast<GLint>(planes.width) : 0);
  drawFromPlanes(planes.format);
  return {};
}

namespace {
/// Layouts a picture can be drawn from straight: planar, sampled with texture() through the
/// picture's own coordinates (the packed ones fetch by fragment position, which only the
/// conversion pass's one-to-one target gives).
bool drawableFromPlanes(PixelFormat f) {
  return f == PixelFormat::kI420 || f == PixelFormat::kYv12 || f == PixelFormat::kNv12 || f == PixelFormat::kNv21;
}

/// A picture's rectangle (pixels from the top-left) in normalised device coordinates (y up):
/// x0, y0, x1, y1, as the quad shader's uRect takes it. Sets the viewport to the whole output.
std::array<float, 4> pictureNdc(const PictureRect& rect, Size viewport) {
  const auto vw = static_cast<float>(viewport.width), vh = static_cast<float>(viewport.height);
  glViewport(0, 0, static_cast<GLsizei>(viewport.width), static_cast<GLsizei>(viewport.height));
  return {rect.x / vw * 2.0f - 1.0f, 1.0f - (rect.y + rect.height) / vh * 2.0f,
          (rect.x + rect.width) / vw * 2.0f - 1.0f, 1.0f - rect.y / vh * 2.0f};
}
}  // namespace

void StreamTexture::setPictureOnly(bool pictureOnly) {
  if (pictureOnly == pictureOnly_) return;
  pictureOnly_ = pictureOnly;
  if (pictureOnly_ || converted_) return;
  if (auto r = ensureConverted(); !r) log::warn(kLogRender, "stream '{}': {}", name_, r.error().describe());
}

Result<void> StreamTexture::ensureConverted() {
  if (converted_ || fallback_ || uploaded_.format == PixelFormat::kUnknown) return {};
  return convert(uploaded_);
}

void StreamTexture::drawPicture(PictureOverlay& overlay, const PictureRect& rect, Size viewport, float opacity) {
  if (fallback_ || path_ == UploadPath::kNone || viewport.width == 0 || viewport.height == 0) {
    if (fallback_) overlay.draw(view_, rect, viewport, opacity);
    return;
  }
  if (pictureOnly_ && opacity >= 1.0f && !uploaded_.packed && drawableFromPlanes(uploaded_.format)) {
    const std::array<float, 4> ndc = pictureNdc(rect, viewport);
    // At the frame's own size the planes are read texel by texel (nearest: a plain load in a
    // software renderer); scaled, they are filtered as the texture path filters its texture.
    // (Imported dmabuf planes are filtered already.)
    const bool scaled = path_ == UploadPath::kPlanes &&
                        (std::lround(rect.width) != uploaded_.width || std::lround(rect.height) != uploaded_.height);
    auto filter = [this](GLenum f) {
      for (int i = 0; i < gpu_->planeCount; ++i) {
        glBindTexture(GL_TEXTURE_2D, gpu_->planes[static_cast<std::size_t>(i)].id());
        setSampling(f);
      }
      glBindTexture(GL_TEXTURE_2D, 0);
    };
    if (scaled) filter(GL_LINEAR);
    auto drawn = drawPlanes(uploaded_, ndc, true);
    if (scaled) filter(GL_NEAREST);
    if (drawn) {
      ++directPictures_;
      return;
    }
  }
  // The texture path: the caller's framebuffer stays bound around an on-demand conversion.
  if (!converted_) {
    GLint bound = 0;
    glGetIntegerv(GL_FRAMEBUFFER_BINDING, &bound);
    if (auto r = ensureConverted(); !r) log::warn(kLogRender, "stream '{}': {}", name_, r.error().describe());
    glBindFramebuffer(GL_FRAMEBUFFER, static_cast<GLuint>(bound));
  }
  if (opacity >= 1.0f && blitPicture(rect, viewport)) {
    ++blitPictures_;
    return;
  }
  overlay.draw(view_, rect, viewport, opacity);
}

bool StreamTexture::blitPicture(const PictureRect& rect, Size viewport) {
  // At the texture's own size, on whole pixels, inside the output: a copy, no draw. A texture
  // stored bottom row first (the packed pass's) copies straight; one stored top row first is
  // copied upside down, which costs a software renderer a draw's worth.
  const Gpu& g = *gpu_;
  if (rect.x != std::floor(rect.x) || rect.y != std::floor(rect.y) || rect.x < 0 || rect.y < 0 ||
      std::lround(rect.width) != g.width || std::lround(rect.height) != g.height ||
      rect.x + rect.width > static_cast<float>(viewport.width) ||
      rect.y + rect.height > static_cast<float>(viewport.height)) {
    return false;
  }
  GLint samples = 0;
  glGetIntegerv(GL_SAMPLE_BUFFERS, &samples);
  if (samples != 0) return false;  // a multisampled output takes no blit from a texture
  GLint read = 0;
  glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &read);
  const auto x0 = static_cast<GLint>(rect.x), x1 = x0 + static_cast<GLint>(g.width);
  const auto top = static_cast<GLint>(viewport.height) - static_cast<GLint>(rect.y);
  const GLint bottom = top - static_cast<GLint>(g.height);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, g.fbo.id());
  const auto w = static_cast<GLint>(g.width), h = static_cast<GLint>(g.height);
  if (view_.bottomUp) {
    glBlitFramebuffer(0, 0, w, h, x0, bottom, x1, top, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  } else {
    glBlitFramebuffer(0, 0, w, h, x0, top, x1, bottom, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  }
  glBindFramebuffer(GL_READ_FRAMEBUFFER, static_cast<GLuint>(read));
  return true;
}

void StreamTexture::setMirror(bool mirror) {
  if (mirror == mirror_) return;
  mirror_ = mirror;
  shown_ = nullptr;  // the frame on the texture is converted again, flipped or not
}

Result<bool> StreamTexture::update(const FrameRef& ref) {
  if (!ref) return false;
  const Frame& frame = *ref;
  if (!fallback_ && shown_ == &frame && shownSequence_ == frame.sequence && shownPts_ == frame.pts.count()) {
    return false;  // the same frame again: nothing to do, however many parts show it
  }
  if (layoutOf(frame.format) < 0) {
    return fail(Errc::kUnsupported, fmt::format("stream '{}': {} frames cannot be shown (decode MJPEG first)", name_,
                                                pixelFormatName(frame.format)));
  }
  if (auto r = ensureTarget(frame.width, frame.height); !r) return std::unexpected(r.error());
  UploadPath path = UploadPath::kPlanes;
  const bool dmabuf = frame.planes[0].dmabufFd >= 0;
  if (dmabuf && dmabufOffered_) {
    if (auto r = importDmabuf(frame); r) {
      path = UploadPath::kDmabufImport;
    } else {
      static log::Once once;
      if (once.first()) log::warn(kLogRender, "stream '{}': {}; uploading instead", name_, r.error().describe());
      dmabufOffered_ = false;
    }
  }
  if (path == UploadPath::kPlanes && frame.format == PixelFormat::kRgba8 && !mirror_) {
    // Already what the renderer samples: straight into the target, no pass.
    if (auto r = uploadRgba(frame); !r) return std::unexpected(r.error());
    uploaded_ = {frame.format, frame.width, frame.height, frame.colorimetry, false};
    converted_ = true;
    view_.bottomUp = false;
  } else {
    std::array<PlaneFormat, 3> packedFormats{};
    const bool packed = path == UploadPath::kPlanes && conversionPass_ == ConversionPass::kPacked && !mirror_ &&
                        packedPlaneFormats(frame, packedFormats) > 0;
    if (path == UploadPath::kPlanes) {
      if (auto r = uploadPlanes(frame, packed); !r) return std::unexpected(r.error());
    }
    uploaded_ = {frame.format, frame.width, frame.height, frame.colorimetry, packed};
    converted_ = false;
    // A picture-only stream draws planar frames from their planes: no conversion pass now
    // (unless the packed pass converts them, which costs less than drawing from the planes).
    if (!(pictureOnly_ && !packed && drawableFromPlanes(frame.format))) {
      auto r = convert(uploaded_);
      if (!r && packed) {
        // A renderer that cannot take the packed pass (no RGBA32UI targets): the per-pixel pass
        // from now on, this frame too.
        log::warn(kLogRender, "{}; converting one pixel a fragment instead", r.error().describe());
        conversionPass_ = ConversionPass::kPerPixel;
        if (auto again = uploadPlanes(frame, false); !again) return std::unexpected(again.error());
        uploaded_.packed = false;
        r = convert(uploaded_);
      }
      if (!r) return std::unexpected(r.error());
    }
  }
  if (path != path_ || frame.format != format_ || !(frame.colorimetry == colorimetry_) ||
      uploaded_.packed != packedShown_) {
    path_ = path;
    packedShown_ = uploaded_.packed;
    format_ = frame.format;
    colorimetry_ = frame.colorimetry;
    log::info(kLogRender, "{}{}", describe(),
              dmabuf && path == UploadPath::kPlanes
                  ? "; dmabuf import not offered by this EGL (e.g. Mesa's surfaceless llvmpipe)"
                  : "");
  }
  if (const GLenum e = gl::drainErrors(); e != GL_NO_ERROR) {
    return fail(Errc::kUnavailable, fmt::format("stream '{}': uploading a frame: {}", name_, gl::errorName(e)));
  }
  shown_ = &frame;
  shownSequence_ = frame.sequence;
  shownPts_ = frame.pts.count();
  fallback_ = false;
  ++conversions_;
  ++view_.generation;
  return true;
}

void StreamTexture::publish(TextureRegistry& registry) const { registry.setExternal(name_, view_); }

std::string StreamTexture::describe() const {
  if (path_ == UploadPath::kNone) return fmt::format("stream '{}': no frame yet (fallback shown)", name_);
  const bool yuv = isYuv(format_);
  const std::string_view how = path_ == UploadPath::kPlanes && format_ == PixelFormat::kRgba8 && !mirror_
                                   ? std::string_view("uploaded as is (already RGBA)")
                                   : uploadPathName(path_);
  return fmt::format("stream '{}': {} {}x{}, {}{}{}{}", name_, pixelFormatName(format_), gpu_->width, gpu_->height, how,
                     packedShown_ ? " eight pixels a fragment" : "",
                     yuv ? fmt::format(" ({} {} range)", matrixName(colorimetry_),
                                       colorimetry_.range == Colorimetry::Range::kFull ? "full" : "limited")
                         : std::string{},
                     mirror_ ? ", mirrored" : "");
}

Result<void> StreamTexture::readPixels(Image& out) {
  if (auto r = ensureConverted(); !r) return std::unexpected(r.error());
  const Gpu& g = *gpu_;
  if (out.width != g.width || out.height != g.height || out.channels != 4) out = Image::make(g.width, g.height, 4);
  glBindFramebuffer(GL_FRAMEBUFFER, g.fbo.id());
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glPixelStorei(GL_PACK_ROW_LENGTH, 0);
  glReadPixels(0, 0, static_cast<GLsizei>(g.width), static_cast<GLsizei>(g.height), GL_RGBA, GL_UNSIGNED_BYTE,
               out.pixels.data());
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  if (const GLenum e = gl::drainErrors(); e != GL_NO_ERROR) {
    return fail(Errc::kIo, fmt::format("reading stream '{}' back: {}", name_, gl::errorName(e)));
  }
  // Texture row 0 is the picture's top row (frames are uploaded top row first), or its bottom
  // row after the packed pass.
  if (view_.bottomUp) {
    const std::size_t rowBytes = std::size_t{g.width} * 4;
    for (std::uint32_t y = 0; y < g.height / 2; ++y) {
      std::swap_ranges(out.pixels.begin() + static_cast<std::ptrdiff_t>(rowBytes * y),
                       out.pixels.begin() + static_cast<std::ptrdiff_t>(rowBytes * (y + 1)),
                       out.pixels.begin() + static_cast<std::ptrdiff_t>(rowBytes * (g.height - 1 - y)));
    }
  }
  return {};
}

// --- The Zoom picture -----------------------------------------------------------------------

struct PictureOverlay::Gpu {
  GLuint program = 0;  // the context's (keptProgram)
  gl::Program owned;
  GLint rect = -1, flip = -1, opacity = -1;
  gl::VertexArray vao;
};

PictureOverlay::PictureOverlay() : gpu_(std::make_unique<Gpu>()) {}
PictureOverlay::~PictureOverlay() = default;

Result<std::unique_ptr<PictureOverlay>> PictureOverlay::create() {
  std::unique_ptr<PictureOverlay> o(new PictureOverlay);
  // A movie item makes a picture overlay each time it starts: the program is the context's.
  auto kept = keptProgram("stream_texture.picture", o->gpu_->owned, []() -> Result<gl::Program> {
    auto program = gl::buildProgram(shaders::kQuadVert, shaders::kPictureFrag, "picture");
    if (!program) return program;
    glUseProgram(program->id());
    glUniform1i(glGetUniformLocation(program->id(), "uPicture"), 0);
    glUseProgram(0);
    return program;
  });
  if (!kept) return std::unexpected(kept.error());
  const GLuint p = o->gpu_->program = *kept;
  o->gpu_->rect = glGetUniformLocation(p, "uRect");
  o->gpu_->flip = glGetUniformLocation(p, "uFlipY");
  o->gpu_->opacity = glGetUniformLocation(p, "uOpacity");
  o->gpu_->vao = gl::VertexArray::create();
  return o;
}

void PictureOverlay::draw(const TextureView& texture, const PictureRect& rect, Size viewport, float opacity) {
  if (texture.id == 0 || viewport.width == 0 || viewport.height == 0) return;
  const std::array<float, 4> ndc = pictureNdc(rect, viewport);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  if (opacity < 1.0f) {
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  }
  glUseProgram(gpu_->program);
  glUniform4f(gpu_->rect, ndc[0], ndc[1], ndc[2], ndc[3]);
  glUniform1i(gpu_->flip, texture.bottomUp ? 0 : 1);
  glUniform1f(gpu_->opacity, opacity);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, texture.id);
  glBindVertexArray(gpu_->vao.id());
  glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
  glBindVertexArray(0);
  glBindTexture(GL_TEXTURE_2D, 0);
  glUseProgram(0);
  glDisable(GL_BLEND);
}

}  // namespace basalt::render
