#pragma once

/// \file
/// \brief Movies as frame sources: GStreamer decodes on its own thread into a bounded pool of
/// Frames; the frame loop picks the newest frame due on the show clock. The controls are LAVA's
/// VCR remote (manual §7.1): load and unload, play, pause, stop, step forward and back one frame,
/// rewind, fast-forward 10 frames, shuttle at any speed both ways, repeat, seek to a frame or a
/// time; and playlists that move from clip to clip with no gap.

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "runtime/clock.h"
#include "runtime/error.h"
#include "runtime/frame.h"
#include "runtime/frame_queue.h"

namespace basalt::media {

/// \brief What a loaded movie is.
struct MovieInfo {
  std::filesystem::path path;
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  double pixelAspect = 1;        ///< pixel width / pixel height (anamorphic files are not 1)
  double fps = 0;                ///< nominal frames per second (from the stream, or measured)
  Nanos frameDuration{0};        ///< 1/fps
  std::int64_t frameCount = -1;  ///< estimated from the duration; exact once played through; -1 unknown
  bool frameCountExact = false;  ///< true once the whole clip has been decoded
  Nanos duration{-1};            ///< -1 when the container does not say
  /// Where the picture ended when it ended well before `duration` (more than a second and more
  /// than a twentieth of it): the file is cut short (a Matroska or MP4 with its index first
  /// plays what is left of it). -1 while it has not.
  Nanos endedEarlyAt{-1};
  PixelFormat format = PixelFormat::kUnknown;  ///< what frames arrive in (uploaded as is)
  Colorimetry colorimetry{};
  std::string codec;  ///< e.g. "H.264 (High Profile)"
  bool hasAudio = false;
  /// Sound was asked for (MoviePlayerOptions::audio) and the movie has some, but this machine
  /// has no audio output: the movie plays without sound (said once per process in the log).
  bool audioOutputMissing = false;
  bool seekable = false;
};

/// \brief Where a player is with its file.
enum class MovieState : std::uint8_t {
  kEmpty,    ///< nothing loaded (or unloaded)
  kLoading,  ///< opening and prerolling on the decoder thread
  kReady,    ///< decoding
  kFailed,   ///< the file could not be played, or decoding failed; error() says why
};

/// \brief The VCR's transport.
enum class Transport : std::uint8_t { kStopped, kPlaying, kPaused };

struct MoviePlayerOptions {
  std::size_t queueFrames = 8;  ///< decoded frames kept ahead of the show (the gapless margin)
  bool audio = false;           ///< play sound on the default output; discarded when false or absent
  std::string name = "movie";   ///< for messages: the part or stream it feeds
  /// Converts every frame to this format on the CPU (videoconvert) instead of handing the
  /// decoder's planes on: only for comparisons (the naive path in the benchmarks). kUnknown
  /// (the default) keeps the decoder's format.
  PixelFormat cpuConvertTo = PixelFormat::kUnknown;
  /// A clip that is playing, with room in the queue, but delivers no frame for this long (or
  /// four frame durations, if longer) has stalled: its pipeline is built again and resumes at
  /// the next frame, so that a kiosk's texture keeps moving.
  std::chrono::milliseconds stallTimeout{5000};
  /// Logs a failure (state() becomes kFailed) as an error naming the file. A caller that says
  /// itself what failed and what shows instead (a kiosk's texture stream) turns it off, so that
  /// one failure is one log line.
  bool logFailures = true;
};

/// \brief Counters for the status server and tests.
struct MoviePlayerStats {
  std::uint64_t decoded = 0;  ///< frames the decoder handed over
  std::uint64_t shown = 0;    ///< frames frameAt() returned
  std::uint64_t passed = 0;   ///< frames decoded but passed over (shuttle, late decoder)
  std::uint64_t loops = 0;    ///< times a clip restarted or the playlist moved on
  std::uint64_t stalls = 0;   ///< times a stalled pipeline was built again
};

/// \brief How MoviePlayer::frameNumbered() came by its frame.
enum class NumberedOutcome : std::uint8_t {
  kAgreed,     ///< the frame asked for is the one the player's own timeline shows at that time
  kCorrected,  ///< the player's own timeline would have shown another frame (or a seek was needed)
  kLate,       ///< the frame asked for did not come within the patience: the shown frame stays
};

/// \brief A frame asked for by its number, and how it was come by.
struct NumberedFrame {
  FrameRef frame;  ///< empty when the frame on screen stays (it is the one asked for, or it came late)
  NumberedOutcome outcome = NumberedOutcome::kAgreed;
};

/// \brief A movie file (or a playlist of them) as a FrameSource, with LAVA's VCR controls.
///
/// Threading: every public function is called on the frame loop's thread, except the wait
/// functions, which tests and offline tools use. The controls never block: they post commands
/// to the decoder thread, which owns the GStreamer pipelines. Frames go through a FrameQueue
/// (the decoder waits for room; it never blocks the show).
///
/// Timing: a frame's pts is its place on the player's timeline, which advances with the show
/// clock while playing (times the shuttle speed) and stands still while paused. Loops and
/// playlist moves continue the timeline, so the next clip's first frame is due exactly one frame
/// after the last frame of the one before.
class MoviePlayer final : public FrameSource {
 public:
  static Result<std::unique_ptr<MoviePlayer>> create(MoviePlayerOptions options = {});
  ~MoviePlayer() override;
  MoviePlayer(const MoviePlayer&) = delete;
  MoviePlayer& operator=(const MoviePlayer&) = delete;

