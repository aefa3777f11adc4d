#include "render/egl.h"

#include <dlfcn.h>
#include <link.h>

#include <cstring>
#include <mutex>
#include <utility>

#include "render/gl.h"

namespace basalt::render {

std::string_view eglErrorName(EGLint error) {
  switch (error) {
    case EGL_SUCCESS: return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS: return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT: return "EGL_BAD_CONTEXT";
    case EGL_BAD_CURRENT_SURFACE: return "EGL_BAD_CURRENT_SURFACE";
    case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
    case EGL_BAD_NATIVE_PIXMAP: return "EGL_BAD_NATIVE_PIXMAP";
    case EGL_BAD_NATIVE_WINDOW: return "EGL_BAD_NATIVE_WINDOW";
    case EGL_BAD_PARAMETER: return "EGL_BAD_PARAMETER";
    case EGL_BAD_SURFACE: return "EGL_BAD_SURFACE";
    case EGL_CONTEXT_LOST: return "EGL_CONTEXT_LOST";
    default: return "unknown EGL error";
  }
}

bool extensionListHas(std::string_view all, std::string_view name) {
  for (std::size_t pos = 0; (pos = all.find(name, pos)) != std::string_view::npos; pos += name.size()) {
    const bool startOk = pos == 0 || all[pos - 1] == ' ';
    const bool endOk = pos + name.size() == all.size() || all[pos + name.size()] == ' ';
    if (startOk && endOk) return true;
  }
  return false;
}

namespace {

/// Keeps the EGL vendor and driver libraries loaded until the process ends. They stay loaded
/// for the life of a show anyway; pinning them stops glvnd from unloading them during exit
/// handlers, so that LeakSanitizer can still name them (tests/lsan.supp suppresses the
/// drivers' own leaks by library name).
void pinDriverLibraries() {
  static std::once_flag once;
  std::call_once(once, [] {
    dl_iterate_phdr(
        [](dl_phdr_info* info, std::size_t, void*) {
          const std::string_view path = info->dlpi_name ? info->dlpi_name : "";
          const bool driver =
              path.find("/dri/") != std::string_view::npos || path.find("libEGL_") != std::string_view::npos ||
              path.find("libLLVM") != std::string_view::npos || path.find("libgallium") != std::string_view::npos ||
              path.find("libglapi") != std::string_view::npos;
          if (driver) ::dlopen(info->dlpi_name, RTLD_LAZY | RTLD_NOLOAD | RTLD_NODELETE);
          return 0;
        },
        nullptr);
  });
}

bool clientHasExtension(std::string_view name) {
  const char* ext = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  return ext && extensionListHas(ext, name);
}

}  // namespace

EglDisplay::EglDisplay(Token, EGLDisplay display, int major, int minor)
    : display_(display), major_(major), minor_(minor) {
  if (const char* e = eglQueryString(display_, EGL_EXTENSIONS)) extensions_ = e;
  if (const char* v = eglQueryString(display_, EGL_VENDOR)) vendor_ = v;
}

EglDisplay::~EglDisplay() {
  eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  eglTerminate(display_);
}

bool EglDisplay::hasExtension(std::string_view name) const { return extensionListHas(extensions_, name); }

Result<std::shared_ptr<EglDisplay>> EglDisplay::openPlatform(EGLenum platform, void* nativeDisplay,
                                                             std::string_view what) {
  auto getPlatformDisplay =
      reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (!getPlatformDisplay || !clientHasExtension("EGL_EXT_platform_base")) {
    return fail(Errc::kUnavailable,
                "EGL has no platform displays (EGL_EXT_platform_base missing); install Mesa's EGL "
                "(apt-get install libegl-mesa0 libgl1-mesa-dri)");
  }
  EGLDisplay display = getPlatformDisplay(platform, nativeDisplay, nullptr);
  if (display == EGL_NO_DISPLAY) {
    return fail(Errc::kUnavailable,
                fmt::format("cannot open an EGL display for {} ({})", what, eglErrorName(eglGetError())));
  }
  EGLint major = 0, minor = 0;
  if (!eglInitialize(display, &major, &minor)) {
    return fail(Errc::kUnavailable, fmt::format("eglInitialize failed for {} ({}); is Mesa's EGL "
                                                "driver installed (libegl-mesa0, libgl1-mesa-dri)?",
                                                what, eglErrorName(eglGetError())));
  }
  pinDriverLibraries();
  return std::make_shared<EglDisplay>(Token{}, display, major, minor);
}

Result<std::shared_ptr<EglDisplay>> EglDisplay::openSurfaceless() {
  if (!clientHasExtension("EGL_MESA_platform_surfaceless")) {
    return fail(Errc::kUnavailable,
                "EGL has no surfaceless platform (EGL_MESA_platform_surfaceless); headless rendering "
                "needs Mesa's EGL: apt-get install libegl-mesa0 libgl1-mesa-dri");
  }
  return openPlatform(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, "the surfaceless platform");
}

namespace {
thread_local EglContext* tCurrent = nullptr;  // what makeCurrent() last made current here
}  // namespace

EglContext::EglContext(std::shared_ptr<EglDisplay> display, EGLContext context)
    : display_(std::move(display)), context_(context) {}

EglContext::~EglContext() {
  deleteKeptPrograms();
  if (tCurrent == this) tCurrent = nullptr;
  if (eglGetCurrentContext() == context_) {
    eglMakeCurrent(display_->handle(), EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  }
  eglDestroyContext(display_->handle(), context_);
}

void EglContext::deleteKeptPrograms() {
  if (programs_.empty()) return;
  if (eglGetCurrentContext() == context_) {
    programs_.clear();
    return;
  }
  // Another context (or none) is current on this thread: this one is made current without a
  // surface to delete its own programs (in a share group they would outlive it otherwise), and
  // the thread gets back what it had.
  const EGLDisplay display = display_->handle();
  const EGLDisplay previousDisplay = eglGetCurrentDisplay();
  const EGLContext previous = eglGetCurrentContext();
  const EGLSurface previousDraw = eglGetCurrentSurface(EGL_DRAW);
  const EGLSurface previousRead = eglGetCurrentSurface(EGL_READ);
  if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context_)) {
    // No surfaceless contexts here, or the context is current on another thread: the names go
    // when EGL destroys the context and its objects.
    for (auto& [key, program] : programs_) (void)program.release();
    programs_.clear();
    return;
  }
  programs_.clear();
  if (previous != EGL_NO_CONTEXT) {
    eglMakeCurrent(previousDisplay, previousDraw, previousRead, previous);
  } else {
    eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  }
}

