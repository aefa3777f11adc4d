#include "kiosk/stream_factories.h"

#include "kiosk/movie_item.h"
#include "kiosk/script_player.h"

#include <atomic>
#include <mutex>

#include <fmt/format.h>
#include <fmt/std.h>

#include "devices/hid/hid_backend.h"
#include "devices/libcamera/libcamera_camera.h"
#include "devices/v4l2/v4l2_camera.h"
#include "media/movie_player.h"
#include "render/stream_texture.h"
#include "runtime/log.h"
#include "sim/providers.h"

namespace basalt::kiosk {

BASALT_LOG_CATEGORY(Streams, "kiosk");

namespace {

// ---------------------------------------------------------------------------------------------
// Dial boxes found by a rule

class MatchedDialBox final : public devices::DialBox {
 public:
  MatchedDialBox(std::unique_ptr<devices::DeviceProvider> provider, devices::DeviceRequest request, const Clock& clock)
      : DialBox(devices::DeviceInfo{request.name, std::string(provider->backend()), "", 0, 0, "", ""}, 0, 0),
        provider_(std::move(provider)),
        request_(std::move(request)),
        clock_(clock),
        inner_(1024) {}

  ~MatchedDialBox() override { close(); }
  MatchedDialBox(const MatchedDialBox&) = delete;
  MatchedDialBox& operator=(const MatchedDialBox&) = delete;

 private:
  Result<void> doOpen() override {
    std::string problems;
    for (const devices::DeviceCandidate& c : provider_->enumerate()) {
      if (c.kind != devices::DeviceKind::kDialBox || !request_.match.matches(c.info)) continue;
      if (!c.problem.empty()) {
        problems += fmt::format("; {}: {}", devices::describeDevice(c.info), c.problem);
        continue;
      }
      auto box = provider_->openDialBox(c, request_, clock_);
      if (!box) {
        problems += fmt::format("; {}", box.error().describe());
        continue;
      }
      Event stale;
      while (inner_.pop(stale)) {
      }
      if (auto r = (*box)->open(1, inner_); !r) {
        problems += fmt::format("; {}", r.error().describe());
        continue;
      }
      device_ = std::move(*box);
      setInfo(device_->info());
      setShape(device_->dialCount(), device_->buttonCount());
      return {};
    }
    if (problems.empty()) {
      return fail(Errc::kNotFound, fmt::format("no {} is plugged in", request_.match.describe()));
    }
    return fail(Errc::kUnavailable, fmt::format("{} found but not usable{}", request_.match.describe(), problems));
  }

  void doClose() override {
    if (device_) device_->close();
    device_.reset();
  }

  void doService(Nanos now) override {
    if (!device_) return;
    device_->service(now);
    Event e;
    while (inner_.pop(e)) {
      if (e.kind == EventKind::kDeviceState) continue;
      emit(e);
    }
    if (device_->state() != devices::DeviceState::kLive) {
      auto why = device_->lostReason();
      reportLost(why ? *why
                     : Error{Errc::kIo, fmt::format("{} stopped", devices::describeDevice(device_->info())), {}});
    }
  }

  Result<void> doSetLight(int index, double level, bool pulse) override {
    if (!device_) return fail(Errc::kUnavailable, "the dial box is not connected");
    return device_->setLight(index, level, pulse);
  }

  std::unique_ptr<devices::DeviceProvider> provider_;
  devices::DeviceRequest request_;
  const Clock& clock_;
  BoundedQueue<Event> inner_;  // the device's events, passed on in doService()
  std::unique_ptr<devices::DialBox> device_;
};

// ---------------------------------------------------------------------------------------------
// Movies

class MovieStream final : public TextureStream {
 public:
  MovieStream(MediaSpec media, std::unique_ptr<media::MoviePlayer> player, bool manualClock)
      : media_(std::move(media)), player_(std::move(player)), manualClock_(manualClock) {}

