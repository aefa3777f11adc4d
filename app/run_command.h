#pragma once

/// \file
/// \brief `basalt run`: plays a show; wires the show, the output, the renderer and the frame loop.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string_view>

#include "kiosk/show/video_streams.h"
#include "render/output.h"
#include "runtime/clock.h"
#include "runtime/error.h"

namespace basalt::kiosk {

/// \brief Which clock drives a run: the system clock paces frames in real time; the manual
/// clock advances exactly 1/fps per frame and renders as fast as the machine goes.
enum class ClockMode : std::uint8_t { kAuto, kSystem, kManual };

/// \brief Options of `basalt run`.
struct RunOptions {
  bool help = false;                              ///< --help was given
  std::optional<std::filesystem::path> manifest;  ///< the show.toml to play; none: the default show
  std::optional<std::filesystem::path> show;      ///< a LAVA script (.mdl) to play on the default show
  /// The thesis' command line (Appendix B, `3Deng [.cave] [.sce] [.obj]`): a display file whose
  /// facet fills the output, and a scene or a model to play, without a manifest.
  std::optional<std::filesystem::path> cave;
  std::optional<std::filesystem::path> scene;     ///< a `.sce` scene or a model (.obj, .off)
  std::optional<render::OutputKind> output;       ///< --output (or --headless); none: the manifest's
  bool sizeGiven = false;                         ///< --size was given (else the manifest's size)
  bool fpsGiven = false;                          ///< --fps was given (else the manifest's)
  std::optional<std::filesystem::path> stateDir;  ///< where the resume point is kept
  bool resume = true;                             ///< --no-resume starts from the beginning
  bool strict = false;                            ///< --strict: a show with errors does not start (CI)
  std::optional<WallTime> clockStart;             ///< the manual clock's calendar start (schedules)
  std::optional<std::string> statusListen;        ///< --status ADDRESS:PORT
  std::optional<std::int64_t> frames;             ///< stop after this many frames
  std::optional<double> seconds;                  ///< stop after this much show time
  std::uint32_t width = 500;                      ///< LAVA's start-up window is 500 x 500
  std::uint32_t height = 500;
  bool headless = false;                          ///< force the offscreen output
  std::optional<std::filesystem::path> snapshot;  ///< where the last frame goes
  std::filesystem::path outputDir = "out";        ///< default folder for snapshots
  double fps = 60;
  ClockMode clock = ClockMode::kAuto;
  std::optional<std::filesystem::path> saveImage;                     ///< a script's bare save_image writes this
  std::optional<std::filesystem::path> saveModel;                     ///< write the show as .mdl at the end
  std::vector<std::pair<std::string, std::filesystem::path>> movies;  ///< --movie PART=FILE, in order
  std::vector<std::pair<std::string, ZoomSpec>> zooms;                ///< --zoom PART[=SCALE][@X,Y]
  std::optional<std::pair<int, int>> zoomDials;                       ///< --zoom-dials X,Y
  bool movieOnce = false;                                             ///< --movie-once: no repeat
  bool audio = false;                                                 ///< --audio: movie sound on
  std::optional<std::filesystem::path> record;                        ///< --record PATH
  std::string recordCodec = "auto";                                   ///< --record-codec
  std::optional<std::int64_t> recordFrames;                           ///< --record-frames N
  std::optional<std::filesystem::path> replay;                        ///< a trace folder or hid-recorder file to replay
  bool replayOnce = false;                                            ///< play it once instead of looping
  std::optional<std::string> camera;  ///< --camera SPEC: the camera a script's tv.camera = on shows
};

/// \brief Parses the arguments after `run`.
[[nodiscard]] Result<RunOptions> parseRunOptions(std::span<const std::string_view> args);

/// \brief The text of `basalt run --help`.
std::string_view runUsage();

/// \brief `basalt run ...`: parses, then plays; returns the exit status.
int runMain(std::span<const std::string_view> args);

/// \brief Plays a show as the options say; returns 0, or 1 with a message on stderr that says
/// what failed and what to do.
int runShow(const RunOptions& options);

}  // namespace basalt::kiosk
