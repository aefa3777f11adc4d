// The window output for real, on an X server (Xvfb): the picture drawn into the window reaches
// the X server and matches the headless render of the same frame; output detection picks the
// window when a display server is there and headless when not; `basalt run --output window`
// plays on it; keys, pointer motion and buttons in the window become input events, and a show's
// facet view is calibrated with the thesis' keys typed into its window. Skips, saying so, when
// Xvfb is not installed.
// Example failures: a window that stays black (wrong EGL config or a swap that never happens);
// red and blue swapped on the way to the server; auto-detection opening headless on a desktop.

#include <gtest/gtest.h>

#include <X11/Xlib.h>
#include <X11/keysym.h>
#include <signal.h>
#include <unistd.h>

#include <fstream>
#include <vector>

#include <cstdlib>
#include <string>
#include <thread>

#include "render/output.h"
#include "render/renderer.h"
#include "render/window_output.h"
#include "runtime/show/show.h"
#include "support/kiosk_process.h"
#include "support/polyhedra.h"
#include "support/process.h"
#include "support/test_paths.h"

namespace basalt::render {
namespace {

/// The line of Xvfb's output that is only digits: the display number -displayfd wrote.
std::string displayNumber(const std::string& output) {
  std::size_t start = 0;
  while (start < output.size()) {
    const auto end = output.find('\n', start);
    if (end == std::string::npos) break;
    const std::string line = output.substr(start, end - start);
    if (!line.empty() && line.find_first_not_of("0123456789") == std::string::npos) return line;
    start = end + 1;
  }
  return {};
}

/// An Xvfb server for the test's lifetime, on a display number it chooses itself.
class Xvfb {
 public:
  Xvfb() {
    if (::access("/usr/bin/Xvfb", X_OK) != 0) return;
    // -displayfd lets Xvfb pick a free display and write its number; servers started at the same
    // moment (tests in parallel, other users) can still collide on one, so try again then.
    for (int attempt = 0; attempt < 5 && display_.empty(); ++attempt) {
      process_ = std::make_unique<test::Process>(test::Process::start(
          {"/usr/bin/Xvfb", "-displayfd", "1", "-screen", "0", "640x480x24", "-nolisten", "tcp", "-noreset"}));
      if (!process_->started()) return;
      const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
      while (display_.empty() && std::chrono::steady_clock::now() < deadline) {
        // Reads what arrives within 200 ms (the needle never comes).
        process_->waitForOutput(std::string(1, '\x01'), std::chrono::milliseconds(200));
        display_ = displayNumber(process_->outputSoFar());
        // A server that lost the race for a display says so and exits: start another.
        if (display_.empty() && process_->outputSoFar().find("Fatal server error") != std::string::npos) break;
      }
      if (display_.empty()) process_.reset();
    }
    if (display_.empty()) return;
    display_ = ":" + display_;
    previous_ = std::getenv("DISPLAY") ? std::getenv("DISPLAY") : "";
    ::setenv("DISPLAY", display_.c_str(), 1);
  }
  ~Xvfb() {
    if (previous_.empty()) {
      ::unsetenv("DISPLAY");
    } else {
      ::setenv("DISPLAY", previous_.c_str(), 1);
    }
    if (process_) process_->signal(SIGTERM);
  }
  Xvfb(const Xvfb&) = delete;
  Xvfb& operator=(const Xvfb&) = delete;
  [[nodiscard]] bool running() const { return !display_.empty(); }
  [[nodiscard]] const std::string& display() const { return display_; }

