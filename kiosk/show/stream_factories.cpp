#include "kiosk/show/stream_factories.h"

#include "kiosk/show/file_watch.h"
#include "kiosk/show/script_player.h"
#include "kiosk/show/trace_video_glue.h"

#include <algorithm>
#include <atomic>
#include <mutex>
#include <thread>

#include <fmt/format.h>
#include <fmt/std.h>

#include "devices/hid/hid_backend.h"
#include "devices/libcamera/libcamera_camera.h"
#include "devices/midi/midi_backend.h"
#include "devices/serial/sgi_dial_box.h"
#include "devices/v4l2/v4l2_camera.h"
#include "media/frame_picker.h"
#include "media/mjpeg_decoder.h"
#include "media/movie_player.h"
#include "render/stream_texture.h"
#include "runtime/log.h"
#include "runtime/test_pattern.h"
#include "sim/hid_recording.h"
#include "sim/midi_file.h"
#include "sim/providers.h"

namespace basalt::kiosk {

BASALT_LOG_CATEGORY(Streams, "kiosk");

namespace {

// ---------------------------------------------------------------------------------------------
// Movies

/// How long a file that is being written must be quiet before it is tried (a copy in place
/// sends IN_MODIFY for every write; IN_CLOSE_WRITE ends the wait at once).
constexpr Nanos kWriteQuiet = std::chrono::seconds(1);
/// Where inotify cannot watch the file's folder, the file is looked at on this back-off.
constexpr Nanos kLookFirst = std::chrono::seconds(1);
constexpr Nanos kLookMost = std::chrono::seconds(30);

/// A movie file on a texture. The file may change under the running show
/// (docs/decisions/0062-content-changed-under-a-running-show.md): emptied, cut short, replaced
/// by rename or deleted. Its folder is watched (FileWatch), and a change is acted on at once:
/// the new content is loaded (a replaced file switches immediately, not at the loop's end),
/// a file that is gone or cannot play leaves the stream *degraded* with the fallback showing
/// and one log line, and the stream waits, doing nothing, until the file changes again.
class MovieStream final : public TextureStream {
 public:
  MovieStream(MediaSpec media, std::unique_ptr<media::MoviePlayer> player, bool manualClock)
      : media_(std::move(media)), player_(std::move(player)), manualClock_(manualClock) {}

  bool update(Nanos showTime, render::TextureRegistry& textures, const std::string& name) override {
    leaderResult_ = LeaderFrameResult::kNone;
    if (!started_) {
      started_ = true;
      watchFile(showTime);
      startPlaying("");
    } else {
      lookAtFile(showTime);
    }
    if (!failure_.empty()) return false;
    if (!broken_.empty() && !retrying_) return false;
    if (!texture_) {
      auto texture = render::StreamTexture::create(name);
      if (!texture) {
        failure_ = texture.error().message();
        log::error(kLogStreams, "movie '{}': {}", media_.name, texture.error().describe());
        return false;
      }
      texture_ = std::move(*texture);
    }
    if (origin_ && !aligned_) {
      align(showTime, media::framePatience(manualClock_, patience_));
      // Nothing before the movie is on the group's timeline: a node that showed the clip's first
      // frame meanwhile would show another frame than the others.
      const media::MovieState now = player_->state();
      if (!aligned_ && now != media::MovieState::kFailed && now != media::MovieState::kEmpty) return false;
    }
    // Offline (ManualClock) runs wait for the frame due, so that every frame is exact; a show
    // on the system clock never waits (the newest frame due is shown, or the last one stays),
    // except a frame-locked node, which must draw the group's frame (bounded by its patience).
    media::PickedFrame pick = media::pickFrame(*player_, {.showTime = showTime,
                                                          .leaderFrame = origin_ ? leaderFrame_ : -1,
                                                          .manualClock = manualClock_,
                                                          .patience = patience_,
                                                          .onGroupTimeline = origin_.has_value()});
    FrameRef frame = std::move(pick.frame);
    leaderResult_ = pick.outcome;
    const media::MovieState state = player_->state();
    if (state == media::MovieState::kFailed || state == media::MovieState::kEmpty) {
      const auto error = player_->error();
      fileBroken(fmt::format("cannot play: {}", error ? error->message() : std::string("nothing is loaded")));
      return false;
    }
    if (const Nanos early = player_->endedEarlyAt(); early >= Nanos{0}) {
      // The file lost its end (Matroska, or MP4 with its index first, still open): what is left
      // played once, but it cannot loop or seek reliably, and the copy on disk is broken.
      const Nanos duration = player_->info().duration;
      player_->unload();
      fileBroken(fmt::format("is cut short (its picture ends at {:.1f} s of the {:.1f} s its container gives)",
                             toSeconds(early), toSeconds(duration)));
      return false;
    }
    if (retrying_ && !frame) return false;  // the good file's first frame, not the old one's last
    auto changed = texture_->update(frame);
    if (!changed) {
      failure_ = changed.error().message();
      log::error(kLogStreams, "movie '{}': {}; its textures show their fallback", media_.name,
                 changed.error().describe());
      player_->unload();
      return false;
    }
    if (texture_->showingFallback()) return false;  // no frame yet: never a frame early
    if ((retrying_ || !cause_.empty()) && frame) {  // the changed file's first frame
      if (!broken_.empty()) {
        log::info(kLogStreams, "movie '{}': {} plays again", media_.name, media_.file);
      } else {
        log::info(kLogStreams, "movie '{}': {} {}; playing the new content", media_.name, media_.file, cause_);
      }
      broken_.clear();
      cause_.clear();
      retrying_ = false;
    }
    texture_->publish(textures);
    return true;
  }

