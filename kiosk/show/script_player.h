#pragma once

/// \file
/// \brief Plays a LAVA script in the frame loop (`basalt run show.mdl`, as `lava -file
/// show.mdl`): a FrameParticipant that steps the interpreter one frame at a time, and the
/// script::Host that gives scripts files, images and the picture.
///
/// The script runs up to its first `draw` before frame 0 is drawn; after that it runs in each
/// frame's afterDraw(), while the frame just drawn is still in the framebuffer, up to the next
/// `draw`. So `save_image` and `end_jitter` read exactly the picture the script drew last, and a
/// `quit` makes the frame just drawn the last one.

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "kiosk/lock/frame_lock.h"
#include "kiosk/loop/frame_loop.h"
#include "kiosk/show/show_loader.h"
#include "media/movie_player.h"
#include "render/renderer.h"
#include "render/stream_texture.h"
#include "runtime/image.h"
#include "runtime/script/host.h"
#include "runtime/script/interpreter.h"

namespace basalt::kiosk {

struct ScriptPlayerOptions {
  std::filesystem::path outputDir = "out";  ///< where save_image writes
  /// The file of a bare `save_image`; relative names are in outputDir. LAVA's was "ras.im32".
  std::filesystem::path saveImage = "ras.im32";
  bool quitEndsRun = true;  ///< `quit` ends the run (the script was given on the command line)
  /// Opens the show's camera for `tv.camera = on` (kiosk/show/stream_factories.h scriptCamera());
  /// empty when the show has none, and the script is told so.
  std::function<Result<std::unique_ptr<TextureStream>>()> camera;
  /// An offline run on a ManualClock: the VCR waits for each frame due, so that runs repeat.
  bool manualClock = false;
};

/// \brief Runs one script against the Show of a frame loop.
///
/// Threading: the frame loop's thread, with the GL context current (textures are uploaded and
/// the framebuffer read back here).
///
/// Frame-locked (LockedMovies): the VCR's movie uses the item slot of LockedMovieFrames. A
/// leader sends the frame its VCR shows; a follower shows exactly the leader's frame
/// (MoviePlayer::frameNumbered), whatever its own timestamps say.
class ScriptPlayer final : public FrameParticipant, public script::Host, public LockedMovies {
 public:
  ScriptPlayer(script::Interpreter interpreter, runtime::Show& show, render::Renderer& renderer,
               ScriptPlayerOptions options);
  /// \brief Takes the VCR's texture out of the renderer's registry.
  ~ScriptPlayer() override;
  ScriptPlayer(const ScriptPlayer&) = delete;
  ScriptPlayer& operator=(const ScriptPlayer&) = delete;

  /// \brief Where messages about the script go (errors, warnings, notes), one at a time.
  void setReporter(const script::Interpreter::Reporter& reporter);

  // FrameParticipant
  Result<void> beforeDraw(const FrameContext& frame) override;
  void adjustView(const FrameContext& frame, runtime::ViewTransforms& view, render::Size size) override;
  Result<void> afterDraw(const FrameContext& frame, render::Output& output) override;
  [[nodiscard]] bool wantsStop() const override { return stop_; }

  // LockedMovies
  void lockedMovieFrames(LockedMovieFrames& frames) const override;
  void followMovieFrames(const LockedMovieFrames& frames) override;
  [[nodiscard]] LockedMovieCounts movieFrameCounts() const override { return movieCounts_; }
  /// \brief Frame-locked follower: the VCR shows the leader's movie frames, waiting up to
  /// `patience` for one not decoded yet (ten seconds on a manual clock).
  void followLeader(std::chrono::milliseconds patience);

  // script::Host
  [[nodiscard]] Result<void> loadObject(const std::filesystem::path& file, runtime::Show& show) override;
  [[nodiscard]] Result<void> loadTexture(const std::filesystem::path& file, const std::string& name) override;
  [[nodiscard]] Result<void> saveImage(std::string_view name) override;
  [[nodiscard]] Result<void> accumulateJitterPass(int pass, int passes) override;
  [[nodiscard]] Result<void> tv(const script::TvRequest& request) override;
  [[nodiscard]] bool renders(script::Feature feature) const override;