  // -- Movie menu --
  /// \brief Loads one movie (replacing what was loaded) and shows its first frame, stopped.
  /// Fails at once for a missing or unreadable file; decoding problems arrive later as
  /// state() == kFailed with error().
  [[nodiscard]] Result<void> load(const std::filesystem::path& path);
  /// \brief Loads clips played one after the other; the next is prerolled while one plays.
  [[nodiscard]] Result<void> loadPlaylist(const std::vector<std::filesystem::path>& paths);
  void unload();

  // -- VCR remote --
  void play();
  void pause();
  /// \brief Stops and shows the first frame.
  void stop();
  void stepForward();
  void stepBack();
  /// \brief Back to the first frame, keeping play or pause.
  void rewind();
  /// \brief LAVA's FFwd: `frames` (10) frames ahead.
  void fastForward(std::int64_t frames = 10);
  /// \brief Plays at `speed` times normal, backwards when negative (LAVA's SmartPlay shuttle).
  /// 0 pauses; 1 is normal play.
  void shuttle(double speed);
  /// \brief LAVA's SmartPlay repeat: loop the clip (or the playlist) with no gap.
  void setRepeat(bool on);
  void seekFrame(std::int64_t frame);
  void seekTime(Nanos time);
  /// \brief Seeks to `frame`, placing it at `timeline` on the player's timeline (the frames
  /// after it follow by their timestamps), and anchors the timeline so that it is due at show
  /// time `due` (which may have passed: later frames then catch up) rather than when the seek
  /// lands. Frame-locked nodes start a movie this way on the leader's timeline, so that every
  /// later frame (and loop) falls where the leader's does.
  void seekFrameDueAt(std::int64_t frame, Nanos due, Nanos timeline);
  /// \brief One pass of a looping clip on the timeline (its last frame's timestamp plus a frame
  /// duration), known once it has looped; 0 before.
  [[nodiscard]] Nanos passDuration() const;
  /// \brief MovieInfo::endedEarlyAt of the loaded clip, without copying the info (each frame).
  [[nodiscard]] Nanos endedEarlyAt() const;

  [[nodiscard]] bool repeat() const { return repeat_; }
  [[nodiscard]] Transport transport() const { return transport_; }
  [[nodiscard]] double speed() const { return speed_; }
  /// \brief The number of frames of the current clip (estimated until played through), or -1.
  [[nodiscard]] std::int64_t frameCount() const;
  /// \brief The frame number of the frame last returned by frameAt(), or -1 before the first.
  [[nodiscard]] std::int64_t currentFrame() const { return shownIndex_; }
  /// \brief The playlist entry the shown frame belongs to.
  [[nodiscard]] std::size_t currentClip() const { return shownClip_; }