  [[nodiscard]] bool degraded() const override { return !broken_.empty(); }

  void alignTo(Nanos origin, std::chrono::milliseconds patience) override {
    if (origin_ == origin && patience_ == patience) return;
    origin_ = origin;
    patience_ = patience;
    aligned_ = false;
  }

  void setLeaderPass(Nanos pass) override { leaderPass_ = pass; }
  void setLeaderFrame(std::int64_t frame) override { leaderFrame_ = frame; }
  [[nodiscard]] LeaderFrameResult leaderFrameResult() const override { return leaderResult_; }
  [[nodiscard]] Nanos passDuration() const override { return started_ ? player_->passDuration() : Nanos{0}; }

  [[nodiscard]] std::int64_t shownFrame() const override {
    return started_ && failure_.empty() ? player_->currentFrame() : -1;
  }

  [[nodiscard]] std::string describe() const override {
    if (!failure_.empty()) return fmt::format("movie {}: {}", media_.file.filename(), failure_);
    if (!broken_.empty()) {
      return fmt::format("movie {}: {}; waiting for a good file", media_.file.filename(), broken_);
    }
    const media::MovieInfo info = player_->info();
    const media::MoviePlayerStats stats = player_->stats();
    return fmt::format("movie {}: frame {} of {}, {} loops{}", media_.file.filename(), player_->currentFrame(),
                       info.frameCount, stats.loops,
                       stats.stalls > 0 ? fmt::format(", restarted {} times after a stall", stats.stalls) : "");
  }

 private:
  /// Seeks to the frame due at `showTime` on the timeline that starts at origin_, due at the
  /// show time that frame belongs to (not when the seek lands), once the clip's length is known.
  void align(Nanos showTime, std::chrono::milliseconds patience) {
    // Opening takes longer than a frame: the first time, wait up to a second for it.
    // (Not loaded yet: the next update tries again; failed: update() reports it.)
    if (!player_->waitUntilLoaded(std::max(patience, std::chrono::milliseconds(1000)))) return;
    if (player_->state() != media::MovieState::kReady) return;
    const Nanos frame = player_->info().frameDuration;
    if (frame <= Nanos{0}) return;
    // The leader's timeline: show time t is at t - origin, a loop's frames at its pass's start
    // plus their timestamps, each pass one leader pass long.
    const Nanos elapsed = std::max(Nanos{0}, showTime - *origin_);
    const std::int64_t count = player_->frameCount();
    Nanos passStart{0};
    if (media_.loop && leaderPass_ > Nanos{0}) {
      passStart = (elapsed / leaderPass_) * leaderPass_;
    } else if (media_.loop && count > 0 && elapsed >= frame * count) {
      passStart = (elapsed / (frame * count)) * (frame * count);  // the leader's pass is not known yet
    }
    // The frame due is the last whose timestamp is at most the time (plus the player's 1.5 ms for
    // rounded timestamps); timestamps sit up to half a millisecond off the frame grid, so take the
    // one before when in doubt: the update after the seek takes the next if it is due, by the same
    // timestamps the leader reads.
    std::int64_t index = std::max<std::int64_t>(0, (elapsed - passStart + std::chrono::microseconds(1000)) / frame);
    if (count > 0) index = std::min(index, count - 1);
    const Nanos timeline = passStart + frame * index;
    player_->seekFrameDueAt(index, *origin_ + timeline, timeline);
    aligned_ = true;
    log::debug(kLogStreams, "movie '{}' joins the group's timeline at show time {:.3f} s: frame {}", media_.name,
               toSeconds(showTime), index);
  }

