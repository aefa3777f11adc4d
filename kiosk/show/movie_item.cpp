// Movies as show items: a media::MoviePlayer decoding on its own thread, its frames converted
// on the GPU by a render::StreamTexture, drawn full screen by a render::PictureOverlay after the
// (empty, black) show is drawn. Under a ManualClock each frame waits for the frame due, so that
// offline runs and tests are exact; on the system clock the frame loop never waits.

#include "kiosk/show/movie_item.h"

#include "kiosk/show/file_watch.h"

#include <algorithm>
#include <chrono>
#include <optional>

#include <fmt/format.h>
#include <fmt/std.h>

#include "media/frame_picker.h"
#include "media/movie_player.h"
#include "runtime/log.h"

namespace basalt::kiosk {

BASALT_LOG_CATEGORY(MovieItems, "items");

namespace {

/// How long the loader waits for a movie's first frame before calling it unplayable.
constexpr std::chrono::seconds kLoadTimeout{10};

/// The error, located at the manifest line that names the movie (the file it concerns, if any,
/// kept in the message).
Error atEntry(const Error& e, const std::string& where) {
  if (e.where().empty()) return e.at(where);
  return {e.code(), fmt::format("{}: {}", e.where(), e.message()), where};
}

/// How long a movie file that is being written must be quiet before it is looked at (a copy in
/// place sends IN_MODIFY for every write; IN_CLOSE_WRITE ends the wait at once).
constexpr Nanos kWriteQuiet = std::chrono::seconds(1);

/// A movie played full screen as a playlist item. Its file may change while the show runs
/// (docs/decisions/0062-content-changed-under-a-running-show.md): the file's folder is watched,
/// and a file replaced or written over while the item plays switches to the new content at once
/// (one info line), a file deleted or emptied ends the item with one error naming the file and
/// what happened (the list moves on, as for any item that fails), and a changed file is loaded
/// afresh at the item's next start.
class MovieItem final : public ItemPlayer {
 public:
  MovieItem(EntrySpec entry, std::string where, std::unique_ptr<media::MoviePlayer> player,
            std::optional<FileIdentity> loaded)
      : entry_(std::move(entry)), where_(std::move(where)), player_(std::move(player)), loaded_(loaded) {
    auto watch = FileWatch::open(entry_.path);
    if (watch) {
      watch_ = std::move(*watch);
    } else {
      log::warn(kLogMovieItems,
                "{}: movie {}: {}; a change to the file is seen at the item's next start instead of at once", where_,
                entry_.text, watch.error().describe());
    }
  }

  void setPlayback(const Playback& playback) override { playback_ = playback; }

  Result<void> start(runtime::Show& show, Nanos position, double /*fps*/) override {
    show = runtime::Show();  // black around the picture
    if (!texture_) {
      auto texture = render::StreamTexture::create(fmt::format("movie item {}", entry_.text));
      if (!texture) return std::unexpected(atEntry(texture.error(), where_));
      texture_ = std::move(*texture);
      texture_->setFallbackColor(0, 0, 0);
      auto overlay = render::PictureOverlay::create();
      if (!overlay) return std::unexpected(atEntry(overlay.error(), where_));
      overlay_ = std::move(*overlay);
    }
    if (watch_) (void)watch_->take();  // what changed before this start is looked at now
    writingSince_.reset();
    if (const std::optional<FileIdentity> now = identify(entry_.path); now != loaded_) {
      // Changed since it was loaded: play what is there now (or say what became of it).
      const std::string what = describeChange(loaded_, now);
      loaded_ = now;
      player_->unload();
      if (!now || now->size == 0) return std::unexpected(changed(what));
      log::info(kLogMovieItems, "{}: movie {} {}; loading the new content", where_, entry_.text, what);
    }
    if (player_->state() == media::MovieState::kEmpty) {
      // Unloaded after a failure or a change: load the file again.
      if (auto r = player_->load(entry_.path); !r) return std::unexpected(atEntry(r.error(), where_));
    }
    if (player_->state() == media::MovieState::kFailed) return std::unexpected(failure());
    player_->setRepeat(playback_.loop);
    if (playback_.timelineStart && placeOnTimeline(position)) {
      // Nothing from an earlier turn, and never the clip's first frame: the screen stays black
      // until the frame due on the group's timeline is there.
      texture_->showFallback();
    } else {
      const Nanos duration = player_->info().duration;
      if (duration > Nanos{0} && position >= duration) position = playback_.loop ? position % duration : Nanos{0};
      if (started_ || position > Nanos{0}) player_->seekTime(position);
    }
    player_->play();
    started_ = true;
    ended_ = false;
    endsAt_.reset();
    return {};
  }

