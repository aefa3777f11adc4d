#pragma once

/// \file
/// \brief Where frames go: the Output interface, the headless output, and choosing between
/// headless, KMS (render/kms_output.h) and window (render/window_output.h) outputs (DESIGN.md §3).

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "runtime/error.h"
#include "runtime/event.h"
#include "runtime/image.h"

namespace basalt::render {

struct Size {
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  friend bool operator==(const Size&, const Size&) = default;
};

/// \brief A place frames are drawn into and presented: an offscreen framebuffer, a KMS
/// connector or a window. The output owns the EGL display and context the renderer draws with.
///
/// Threading: created, used and destroyed on the frame loop's thread, which holds the context.
class Output {
 public:
  virtual ~Output() = default;

  /// \brief "headless", "kms" or "window".
  [[nodiscard]] virtual std::string_view kind() const = 0;
  [[nodiscard]] virtual Size size() const = 0;
  /// \brief One line for people: kind, size, renderer, connector or window.
  [[nodiscard]] virtual std::string describe() const = 0;

  /// \brief Binds the framebuffer the next frame is drawn into and sets the viewport.
  [[nodiscard]] virtual Result<void> beginFrame() = 0;
  /// \brief Shows what was drawn since beginFrame(): a swap, a page flip, or nothing.
  [[nodiscard]] virtual Result<void> present() = 0;
  /// \brief Copies the frame drawn since beginFrame() into `out` as RGBA8, top row first.
  /// Call before present(). Reuses `out`'s storage when its shape already fits.
  [[nodiscard]] virtual Result<void> readBack(Image& out);
  /// \brief A descriptor that becomes readable when the output is ready for the next frame
  /// (a DRM page-flip event), or -1 when presenting does not pace the loop.
  [[nodiscard]] virtual int paceFd() const { return -1; }
  /// \brief Handles readiness of paceFd() (reads the DRM event).
  virtual void onPaceReady() {}
  /// \brief False while the previous frame is still waiting to reach the screen (a page flip
  /// pending): the frame loop waits on paceFd() before drawing the next one.
  [[nodiscard]] virtual bool readyForFrame() const { return true; }
  /// \brief Switches the display off (KMS DPMS) or back on. Outputs without a display to
  /// switch answer kUnsupported; the caller then shows black instead.
  [[nodiscard]] virtual Result<void> setDisplayPower(bool on);
  /// \brief True once the person at a window closed it (window output only).
  [[nodiscard]] virtual bool closeRequested() const { return false; }
  /// \brief Moves the keyboard and pointer input the output received since the last call into
  /// `into` (as many as fit; call again for the rest) and returns how many: `kKey` with the
  /// Linux key code, `kPointerMotion` in pixels, `kPointerButton`. Their `time` is left 0 for the
  /// caller to stamp on the show's clock; `device` is kOutputInputDevice. Outputs without
  /// input (headless, KMS: keyboards there are input devices of their own) give none.
  virtual std::size_t takeInput(std::span<Event> into) {
    (void)into;
    return 0;
  }
  /// \brief The events dropped because nobody took them in time (the buffer holds 256).
  [[nodiscard]] virtual std::uint64_t inputDropped() const { return 0; }
};

/// \brief The device id of the input an output's window receives (keyboard and pointer).
inline constexpr DeviceId kOutputInputDevice = 0xFFFF'FF00U;

/// \brief Renders into an offscreen framebuffer on EGL's surfaceless platform (Mesa): no
/// display, no DRM master, no window system. What tests, CI, recording and headless nodes use.
class HeadlessOutput;

/// \brief Opens a headless output of `size`. Fails with a message saying what to install when
/// EGL or OpenGL ES 3 is missing.
Result<std::unique_ptr<Output>> createHeadlessOutput(Size size);

/// \brief Reads the bound read framebuffer's `size` into `out` as RGBA8, top row first.
Result<void> readFramebuffer(Size size, Image& out);

/// \brief Which output to open. `kAuto` detects in DESIGN.md §3's order: KMS when the process
/// can be DRM master, a window when a display server is present, headless otherwise.
enum class OutputKind : std::uint8_t { kAuto, kHeadless, kKms, kWindow };

/// \brief A display mode asked for: exact size, and refresh within half a hertz when not 0.
struct ModeWish {
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  double refresh = 0;
};

/// \brief Everything an output may be asked for; each kind reads what applies to it.
struct OutputRequest {
  OutputKind kind = OutputKind::kAuto;
  Size size{500, 500};           ///< headless and window
  std::string drmDevice;         ///< KMS: /dev/dri/cardN; empty = the first card with a display
  std::string connector;         ///< KMS: "HDMI-A-1"; empty = the first connected
  std::optional<ModeWish> mode;  ///< KMS: empty = the connector's preferred mode
  bool fullscreen = false;       ///< window
  std::string title = "Basalt";  ///< window
};

/// \brief Opens the output the request names. With kAuto, tries KMS, then a window, then
/// headless, and `why` (when given) receives one line per output it passed over and why.
Result<std::unique_ptr<Output>> openOutput(const OutputRequest& request, std::string* why = nullptr);

}  // namespace basalt::render