  [[nodiscard]] const script::Interpreter& interpreter() const { return interpreter_; }
  /// \brief Frames that showed a draw of the script (the interpreter has also counted the draw it
  /// stopped at for the next frame, which a run that ends now never shows).
  [[nodiscard]] std::uint64_t drawsShown() const { return drawsShown_; }
  /// \brief Files save_image wrote, in order.
  [[nodiscard]] const std::vector<std::filesystem::path>& imagesWritten() const { return written_; }
  /// \brief How the frame being made is drawn: the step that ended it.
  [[nodiscard]] const script::StepResult& currentStep() const { return step_; }
  /// \brief The VCR's movie player (null before the first tv.movie).
  [[nodiscard]] const media::MoviePlayer* vcr() const { return vcr_.get(); }
  /// \brief Whether the VCR's texture (kScriptVideoTexture) shows a movie or camera frame now.
  [[nodiscard]] bool videoLive() const { return videoLive_; }

 private:
  void runStep();
  Result<const Image*> currentPicture();
  Result<void> presentPicture(const Image& image);
  void warn(std::string message);
  Result<void> vcrCommand(const script::TvRequest& request);
  void updateVideo(const FrameContext& frame, bool manualClock);
  /// The VCR's frame for this frame: the leader's by number on a follower, else by the timeline.
  FrameRef vcrFrame(Nanos showTime, bool manualClock);

  script::Interpreter interpreter_;
  runtime::Show& show_;
  render::Renderer& renderer_;
  ScriptPlayerOptions options_;
  script::Interpreter::Reporter reporter_;

  script::StepResult step_;
  bool started_ = false;
  bool stop_ = false;
  render::Output* output_ = nullptr;  // set only while afterDraw() runs the script
  Image frame_;                       // the frame just drawn, read back on demand
  bool frameRead_ = false;
  std::vector<std::uint32_t> jitterSum_;  // per channel, sized on the first pass
  Image jitterAverage_;
  bool jitterReady_ = false;                         // jitterAverage_ is the current picture (until the next draw)
  std::unique_ptr<render::PictureOverlay> overlay_;  // puts the jitter average on the output
  std::vector<std::filesystem::path> written_;
  std::uint64_t drawsShown_ = 0;
  // The VCR (LAVA §7): one movie player and the live camera, shown as kScriptVideoTexture.
  std::unique_ptr<media::MoviePlayer> vcr_;
  bool vcrLoaded_ = false;  // a movie is loaded (the player's state lags its commands)
  std::unique_ptr<TextureStream> camera_;
  std::unique_ptr<render::StreamTexture> video_;
  bool videoLive_ = false;
  // Frame-locked follower (followLeader): the leader's VCR frame in the coming frame, -1 for none.
  bool follower_ = false;
  std::chrono::milliseconds patience_{0};
  std::int64_t leaderFrame_ = -1;
  LockedMovieCounts movieCounts_;
};

/// \brief Whether `path` names a LAVA script (.mdl, any case).
bool isScriptFile(const std::filesystem::path& path);
/// \brief Reads and parses a script, printing what parsing found wrong (the run goes on).
Result<script::Interpreter> loadScript(const std::filesystem::path& path);
/// \brief Whether the script has a `quit` (a batch job rather than a show that plays on).
bool scriptQuits(const script::Program& program);
/// \brief Prints one message about a script: "basalt: error: show.mdl:12: ...".
void printScriptDiagnostic(const script::Diagnostic& diagnostic);
/// \brief Prints what a script did: frames drawn, problems reported, images written.
void printScriptSummary(const ScriptPlayer& player);
/// \brief Writes a saved model (or any text) to `path`, atomically.
Result<void> writeSavedModel(const std::filesystem::path& path, std::string_view text);

}  // namespace basalt::kiosk