  /// \brief True when the clip (or playlist) has ended without repeat and its last frame is shown.
  [[nodiscard]] bool atEnd() const;
  [[nodiscard]] MovieState state() const;
  /// \brief Why the state is kFailed.
  [[nodiscard]] std::optional<Error> error() const;
  [[nodiscard]] MovieInfo info() const;
  [[nodiscard]] MoviePlayerStats stats() const;

  /// \brief The newest frame due at `showTime`, or empty when the shown frame stays. Never
  /// blocks. Frames come in the format the decoder made (YUV planes: the renderer converts).
  FrameRef frameAt(Nanos showTime) override;

  /// \brief Fault injection for tests and drills: blocks the video stream of the clip playing
  /// now (a blocking probe in front of its sink), as a decoder that hangs does, so that the
  /// stall watchdog has something to recover from.
  void injectStall();
  /// \brief Waits until the loaded movie is ready or failed (tests, tools, `basalt check`).
  [[nodiscard]] Result<MovieInfo> waitUntilLoaded(std::chrono::milliseconds timeout);
  /// \brief Frame-locked followers: frame `index` of the clip (its number from 0, as
  /// currentFrame() counts), whatever the player's own timeline says at `showTime`: the leader
  /// says which frame it shows, and two decoders' timestamps need not add up alike. The queued
  /// frames before it are passed over; one not decoded yet is waited for, at most `patience`
  /// (then the shown frame stays: kLate). A frame behind the player (the one on screen is later,
  /// or the number is nearer behind it than ahead of it in the loop) is gone from the queue: the
  /// player seeks back to it, due at `showTime`, rather than hold a frame the leader does not
  /// show. Frame 0 after the clip's last is the next loop's. Empty frame when the shown one is
  /// the one asked for. The timeline's anchor is kept, so frameAt() can take over again.
  NumberedFrame frameNumbered(std::int64_t index, Nanos showTime, std::chrono::milliseconds patience);

  /// \brief For offline rendering on a manual clock only: waits until the frame due at
  /// `showTime` has been decoded (or the clip ended or failed), so that every frame of a fast
  /// run is exact. A show on the system clock never calls this.
  bool waitForFrameDue(Nanos showTime, std::chrono::milliseconds timeout);

 private:
  struct Impl;
  explicit MoviePlayer(std::unique_ptr<Impl> impl);
  void requestSeek(std::int64_t index, std::optional<Nanos> timeline = std::nullopt);
  [[nodiscard]] Nanos targetTime(Nanos showTime) const;
  [[nodiscard]] Nanos frameDuration() const;
  [[nodiscard]] std::int64_t logicalIndex() const;
  void anchorAtShown();

  std::unique_ptr<Impl> impl_;
  // Frame loop thread only:
  Transport transport_ = Transport::kStopped;
  double speed_ = 1.0;
  bool repeat_ = false;
  bool awaitFirst_ = false;      // a seek or load is pending: show the first frame that comes
  bool needShowAnchor_ = false;  // take anchorShow_ at the next frameAt()
  Nanos anchorShow_{0};          // show time at which the timeline was at anchorPts_
  Nanos anchorPts_{0};           // timeline position
  std::int64_t reverseAnchorIndex_ = 0;
  Nanos reverseAnchorShow_{0};
  Nanos lastShowTime_{0};          // the show time of the last frameAt()
  std::int64_t pendingIndex_ = 0;  // the frame a pending seek goes to
  std::int64_t shownIndex_ = -1;
  std::size_t shownClip_ = 0;
  Nanos shownPts_{0};
  std::uint64_t generation_ = 0;  // bumped by every seek and load
  std::uint64_t shownGeneration_ = 0;
  FrameRef carry_;                  // a due frame waitForFrameDue() took out of a full queue
  std::optional<Nanos> seekDueAt_;  // seekFrameDueAt(): the show time the pending seek's frame is due
};

}  // namespace basalt::media
