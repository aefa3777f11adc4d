// WindowOutput: a window on the developer's desktop.
//
// Hardware: any X server (Xorg, XWayland, Xvfb in tests) with an EGL driver for it (Mesa).
// Limits: X11 only; Wayland desktops run it through XWayland. The window can be resized (the
// output's size follows) and closed (closeRequested() turns true and `basalt run` stops).
// Presentation is not synchronised to vertical blank: the frame loop paces itself. Keys, pointer
// motion and buttons in the window become input events (takeInput) for the show's calibration
// and navigation keys.
// Configuration: $DISPLAY; the manifest's [output] size and fullscreen.

#include "render/window_output.h"

#include <X11/Xatom.h>
#include <X11/Xlib.h>
#include <X11/Xutil.h>

#include <algorithm>
#include <array>
#include <cstdlib>

#include <fmt/format.h>

#include "render/egl.h"
#include "render/gl.h"

namespace basalt::render {

namespace {

/// Xlib's default error handler exits the process; this one keeps the show going and lets the
/// failing call report.
int keepGoingOnXError(Display* /*display*/, XErrorEvent* /*event*/) { return 0; }

struct DisplayCloser {
  void operator()(Display* d) const {
    if (d) XCloseDisplay(d);
  }
};
using XDisplay = std::unique_ptr<Display, DisplayCloser>;

}  // namespace

struct WindowOutput::State {
  XDisplay xDisplay;
  Window window = 0;
  Colormap colormap = 0;
  Atom deleteAtom = 0;
  Size size;
  std::unique_ptr<EglContext> context;
  EglSurface surface;  // on `window`
  std::string renderer;
  bool closeRequested = false;
  // Input received and not taken yet: a fixed ring, so that receiving allocates nothing; the
  // oldest gives way when it is full (counted).
  std::array<Event, 256> input{};
  std::size_t inputFirst = 0;
  std::size_t inputCount = 0;
  std::uint64_t inputDropped = 0;
  bool pointerKnown = false;
  int pointerX = 0, pointerY = 0;

  void push(EventKind kind, std::uint16_t index, double value) {
    if (inputCount == input.size()) {
      inputFirst = (inputFirst + 1) % input.size();
      --inputCount;
      ++inputDropped;
    }
    Event& e = input[(inputFirst + inputCount) % input.size()];
    e = Event{};
    e.device = kOutputInputDevice;
    e.kind = kind;
    e.index = index;
    e.value = value;
    ++inputCount;
  }