  bool update(Nanos showTime, render::TextureRegistry& textures, const std::string& name) override {
    if (!started_) {
      started_ = true;
      if (auto r = player_->load(media_.file); !r) {
        failure_ = r.error().message();
        log::error(kLogStreams, "movie '{}': {}; its textures show their fallback", media_.name, r.error().describe());
        return false;
      }
      player_->setRepeat(media_.loop);
      player_->play();
    }
    if (!failure_.empty()) return false;
    if (!texture_) {
      auto texture = render::StreamTexture::create(name);
      if (!texture) {
        failure_ = texture.error().message();
        log::error(kLogStreams, "movie '{}': {}", media_.name, texture.error().describe());
        return false;
      }
      texture_ = std::move(*texture);
    }
    // Offline (ManualClock) runs wait for the frame due, so that every frame is exact; a show
    // on the system clock never waits: the newest frame due is shown, or the last one stays.
    if (manualClock_) player_->waitForFrameDue(showTime, std::chrono::seconds(10));
    const FrameRef frame = player_->frameAt(showTime);
    const media::MovieState state = player_->state();
    if (state == media::MovieState::kFailed || state == media::MovieState::kEmpty) {
      if (!reportedFailure_) {
        reportedFailure_ = true;
        const auto error = player_->error();
        log::error(kLogStreams, "movie '{}' cannot play: {}; its textures show their fallback", media_.name,
                   error ? error->describe() : std::string("nothing is loaded"));
      }
      return false;
    }
    auto changed = texture_->update(frame);
    if (!changed) {
      failure_ = changed.error().message();
      log::error(kLogStreams, "movie '{}': {}; its textures show their fallback", media_.name,
                 changed.error().describe());
      player_->unload();
      return false;
    }
    if (texture_->showingFallback()) return false;  // no frame yet: never a frame early
    texture_->publish(textures);
    return true;
  }

  [[nodiscard]] std::string describe() const override {
    if (!failure_.empty()) return fmt::format("movie {}: {}", media_.file.filename(), failure_);
    const media::MovieInfo info = player_->info();
    return fmt::format("movie {}: frame {} of {}, {} loops", media_.file.filename(), player_->currentFrame(),
                       info.frameCount, player_->stats().loops);
  }

 private:
  MediaSpec media_;
  std::unique_ptr<media::MoviePlayer> player_;
  std::unique_ptr<render::StreamTexture> texture_;
  bool manualClock_;
  bool started_ = false;
  bool reportedFailure_ = false;
  std::string failure_;
};

Result<std::unique_ptr<TextureStream>> makeMovieStream(const MediaSpec& media, const Manifest& /*show*/,
                                                       const Clock& clock) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(media.file, ec)) {
    return fail(Errc::kNotFound, "the movie file is missing", media.file.string());
  }
  media::MoviePlayerOptions options;
  options.name = fmt::format("movie '{}'", media.name);
  options.audio = media.audio;
  auto player = media::MoviePlayer::create(options);
  if (!player) return std::unexpected(player.error());
  return std::make_unique<MovieStream>(media, std::move(*player), clock.isManual());
}

// ---------------------------------------------------------------------------------------------
// Cameras

class CameraStream final : public TextureStream {
 public:
  CameraStream(std::string media, std::unique_ptr<devices::DeviceProvider> provider, devices::DeviceRequest request,
               const Clock& clock)
      : media_(std::move(media)), clock_(clock), events_(256), manager_(clock, events_), name_(request.name) {
    manager_.addProvider(std::move(provider));
    requested_ = manager_.request(std::move(request)).has_value();
    stream_ = manager_.videoStream(name_);
  }
  ~CameraStream() override { manager_.stop(); }
  CameraStream(const CameraStream&) = delete;
  CameraStream& operator=(const CameraStream&) = delete;

  bool update(Nanos showTime, render::TextureRegistry& textures, const std::string& name) override {
    if (!started_) {
      started_ = true;
      // On the system clock the manager opens and reopens the camera on a thread of its own;
      // under a ManualClock it is stepped here, frame by frame, so that a run is repeatable.
      if (!clock_.isManual()) manager_.start();
    }
    if (clock_.isManual()) manager_.step(showTime);
    Event stale;
    while (events_.pop(stale)) {
    }
    if (!stream_ || !requested_) return false;
    if (!texture_) {
      auto texture = render::StreamTexture::create(name);
      if (!texture) {
        log::error(kLogStreams, "camera '{}': {}", media_, texture.error().describe());
        requested_ = false;
        return false;
      }
      texture_ = std::move(*texture);
    }
    const FrameRef frame = stream_->frameAt(showTime);
    if (stream_->health().state != SourceState::kLive) return false;
    auto changed = texture_->update(frame);
    if (!changed) {
      log::warn(kLogStreams, "camera '{}': {}", media_, changed.error().describe());
      return false;
    }
    if (texture_->showingFallback()) return false;
    texture_->publish(textures);
    return true;
  }

  [[nodiscard]] std::string describe() const override {
    for (const devices::DeviceStatus& s : manager_.status()) {
      if (s.name != name_) continue;
      if (s.state == devices::DeviceState::kLive) {
        return fmt::format("camera {}: {}", devices::describeDevice(s.device),
                           s.mode ? devices::describeMode(*s.mode) : std::string("live"));
      }
      return fmt::format("camera '{}' ({}) is {}: {}", name_, s.match, devices::deviceStateName(s.state),
                         s.lastError.empty() ? std::string("looking for it") : s.lastError);
    }
    return fmt::format("camera '{}' was not requested", name_);
  }