  /// Watches the file's folder; where that cannot be done, the file is looked at on a back-off.
  void watchFile(Nanos showTime) {
    auto watch = FileWatch::open(media_.file);
    if (watch) {
      watch_ = std::move(*watch);
      return;
    }
    watch_.reset();
    if (!watchFailed_) {
      watchFailed_ = true;
      log::warn(kLogStreams, "movie '{}': {}; a change to the file is seen within {} s instead of at once", media_.name,
                watch.error().describe(), toSeconds(kLookMost));
    }
    nextLook_ = showTime + lookEvery_;
    lookEvery_ = std::min(lookEvery_ * 2, kLookMost);
  }

  /// Acts on a change to the file: at once when it settled (closed after writing, moved, created,
  /// deleted), after kWriteQuiet when it is being written. Costs one non-blocking read a frame.
  void lookAtFile(Nanos showTime) {
    bool look = false;
    if (watch_) {
      switch (watch_->take()) {
        case FileChange::kNone: break;
        case FileChange::kWriting: writingSince_ = showTime; break;
        case FileChange::kSettled: look = true; break;
        case FileChange::kWatchLost:
          look = true;
          watchFile(showTime);  // the folder went away: watched again, or looked at on the back-off
          break;
      }
    } else if (showTime >= nextLook_) {
      look = true;
      watchFile(showTime);
    }
    if (writingSince_ && showTime - *writingSince_ >= kWriteQuiet) look = true;
    if (!look) return;
    writingSince_.reset();
    const std::optional<FileIdentity> now = identify(media_.file);
    if (now == tried_) return;  // unchanged since it was last loaded (or found gone)
    if (!now) {
      player_->unload();  // what plays is no longer the file the manifest names
      cause_ = changeSince(now);
      tried_.reset();
      fileBroken("");
      return;
    }
    startPlaying(changeSince(now));
  }

  /// Loads the file as it is now; `cause` says what happened to it, for the log ("" at start).
  void startPlaying(std::string cause) {
    cause_ = std::move(cause);
    tried_ = identify(media_.file);
    aligned_ = false;
    if (!tried_ || tried_->size == 0) {
      player_->unload();
      fileBroken("");
      return;
    }
    if (auto r = player_->load(media_.file); !r) {
      fileBroken(fmt::format("cannot play: {}", r.error().message()));
      return;
    }
    player_->setRepeat(media_.loop);
    player_->play();
    retrying_ = !broken_.empty();
  }

  /// What happened to the file since it was last loaded: deleted, emptied, replaced (another
  /// inode under the name) or written over in place.
  [[nodiscard]] std::string changeSince(const std::optional<FileIdentity>& now) const {
    return describeChange(tried_, now);
  }

  /// The file is gone or cannot play: the fallback shows and the stream is degraded until the
  /// file changes. Said once (what happened and why), however often a changed file fails again.
  void fileBroken(const std::string& why) {
    retrying_ = false;
    std::string text = cause_;
    cause_.clear();
    if (text.empty()) {
      const std::optional<FileIdentity> now = identify(media_.file);
      if (now != tried_) {
        text = changeSince(now);  // changed under the decoder before its folder's event came
      } else if (!now) {
        text = "is missing";
      } else if (now->size == 0) {
        text = "is empty";
      }
    }
    if (!why.empty()) text += (text.empty() ? "" : " and ") + why;
    if (!broken_.empty()) {
      log::debug(kLogStreams, "movie '{}': {} {}", media_.name, media_.file, text);
      return;
    }
    broken_ = text;
    log::error(kLogStreams, "movie '{}': {} {}; its textures show their fallback until a good file is there",
               media_.name, media_.file, text);
  }