  ~State() {
    surface.reset();  // before the window under it
    context.reset();  // the EGL display goes with it, before the X connection it uses
    if (xDisplay && window) XDestroyWindow(xDisplay.get(), window);
    if (xDisplay && colormap) XFreeColormap(xDisplay.get(), colormap);
  }
};

WindowOutput::WindowOutput(std::unique_ptr<State> state) : state_(std::move(state)) {}
WindowOutput::~WindowOutput() = default;

Size WindowOutput::size() const { return state_->size; }

std::string WindowOutput::describe() const {
  return fmt::format("window {}x{} on X display {} ({})", state_->size.width, state_->size.height,
                     DisplayString(state_->xDisplay.get()), state_->renderer);
}

Result<void> WindowOutput::beginFrame() {
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glViewport(0, 0, static_cast<GLsizei>(state_->size.width), static_cast<GLsizei>(state_->size.height));
  return {};
}

Result<void> WindowOutput::present() {
  if (!eglSwapBuffers(state_->context->display()->handle(), state_->surface.handle())) {
    return fail(Errc::kIo, fmt::format("eglSwapBuffers on the window failed ({})", eglErrorName(eglGetError())));
  }
  handleEvents();
  return {};
}

bool WindowOutput::closeRequested() const { return state_->closeRequested; }

void WindowOutput::handleEvents() {
  Display* d = state_->xDisplay.get();
  while (XPending(d) > 0) {
    XEvent event;
    XNextEvent(d, &event);
    if (event.type == ClientMessage && static_cast<Atom>(event.xclient.data.l[0]) == state_->deleteAtom) {
      state_->closeRequested = true;
    } else if (event.type == ConfigureNotify && event.xconfigure.width > 0 && event.xconfigure.height > 0) {
      state_->size = {static_cast<std::uint32_t>(event.xconfigure.width),
                      static_cast<std::uint32_t>(event.xconfigure.height)};
    } else if ((event.type == KeyPress || event.type == KeyRelease) && event.xkey.keycode >= 8) {
      // X key codes are the kernel's plus 8 on evdev keymaps. A held key repeats as press after
      // press (without detectable auto-repeat, releases in between): each press counts.
      state_->push(EventKind::kKey, static_cast<std::uint16_t>(event.xkey.keycode - 8), event.type == KeyPress ? 1 : 0);
    } else if (event.type == MotionNotify) {
      if (state_->pointerKnown) {
        if (event.xmotion.x != state_->pointerX)
          state_->push(EventKind::kPointerMotion, 0, event.xmotion.x - state_->pointerX);
        if (event.xmotion.y != state_->pointerY)
          state_->push(EventKind::kPointerMotion, 1, event.xmotion.y - state_->pointerY);
      }
      state_->pointerKnown = true;
      state_->pointerX = event.xmotion.x;
      state_->pointerY = event.xmotion.y;
    } else if ((event.type == ButtonPress || event.type == ButtonRelease) && event.xbutton.button >= Button1 &&
               event.xbutton.button <= Button3) {
      // X numbers left, middle, right 1, 2, 3; the wheel (4, 5) is not a pointer button.
      state_->push(EventKind::kPointerButton, static_cast<std::uint16_t>(event.xbutton.button - Button1),
                   event.type == ButtonPress ? 1 : 0);
    }
  }
}

std::size_t WindowOutput::takeInput(std::span<Event> into) {
  handleEvents();
  State& s = *state_;
  const std::size_t n = std::min(into.size(), s.inputCount);
  for (std::size_t i = 0; i < n; ++i) into[i] = s.input[(s.inputFirst + i) % s.input.size()];
  s.inputFirst = (s.inputFirst + n) % s.input.size();
  s.inputCount -= n;
  return n;
}

std::uint64_t WindowOutput::inputDropped() const { return state_->inputDropped; }

Result<void> WindowOutput::readFromServer(Image& out) {
  Display* d = state_->xDisplay.get();
  XSync(d, False);
  XImage* image = XGetImage(d, state_->window, 0, 0, state_->size.width, state_->size.height, AllPlanes, ZPixmap);
  if (!image) return fail(Errc::kIo, "the X server did not return the window's pixels");
  if (out.width != state_->size.width || out.height != state_->size.height || out.channels != 4 ||
      out.type != ChannelType::kU8) {
    out = Image::make(state_->size.width, state_->size.height, 4);
  }
  for (std::uint32_t y = 0; y < out.height; ++y) {
    std::uint8_t* dst = out.row(y);
    for (std::uint32_t x = 0; x < out.width; ++x, dst += 4) {
      const unsigned long pixel = XGetPixel(image, static_cast<int>(x), static_cast<int>(y));
      const auto channel = [pixel](unsigned long mask) {
        if (mask == 0) return std::uint8_t{0};
        int shift = 0;
        while (((mask >> shift) & 1UL) == 0) ++shift;
        const unsigned long max = mask >> shift;
        return static_cast<std::uint8_t>(((pixel & mask) >> shift) * 255 / max);
      };
      dst[0] = channel(image->red_mask);
      dst[1] = channel(image->green_mask);
      dst[2] = channel(image->blue_mask);
      dst[3] = 255;
    }
  }
  XDestroyImage(image);
  return {};
}

bool displayServerPresent() {
  const char* x = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  return (x && *x) || (wayland && *wayland);
}

Result<std::unique_ptr<WindowOutput>> WindowOutput::open(const OutputRequest& request) {
  const char* name = std::getenv("DISPLAY");
  if (!name || !*name) {
    return fail(Errc::kUnavailable,
                "no X display to open a window on ($DISPLAY is not set); use the kms or headless output");
  }
  XSetErrorHandler(keepGoingOnXError);
  XDisplay xDisplay(XOpenDisplay(name));
  if (!xDisplay) {
    return fail(Errc::kUnavailable, fmt::format("cannot connect to the X display '{}'; is the X server running and "
                                                "may this user use it (xhost, XAUTHORITY)?",
                                                name));
  }
  Display* x = xDisplay.get();
  auto display = EglDisplay::openPlatform(EGL_PLATFORM_X11_KHR, x, fmt::format("X display {}", name));
  if (!display) return std::unexpected(display.error());
  EGLConfig config = nullptr;
  EGLint count = 0;
  for (const EGLint depth : {24, 16}) {
    const EGLint attributes[] = {EGL_SURFACE_TYPE,
                                 EGL_WINDOW_BIT,
                                 EGL_RED_SIZE,
                                 8,
                                 EGL_GREEN_SIZE,
                                 8,
                                 EGL_BLUE_SIZE,
                                 8,
                                 EGL_DEPTH_SIZE,
                                 depth,
                                 EGL_RENDERABLE_TYPE,
                                 EGL_OPENGL_ES3_BIT,
                                 EGL_NONE};
    if (eglChooseConfig((*display)->handle(), attributes, &config, 1, &count) && count > 0) break;
  }
  if (count == 0)
    return fail(Errc::kUnavailable, fmt::format("EGL offers no OpenGL ES 3 window on X display {}", name));
  EGLint visualId = 0;
  eglGetConfigAttrib((*display)->handle(), config, EGL_NATIVE_VISUAL_ID, &visualId);
  XVisualInfo wanted{};
  wanted.visualid = static_cast<VisualID>(visualId);
  int visuals = 0;
  XVisualInfo* info = XGetVisualInfo(x, VisualIDMask, &wanted, &visuals);
  if (!info || visuals == 0) {
    return fail(Errc::kUnavailable, fmt::format("X display {} has no visual for EGL's configuration", name));
  }
  const Window root = RootWindow(x, info->screen);
  Size size = request.size;
  if (request.fullscreen) {
    size = {static_cast<std::uint32_t>(DisplayWidth(x, info->screen)),
            static_cast<std::uint32_t>(DisplayHeight(x, info->screen))};
  }
  XSetWindowAttributes attributes{};
  attributes.colormap = XCreateColormap(x, root, info->visual, AllocNone);
  attributes.event_mask =
      StructureNotifyMask | KeyPressMask | KeyReleaseMask | PointerMotionMask | ButtonPressMask | ButtonReleaseMask;
  attributes.background_pixel = 0;
  attributes.border_pixel = 0;
  const Window window = XCreateWindow(x, root, 0, 0, size.width, size.height, 0, info->depth, InputOutput, info->visual,
                                      CWColormap | CWEventMask | CWBackPixel | CWBorderPixel, &attributes);
  XFree(info);
  XStoreName(x, window, request.title.c_str());
  Atom deleteAtom = XInternAtom(x, "WM_DELETE_WINDOW", False);
  XSetWMProtocols(x, window, &deleteAtom, 1);
  if (request.fullscreen) {
    Atom state = XInternAtom(x, "_NET_WM_STATE", False);
    Atom full = XInternAtom(x, "_NET_WM_STATE_FULLSCREEN", False);
    XChangeProperty(x, window, state, XA_ATOM, 32, PropModeReplace, reinterpret_cast<unsigned char*>(&full), 1);
  }
  XMapWindow(x, window);
  XSync(x, False);

  auto state = std::make_unique<State>();
  state->xDisplay = std::move(xDisplay);
  state->window = window;
  state->colormap = attributes.colormap;
  state->deleteAtom = deleteAtom;
  state->size = size;
  auto context = EglContext::create(*display, config);
  if (!context) return std::unexpected(context.error());
  state->context = std::move(*context);
  Window nativeWindow = window;
  auto surface = EglSurface::createWindow(*display, config, &nativeWindow, "the window");
  if (!surface) return std::unexpected(surface.error());
  state->surface = std::move(*surface);
  if (auto r = state->context->makeCurrent(state->surface.handle()); !r) return std::unexpected(r.error());
  eglSwapInterval(state->context->display()->handle(), 0);  // the frame loop paces itself
  state->renderer = gl::rendererDescription();
  return std::unique_ptr<WindowOutput>(new WindowOutput(std::move(state)));
}

}  // namespace basalt::render