  Result<void> beforeDraw(const FrameContext& frame, runtime::Show& /*show*/) override {
    leaderResult_ = LeaderFrameResult::kNone;
    if (auto r = lookAtFile(frame.time); !r) return r;
    if (endsAt_) {
      // The last frame stays up for its own duration, then the item ends.
      if (frame.time >= *endsAt_) ended_ = true;
      return {};
    }
    // Offline runs wait for the frame due; so does a frame-locked node on the system clock,
    // bounded, so that it draws the frame the others draw.
    const bool locked = playback_.timelineStart.has_value();
    media::PickedFrame pick = media::pickFrame(*player_, {.showTime = frame.time,
                                                          .leaderFrame = locked ? leaderFrame_ : -1,
                                                          .manualClock = playback_.manualClock,
                                                          .patience = playback_.patience,
                                                          .onGroupTimeline = locked});
    FrameRef f = std::move(pick.frame);
    leaderResult_ = pick.outcome;
    const media::MovieState state = player_->state();
    if (state == media::MovieState::kFailed || state == media::MovieState::kEmpty) return std::unexpected(failure());
    if (const Nanos early = player_->endedEarlyAt(); early >= Nanos{0}) {
      // The file lost its end: what was left has played; it cannot loop or seek reliably.
      const Nanos duration = player_->info().duration;
      player_->unload();
      return std::unexpected(
          changed(fmt::format("is cut short (its picture ends at {:.1f} s of the {:.1f} s its "
                              "container gives)",
                              toSeconds(early), toSeconds(duration))));
    }
    auto changed = texture_->update(f);
    if (!changed) {
      player_->unload();
      return std::unexpected(atEntry(changed.error(), where_));
    }
    if (!playback_.loop && player_->atEnd()) {
      const Nanos frameDuration = player_->info().frameDuration;
      endsAt_ = frame.time + std::max(frameDuration, Nanos{1});
    }
    return {};
  }

  Result<void> afterDraw(const FrameContext& /*frame*/, render::Output& output) override {
    if (!texture_ || texture_->showingFallback()) return {};  // no frame yet: black, never a grey flash
    const render::TextureView& view = texture_->view();
    const double aspect = player_->info().pixelAspect > 0 ? player_->info().pixelAspect : 1.0;
    const render::Size size = output.size();
    overlay_->draw(view, letterbox(view.size.width * aspect, view.size.height, size), size);
    return {};
  }

  [[nodiscard]] bool ended() const override { return ended_; }

  [[nodiscard]] std::int64_t shownFrame() const override {
    return texture_ && !texture_->showingFallback() ? player_->currentFrame() : -1;
  }

  void setLeaderFrame(std::int64_t frame) override { leaderFrame_ = frame; }
  [[nodiscard]] LeaderFrameResult leaderFrameResult() const override { return leaderResult_; }

 private:
  /// Frame-locked: seeks to the frame due `position` after the item's start on the group's
  /// timeline, due at the show time it belongs to (not when the seek lands), so that every
  /// later frame and loop falls where it falls on the other nodes. A loop's pass is the
  /// player's own once it has looped, else the clip's frames x their duration. False when the
  /// clip's frame rate is unknown (then it plays from its own start).
  bool placeOnTimeline(Nanos position) {
    const Nanos frame = player_->info().frameDuration;
    if (frame <= Nanos{0}) return false;
    const Nanos elapsed = std::max(Nanos{0}, position);
    const std::int64_t count = player_->frameCount();
    Nanos passStart{0};
    if (playback_.loop) {
      const Nanos pass = player_->passDuration() > Nanos{0} ? player_->passDuration()
                         : count > 0                        ? frame * count
                                                            : Nanos{0};
      if (pass > Nanos{0}) passStart = (elapsed / pass) * pass;
    }
    // As for a movie stream (kiosk/show/stream_factories.cpp): timestamps sit up to half a
    // millisecond off the frame grid, so take the frame before when in doubt; the next update
    // takes the next one if it is due.
    std::int64_t index = std::max<std::int64_t>(0, (elapsed - passStart + std::chrono::microseconds(1000)) / frame);
    if (count > 0) index = std::min(index, count - 1);
    const Nanos timeline = passStart + frame * index;
    player_->seekFrameDueAt(index, *playback_.timelineStart + timeline, timeline);
    log::debug(kLogMovieItems, "{}: movie {} joins the group's timeline {:.3f} s into the item: frame {}", where_,
               entry_.text, toSeconds(position), index);
    return true;
  }