  MediaSpec media_;
  std::unique_ptr<media::MoviePlayer> player_;
  std::unique_ptr<render::StreamTexture> texture_;
  bool manualClock_;
  std::optional<Nanos> origin_;            // frame-locked: the show time of frame 0
  std::chrono::milliseconds patience_{0};  // frame-locked follower: how long to wait for a frame
  bool aligned_ = false;                   // the seek onto the group's timeline is asked for
  Nanos leaderPass_{0};                    // frame-locked follower: the leader's pass of this loop (0: unknown)
  std::int64_t leaderFrame_ = -1;          // frame-locked follower: the leader's movie frame in the coming frame
  LeaderFrameResult leaderResult_ = LeaderFrameResult::kNone;
  bool started_ = false;
  std::string failure_;  // the texture cannot be made or filled: for good
  // The file and what became of it:
  std::optional<FileWatch> watch_;
  bool watchFailed_ = false;           // said once that the folder cannot be watched
  Nanos nextLook_{0};                  // no watch: when the file is looked at next
  Nanos lookEvery_ = kLookFirst;       // ... and the back-off after that
  std::optional<Nanos> writingSince_;  // the file is being written: look once it is quiet
  std::optional<FileIdentity> tried_;  // the file as it was last loaded (none: it was not there)
  std::string cause_;                  // what happened to the file before the load under way (for the log)
  std::string broken_;                 // why the fallback shows (the stream is degraded); "" while it plays
  bool retrying_ = false;              // broken, and a changed file is loading: its first frame ends it
};

}  // namespace

Result<std::unique_ptr<TextureStream>> makeMovieStream(const MediaSpec& media, const Manifest& /*show*/,
                                                       const Clock& clock) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(media.file, ec)) {
    return fail(Errc::kNotFound, "the movie file is missing", media.file.string());
  }
  media::MoviePlayerOptions options;
  options.name = fmt::format("movie '{}'", media.name);
  options.audio = media.audio;
  options.logFailures = false;  // the stream says what failed and what shows instead, once
  auto player = media::MoviePlayer::create(options);
  if (!player) return std::unexpected(player.error());
  return std::make_unique<MovieStream>(media, std::move(*player), clock.isManual());
}

namespace {

// ---------------------------------------------------------------------------------------------
// Cameras

/// A camera's MJPEG frames, decoded off the frame loop: the device manager's frame tap hands
/// every JPEG the camera delivers to a media::MjpegDecoder on the producer's thread (the
/// manager's or the backend's capture thread; the frame loop's only under a ManualClock, where
/// the manager is stepped there), and GStreamer decodes it on its streaming thread. The decoder is
/// made for the first JPEG; one that cannot be made is kept as the failure.
class MjpegTap final : public devices::FrameTap {
 public:
  explicit MjpegTap(std::string camera) : camera_(std::move(camera)) {}

  void onFrame(DeviceId /*device*/, const FrameRef& frame) override {
    if (!frame || frame->format != PixelFormat::kMjpeg) return;
    std::shared_ptr<media::MjpegDecoder> decoder;
    {
      std::lock_guard lock(mutex_);
      if (!decoder_ && failure_.empty()) {
        auto made = media::MjpegDecoder::create({3, fmt::format("camera '{}'", camera_)});
        if (made) {
          decoder_ = std::move(*made);
        } else {
          failure_ = made.error().describe();
        }
      }
      decoder = decoder_;
    }
    if (decoder && decoder->push(frame)) pushed_.fetch_add(1, std::memory_order_release);
  }

  [[nodiscard]] std::shared_ptr<media::MjpegDecoder> decoder() const {
    std::lock_guard lock(mutex_);
    return decoder_;
  }
  [[nodiscard]] std::string failure() const {
    std::lock_guard lock(mutex_);
    return failure_;
  }
  /// JPEGs handed to the decoder so far.
  [[nodiscard]] std::uint64_t pushed() const { return pushed_.load(std::memory_order_acquire); }

