#pragma once

/// \file
/// \brief Plays a script through the real frame loop, headless, under a ManualClock, and keeps
/// the Show state and the picture of chosen frames.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "kiosk/loop/frame_loop.h"
#include "kiosk/show/script_player.h"
#include "render/output.h"
#include "render/renderer.h"
#include "runtime/image.h"
#include "runtime/script/program.h"
#include "runtime/show/show.h"

namespace basalt::script::test {

/// \brief One kept frame: the Show as it was drawn, and (when asked) its picture.
struct KeptFrame {
  std::int64_t frame = 0;
  runtime::Show show;
  Image image;
  StepResult step;  ///< how the script ended this frame
};

/// \brief What playing a script gave.
struct Played {
  std::vector<KeptFrame> frames;     ///< in frame order
  std::vector<Diagnostic> messages;  ///< parse and run-time messages
  kiosk::FrameLoopStats stats;
  bool quit = false;
  bool finished = false;
  std::vector<std::filesystem::path> imagesWritten;
  ObjectSource object;
  runtime::Show finalShow;
  [[nodiscard]] const KeptFrame& at(std::int64_t frame) const;
  [[nodiscard]] std::size_t count(Severity severity, std::string_view needle = {}) const;
};

/// \brief A headless output and renderer shared by a test's plays and reference renders.
class Stage {
 public:
  /// \brief Empty (and `why` set) when there is no headless EGL here.
  static std::unique_ptr<Stage> open(render::Size size, std::string& why);

  /// \brief Plays `script` for at most `maxFrames` frames; keeps the Show of `keepState` frames
  /// and also the picture of `keepImage` frames.
  Played play(const std::filesystem::path& script, std::int64_t maxFrames, const std::set<std::int64_t>& keepState,
              const std::set<std::int64_t>& keepImage, kiosk::ScriptPlayerOptions options = {});
  /// \brief Draws `show` as frame loop would (no participants) and reads it back.
  Image render(const runtime::Show& show);

  render::Output& output() { return *output_; }
  render::Renderer& renderer() { return *renderer_; }

 private:
  std::unique_ptr<render::Output> output_;
  std::unique_ptr<render::Renderer> renderer_;
};

/// \brief Fraction of pixels that are not the (black) background.
double coverage(const Image& image);

}  // namespace basalt::script::test
