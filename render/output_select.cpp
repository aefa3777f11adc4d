// Choosing the output: the one the manifest or the command line names, or detected in
// DESIGN.md §3's order (KMS when this process can be DRM master, a window when a display server
// is present, headless otherwise).

#include <fmt/format.h>

#include "render/kms_output.h"
#include "render/output.h"
#include "render/window_output.h"

namespace basalt::render {

Result<void> Output::setDisplayPower(bool on) {
  (void)on;
  return fail(Errc::kUnsupported, fmt::format("the {} output has no display to switch", kind()));
}

Result<std::unique_ptr<Output>> openOutput(const OutputRequest& request, std::string* why) {
  switch (request.kind) {
    case OutputKind::kHeadless: return createHeadlessOutput(request.size);
    case OutputKind::kWindow: {
      auto window = WindowOutput::open(request);
      if (!window) return std::unexpected(window.error());
      return std::unique_ptr<Output>(std::move(*window));
    }
    case OutputKind::kKms: {
      auto kms = KmsOutput::open(request);
      if (!kms) return std::unexpected(kms.error());
      return std::unique_ptr<Output>(std::move(*kms));
    }
    case OutputKind::kAuto: break;
  }
  std::string passed;
  auto kms = KmsOutput::open(request);
  if (kms) return std::unique_ptr<Output>(std::move(*kms));
  passed += fmt::format("kms: {}\n", kms.error().describe());
  if (displayServerPresent()) {
    auto window = WindowOutput::open(request);
    if (window) {
      if (why) *why = passed;
      return std::unique_ptr<Output>(std::move(*window));
    }
    passed += fmt::format("window: {}\n", window.error().describe());
  } else {
    passed += "window: no display server ($DISPLAY and $WAYLAND_DISPLAY are not set)\n";
  }
  if (why) *why = passed;
  return createHeadlessOutput(request.size);
}

}  // namespace basalt::render