 private:
  std::string camera_;
  mutable std::mutex mutex_;
  std::shared_ptr<media::MjpegDecoder> decoder_;  // guarded by mutex_
  std::string failure_;                           // guarded by mutex_
  std::atomic<std::uint64_t> pushed_{0};
};

/// A camera's texture. The camera itself is the DeviceManager's: the director requested it when
/// the show took over, and the stream only reads its frames and its state by the device's name.
/// The scripts' VCR camera, which no director requests, holds the camera itself (shares the
/// request if one is there, else makes it) and gives it back when the VCR lets it go.
class CameraStream final : public TextureStream {
 public:
  /// `ownSource` makes the request when the stream must hold the camera itself (the VCR's).
  CameraStream(const MediaSpec& media, std::string device, const Clock& clock,
               std::function<Result<DeviceSource>()> ownSource = nullptr)
      : media_(media.name),
        onLoss_(media.onLoss),
        lossColour_(media.lossColour),
        clock_(clock),
        mjpeg_(std::make_shared<MjpegTap>(device)),
        name_(std::move(device)),
        ownSource_(std::move(ownSource)) {}
  ~CameraStream() override {
    if (!devices_) return;
    devices_->removeFrameTap(name_, mjpeg_.get());
    if (holds_) devices_->withdraw(name_);
  }
  CameraStream(const CameraStream&) = delete;
  CameraStream& operator=(const CameraStream&) = delete;

  void useDevices(devices::DeviceManager& devices) override {
    if (devices_) return;
    devices_ = &devices;
    // The VCR's camera: shared with a texture that shows it, else requested here.
    if (ownSource_) holds_ = devices.share(name_).has_value() || requestOwn(devices);
    stream_ = devices.videoStream(name_);
    // Every JPEG the camera delivers goes to this stream's decoder on the producer's thread.
    if (stream_) devices.addFrameTap(name_, mjpeg_);
  }

  bool update(Nanos showTime, render::TextureRegistry& textures, const std::string& name) override {
    // The manager opens and reopens the camera (on its thread on the system clock; stepped by
    // the director before this update under a ManualClock, so that a run is repeatable).
    if (!stream_ || !usable_) return false;
    if (!texture_) {
      auto texture = render::StreamTexture::create(name);
      if (!texture) {
        log::error(kLogStreams, "camera '{}': {}", media_, texture.error().describe());
        usable_ = false;
        return false;
      }
      texture_ = std::move(*texture);
    }
    // A camera that cannot flip in the device is mirrored by its texture.
    texture_->setMirror(stream_->mirrorInRenderer());
    FrameRef frame = stream_->frameAt(showTime);
    state_ = stream_->health().state;
    if (state_ != SourceState::kLive) return showLoss(textures);
    const std::optional<devices::VideoMode> mode = stream_->mode();
    if ((frame && frame->format == PixelFormat::kMjpeg) || (mode && mode->format == PixelFormat::kMjpeg)) {
      // The JPEG went to the decoder when the camera delivered it (MjpegTap): show the newest
      // decoded frame due. A ManualClock run waits for the decoder, so that every run is exact.
      if (const std::string failure = mjpeg_->failure(); !failure.empty()) {
        if (!reportedMjpegFailure_) {
          reportedMjpegFailure_ = true;
          log::error(kLogStreams,
                     "camera '{}' delivers MJPEG, which cannot be decoded: {}; its textures show their "
                     "fallback",
                     name_, failure);
        }
        return false;
      }
      const std::shared_ptr<media::MjpegDecoder> decoder = mjpeg_->decoder();
      if (!decoder) return false;
      if (clock_.isManual()) (void)decoder->waitForFinished(mjpeg_->pushed(), std::chrono::seconds(10));
      frame = decoder->frameAt(showTime);
    }
    auto changed = texture_->update(frame);
    if (!changed) {
      log::warn(kLogStreams, "camera '{}': {}", media_, changed.error().describe());
      return false;
    }
    if (*changed) showingLoss_ = false;
    if (showingLoss_) return true;  // the loss picture stays until the camera's first new frame
    if (texture_->showingFallback()) return false;
    texture_->publish(textures);
    return true;
  }

  [[nodiscard]] std::string lossName() const {
    switch (onLoss_) {
      case CameraLoss::kFallbackImage: return "the texture's fallback image";
      case CameraLoss::kLastFrame: return "its last frame";
      case CameraLoss::kTestPattern: return "a test pattern";
      case CameraLoss::kColour:
        return fmt::format("#{:02x}{:02x}{:02x}", lossColour_[0], lossColour_[1], lossColour_[2]);
    }
    return "?";
  }