EglContext* EglContext::current() {
  return tCurrent && eglGetCurrentContext() == tCurrent->context_ ? tCurrent : nullptr;
}

GLuint EglContext::keptProgram(std::string_view key) const {
  const auto it = programs_.find(key);
  return it == programs_.end() ? 0 : it->second.id();
}

GLuint EglContext::keepProgram(std::string key, gl::Program program) {
  const GLuint id = program.id();
  if (const auto it = programs_.find(key); it != programs_.end()) {
    it->second = std::move(program);  // deletes the one kept before
  } else {
    programs_.emplace(std::move(key), std::move(program));
  }
  return id;
}

Result<std::unique_ptr<EglContext>> EglContext::create(std::shared_ptr<EglDisplay> display, EGLConfig config,
                                                       const EglContext* shareWith) {
  if (!eglBindAPI(EGL_OPENGL_ES_API)) {
    return fail(Errc::kUnavailable, "this EGL cannot bind the OpenGL ES API");
  }
  EGLContext context = EGL_NO_CONTEXT;
  for (EGLint minor : {2, 1, 0}) {
    const EGLint attributes[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, minor, EGL_NONE};
    context = eglCreateContext(display->handle(), config, shareWith ? shareWith->context_ : EGL_NO_CONTEXT, attributes);
    if (context != EGL_NO_CONTEXT) break;
  }
  if (context == EGL_NO_CONTEXT) {
    return fail(Errc::kUnavailable,
                fmt::format("cannot create an OpenGL ES 3 context ({})", eglErrorName(eglGetError())));
  }
  return std::unique_ptr<EglContext>(new EglContext(std::move(display), context));
}

Result<void> EglContext::makeCurrent(EGLSurface surface) {
  if (!eglMakeCurrent(display_->handle(), surface, surface, context_)) {
    return fail(Errc::kUnavailable, fmt::format("eglMakeCurrent failed ({})", eglErrorName(eglGetError())));
  }
  tCurrent = this;
  return {};
}

Result<EglSurface> EglSurface::createWindow(std::shared_ptr<EglDisplay> display, EGLConfig config, void* nativeWindow,
                                            std::string_view what) {
  // The display was opened with eglGetPlatformDisplayEXT (EGL_EXT_platform_base): its windows
  // are made with the matching platform call.
  static const auto createPlatformWindowSurface = reinterpret_cast<PFNEGLCREATEPLATFORMWINDOWSURFACEEXTPROC>(
      eglGetProcAddress("eglCreatePlatformWindowSurfaceEXT"));
  if (!createPlatformWindowSurface) {
    return fail(Errc::kUnavailable,
                fmt::format("cannot make an EGL surface for {}: EGL has no eglCreatePlatformWindowSurfaceEXT", what));
  }
  const EGLSurface surface = createPlatformWindowSurface(display->handle(), config, nativeWindow, nullptr);
  if (surface == EGL_NO_SURFACE) {
    return fail(Errc::kUnavailable,
                fmt::format("cannot make an EGL surface for {} ({})", what, eglErrorName(eglGetError())));
  }
  return EglSurface(std::move(display), surface);
}

EglSurface EglSurface::wrap(std::shared_ptr<EglDisplay> display, EGLSurface surface) {
  if (surface == EGL_NO_SURFACE) return {};
  return EglSurface(std::move(display), surface);
}

EglSurface::EglSurface(EglSurface&& other) noexcept
    : display_(std::move(other.display_)), surface_(std::exchange(other.surface_, EGL_NO_SURFACE)) {}

EglSurface& EglSurface::operator=(EglSurface&& other) noexcept {
  if (this != &other) {
    reset();
    display_ = std::move(other.display_);
    surface_ = std::exchange(other.surface_, EGL_NO_SURFACE);
  }
  return *this;
}

EGLSurface EglSurface::release() {
  display_.reset();
  return std::exchange(surface_, EGL_NO_SURFACE);
}

void EglSurface::reset() {
  if (surface_ == EGL_NO_SURFACE) return;
  const EGLDisplay display = display_->handle();
  if (eglGetCurrentDisplay() == display &&
      (eglGetCurrentSurface(EGL_DRAW) == surface_ || eglGetCurrentSurface(EGL_READ) == surface_)) {
    // EGL destroys a current surface only once it stops being current: let go of it now, keeping
    // the context where surfaceless contexts are allowed.
    const EGLContext context = eglGetCurrentContext();
    if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context)) {
      eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    }
  }
  eglDestroySurface(display, surface_);
  surface_ = EGL_NO_SURFACE;
  display_.reset();
}

}  // namespace basalt::render