 private:
  std::unique_ptr<test::Process> process_;
  std::string display_;
  std::string previous_;
};

#define REQUIRE_XVFB(x)                                                                       \
  if (!(x).running()) {                                                                       \
    GTEST_SKIP() << "Xvfb is not installed or did not start (apt-get install xvfb; it is in " \
                    "scripts/packages-test.txt)";                                             \
  }

/// Draws frame `frames` of the default show into `output` and reads it back through GL.
Image drawDefaultShow(Output& output, int frames) {
  auto renderer = Renderer::create();
  EXPECT_TRUE(renderer) << renderer.error().describe();
  runtime::Show show = runtime::Show::makeDefault();
  for (int i = 0; i < frames; ++i) show.advanceFrame();
  EXPECT_TRUE(output.beginFrame());
  const Size size = output.size();
  (*renderer)->draw(show, runtime::computeView(show, static_cast<float>(size.width) / static_cast<float>(size.height)),
                    size);
  Image image;
  EXPECT_TRUE(output.readBack(image));
  return image;
}

TEST(WindowOutput, ThePictureReachesTheXServer) {
  Xvfb x;
  REQUIRE_XVFB(x);
  Image headless;
  {
    auto output = createHeadlessOutput({320, 240});
    if (!output) GTEST_SKIP() << "no headless EGL here: " << output.error().describe();
    headless = drawDefaultShow(**output, 30);
  }
  OutputRequest request;
  request.kind = OutputKind::kWindow;
  request.size = {320, 240};
  auto window = WindowOutput::open(request);
  ASSERT_TRUE(window) << window.error().describe();
  EXPECT_EQ((*window)->kind(), "window");
  EXPECT_NE((*window)->describe().find("window 320x240 on X display " + x.display()), std::string::npos)
      << (*window)->describe();
  const Image drawn = drawDefaultShow(**window, 30);
  ASSERT_TRUE((*window)->present());
  Image shown;
  ASSERT_TRUE((*window)->readFromServer(shown));
  ASSERT_EQ(shown.width, 320u);
  ASSERT_EQ(shown.height, 240u);

  const ImageDifference toHeadless = compareImages(drawn, headless, 2);
  EXPECT_EQ(toHeadless.pixelsOverTolerance, 0u) << "the window renders what headless renders";
  const ImageDifference onServer = compareImages(shown, drawn, 2);
  EXPECT_EQ(onServer.pixelsOverTolerance, 0u)
      << "what the X server shows is what was drawn (max delta " << onServer.maxChannelDelta << ")";
  // Not black: the cube's faces are there, red and blue the right way round.
  std::size_t red = 0;
  std::size_t lit = 0;
  for (std::uint32_t y = 0; y < shown.height; ++y) {
    for (std::uint32_t xx = 0; xx < shown.width; ++xx) {
      const int r = shown.at(xx, y, 0);
      const int g = shown.at(xx, y, 1);
      const int b = shown.at(xx, y, 2);
      if (r + g + b > 60) ++lit;
      if (r > 100 && g < 40 && b < 40) ++red;
    }
  }
  EXPECT_GT(lit, 320u * 240u / 10) << "the window is black";
  EXPECT_GT(red, 100u) << "no red face: channels swapped?";
  EXPECT_FALSE((*window)->closeRequested());
}

TEST(WindowOutput, DetectionPrefersAWindowWhenADisplayServerIsThere) {
  Xvfb x;
  REQUIRE_XVFB(x);
  OutputRequest request;
  request.size = {64, 48};
  std::string why;
  auto output = openOutput(request, &why);
  ASSERT_TRUE(output) << output.error().describe();
  EXPECT_EQ((*output)->kind(), "window") << why;
  EXPECT_NE(why.find("kms: "), std::string::npos) << "says why KMS was passed over: " << why;
}

TEST(WindowOutput, WithoutADisplayServerDetectionFallsBackToHeadless) {
  const std::string display = std::getenv("DISPLAY") ? std::getenv("DISPLAY") : "";
  const std::string wayland = std::getenv("WAYLAND_DISPLAY") ? std::getenv("WAYLAND_DISPLAY") : "";
  ::unsetenv("DISPLAY");
  ::unsetenv("WAYLAND_DISPLAY");
  OutputRequest request;
  request.size = {64, 48};
  std::string why;
  auto output = openOutput(request, &why);
  if (!display.empty()) ::setenv("DISPLAY", display.c_str(), 1);
  if (!wayland.empty()) ::setenv("WAYLAND_DISPLAY", wayland.c_str(), 1);
  if (!output) GTEST_SKIP() << "no headless EGL here: " << output.error().describe();
  EXPECT_EQ((*output)->kind(), "headless");
  EXPECT_NE(why.find("window: no display server"), std::string::npos) << why;
  // Asking for a window without a display is one clear error.
  ::unsetenv("DISPLAY");
  request.kind = OutputKind::kWindow;
  auto window = openOutput(request);
  if (!display.empty()) ::setenv("DISPLAY", display.c_str(), 1);
  ASSERT_FALSE(window);
  EXPECT_NE(window.error().message().find("$DISPLAY is not set"), std::string::npos);
}

TEST(WindowOutput, BasaltRunPlaysInAWindow) {
  Xvfb x;
  REQUIRE_XVFB(x);
  const auto dir = test::scratchDir("window-run");
  const auto r = test::run({(test::binaryDir() / "basalt").string(), "run", "--output", "window", "--frames", "20",
                            "--size", "200x150", "--snapshot", (dir / "last.png").string()},
                           {{"DISPLAY", x.display()}});
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("output: window 200x150 on X display"), std::string::npos) << r.output;
}

/// A second client of the X server, as a person's keyboard and mouse: finds a window by its title
/// and sends it events the way the server delivers them.
class XClient {
 public:
  XClient() : d_(XOpenDisplay(nullptr)) {}
  ~XClient() {
    if (d_) XCloseDisplay(d_);
  }
  XClient(const XClient&) = delete;
  XClient& operator=(const XClient&) = delete;
  [[nodiscard]] bool open() const { return d_ != nullptr; }
  /// The server's key code for a key symbol (its keymap, not a guess).
  unsigned keycode(KeySym symbol) const { return XKeysymToKeycode(d_, symbol); }