  /// While the camera is lost or not there yet: what the manifest's on_loss asks for. False
  /// leaves the texture's fallback image to the director.
  bool showLoss(render::TextureRegistry& textures) {
    switch (onLoss_) {
      case CameraLoss::kFallbackImage: return false;
      case CameraLoss::kLastFrame:
        // The texture keeps its last frame; before the first one there is none to keep.
        return !texture_->showingFallback();
      case CameraLoss::kColour:
        if (!showingLoss_) {
          texture_->setFallbackColor(static_cast<float>(lossColour_[0]) / 255.0f,
                                     static_cast<float>(lossColour_[1]) / 255.0f,
                                     static_cast<float>(lossColour_[2]) / 255.0f);
          texture_->showFallback();
          texture_->publish(textures);
          showingLoss_ = true;
        }
        return true;
      case CameraLoss::kTestPattern:
        if (!showingLoss_) {
          // Drawn once per loss, at the size of the last frame shown (else 640x360), in RGBA.
          const render::Size size = texture_->showingFallback() || texture_->view().size.width == 0
                                        ? render::Size{640, 360}
                                        : texture_->view().size;
          if (!patternPool_ || patternPool_->config().width != size.width ||
              patternPool_->config().height != size.height) {
            patternPool_ = FramePool::create({PixelFormat::kRgba8, size.width, size.height, 1, 1, true});
          }
          FrameRef pattern = patternPool_->acquire();
          if (!pattern) return false;
          drawTestPattern(*pattern, TestPattern::kColourBars, 0, false);
          pattern->sequence = ++patternSequence_;
          if (auto r = texture_->update(pattern); !r) {
            log::warn(kLogStreams, "camera '{}': test pattern: {}", media_, r.error().describe());
            return false;
          }
          texture_->publish(textures);
          showingLoss_ = true;
        }
        return true;
    }
    return false;
  }

  [[nodiscard]] std::optional<SourceState> deviceState() const override { return state_; }

  [[nodiscard]] std::string describe() const override {
    if (!devices_) return fmt::format("camera '{}' has no device manager to find it in", name_);
    for (const devices::DeviceStatus& s : devices_->status()) {
      if (s.name != name_) continue;
      if (s.state == devices::DeviceState::kLive) {
        return fmt::format("camera {}: {}{}{}", devices::describeDevice(s.device),
                           s.mode ? devices::describeMode(*s.mode) : std::string("live"), describeMjpeg(),
                           texture_ && texture_->mirror() ? ", mirrored by the renderer" : "");
      }
      return fmt::format("camera '{}' ({}) is {}: {}; showing {}", name_, s.match, devices::deviceStateName(s.state),
                         s.lastError.empty() ? std::string("looking for it") : s.lastError, lossName());
    }
    return fmt::format("camera '{}' was not requested", name_);
  }

  /// Asks `devices` for the camera itself; whether it holds it now.
  bool requestOwn(devices::DeviceManager& devices) {
    auto source = ownSource_();
    if (!source) {
      log::error(kLogStreams, "camera '{}': {}", name_, source.error().describe());
      return false;
    }
    auto id = devices.request(std::move(source->request), std::move(source->provider), source->upkeep);
    if (!id) log::error(kLogStreams, "camera '{}': {}", name_, id.error().describe());
    return id.has_value();
  }

  /// For tests: the thread the camera's JPEGs are decoded on; none before the first.
  [[nodiscard]] std::optional<std::thread::id> mjpegDecodeThread() const {
    const std::shared_ptr<media::MjpegDecoder> decoder = mjpeg_->decoder();
    if (!decoder || decoder->decodeThread() == std::thread::id{}) return std::nullopt;
    return decoder->decodeThread();
  }

 private:
  /// ", JPEG decoded off the frame loop, 2 corrupt JPEGs dropped" for an MJPEG camera.
  [[nodiscard]] std::string describeMjpeg() const {
    if (const std::string failure = mjpeg_->failure(); !failure.empty()) {
      return fmt::format(", MJPEG that cannot be decoded ({}); showing {}", failure, lossName());
    }
    const std::shared_ptr<media::MjpegDecoder> decoder = mjpeg_->decoder();
    if (!decoder) return "";
    const std::uint64_t corrupt = decoder->corrupt();
    return fmt::format(
        ", JPEG decoded off the frame loop{}",
        corrupt == 0 ? std::string() : fmt::format(", {} corrupt JPEG{} dropped", corrupt, corrupt == 1 ? "" : "s"));
  }

