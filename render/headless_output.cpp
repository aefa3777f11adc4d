// HeadlessOutput: rendering with no display at all.
//
// Hardware: none. Mesa's EGL surfaceless platform gives an OpenGL ES 3.2 context on llvmpipe
// (software) or on a GPU's render node; frames go into a framebuffer object and are read back
// for snapshots, recording and tests.
// Limits: nothing is shown; present() only flushes. Configuration: the size from the manifest or
// --size; EGL picks the device (EGL_PLATFORM_SURFACELESS_MESA).

#include <fmt/format.h>

#include "render/egl.h"
#include "render/gl.h"
#include "render/output.h"

namespace basalt::render {

class HeadlessOutput final : public Output {
 public:
  HeadlessOutput(std::unique_ptr<EglContext> context, Size size, gl::Framebuffer fbo, gl::Renderbuffer color,
                 gl::Renderbuffer depth, std::string renderer)
      : context_(std::move(context)),
        size_(size),
        fbo_(std::move(fbo)),
        color_(std::move(color)),
        depth_(std::move(depth)),
        renderer_(std::move(renderer)) {}

  ~HeadlessOutput() override {
    // GL objects go before the context that owns them.
    fbo_.reset();
    color_.reset();
    depth_.reset();
  }

  [[nodiscard]] std::string_view kind() const override { return "headless"; }
  [[nodiscard]] Size size() const override { return size_; }
  [[nodiscard]] std::string describe() const override {
    return fmt::format("headless {}x{} on {} (EGL surfaceless)", size_.width, size_.height, renderer_);
  }

  [[nodiscard]] Result<void> beginFrame() override {
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_.id());
    glViewport(0, 0, static_cast<GLsizei>(size_.width), static_cast<GLsizei>(size_.height));
    return {};
  }

  [[nodiscard]] Result<void> present() override {
    glFlush();
    return {};
  }

 private:
  std::unique_ptr<EglContext> context_;
  Size size_;
  gl::Framebuffer fbo_;
  gl::Renderbuffer color_;
  gl::Renderbuffer depth_;
  std::string renderer_;
};

Result<std::unique_ptr<Output>> createHeadlessOutput(Size size) {
  if (size.width == 0 || size.height == 0) {
    return fail(Errc::kInvalidArgument, fmt::format("output size {}x{} is empty", size.width, size.height));
  }
  auto display = EglDisplay::openSurfaceless();
  if (!display) return std::unexpected(display.error());
  if (!(*display)->hasExtension("EGL_KHR_surfaceless_context")) {
    return fail(Errc::kUnavailable,
                "this EGL cannot make a context current without a surface "
                "(EGL_KHR_surfaceless_context); update Mesa");
  }
  EGLConfig config = EGL_NO_CONFIG_KHR;
  if (!(*display)->hasExtension("EGL_KHR_no_config_context") &&
      !(*display)->hasExtension("EGL_MESA_configless_context")) {
    const EGLint attributes[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_ES3_BIT, EGL_NONE};
    EGLint count = 0;
    if (!eglChooseConfig((*display)->handle(), attributes, &config, 1, &count) || count == 0) {
      return fail(Errc::kUnavailable, "EGL offers no OpenGL ES 3 configuration");
    }
  }
  auto context = EglContext::create(*display, config);
  if (!context) return std::unexpected(context.error());
  if (auto r = (*context)->makeCurrent(); !r) return std::unexpected(r.error());

  GLint maxSize = 0;
  glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &maxSize);
  if (size.width > static_cast<std::uint32_t>(maxSize) || size.height > static_cast<std::uint32_t>(maxSize)) {
    return fail(Errc::kInvalidArgument,
                fmt::format("output size {}x{} exceeds this renderer's limit of {}", size.width, size.height, maxSize));
  }
  auto color = gl::Renderbuffer::create();
  glBindRenderbuffer(GL_RENDERBUFFER, color.id());
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, static_cast<GLsizei>(size.width), static_cast<GLsizei>(size.height));
  auto depth = gl::Renderbuffer::create();
  glBindRenderbuffer(GL_RENDERBUFFER, depth.id());
  glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH24_STENCIL8, static_cast<GLsizei>(size.width),
                        static_cast<GLsizei>(size.height));
  auto fbo = gl::Framebuffer::create();
  glBindFramebuffer(GL_FRAMEBUFFER, fbo.id());
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color.id());
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, depth.id());
  if (const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER); status != GL_FRAMEBUFFER_COMPLETE) {
    return fail(Errc::kUnavailable, fmt::format("offscreen framebuffer incomplete (0x{:x})", status));
  }
  if (const GLenum e = gl::drainErrors(); e != GL_NO_ERROR) {
    return fail(Errc::kUnavailable, fmt::format("creating the offscreen framebuffer: {}", gl::errorName(e)));
  }
  return std::make_unique<HeadlessOutput>(std::move(*context), size, std::move(fbo), std::move(color), std::move(depth),
                                          gl::rendererDescription());
}

}  // namespace basalt::render
