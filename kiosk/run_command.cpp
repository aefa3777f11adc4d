#include "kiosk/run_command.h"

#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <memory>
#include <system_error>

#include <fmt/format.h>
#include <fmt/std.h>

#include "kiosk/frame_loop.h"
#include "media/image_io.h"
#include "render/output.h"
#include "render/renderer.h"
#include "runtime/event_loop.h"
#include "runtime/image.h"
#include "runtime/log.h"
#include "runtime/show/show.h"

namespace basalt::kiosk {

namespace {

int failWith(const Error& error, std::string_view what) {
  fmt::print(stderr, "basalt: error: {}: {}\n", what, error.describe());
  return 1;
}

/// Makes sure snapshots can be written before anything is rendered.
Result<void> checkWritableFolder(const std::filesystem::path& file) {
  const std::filesystem::path folder = file.has_parent_path() ? file.parent_path() : std::filesystem::path(".");
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (ec) {
    return fail(Errc::kIo, fmt::format("cannot create the output folder {}: {}; choose another with "
                                       "--output-dir or --snapshot",
                                       folder, ec.message()));
  }
  if (::access(folder.c_str(), W_OK) != 0) {
    return fail(Errc::kPermissionDenied,
                fmt::format("the output folder {} is not writable ({}); choose another with --output-dir or "
                            "--snapshot",
                            folder, std::strerror(errno)));
  }
  return {};
}

}  // namespace

int runShow(const RunOptions& options) {
  const std::filesystem::path snapshotPath = options.snapshot ? *options.snapshot : options.outputDir / "snapshot.png";
  if (auto r = checkWritableFolder(snapshotPath); !r) return failWith(r.error(), "cannot start");

  std::int64_t maxFrames = -1;
  if (options.frames) maxFrames = *options.frames;
  if (options.seconds) {
    const auto fromSeconds = static_cast<std::int64_t>(std::ceil(*options.seconds * options.fps));
    maxFrames = maxFrames < 0 ? fromSeconds : std::min(maxFrames, fromSeconds);
  }
  const bool manual = options.clock == ClockMode::kManual || (options.clock == ClockMode::kAuto && maxFrames >= 0);
  SystemClock systemClock;
  ManualClock manualClock;
  const Clock& clock = manual ? static_cast<const Clock&>(manualClock) : systemClock;

  auto loop = runtime::EventLoop::create(clock);
  if (!loop) return failWith(loop.error(), "cannot start the event loop");

  // Only the headless output exists in this build; KMS and window outputs plug in here.
  auto output = render::createHeadlessOutput({options.width, options.height});
  if (!output) return failWith(output.error(), "cannot open the headless output");
  auto renderer = render::Renderer::create();
  if (!renderer) return failWith(renderer.error(), "cannot set up the renderer");

  runtime::Show show = runtime::Show::makeDefault();
  FrameLoop frameLoop({options.fps, maxFrames}, clock, manual ? &manualClock : nullptr, **loop, show, **output,
                      **renderer);

  auto stopOnSignal = (*loop)->watchSignals({SIGINT, SIGTERM}, [&frameLoop](int) { frameLoop.requestStop(); });
  if (!stopOnSignal) return failWith(stopOnSignal.error(), "cannot watch for signals");

  Image snapshot;
  bool snapshotWritten = false;
  frameLoop.setFrameHook([&](std::int64_t, bool last, render::Output& out) -> Result<void> {
    if (!last) return {};
    if (auto r = out.readBack(snapshot); !r) return r;
    if (auto r = media::writeImage(snapshotPath, snapshot); !r) return r;
    snapshotWritten = true;
    return {};
  });

  auto stats = frameLoop.run();
  if (!stats) return failWith(stats.error(), "the show stopped");

  const double fps = stats->wallSeconds > 0 ? static_cast<double>(stats->frames) / stats->wallSeconds : 0;
  fmt::print("basalt: played the default show: {} frames in {:.2f} s ({:.1f} frames per second, {} clock)\n",
             stats->frames, stats->wallSeconds, fps, manual ? "manual" : "system");
  fmt::print("basalt: output: {}\n", (*output)->describe());
  fmt::print("basalt: first frame after {:.1f} ms\n", stats->firstFrameSeconds * 1000);
  if (snapshotWritten) fmt::print("basalt: snapshot written to {}\n", snapshotPath.string());
  std::fflush(stdout);
  return 0;
}

}  // namespace basalt::kiosk