  std::string media_;
  CameraLoss onLoss_;
  std::array<std::uint8_t, 3> lossColour_;
  bool showingLoss_ = false;  // the loss picture is on the texture
  SourceState state_ = SourceState::kWaiting;
  std::shared_ptr<FramePool> patternPool_;
  std::uint64_t patternSequence_ = 0;
  const Clock& clock_;
  std::shared_ptr<MjpegTap> mjpeg_;  // shared with the manager, which may hand it a frame after we go
  bool reportedMjpegFailure_ = false;
  std::string name_;  // the camera's device name
  std::function<Result<DeviceSource>()> ownSource_;
  devices::DeviceManager* devices_ = nullptr;  // borrowed: outlives the stream
  bool holds_ = false;                         // this stream holds the camera's request (the VCR's)
  bool usable_ = true;                         // false once its texture cannot be made
  std::shared_ptr<devices::ManagedVideoStream> stream_;
  std::unique_ptr<render::StreamTexture> texture_;
};

const DeviceSpec* cameraSpec(const Manifest& show, const std::string& device) {
  for (const DeviceSpec& d : show.devices) {
    if (d.name == device) return d.kind == DeviceKind::kCamera ? &d : nullptr;
  }
  return nullptr;
}

}  // namespace

Result<std::unique_ptr<TextureStream>> makeCameraStream(const MediaSpec& media, const Manifest& show,
                                                        const Clock& clock) {
  if (!cameraSpec(show, media.device)) {
    return fail(Errc::kNotFound, fmt::format("media '{}': no camera '{}' in [devices]", media.name, media.device));
  }
  return std::make_unique<CameraStream>(media, media.device, clock);
}

namespace {

/// The DeviceManager's request for a camera of the manifest: its size, format, mirror, and the
/// synthetic backend's scripted faults.
devices::DeviceRequest cameraRequest(const DeviceSpec& spec) {
  devices::DeviceRequest request;
  request.name = spec.name;
  request.kind = devices::DeviceKind::kVideoSource;
  request.match = deviceMatchFor(spec);
  if (spec.width && spec.height) request.options["size"] = fmt::format("{}x{}", *spec.width, *spec.height);
  if (spec.backend == DeviceBackend::kReplay || spec.backend == DeviceBackend::kSynthetic) {
    request.options["loop"] = spec.loop ? "true" : "false";
  }
  if (!spec.format.empty()) request.options["format"] = spec.format;
  request.controls.mirror = spec.mirror;
  if (spec.backend == DeviceBackend::kSynthetic && !spec.faults.empty()) {
    std::string faults;
    for (const SyntheticFault& f : spec.faults) {
      if (!faults.empty()) faults += ',';
      switch (f.kind) {
        case SyntheticFault::Kind::kUnplug: faults += fmt::format("unplug@{}", f.at.count()); break;
        case SyntheticFault::Kind::kSignalLost:
          faults += fmt::format("signal_lost@{}+{}", f.at.count(), f.duration.count());
          break;
        case SyntheticFault::Kind::kStall:
          faults += fmt::format("stall@{}+{}", f.at.count(), f.duration.count());
          break;
        case SyntheticFault::Kind::kCorrupt: faults += fmt::format("corrupt@{}", f.at.count()); break;
      }
    }
    request.options["faults"] = faults;
  }
  return request;
}

/// The DeviceManager's request for a dial box of the manifest.
Result<devices::DeviceRequest> dialBoxRequest(const DeviceSpec& spec) {
  devices::DeviceRequest request;
  request.name = spec.name;
  request.kind = devices::DeviceKind::kDialBox;
  request.match = deviceMatchFor(spec);
  request.options["loop"] = spec.loop ? "true" : "false";
  std::error_code ec;
  if (spec.backend == DeviceBackend::kReplay && std::filesystem::is_regular_file(spec.trace, ec) &&
      !sim::isMidiFilePath(spec.trace)) {
    // A hid-recorder file of several nodes (a tablet's pad and pen, a keydial's two interfaces):
    // the box plays the busiest one (its path in the replay is FILE#N).
    auto recording = sim::readHidRecording(spec.trace);
    if (!recording) return std::unexpected(recording.error());
    if (recording->devices.size() > 1) {
      const auto busiest = std::ranges::max_element(recording->devices, {},
                                                    [](const sim::HidRecordedDevice& d) { return d.reports.size(); });
      request.match.path = fmt::format("{}#{}", spec.trace.string(), busiest->index);
    }
  }
  // The SGI box answers its reset within milliseconds; a retry with nothing on the port must not
  // hold the device thread for the backend's default second.
  if (spec.backend == DeviceBackend::kSerial) request.options["reset_timeout_ms"] = "200";
  // A MIDI controller's profile and overrides, checked when the manifest was read.
  for (const auto& [key, value] : spec.midi) request.options[key] = value;
  return request;
}

}  // namespace

