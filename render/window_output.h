#pragma once

/// \file
/// \brief A window on a desktop, for developing shows: X11 through EGL (on Wayland desktops it
/// runs through XWayland).

#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "render/output.h"
#include "runtime/error.h"
#include "runtime/image.h"

namespace basalt::render {

/// \brief An X11 window drawn with EGL.
///
/// Threading: the frame loop's thread. Presentation is not tied to vertical blank: the frame
/// loop paces itself.
class WindowOutput final : public Output {
 public:
  /// \brief Opens a window of `request.size` (or covering the screen with `fullscreen`) on the
  /// X display named by $DISPLAY. Fails with one line when there is no display or its EGL
  /// cannot draw into windows.
  static Result<std::unique_ptr<WindowOutput>> open(const OutputRequest& request);
  ~WindowOutput() override;
  WindowOutput(const WindowOutput&) = delete;
  WindowOutput& operator=(const WindowOutput&) = delete;

  [[nodiscard]] std::string_view kind() const override { return "window"; }
  [[nodiscard]] Size size() const override;
  [[nodiscard]] std::string describe() const override;
  [[nodiscard]] Result<void> beginFrame() override;
  [[nodiscard]] Result<void> present() override;
  [[nodiscard]] bool closeRequested() const override;
  /// \brief Keys (X key codes less 8: the Linux key codes on X servers with evdev keymaps, as
  /// Xorg, XWayland and Xvfb have), pointer motion and buttons the window received.
  std::size_t takeInput(std::span<Event> into) override;
  [[nodiscard]] std::uint64_t inputDropped() const override;

  /// \brief Copies what the X server shows in the window into `out` as RGBA8, top row first
  /// (after present()): the picture as it reached the display server.
  [[nodiscard]] Result<void> readFromServer(Image& out);

  struct State;

 private:
  explicit WindowOutput(std::unique_ptr<State> state);
  void handleEvents();
  std::unique_ptr<State> state_;
};

/// \brief True when a display server is there to open windows on ($DISPLAY or
/// $WAYLAND_DISPLAY set).
bool displayServerPresent();

}  // namespace basalt::render
