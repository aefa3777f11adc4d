#pragma once

/// \file
/// \brief Owners of EGL handles: a display (terminated when the last owner goes), and a context
/// and surfaces that keep their display alive (Magnum's rule: GL objects never outlive what they
/// need).

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <string_view>

#include "render/gl.h"
#include "runtime/error.h"

namespace basalt::render {

/// \brief An initialised EGLDisplay. Shared: contexts and surfaces hold a reference.
class EglDisplay {
 public:
  /// \brief Mesa's surfaceless platform: rendering with no display server and no DRM master.
  static Result<std::shared_ptr<EglDisplay>> openSurfaceless();
  /// \brief A display on a native platform (GBM device, Wayland or X11 display).
  static Result<std::shared_ptr<EglDisplay>> openPlatform(EGLenum platform, void* nativeDisplay, std::string_view what);
  ~EglDisplay();
  EglDisplay(const EglDisplay&) = delete;
  EglDisplay& operator=(const EglDisplay&) = delete;

  [[nodiscard]] EGLDisplay handle() const { return display_; }
  [[nodiscard]] bool hasExtension(std::string_view name) const;
  [[nodiscard]] const std::string& vendor() const { return vendor_; }
  [[nodiscard]] int major() const { return major_; }
  [[nodiscard]] int minor() const { return minor_; }

 private:
  struct Token {};

 public:
  EglDisplay(Token, EGLDisplay display, int major, int minor);

 private:
  EGLDisplay display_;
  int major_;
  int minor_;
  std::string extensions_;
  std::string vendor_;
};

/// \brief An OpenGL ES 3 context. Keeps its display alive; destroyed on the thread that owns it.
///
/// Owns the GL programs kept in it (keepProgram()): they are deleted with the context, which is
/// made current for that (without a surface) if it is not, and the thread's current context
/// restored afterwards.
class EglContext {
 public:
  /// \brief Creates an ES 3.x context (3.2 where offered, 3.0 at least). `config` may be
  /// EGL_NO_CONFIG_KHR for a surfaceless context. With `shareWith`, the two contexts share
  /// their objects (textures, buffers, programs); the caller keeps `shareWith` alive meanwhile.
  static Result<std::unique_ptr<EglContext>> create(std::shared_ptr<EglDisplay> display, EGLConfig config,
                                                    const EglContext* shareWith = nullptr);
  ~EglContext();
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;

  /// \brief Makes the context current on this thread with `surface` (or none).
  [[nodiscard]] Result<void> makeCurrent(EGLSurface surface = EGL_NO_SURFACE);
  [[nodiscard]] EGLContext handle() const { return context_; }
  [[nodiscard]] const std::shared_ptr<EglDisplay>& display() const { return display_; }

  /// \brief The context this thread last made current through makeCurrent() (null when none,
  /// or when it has been destroyed).
  [[nodiscard]] static EglContext* current();
  /// \brief The GL program kept under `key` for the context's life (0 when none): what many
  /// objects compile alike (a stream texture's conversion programs, made again each time a movie
  /// item starts) is compiled once. The name is borrowed: valid while the context lives.
  [[nodiscard]] GLuint keptProgram(std::string_view key) const;
  /// \brief Hands `program` to the context under `key`, replacing (deleting) one kept there
  /// before; returns its name. The context must be current: the program is one of its own.
  GLuint keepProgram(std::string key, gl::Program program);

 private:
  EglContext(std::shared_ptr<EglDisplay> display, EGLContext context);
  /// Deletes the kept programs in this context (made current for it where it is not).
  void deleteKeptPrograms();
  std::shared_ptr<EglDisplay> display_;
  EGLContext context_;
  std::map<std::string, gl::Program, std::less<>> programs_;  // names of this context's
};

/// \brief An EGL surface (a window or pbuffer surface). Move-only; keeps its display alive and
/// destroys the surface with it. A surface still current on this thread is let go first (the
/// thread keeps its context where EGL allows a context without a surface), so that the surface
/// is gone when this returns rather than when it stops being current: the native window under it
/// (a GBM surface, an X window) may go right after.
///
/// Threading: destroyed on the thread that has it current, if any.
class EglSurface {
 public:
  EglSurface() = default;
  /// \brief A window surface on `nativeWindow` as eglCreatePlatformWindowSurface takes it for
  /// the display's platform: a gbm_surface* on GBM, a pointer to the X Window on X11. `what`
  /// names the window in the error. (EGLNativeWindowType is not used: its type depends on the
  /// headers included before EGL's.)
  static Result<EglSurface> createWindow(std::shared_ptr<EglDisplay> display, EGLConfig config, void* nativeWindow,
                                         std::string_view what);
  /// \brief Adopts `surface`, made on `display` by the caller (EGL_NO_SURFACE gives an empty one).
  static EglSurface wrap(std::shared_ptr<EglDisplay> display, EGLSurface surface);
  EglSurface(EglSurface&& other) noexcept;
  EglSurface& operator=(EglSurface&& other) noexcept;
  EglSurface(const EglSurface&) = delete;
  EglSurface& operator=(const EglSurface&) = delete;
  ~EglSurface() { reset(); }

  [[nodiscard]] EGLSurface handle() const { return surface_; }
  explicit operator bool() const { return surface_ != EGL_NO_SURFACE; }
  [[nodiscard]] const std::shared_ptr<EglDisplay>& display() const { return display_; }
  /// \brief Gives the surface up to the caller, who destroys it (the display is let go too).
  [[nodiscard]] EGLSurface release();
  /// \brief Destroys the surface now (nothing when empty).
  void reset();

 private:
  EglSurface(std::shared_ptr<EglDisplay> display, EGLSurface surface)
      : display_(std::move(display)), surface_(surface) {}
  std::shared_ptr<EglDisplay> display_;
  EGLSurface surface_ = EGL_NO_SURFACE;
};

/// \brief True when the space-separated extension list `all` names `name` exactly (EGL and GL).
bool extensionListHas(std::string_view all, std::string_view name);

/// \brief "EGL_BAD_ALLOC" and friends, for messages.
std::string_view eglErrorName(EGLint error);

}  // namespace basalt::render