Result<DeviceSource> makeDeviceSource(const DeviceSpec& spec) {
  auto provider = providerFor(spec);
  if (!provider) return std::unexpected(provider.error());
  DeviceSource source;
  source.provider = std::move(*provider);
  if (spec.kind == DeviceKind::kCamera) {
    source.request = cameraRequest(spec);
  } else if (spec.kind == DeviceKind::kTracker) {
    source.request.name = spec.name;
    source.request.kind = devices::DeviceKind::kTracker;
    source.request.match = deviceMatchFor(spec);
    source.request.options["loop"] = spec.loop ? "true" : "false";
  } else {
    auto request = dialBoxRequest(spec);
    if (!request) return std::unexpected(request.error());
    source.request = std::move(*request);
  }
  return source;
}

devices::DeviceMatch deviceMatchFor(const DeviceSpec& spec) {
  devices::DeviceMatch m;
  m.backend = std::string(deviceBackendName(spec.backend));
  m.vendor = spec.match.vendor;
  m.product = spec.match.product;
  m.name = spec.match.name;
  m.serial = spec.match.serial;
  // A replayed device's path is its recording's; the manifest's path names the real device.
  if (spec.backend != DeviceBackend::kReplay) m.path = spec.match.path;
  return m;
}

Result<std::unique_ptr<devices::DeviceProvider>> providerFor(const DeviceSpec& spec) {
  switch (spec.backend) {
    case DeviceBackend::kHid: return std::make_unique<devices::HidProvider>();
    case DeviceBackend::kMidi: return std::make_unique<devices::MidiProvider>();
    case DeviceBackend::kOsc:
      return fail(
          Errc::kUnavailable,
          fmt::format("the tracker '{}' is fed by the run's OSC input (OscTrackerFeeds), not opened alone", spec.name));
    case DeviceBackend::kV4l2: return std::make_unique<devices::V4l2Provider>();
    case DeviceBackend::kLibcamera: return std::make_unique<devices::LibcameraProvider>();
    case DeviceBackend::kSynthetic: return std::make_unique<sim::SyntheticProvider>();
    // The SGI box on the manifest's port (and any USB serial adapter; the match picks the port).
    case DeviceBackend::kSerial: return std::make_unique<devices::SerialProvider>(std::vector{spec.match.path});
    case DeviceBackend::kReplay: {
      auto replay = std::make_unique<sim::ReplayProvider>(matroskaTraceReaderFactory());
      std::error_code ec;
      auto added = std::filesystem::is_directory(spec.trace, ec) ? replay->addTrace(spec.trace)
                                                                 : replay->addHidRecording(spec.trace);
      if (!added) return std::unexpected(added.error());
      return replay;
    }
  }
  return fail(Errc::kUnsupported, fmt::format("no {} backend", deviceBackendName(spec.backend)));
}

void setScriptVcrOptions(ScriptPlayerOptions& options, const Manifest& show, const Clock& clock,
                         devices::DeviceManager& devices) {
  options.manualClock = clock.isManual();
  for (const DeviceSpec& d : show.devices) {
    if (d.kind != DeviceKind::kCamera) continue;
    MediaSpec media;
    media.name = "the script's camera";
    media.kind = MediaKind::kCamera;
    media.device = d.name;
    options.camera = [media, spec = d, &clock, &devices]() -> Result<std::unique_ptr<TextureStream>> {
      auto stream = std::make_unique<CameraStream>(media, spec.name, clock, [spec] { return makeDeviceSource(spec); });
      stream->useDevices(devices);
      return stream;
    };
    return;
  }
  options.camera = nullptr;
}

std::optional<std::thread::id> mjpegDecodeThread(const TextureStream& stream) {
  const auto* camera = dynamic_cast<const CameraStream*>(&stream);
  return camera ? camera->mjpegDecodeThread() : std::nullopt;
}

}  // namespace basalt::kiosk
