#pragma once

/// \file
/// \brief Wiring movies into a show: a MoviePlayer per named stream, its StreamTexture in the
/// renderer's registry under that name (the texture of the part of that name, LAVA's
/// `texture.switch = video`), the Zoom picture, and the recorder of the rendered output. The show
/// manifest (issue 9) builds the same MovieStreamSpecs; `basalt run --movie/--zoom/--record`
/// builds them from the command line until then.

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "kiosk/lock/frame_lock.h"
#include "kiosk/loop/frame_loop.h"
#include "media/movie_player.h"
#include "media/recorder.h"
#include "render/renderer.h"
#include "render/stream_texture.h"
#include "runtime/bindings.h"
#include "runtime/error.h"
#include "runtime/show/show.h"

namespace basalt::kiosk {

/// \brief LAVA's Zoom: the stream as a 2D picture over the scene.
struct ZoomSpec {
  double scale = 0.5;  ///< of the movie's own size ("1/2x" in LAVA's demo)
  float x = 10;        ///< top-left corner, output pixels
  float y = 10;
};

/// \brief One movie stream of a show.
struct MovieStreamSpec {
  std::string name;                          ///< texture name; the part of that name shows it
  std::vector<std::filesystem::path> files;  ///< one movie, or a playlist
  bool repeat = true;                        ///< installations loop
  bool audio = false;
  std::optional<ZoomSpec> zoom;
};

/// \brief Parses `PART=FILE` (the value of --movie).
[[nodiscard]] Result<std::pair<std::string, std::filesystem::path>> parseMovieOption(std::string_view text);
/// \brief Parses `PART[=SCALE][@X,Y]` (the value of --zoom).
[[nodiscard]] Result<std::pair<std::string, ZoomSpec>> parseZoomOption(std::string_view text);

/// \brief Movie streams taking part in every frame: each picks its newest due frame (never
/// blocking on a system clock; waiting for the decoder under a manual clock so that an offline
/// run is exact), converts it on the GPU and draws the Zoom pictures over the scene.
///
/// Frame-locked (LockedMovies): the streams use the last texture slots of LockedMovieFrames,
/// the first stream the last slot (the show's own movie streams take the first slots; a
/// stream beyond the four, and a playlist, keeps its own timeline). A leader sends the frame
/// each shows; a follower shows exactly the leader's (MoviePlayer::frameNumbered).
class VideoStreams final : public FrameParticipant, public LockedMovies {
 public:
  /// \brief Starts the players (GStreamer starts here, only for shows with movies). A file
  /// that cannot be played is reported, its part shows the fallback, and the show goes on.
  [[nodiscard]] static Result<std::unique_ptr<VideoStreams>> create(const std::vector<MovieStreamSpec>& specs,
                                                                    runtime::Show& show, render::Renderer& renderer,
                                                                    bool manualClock);
  ~VideoStreams() override;
  VideoStreams(const VideoStreams&) = delete;
  VideoStreams& operator=(const VideoStreams&) = delete;

  Result<void> beforeDraw(const FrameContext& frame) override;
  Result<void> afterDraw(const FrameContext& frame, render::Output& output) override;

  // LockedMovies
  void lockedMovieFrames(LockedMovieFrames& frames) const override;
  void followMovieFrames(const LockedMovieFrames& frames) override;
  [[nodiscard]] LockedMovieCounts movieFrameCounts() const override { return movieCounts_; }
  /// \brief Frame-locked follower: the streams show the leader's movie frames, waiting up to
  /// `patience` for one not decoded yet (ten seconds on a manual clock).
  void followLeader(std::chrono::milliseconds patience);

  /// \brief The player of stream `name` (the VCR remote), or null.
  [[nodiscard]] media::MoviePlayer* player(std::string_view name);
  /// \brief Moves stream `name`'s Zoom picture by (dx, dy) pixels (LAVA: Shift + drag).
  void moveZoom(std::string_view name, float dx, float dy);
  /// \brief Lets dials move the Zoom pictures: before each frame, what the `move_zoom_x` and
  /// `move_zoom_y` dials of `bindings` turned (runtime::Bindings::takeZoomMove) moves every Zoom
  /// picture. `bindings` must outlive this; null stops following.
  void followZoomDials(runtime::Bindings* bindings) { zoomDials_ = bindings; }
  /// \brief Where stream `name`'s Zoom picture is now (output pixels), or nullopt.
  [[nodiscard]] std::optional<render::PictureRect> zoomRect(std::string_view name) const;
  /// \brief One line per stream: file, state, frame, upload path.
  [[nodiscard]] std::vector<std::string> status() const;

 private:
  struct Stream;
  VideoStreams(render::Renderer& renderer, bool manualClock);
  render::Renderer& renderer_;
  runtime::Show* show_ = nullptr;  // borrowed: the show whose parts may name a stream's texture
  bool manualClock_;
  std::vector<std::unique_ptr<Stream>> streams_;
  std::unique_ptr<render::PictureOverlay> overlay_;
  runtime::Bindings* zoomDials_ = nullptr;
  // Frame-locked follower (followLeader): each stream's leaderFrame is set by followMovieFrames.
  bool follower_ = false;
  std::chrono::milliseconds patience_{0};
  LockedMovieCounts movieCounts_;
};

/// \brief Records the rendered output (LAVA's Rec): reads each frame back after drawing and
/// hands it to a media::Recorder. A write error (full disk) stops the recording with one
/// message; the show goes on.
class ScreenRecorder final : public FrameParticipant {
 public:
  [[nodiscard]] static Result<std::unique_ptr<ScreenRecorder>> create(const media::RecorderOptions& options);
  Result<void> afterDraw(const FrameContext& frame, render::Output& output) override;
  /// \brief Ends the file; returns the first error of the recording, if any.
  [[nodiscard]] Result<void> finish();
  [[nodiscard]] std::int64_t frames() const { return recorder_ ? recorder_->framesWritten() : 0; }
  [[nodiscard]] const media::RecorderOptions& options() const { return options_; }
  [[nodiscard]] std::string describe() const { return recorder_ ? recorder_->describe() : std::string{}; }

 private:
  explicit ScreenRecorder(std::unique_ptr<media::Recorder> recorder, media::RecorderOptions options)
      : recorder_(std::move(recorder)), options_(std::move(options)) {}
  std::unique_ptr<media::Recorder> recorder_;
  media::RecorderOptions options_;
  Image frame_;  // read-back buffer, allocated once
  std::optional<Error> failure_;
};

}  // namespace basalt::kiosk