 private:
  std::string media_;
  const Clock& clock_;
  BoundedQueue<Event> events_;  // state events of the manager; the status comes from status()
  devices::DeviceManager manager_;
  std::string name_;
  bool requested_ = false;
  bool started_ = false;
  std::shared_ptr<devices::ManagedVideoStream> stream_;
  std::unique_ptr<render::StreamTexture> texture_;
};

Result<std::unique_ptr<TextureStream>> makeCameraStream(const MediaSpec& media, const Manifest& show,
                                                        const Clock& clock) {
  const DeviceSpec* spec = nullptr;
  for (const DeviceSpec& d : show.devices) {
    if (d.name == media.device) spec = &d;
  }
  if (!spec || spec->kind != DeviceKind::kCamera) {
    return fail(Errc::kNotFound, fmt::format("media '{}': no camera '{}' in [devices]", media.name, media.device));
  }
  auto provider = providerFor(*spec);
  if (!provider) return std::unexpected(provider.error());
  devices::DeviceRequest request;
  request.name = spec->name;
  request.kind = devices::DeviceKind::kVideoSource;
  request.match = deviceMatchFor(*spec);
  if (spec->width && spec->height) request.options["size"] = fmt::format("{}x{}", *spec->width, *spec->height);
  if (spec->backend == DeviceBackend::kReplay || spec->backend == DeviceBackend::kSynthetic) {
    request.options["loop"] = spec->loop ? "true" : "false";
  }
  return std::make_unique<CameraStream>(media.name, std::move(*provider), std::move(request), clock);
}

Result<std::unique_ptr<devices::DialBox>> makeDialBoxFromSpec(const DeviceSpec& spec, const Clock& clock) {
  auto provider = providerFor(spec);
  if (!provider) return std::unexpected(provider.error());
  devices::DeviceRequest request;
  request.name = spec.name;
  request.kind = devices::DeviceKind::kDialBox;
  request.match = deviceMatchFor(spec);
  request.options["loop"] = spec.loop ? "true" : "false";
  return makeMatchedDialBox(std::move(*provider), std::move(request), clock);
}

}  // namespace

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
    case DeviceBackend::kV4l2: return std::make_unique<devices::V4l2Provider>();
    case DeviceBackend::kLibcamera: return std::make_unique<devices::LibcameraProvider>();
    case DeviceBackend::kSynthetic: return std::make_unique<sim::SyntheticProvider>();
    case DeviceBackend::kReplay: {
      auto replay = std::make_unique<sim::ReplayProvider>();
      std::error_code ec;
      auto added = std::filesystem::is_directory(spec.trace, ec) ? replay->addTrace(spec.trace)
                                                                 : replay->addHidRecording(spec.trace);
      if (!added) return std::unexpected(added.error());
      return replay;
    }
  }
  return fail(Errc::kUnsupported, fmt::format("no {} backend", deviceBackendName(spec.backend)));
}

std::unique_ptr<devices::DialBox> makeMatchedDialBox(std::unique_ptr<devices::DeviceProvider> provider,
                                                     devices::DeviceRequest request, const Clock& clock) {
  return std::make_unique<MatchedDialBox>(std::move(provider), std::move(request), clock);
}

void setScriptVcrOptions(ScriptPlayerOptions& options, const Manifest& show, const Clock& clock) {
  options.manualClock = clock.isManual();
  for (const DeviceSpec& d : show.devices) {
    if (d.kind != DeviceKind::kCamera) continue;
    MediaSpec media;
    media.name = "the script's camera";
    media.kind = MediaKind::kCamera;
    media.device = d.name;
    options.camera = [media, &show, &clock]() { return makeCameraStream(media, show, clock); };
    return;
  }
  options.camera = nullptr;
}

void registerShowFactories() {
  static std::once_flag once;
  std::call_once(once, [] {
    setDialBoxFactory(DeviceBackend::kHid, makeDialBoxFromSpec);
    setDialBoxFactory(DeviceBackend::kReplay, makeDialBoxFromSpec);
    setStreamFactory(MediaKind::kMovie, makeMovieStream);
    setStreamFactory(MediaKind::kCamera, makeCameraStream);
    setItemFactory(EntryKind::kMovie, makeMovieItem);
  });
}

}  // namespace basalt::kiosk
