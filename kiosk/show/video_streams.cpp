#include "kiosk/show/video_streams.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <utility>

#include <fmt/format.h>
#include <fmt/std.h>

#include "media/frame_picker.h"
#include "runtime/log.h"
#include "runtime/script/command_table.h"
#include "runtime/script/lexer.h"

namespace basalt::kiosk {

BASALT_LOG_CATEGORY(Kiosk, "kiosk");

Result<std::pair<std::string, std::filesystem::path>> parseMovieOption(std::string_view text) {
  const auto eq = text.find('=');
  if (eq == std::string_view::npos || eq == 0 || eq + 1 == text.size()) {
    return fail(Errc::kInvalidArgument,
                fmt::format("--movie needs PART=FILE (the part that shows the movie, and the movie), not '{}'", text));
  }
  return std::pair{std::string(text.substr(0, eq)), std::filesystem::path(text.substr(eq + 1))};
}

Result<std::pair<std::string, ZoomSpec>> parseZoomOption(std::string_view text) {
  ZoomSpec zoom;
  const auto bad = [&] {
    return fail(Errc::kInvalidArgument,
                fmt::format("--zoom needs PART[=SCALE][@X,Y] (e.g. movie=0.5@10,10), not '{}'", text));
  };
  std::string_view rest = text;
  std::string_view at;
  if (const auto a = rest.find('@'); a != std::string_view::npos) {
    at = rest.substr(a + 1);
    rest = rest.substr(0, a);
  }
  std::string name(rest);
  if (const auto eq = rest.find('='); eq != std::string_view::npos) {
    name = std::string(rest.substr(0, eq));
    const std::string_view s = rest.substr(eq + 1);
    const auto r = std::from_chars(s.data(), s.data() + s.size(), zoom.scale);
    if (r.ec != std::errc{} || r.ptr != s.data() + s.size() || !(zoom.scale > 0 && zoom.scale <= 16)) return bad();
  }
  if (!at.empty()) {
    const auto comma = at.find(',');
    if (comma == std::string_view::npos) return bad();
    const std::string_view xs = at.substr(0, comma), ys = at.substr(comma + 1);
    const auto rx = std::from_chars(xs.data(), xs.data() + xs.size(), zoom.x);
    const auto ry = std::from_chars(ys.data(), ys.data() + ys.size(), zoom.y);
    if (rx.ec != std::errc{} || ry.ec != std::errc{} || rx.ptr != xs.data() + xs.size() ||
        ry.ptr != ys.data() + ys.size() || !std::isfinite(zoom.x) || !std::isfinite(zoom.y)) {
      return bad();
    }
  }
  if (name.empty()) return bad();
  return std::pair{name, zoom};
}

namespace {

/// " (its parts: 'face 1', ..., 'face 6'; did you mean 'face 1'?)": what a mistyped part name
/// could have been. Bounded: the first parts only are listed and compared.
std::string partsHint(const runtime::Show& show, std::string_view name) {
  constexpr std::size_t kListed = 8;
  constexpr std::size_t kCompared = 256;
  constexpr std::size_t kLongest = 64;
  if (show.partCount() == 0) return " (the show has no parts yet)";
  std::vector<std::string_view> parts;
  std::string listed;
  for (std::size_t i = 0; i < std::min(show.partCount(), kCompared); ++i) {
    const std::string_view part = show.part(static_cast<runtime::PartId>(i)).name;
    if (i < kListed) listed += fmt::format("{}'{}'", i ? ", " : "", part);
    if (part.size() <= kLongest) parts.push_back(part);
  }
  if (show.partCount() > kListed) listed += fmt::format(" and {} more", show.partCount() - kListed);
  std::string hint = fmt::format(" (its parts: {}", listed);
  // Part names are case-sensitive: one that differs only in case is the likeliest meaning.
  auto same =
      std::find_if(parts.begin(), parts.end(), [&](std::string_view p) { return script::equalsIgnoreCase(p, name); });
  std::optional<std::string_view> guess = same != parts.end() ? std::optional(*same) : std::nullopt;
  if (!guess && name.size() <= kLongest) guess = script::closestMatch(name, parts);
  if (guess) hint += fmt::format("; did you mean '{}'?", *guess);
  return hint + ")";
}

}  // namespace

struct VideoStreams::Stream {
  MovieStreamSpec spec;
  std::unique_ptr<media::MoviePlayer> player;
  std::unique_ptr<render::StreamTexture> texture;
  media::MovieState lastState = media::MovieState::kEmpty;
  render::PictureRect zoomRect{};
  bool zoomPlaced = false;
  std::int64_t leaderFrame = -1;  // frame-locked follower: the leader's frame in the coming frame
  bool shows = false;             // a frame of the movie is on the texture (not the fallback)
};

namespace {
/// The slot of LockedMovieFrames::textures that stream `index` uses, or -1 beyond them.
int lockedSlot(std::size_t index, std::size_t slots) {
  return index < slots ? static_cast<int>(slots - 1 - index) : -1;
}
}  // namespace

VideoStreams::VideoStreams(render::Renderer& renderer, bool manualClock)
    : renderer_(renderer), manualClock_(manualClock) {}

VideoStreams::~VideoStreams() {
  for (const auto& s : streams_) renderer_.textures().remove(s->spec.name);
}

Result<std::unique_ptr<VideoStreams>> VideoStreams::create(const std::vector<MovieStreamSpec>& specs,
                                                           runtime::Show& show, render::Renderer& renderer,
                                                           bool manualClock) {
  std::unique_ptr<VideoStreams> v(new VideoStreams(renderer, manualClock));
  v->show_ = &show;
  for (const MovieStreamSpec& spec : specs) {
    auto stream = std::make_unique<Stream>();
    stream->spec = spec;
    media::MoviePlayerOptions options;
    options.name = fmt::format("movie '{}'", spec.name);
    options.audio = spec.audio;
    auto player = media::MoviePlayer::create(options);
    if (!player) return std::unexpected(player.error());
    stream->player = std::move(*player);
    auto texture = render::StreamTexture::create(spec.name);
    if (!texture) return std::unexpected(texture.error());
    stream->texture = std::move(*texture);
    stream->texture->publish(renderer.textures());
    if (auto r = stream->player->loadPlaylist(spec.files); !r) {
      // A missing file: say so and show the fallback; the show goes on.
      log::error(kLogKiosk, "{}: {}; showing the fallback texture", options.name, r.error().describe());
    } else {
      stream->player->setRepeat(spec.repeat);
      stream->player->play();
    }
    if (auto part = show.findPart(spec.name)) {
      show.setPartTexture(*part, spec.name);
      show.texture().source = runtime::TextureSource::kVideo;  // LAVA's texture.switch = video
    } else if (!spec.zoom) {
      log::warn(kLogKiosk,
                "movie '{}': the show has no part of that name{}; the movie is a texture named '{}' for later use",
                spec.name, partsHint(show, spec.name), spec.name);
    } else {
      // Only the Zoom picture shows it: drawn from the decoder's planes in one pass.
      stream->texture->setPictureOnly(true);
    }
    v->streams_.push_back(std::move(stream));
  }
  if (std::any_of(specs.begin(), specs.end(), [](const MovieStreamSpec& s) { return s.zoom.has_value(); })) {
    auto overlay = render::PictureOverlay::create();
    if (!overlay) return std::unexpected(overlay.error());
    v->overlay_ = std::move(*overlay);
  }
  return v;
}

namespace {
/// Whether a part of `show` shows the texture `name` (allocates nothing).
bool usedOnAPart(const runtime::Show& show, std::string_view name) {
  for (std::size_t i = 0; i < show.partCount(); ++i) {
    const runtime::PartState& p = show.part(static_cast<runtime::PartId>(i));
    if (p.texture == name || p.reflectionTexture == name) return true;
  }
  return false;
}
}  // namespace

Result<void> VideoStreams::beforeDraw(const FrameContext& frame) {
  if (zoomDials_) {
    // The frame loop applied this frame's input just before: the dials' turns since last frame.
    const runtime::Bindings::ZoomMove move = zoomDials_->takeZoomMove();
    if (move.dx != 0 || move.dy != 0) {
      for (const auto& s : streams_) moveZoom(s->spec.name, move.dx, move.dy);
    }
  }
  for (const auto& s : streams_) {
    media::MoviePlayer& player = *s->player;
    // The leader's frame by its number when a follower is given one (used up: the next frame
    // brings its own); otherwise the stream's own timeline, which waits only offline.
    const std::int64_t leader = std::exchange(s->leaderFrame, -1);
    media::PickedFrame pick = media::pickFrame(player, {.showTime = frame.time,
                                                        .leaderFrame = follower_ ? leader : -1,
                                                        .manualClock = manualClock_,
                                                        .patience = patience_});
    if (pick.outcome == media::FrameOutcome::kCorrected) ++movieCounts_.corrected;
    if (pick.outcome == media::FrameOutcome::kLate) ++movieCounts_.late;
    FrameRef f = std::move(pick.frame);
    const media::MovieState state = player.state();
    if (state != s->lastState) {
      s->lastState = state;
      if (state == media::MovieState::kFailed || state == media::MovieState::kEmpty) s->texture->showFallback();
    }
    s->shows = false;
    if (state == media::MovieState::kFailed) continue;
    // A part that takes up a picture-only stream's texture (a script's texture command) gets it
    // converted from then on.
    if (s->texture->pictureOnly() && usedOnAPart(*show_, s->spec.name)) s->texture->setPictureOnly(false);
    auto changed = s->texture->update(f);
    if (!changed) {
      log::error(kLogKiosk, "{}; showing the fallback texture", changed.error().describe());
      s->texture->showFallback();
      player.unload();
      s->lastState = media::MovieState::kEmpty;
    }
    s->texture->publish(renderer_.textures());
    s->shows = changed && !s->texture->showingFallback();
    // Which movie frame each stream shows in which frame (BASALT_LOG=kiosk=debug): frame-locked
    // nodes are compared with it.
    if (const std::int64_t shown = player.currentFrame(); s->shows && shown >= 0 && !s->spec.files.empty()) {
      log::debug(kLogKiosk, "frame {}: texture '{}' shows movie '{}' frame {}", frame.frame, s->spec.name,
                 s->spec.files[std::min(player.currentClip(), s->spec.files.size() - 1)].filename().string(), shown);
    }
  }
  return {};
}

void VideoStreams::lockedMovieFrames(LockedMovieFrames& frames) const {
  for (std::size_t i = 0; i < streams_.size(); ++i) {
    const int slot = lockedSlot(i, frames.textures.size());
    if (slot < 0) break;
    const Stream& s = *streams_[i];
    // A playlist's frames are numbered in their clip: it keeps to its own timeline (-1).
    const std::int64_t shown = s.shows && s.spec.files.size() == 1 ? s.player->currentFrame() : -1;
    frames.textures[static_cast<std::size_t>(slot)] =
        shown >= 0 && shown <= std::numeric_limits<std::int32_t>::max() ? static_cast<std::int32_t>(shown) : -1;
  }
}

void VideoStreams::followMovieFrames(const LockedMovieFrames& frames) {
  for (std::size_t i = 0; i < streams_.size(); ++i) {
    const int slot = lockedSlot(i, frames.textures.size());
    if (slot < 0) break;
    streams_[i]->leaderFrame = frames.textures[static_cast<std::size_t>(slot)];
  }
}

void VideoStreams::followLeader(std::chrono::milliseconds patience) {
  follower_ = true;
  patience_ = patience;
}

Result<void> VideoStreams::afterDraw(const FrameContext&, render::Output& output) {
  if (!overlay_) return {};
  for (const auto& s : streams_) {
    if (!s->spec.zoom) continue;
    const render::TextureView& view = s->texture->view();
    if (!s->zoomPlaced) {
      s->zoomRect = {s->spec.zoom->x, s->spec.zoom->y, 0, 0};
      s->zoomPlaced = true;
    }
    const double aspect = s->player->info().pixelAspect;
    s->zoomRect.width = static_cast<float>(view.size.width * s->spec.zoom->scale * (aspect > 0 ? aspect : 1.0));
    s->zoomRect.height = static_cast<float>(view.size.height * s->spec.zoom->scale);
    s->texture->drawPicture(*overlay_, s->zoomRect, output.size());
  }
  return {};
}

media::MoviePlayer* VideoStreams::player(std::string_view name) {
  for (const auto& s : streams_) {
    if (s->spec.name == name) return s->player.get();
  }
  return nullptr;
}

void VideoStreams::moveZoom(std::string_view name, float dx, float dy) {
  for (const auto& s : streams_) {
    if (s->spec.name != name || !s->spec.zoom) continue;
    if (!s->zoomPlaced) {
      s->zoomRect = {s->spec.zoom->x, s->spec.zoom->y, 0, 0};
      s->zoomPlaced = true;
    }
    s->zoomRect.x += dx;
    s->zoomRect.y += dy;
  }
}

std::optional<render::PictureRect> VideoStreams::zoomRect(std::string_view name) const {
  for (const auto& s : streams_) {
    if (s->spec.name != name || !s->spec.zoom) continue;
    if (s->zoomPlaced) return s->zoomRect;
    return render::PictureRect{s->spec.zoom->x, s->spec.zoom->y, 0, 0};
  }
  return std::nullopt;
}

std::vector<std::string> VideoStreams::status() const {
  std::vector<std::string> lines;
  for (const auto& s : streams_) {
    const media::MovieInfo info = s->player->info();
    const char* state = "empty";
    switch (s->player->state()) {
      case media::MovieState::kLoading: state = "loading"; break;
      case media::MovieState::kReady: state = "playing"; break;
      case media::MovieState::kFailed: state = "failed"; break;
      case media::MovieState::kEmpty: break;
    }
    const media::MoviePlayerStats st = s->player->stats();
    lines.push_back(fmt::format(
        "movie '{}': {} ({}), frame {} of {}, {} shown, {} loops{}; {}", s->spec.name, info.path.filename(), state,
        s->player->currentFrame(), info.frameCount, st.shown, st.loops,
        st.stalls > 0 ? fmt::format(", restarted {} times after a stall", st.stalls) : "", s->texture->describe()));
  }
  return lines;
}

Result<std::unique_ptr<ScreenRecorder>> ScreenRecorder::create(const media::RecorderOptions& options) {
  auto recorder = media::Recorder::create(options);
  if (!recorder) return std::unexpected(recorder.error());
  return std::unique_ptr<ScreenRecorder>(new ScreenRecorder(std::move(*recorder), options));
}

Result<void> ScreenRecorder::afterDraw(const FrameContext&, render::Output& output) {
  if (!recorder_ || failure_ || recorder_->full()) return {};
  if (auto r = output.readBack(frame_); !r) return r;
  if (auto r = recorder_->push(frame_); !r) {
    // A full disk ends the recording, not the show.
    failure_ = r.error();
    log::error(kLogKiosk, "{}; the show goes on without recording", r.error().describe());
  }
  return {};
}

Result<void> ScreenRecorder::finish() {
  if (!recorder_) return {};
  auto r = recorder_->finish();
  if (failure_) return std::unexpected(*failure_);
  return r;
}

}  // namespace basalt::kiosk