  /// The top-level window whose title starts with `title`, waiting up to 10 s for it; 0 if none.
  Window find(const std::string& title) const {
    for (int attempt = 0; attempt < 100; ++attempt) {
      Window root = 0, parent = 0;
      Window* children = nullptr;
      unsigned count = 0;
      Window found = 0;
      if (XQueryTree(d_, DefaultRootWindow(d_), &root, &parent, &children, &count)) {
        for (unsigned i = 0; i < count && !found; ++i) {
          char* name = nullptr;
          if (XFetchName(d_, children[i], &name) && name) {
            if (std::string(name).starts_with(title)) found = children[i];
            XFree(name);
          }
        }
        if (children) XFree(children);
      }
      if (found) return found;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return 0;
  }

  void key(Window w, unsigned code, bool press, unsigned state = 0) const {
    XEvent e{};
    e.xkey.type = press ? KeyPress : KeyRelease;
    e.xkey.display = d_;
    e.xkey.window = w;
    e.xkey.root = DefaultRootWindow(d_);
    e.xkey.keycode = code;
    e.xkey.state = state;
    e.xkey.same_screen = True;
    send(w, press ? KeyPressMask : KeyReleaseMask, e);
  }
  void motion(Window w, int x, int y) const {
    XEvent e{};
    e.xmotion.type = MotionNotify;
    e.xmotion.display = d_;
    e.xmotion.window = w;
    e.xmotion.root = DefaultRootWindow(d_);
    e.xmotion.x = x;
    e.xmotion.y = y;
    e.xmotion.same_screen = True;
    send(w, PointerMotionMask, e);
  }
  void button(Window w, unsigned number, bool press) const {
    XEvent e{};
    e.xbutton.type = press ? ButtonPress : ButtonRelease;
    e.xbutton.display = d_;
    e.xbutton.window = w;
    e.xbutton.root = DefaultRootWindow(d_);
    e.xbutton.button = number;
    e.xbutton.same_screen = True;
    send(w, press ? ButtonPressMask : ButtonReleaseMask, e);
  }

 private:
  void send(Window w, long mask, XEvent& e) const {
    XSendEvent(d_, w, False, mask, &e);
    XSync(d_, False);
  }
  Display* d_;
};

TEST(WindowOutput, KeysAndThePointerBecomeInputEvents) {
  // Makes sure what a person does in the window reaches the show as Basalt's input events: Linux
  // key codes (the server's key code for 'a' is KEY_A, 30, plus 8), pointer motion as deltas,
  // buttons numbered from 0. Example failure: X key codes passed on unchanged, so the thesis'
  // calibration keys never match.
  Xvfb x;
  REQUIRE_XVFB(x);
  OutputRequest request;
  request.kind = OutputKind::kWindow;
  request.size = {160, 120};
  request.title = "Basalt input test";
  auto window = WindowOutput::open(request);
  ASSERT_TRUE(window) << window.error().describe();
  drawDefaultShow(**window, 1);
  ASSERT_TRUE((*window)->present());
  XClient person;
  ASSERT_TRUE(person.open());
  const Window w = person.find("Basalt input test");
  ASSERT_NE(w, 0u);
  const unsigned a = person.keycode(XK_a);
  EXPECT_EQ(a, 30u + 8u) << "Xvfb's keymap is not evdev's";
  person.key(w, a, true);
  person.key(w, a, false);
  person.motion(w, 10, 10);  // where the pointer is: no motion yet
  person.motion(w, 15, 7);
  person.button(w, 3, true);
  person.button(w, 3, false);
  std::vector<Event> got;
  std::array<Event, 4> buffer;  // smaller than what arrives: takeInput hands the rest out next time
  for (int attempt = 0; attempt < 100 && got.size() < 6; ++attempt) {
    while (const std::size_t n = (*window)->takeInput(buffer))
      got.insert(got.end(), buffer.begin(), buffer.begin() + n);
    if (got.size() < 6) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_EQ(got.size(), 6u);
  const struct {
    EventKind kind;
    std::uint16_t index;
    double value;
  } expected[6] = {{EventKind::kKey, 30, 1},          {EventKind::kKey, 30, 0},
                   {EventKind::kPointerMotion, 0, 5}, {EventKind::kPointerMotion, 1, -3},
                   {EventKind::kPointerButton, 2, 1}, {EventKind::kPointerButton, 2, 0}};
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_EQ(got[i].kind, expected[i].kind) << i;
    EXPECT_EQ(got[i].index, expected[i].index) << i;
    EXPECT_EQ(got[i].value, expected[i].value) << i;
    EXPECT_EQ(got[i].device, kOutputInputDevice) << i;
  }
  EXPECT_EQ((*window)->inputDropped(), 0u);
}

TEST(WindowOutput, TheCalibrationKeysTypedIntoTheWindowCalibrateTheFacetView) {
  // A technician at the show's window: Shift and ':' (the thesis' Xskew, small step up) reach
  // the facet view, whose calibration the control server then reports; Shift and 'S' turn the base
  // side.
  // Example failure: keys read by the window but never handed to the views.
  Xvfb x;
  REQUIRE_XVFB(x);
  const auto dir = test::writeShow("window-calibration", R"(
[show]
name = "Keys"
entry = "default"
fps = 30

[output]
kind = "window"
size = "160x120"

[[views]]
name = "front"
kind = "facet"
cave = "display.cave"

[status]
listen = "127.0.0.1:0"
token_file = "token"
)");
  const std::string token = "0123456789abcdef0123456789abcdef";
  std::ofstream(dir / "token") << token << "\n";
  std::ofstream(dir / "display.obj") << test::cubeDisplayObj();
  std::ofstream(dir / "display.cave") << "model display.obj\nfacet[5]\n";
  std::string why;
  auto show = test::RunningShow::start({(dir / "show.toml").string(), "--no-resume"}, {{"DISPLAY", x.display()}}, why);
  ASSERT_TRUE(show) << why;
  XClient person;
  ASSERT_TRUE(person.open());
  const Window w = person.find("Basalt: Keys");
  ASSERT_NE(w, 0u) << show->process().outputSoFar();
  const unsigned shift = person.keycode(XK_Shift_L), semicolon = person.keycode(XK_semicolon);
  const unsigned s = person.keycode(XK_s);
  person.key(w, shift, true);
  person.key(w, semicolon, true, ShiftMask);
  person.key(w, semicolon, false, ShiftMask);
  person.key(w, s, true, ShiftMask);
  person.key(w, s, false, ShiftMask);
  person.key(w, shift, false);
  const std::string bearer = "Bearer " + token;
  std::string settings;
  for (int attempt = 0; attempt < 50; ++attempt) {
    settings = show->post("/control/calibrate", "", bearer).body;
    if (settings.find("side[1]") != std::string::npos) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  EXPECT_NE(settings.find("Xskew[0.5]"), std::string::npos) << settings;
  EXPECT_NE(settings.find("side[1]"), std::string::npos) << settings;
  show->process().signal(SIGTERM);
  EXPECT_EQ(show->process().wait(std::chrono::seconds(20)).exitCode, 0);
}

}  // namespace
}  // namespace basalt::render
