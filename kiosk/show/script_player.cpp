// The kiosk's side of the script language: steps the interpreter in the frame loop and serves
// its files and pictures with media/ and render/.
//
// load_object reads models through runtime/formats (kiosk/show/show_host.h), save_image writes what
// media::writeImage writes (LAVA's Sun rasterfile ras.im32 by default), and the VCR drives a
// media::MoviePlayer shown on the video texture. A limit of this build, reported to the script's
// author once, never silently: tv.camera works where the run has a camera (basalt run --camera, or
// the show manifest's first camera).

#include "kiosk/show/script_player.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <fstream>
#include <limits>
#include <utility>

#include <fmt/format.h>
#include <fmt/std.h>

#include "kiosk/show/show_host.h"
#include "kiosk/show/stream_factories.h"
#include "media/frame_picker.h"
#include "media/image_io.h"
#include "render/stream_texture.h"
#include "runtime/log.h"

namespace basalt::kiosk {

BASALT_LOG_CATEGORY(ScriptPlayer, "script");
BASALT_LOG_CATEGORY(Kiosk, "kiosk");  // the movie frame each frame shows, as the director logs its own

using script::Feature;
using script::StepStop;

namespace {

/// The averaged picture of a jitter loop, drawn over the output (not a name parts can use).
constexpr std::string_view kJitterTexture = "lava:jitter-average";

std::string lowerExtension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

}  // namespace

bool isScriptFile(const std::filesystem::path& path) { return lowerExtension(path) == ".mdl"; }

Result<script::Interpreter> loadScript(const std::filesystem::path& path) {
  auto interpreter = script::Interpreter::load(path);
  if (!interpreter) return interpreter;
  for (const script::Diagnostic& d : interpreter->program().diagnostics) printScriptDiagnostic(d);
  return interpreter;
}

bool scriptQuits(const script::Program& program) {
  for (const script::Instr& in : program.instrs) {
    if (program.def(in).action == script::Action::kQuit) return true;
  }
  return false;
}

void printScriptDiagnostic(const script::Diagnostic& diagnostic) {
  std::fflush(stdout);
  fmt::print(stderr, "basalt: {}: {}\n", script::severityName(diagnostic.severity), diagnostic.describe());
  std::fflush(stderr);
}

void printScriptSummary(const ScriptPlayer& player) {
  const script::Interpreter& in = player.interpreter();
  const std::size_t parseErrors = in.program().errorCount();
  const std::uint64_t problems = in.runtimeProblems() + parseErrors;
  std::string state = in.quit() ? "quit" : (in.finished() ? "ended" : "still running when the run stopped");
  fmt::print("basalt: script {}: {} draws, {} commands carried out; {}\n", in.program().file, player.drawsShown(),
             in.instructionsRun(),
             problems == 0 ? std::string("no problems") : fmt::format("{} problems reported above", problems));
  fmt::print("basalt: script {}\n", state);
  const auto& written = player.imagesWritten();
  if (!written.empty()) {
    fmt::print("basalt: save_image wrote {} {} (last: {})\n", written.size(), written.size() == 1 ? "image" : "images",
               written.back().string());
  }
}

Result<void> writeSavedModel(const std::filesystem::path& path, std::string_view text) {
  std::error_code ec;
  const std::filesystem::path folder = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  std::filesystem::create_directories(folder, ec);
  if (ec) return fail(Errc::kIo, fmt::format("cannot create the folder {}: {}", folder, ec.message()), path.string());
  std::filesystem::path partial = folder / fmt::format(".{}.{}.partial", path.filename().string(), ::getpid());
  {
    std::ofstream out(partial, std::ios::binary | std::ios::trunc);
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    out.close();
    if (!out) {
      std::filesystem::remove(partial, ec);
      return fail(Errc::kIo, "cannot write the file; is the disk full or the folder read-only?", path.string());
    }
  }
  std::filesystem::rename(partial, path, ec);
  if (ec) {
    std::filesystem::remove(partial, ec);
    return fail(Errc::kIo, fmt::format("cannot move the file into place: {}", ec.message()), path.string());
  }
  return {};
}

ScriptPlayer::ScriptPlayer(script::Interpreter interpreter, runtime::Show& show, render::Renderer& renderer,
                           ScriptPlayerOptions options)
    : interpreter_(std::move(interpreter)), show_(show), renderer_(renderer), options_(std::move(options)) {}

ScriptPlayer::~ScriptPlayer() {
  if (videoLive_) renderer_.textures().remove(kScriptVideoTexture);
  if (overlay_) renderer_.textures().remove(kJitterTexture);
}

void ScriptPlayer::setReporter(const script::Interpreter::Reporter& reporter) {
  reporter_ = reporter;
  interpreter_.setReporter(reporter);
}

void ScriptPlayer::warn(std::string message) {
  script::Diagnostic d{script::Severity::kWarning, interpreter_.program().file, interpreter_.currentLine(),
                       std::move(message)};
  if (reporter_) {
    reporter_(d);
  } else {
    log::warn(kLogScriptPlayer, "{}", d.describe());
  }
}

void ScriptPlayer::runStep() {
  step_ = interpreter_.step(show_, *this);
  if (step_.stop == StepStop::kQuit && options_.quitEndsRun) stop_ = true;
}

Result<void> ScriptPlayer::beforeDraw(const FrameContext& frame) {
  updateVideo(frame, options_.manualClock);
  if (!started_) {
    // Frame 0 shows what the script set up to its first draw.
    started_ = true;
    runStep();
  }
  return {};
}

void ScriptPlayer::adjustView(const FrameContext& frame, runtime::ViewTransforms& view, render::Size size) {
  (void)frame;
  const bool drawn = step_.stop == StepStop::kDraw || step_.stop == StepStop::kBudget;
  if (!drawn || (step_.offset.x == 0 && step_.offset.y == 0) || size.width == 0 || size.height == 0) return;
  // A shift of (x, y) pixels is 2x/width and 2y/height in normalised device coordinates; the
  // translation is applied in clip space, so it scales with w and moves every depth alike.
  const float dx = 2.0f * step_.offset.x / static_cast<float>(size.width);
  const float dy = 2.0f * step_.offset.y / static_cast<float>(size.height);
  view.projection = Mat4::translation({dx, dy, 0}) * view.projection;
}

Result<void> ScriptPlayer::afterDraw(const FrameContext& frame, render::Output& output) {
  (void)frame;
  frameRead_ = false;
  jitterReady_ = false;
  if (step_.stop == StepStop::kDraw) ++drawsShown_;
  if (interpreter_.finished()) {
    step_ = {};
    return {};
  }
  output_ = &output;
  runStep();
  output_ = nullptr;
  return {};
}

Result<const Image*> ScriptPlayer::currentPicture() {
  if (jitterReady_) return &jitterAverage_;
  if (!output_) {
    return fail(Errc::kUnavailable, "nothing has been drawn yet; put a draw before it");
  }
  if (!frameRead_) {
    if (auto r = output_->readBack(frame_); !r) return std::unexpected(r.error());
    frameRead_ = true;
  }
  return &frame_;
}

Result<void> ScriptPlayer::loadObject(const std::filesystem::path& file, runtime::Show& show) {
  return loadObjectWithTextures(file, show, &renderer_.textures(), nullptr,
                                [this](std::string message) { warn(std::move(message)); });
}

Result<void> ScriptPlayer::loadTexture(const std::filesystem::path& file, const std::string& name) {
  auto image = media::readImage(file);
  if (!image) return std::unexpected(image.error());
  return renderer_.textures().setImage(name, *image);
}

Result<void> ScriptPlayer::saveImage(std::string_view name) {
  auto picture = currentPicture();
  if (!picture) return std::unexpected(picture.error());
  const std::filesystem::path path =
      name.empty() ? options_.outputDir / options_.saveImage : options_.outputDir / std::filesystem::path(name);
  if (auto r = media::writeImage(path, **picture); !r) return r;
  written_.push_back(path);
  return {};
}

Result<void> ScriptPlayer::accumulateJitterPass(int pass, int passes) {
  if (!output_) return fail(Errc::kUnavailable, "no pass has been drawn; put a draw inside the jitter loop");
  jitterReady_ = false;
  auto picture = currentPicture();
  if (!picture) return std::unexpected(picture.error());
  const Image& image = **picture;
  if (pass == 0 || jitterSum_.size() != image.pixels.size()) jitterSum_.assign(image.pixels.size(), 0);
  for (std::size_t i = 0; i < image.pixels.size(); ++i) jitterSum_[i] += image.pixels[i];
  if (pass + 1 < passes) return {};
  // The last pass: the average, rounded, is the current picture until the next draw.
  jitterAverage_ = Image::make(image.width, image.height, image.channels, image.type);
  const auto n = static_cast<std::uint32_t>(passes);
  for (std::size_t i = 0; i < jitterSum_.size(); ++i) {
    jitterAverage_.pixels[i] = static_cast<std::uint8_t>((jitterSum_[i] + n / 2) / n);
  }
  jitterReady_ = true;
  // LAVA showed the accumulated picture: the average replaces the last pass on the output, so
  // the frame presented after the jitter loop is the antialiased one (and stays until the next
  // draw). If it cannot be drawn, the last pass shows and save_image still writes the average.
  if (auto r = presentPicture(jitterAverage_); !r) {
    return fail(r.error().code(),
                fmt::format("the averaged picture is not shown ({}); save_image still writes it", r.error().message()));
  }
  return {};
}

Result<void> ScriptPlayer::presentPicture(const Image& image) {
  if (!overlay_) {
    auto overlay = render::PictureOverlay::create();
    if (!overlay) return std::unexpected(overlay.error());
    overlay_ = std::move(*overlay);
  }
  const std::string name(kJitterTexture);
  if (auto r = renderer_.textures().setImage(name, image); !r) return r;
  const render::TextureView* view = renderer_.textures().find(name);
  if (!view) return fail(Errc::kInternal, "the averaged picture's texture is missing");
  const render::Size size = output_->size();
  if (size.width != image.width || size.height != image.height) {
    return fail(Errc::kInternal, "the output changed size during the jitter loop");
  }
  overlay_->draw(*view, {0, 0, static_cast<float>(size.width), static_cast<float>(size.height)}, size);
  return {};
}

Result<void> ScriptPlayer::tv(const script::TvRequest& request) {
  if (request.op == script::TvOp::kCamera) {
    if (!request.on) {
      camera_.reset();
      return {};
    }
    if (camera_) return {};
    if (!options_.camera) {
      return fail(Errc::kUnavailable,
                  "this show has no camera: give one with basalt run --camera (v4l2:/dev/video0, synthetic, ...) "
                  "or name one in the show manifest's [devices] (kind = \"camera\"); the show goes on without "
                  "the camera");
    }
    auto camera = options_.camera();
    if (!camera) return std::unexpected(camera.error());
    camera_ = std::move(*camera);
    return {};
  }
  return vcrCommand(request);
}

Result<void> ScriptPlayer::vcrCommand(const script::TvRequest& request) {
  using script::TvOp;
  if (request.op == TvOp::kMovie) {
    if (!vcr_) {
      media::MoviePlayerOptions options;
      options.name = "the script's movie";
      auto player = media::MoviePlayer::create(options);
      if (!player) return std::unexpected(player.error());
      vcr_ = std::move(*player);
    }
    if (auto r = vcr_->load(request.file); !r) {
      vcr_->unload();
      vcrLoaded_ = false;
      return r;
    }
    vcrLoaded_ = true;
    return {};
  }
  if (!vcr_ || !vcrLoaded_) {
    if (request.op == TvOp::kUnload || request.op == TvOp::kStop) return {};
    return fail(Errc::kUnavailable, "no movie is loaded; load one first with tv.movie = \"FILE\"");
  }
  if (vcr_->state() == media::MovieState::kFailed) {
    const auto error = vcr_->error();
    if (request.op != TvOp::kUnload) {
      return fail(Errc::kUnavailable,
                  fmt::format("the movie cannot play ({})", error ? error->message() : std::string("decoding failed")));
    }
  }
  switch (request.op) {
    case TvOp::kUnload:
      vcr_->unload();
      vcrLoaded_ = false;
      break;
    case TvOp::kPlay: vcr_->play(); break;
    case TvOp::kPause: vcr_->pause(); break;
    case TvOp::kStop: vcr_->stop(); break;
    case TvOp::kStepForward: vcr_->stepForward(); break;
    case TvOp::kStepReverse: vcr_->stepBack(); break;
    case TvOp::kRewind: vcr_->rewind(); break;
    case TvOp::kFastForward: vcr_->fastForward(10); break;
    case TvOp::kShuttle:
      if (request.frames >= 0) {
        vcr_->fastForward(request.frames);
      } else {
        vcr_->seekFrame(std::max<std::int64_t>(0, std::max<std::int64_t>(vcr_->currentFrame(), 0) + request.frames));
      }
      break;
    case TvOp::kRepeat: vcr_->setRepeat(request.on); break;
    case TvOp::kMovie:
    case TvOp::kCamera: break;
  }
  return {};
}

void ScriptPlayer::lockedMovieFrames(LockedMovieFrames& frames) const {
  const std::int64_t shown = vcr_ && vcrLoaded_ && videoLive_ && !camera_ ? vcr_->currentFrame() : -1;
  frames.item = shown >= 0 && shown <= std::numeric_limits<std::int32_t>::max() ? static_cast<std::int32_t>(shown) : -1;
}

void ScriptPlayer::followMovieFrames(const LockedMovieFrames& frames) { leaderFrame_ = frames.item; }

void ScriptPlayer::followLeader(std::chrono::milliseconds patience) {
  follower_ = true;
  patience_ = patience;
}

FrameRef ScriptPlayer::vcrFrame(Nanos showTime, bool manualClock) {
  const std::int64_t leader = std::exchange(leaderFrame_, -1);  // used up: the next frame brings its own
  media::PickedFrame pick = media::pickFrame(*vcr_, {.showTime = showTime,
                                                     .leaderFrame = follower_ ? leader : -1,
                                                     .manualClock = manualClock,
                                                     .patience = patience_});
  if (pick.outcome == media::FrameOutcome::kCorrected) ++movieCounts_.corrected;
  if (pick.outcome == media::FrameOutcome::kLate) ++movieCounts_.late;
  return std::move(pick.frame);
}

void ScriptPlayer::updateVideo(const FrameContext& frameContext, bool manualClock) {
  const Nanos showTime = frameContext.time;
  const std::string name(kScriptVideoTexture);
  bool live = false;
  if (camera_) {
    // The live camera wins over the movie while it is on (LAVA: one video input at a time).
    live = camera_->update(showTime, renderer_.textures(), name);
  } else if (vcr_ && vcrLoaded_ && vcr_->state() != media::MovieState::kFailed) {
    if (!video_) {
      auto texture = render::StreamTexture::create(name);
      if (!texture) {
        warn(fmt::format("the movie cannot be shown: {}", texture.error().describe()));
        vcr_->unload();
        vcrLoaded_ = false;
        return;
      }
      video_ = std::move(*texture);
    }
    const FrameRef frame = vcrFrame(showTime, manualClock);
    auto changed = video_->update(frame);
    if (!changed) {
      warn(fmt::format("the movie cannot be shown: {}; it is unloaded", changed.error().describe()));
      vcr_->unload();
      vcrLoaded_ = false;
    } else if (!video_->showingFallback()) {
      video_->publish(renderer_.textures());
      live = true;
      // Which movie frame the VCR shows in which frame (BASALT_LOG=kiosk=debug): frame-locked
      // nodes are compared with it.
      if (const std::int64_t shown = vcr_->currentFrame(); shown >= 0 && kLogKiosk.enabled(log::Level::kDebug)) {
        log::debug(kLogKiosk, "frame {}: texture '{}' shows movie '{}' frame {}", frameContext.frame, name,
                   vcr_->info().path.filename().string(), shown);
      }
    }
  }
  if (!live && videoLive_) {
    renderer_.textures().remove(name);
    if (video_) video_->showFallback();  // a movie loaded next never shows this one's frame
  }
  videoLive_ = live;
}

bool ScriptPlayer::renders(Feature feature) const { return rendererDraws(feature); }

}  // namespace basalt::kiosk