  /// Acts on a change to the file while the item plays: at once when it settled (closed after
  /// writing, moved, created, deleted), after kWriteQuiet when it is being written. One
  /// non-blocking read a frame; a stat only when the folder says something happened.
  Result<void> lookAtFile(Nanos now) {
    if (!watch_) return {};
    bool look = false;
    switch (watch_->take()) {
      case FileChange::kNone: break;
      case FileChange::kWriting: writingSince_ = now; break;
      case FileChange::kSettled: look = true; break;
      case FileChange::kWatchLost:
        look = true;
        if (auto again = FileWatch::open(entry_.path)) {
          watch_ = std::move(*again);
        } else {
          watch_.reset();  // looked at at the next start instead
        }
        break;
    }
    if (writingSince_ && now - *writingSince_ >= kWriteQuiet) look = true;
    if (!look) return {};
    writingSince_.reset();
    const std::optional<FileIdentity> identity = identify(entry_.path);
    if (identity == loaded_) return {};
    const std::string what = describeChange(loaded_, identity);
    loaded_ = identity;
    if (!identity || identity->size == 0) {
      player_->unload();  // what plays is no longer the file the manifest names
      return std::unexpected(changed(what));
    }
    // Replaced or written over: the new content from its first frame, at once (the old clip's
    // last frame stays up until the new one's first).
    if (auto r = player_->load(entry_.path); !r) return std::unexpected(atEntry(r.error(), where_));
    player_->setRepeat(playback_.loop);
    player_->play();
    ended_ = false;
    endsAt_.reset();
    log::info(kLogMovieItems, "{}: movie {} {}; playing the new content", where_, entry_.text, what);
    return {};
  }

  /// The item cannot go on because its file went away, was emptied or lost its end.
  [[nodiscard]] Error changed(const std::string& what) const {
    return atEntry(Error(Errc::kNotFound, fmt::format("its file {}", what), entry_.path.string()), where_);
  }

  [[nodiscard]] Error failure() const {
    const auto error = player_->error();
    return atEntry(error ? *error : Error(Errc::kIo, "the movie stopped", entry_.path.string()), where_);
  }

  EntrySpec entry_;
  std::string where_;
  std::unique_ptr<media::MoviePlayer> player_;
  std::unique_ptr<render::StreamTexture> texture_;  // made at the first start (needs the GL context)
  std::unique_ptr<render::PictureOverlay> overlay_;
  Playback playback_;
  bool started_ = false;
  bool ended_ = false;
  std::optional<Nanos> endsAt_;    // show time the shown last frame ends at (not looping)
  std::int64_t leaderFrame_ = -1;  // frame-locked follower: the leader's movie frame in the coming frame
  LeaderFrameResult leaderResult_ = LeaderFrameResult::kNone;
  std::optional<FileIdentity> loaded_;  // the file as it was last loaded (none: it was not there)
  std::optional<FileWatch> watch_;      // its folder; none where inotify cannot watch it
  std::optional<Nanos> writingSince_;   // the file is being written: look once it is quiet
};

}  // namespace

render::PictureRect letterbox(double pictureWidth, double pictureHeight, render::Size output) {
  if (!(pictureWidth > 0) || !(pictureHeight > 0) || output.width == 0 || output.height == 0) return {};
  const double scale = std::min(output.width / pictureWidth, output.height / pictureHeight);
  const double w = pictureWidth * scale;
  const double h = pictureHeight * scale;
  return {static_cast<float>((output.width - w) / 2), static_cast<float>((output.height - h) / 2),
          static_cast<float>(w), static_cast<float>(h)};
}

Result<std::unique_ptr<ItemPlayer>> makeMovieItem(const EntrySpec& entry, const Manifest& show) {
  const std::string where = fmt::format("{}:{}", show.file.string(), entry.line);
  media::MoviePlayerOptions options;
  options.name = fmt::format("movie item {}", entry.text);
  auto player = media::MoviePlayer::create(options);
  if (!player) return std::unexpected(atEntry(player.error(), where));
  const std::optional<FileIdentity> loaded = identify(entry.path);
  if (auto r = (*player)->load(entry.path); !r) return std::unexpected(atEntry(r.error(), where));
  auto info = (*player)->waitUntilLoaded(kLoadTimeout);
  if (!info) return std::unexpected(atEntry(info.error(), where));
  log::info(kLogMovieItems, "{}: movie {}: {}x{} at {:.3g} fps, {}", where, entry.text, info->width, info->height,
            info->fps, info->codec.empty() ? std::string("codec unknown") : info->codec);
  return std::make_unique<MovieItem>(entry, where, std::move(*player), loaded);
}

}  // namespace basalt::kiosk
