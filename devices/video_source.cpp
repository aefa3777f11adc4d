#include "devices/video_source.h"

#include <fmt/format.h>

namespace basalt::devices {

std::string describeMode(const VideoMode& mode) {
  if (mode.fps > 0) {
    return fmt::format("{} {}x{} @ {:.4g} fps", pixelFormatName(mode.format), mode.width, mode.height, mode.fps);
  }
  return fmt::format("{} {}x{}", pixelFormatName(mode.format), mode.width, mode.height);
}

VideoSource::VideoSource(DeviceInfo info, const Clock& clock, std::size_t queueDepth)
    : info_(std::move(info)), clock_(clock), queue_(queueDepth) {}

VideoSource::~VideoSource() = default;

void VideoSource::setState(DeviceState state) {
  since_.store(clock_.now().count(), std::memory_order_release);
  state_.store(state, std::memory_order_release);
}

Result<void> VideoSource::open(DeviceId id) {
  const DeviceState before = state();
  if (before == DeviceState::kLive) return {};
  id_ = id;
  setState(before == DeviceState::kLost ? DeviceState::kReopening : DeviceState::kOpening);
  lost_.store(false, std::memory_order_release);
  recovering_.store(false, std::memory_order_release);
  lastKeptPts_.store(INT64_MIN, std::memory_order_relaxed);
  lastDelivery_.store(clock_.now().count(), std::memory_order_relaxed);
  stalled_.store(false, std::memory_order_relaxed);
  {
    std::lock_guard lock(mutex_);
    lostReason_.reset();
  }
  queue_.clear();
  if (auto r = doOpen(); !r) {
    setState(before);
    return r;
  }
  if (auto r = doApplyControls(controls()); !r) {
    doClose();
    setState(before);
    return r;
  }
  // A backend may have reported a loss already (signal absent at open): keep that state.
  if (!lost_.load(std::memory_order_acquire)) setState(DeviceState::kLive);
  return {};
}

void VideoSource::close() {
  const DeviceState s = state();
  if (s == DeviceState::kAbsent) return;
  if (s != DeviceState::kLost || recovering_.load(std::memory_order_acquire)) doClose();
  queue_.clear();
  recovering_.store(false, std::memory_order_release);
  lost_.store(false, std::memory_order_release);
  setState(DeviceState::kAbsent);
}

void VideoSource::service(Nanos now) {
  const DeviceState s = state();
  if (s == DeviceState::kAbsent) return;
  if (lost_.load(std::memory_order_acquire) && !recovering_.load(std::memory_order_acquire)) {
    if (s != DeviceState::kLost || !recovering_.load()) {
      doClose();
      lost_.store(false, std::memory_order_release);
      setState(DeviceState::kLost);
    }
    return;
  }
  if (s == DeviceState::kLive || recovering_.load(std::memory_order_acquire)) doService(now);
  const std::int64_t last = lastDelivery_.load(std::memory_order_relaxed);
  if (state() == DeviceState::kLive && now.count() - last > stallTimeout_.load(std::memory_order_relaxed)) {
    stalled_.store(true, std::memory_order_release);
    reportLost(
        Error(Errc::kTimeout, fmt::format("no frame for {:.1f} s; the camera stalled", toSeconds(now - Nanos{last})),
              describeDevice(info_)),
        true);
  }
}

FrameRef VideoSource::frameAt(Nanos showTime) {
  const DeviceState s = state();
  if (s != DeviceState::kLive) {
    // Nothing stale comes out after a loss: the fallback shows instead.
    if (s == DeviceState::kLost || s == DeviceState::kReopening) queue_.clear();
    return {};
  }
  return queue_.takeDue(showTime);
}

SourceHealth VideoSource::health() const {
  const Nanos since = stateSince();
  switch (state()) {
    case DeviceState::kLive: return {SourceState::kLive, since};
    case DeviceState::kAbsent:
    case DeviceState::kOpening: return {SourceState::kWaiting, since};
    case DeviceState::kLost:
    case DeviceState::kReopening: return {SourceState::kLost, since};
  }
  return {SourceState::kWaiting, since};
}

std::optional<Error> VideoSource::lostReason() const {
  std::lock_guard lock(mutex_);
  return lostReason_;
}

VideoMode VideoSource::mode() const {
  std::lock_guard lock(mutex_);
  return mode_;
}

std::vector<VideoMode> VideoSource::modes() const {
  std::lock_guard lock(mutex_);
  return modes_;
}

VideoControls VideoSource::controls() const {
  std::lock_guard lock(mutex_);
  return controls_;
}

Result<void> VideoSource::setControls(const VideoControls& controls) {
  if (controls.maxFps < 0 || controls.quality > 100) {
    return fail(Errc::kInvalidArgument, "video controls: fps limit must be >= 0 and quality 0..100",
                describeDevice(info_));
  }
  if (state() == DeviceState::kLive) {
    if (auto r = doApplyControls(controls); !r) return r;
  } else {
    setMirrorInRenderer(controls.mirror);
  }
  {
    std::lock_guard lock(mutex_);
    controls_ = controls;
  }
  minInterval_.store(controls.maxFps > 0 ? fromSeconds(1.0 / controls.maxFps).count() : 0, std::memory_order_release);
  return {};
}

Result<void> VideoSource::doApplyControls(const VideoControls& controls) {
  // No hardware controls: the renderer mirrors; the frame-rate limit is applied in deliver().
  setMirrorInRenderer(controls.mirror);
  if (controls.input > 0) {
    return fail(Errc::kInvalidArgument,
                fmt::format("this source has one input; input {} does not exist", controls.input),
                describeDevice(info_));
  }
  return {};
}

std::uint64_t VideoSource::framesDropped() const {
  return rateDrops_.load(std::memory_order_relaxed) + backendDrops_.load(std::memory_order_relaxed) + queue_.dropped();
}

bool VideoSource::deliver(FrameRef frame) {
  if (!frame) return false;
  if (lost_.load(std::memory_order_acquire)) {
    if (!stalled_.load(std::memory_order_acquire)) return false;
    stalled_.store(false, std::memory_order_release);
    reportRecovered();
  }
  lastDelivery_.store(clock_.now().count(), std::memory_order_relaxed);
  const std::int64_t interval = minInterval_.load(std::memory_order_acquire);
  std::int64_t pts = frame->pts.count();
  const std::int64_t last = lastKeptPts_.load(std::memory_order_relaxed);
  if (interval > 0) {
    // Keep a frame when a whole interval has passed since the last kept one (with 1% slack so
    // that 30 fps from a 60 fps camera keeps every other frame despite timestamp jitter).
    if (last != INT64_MIN && pts - last < interval - interval / 100) {
      rateDrops_.fetch_add(1, std::memory_order_relaxed);
      return false;
    }
  }
  // Two frames captured within one tick of the clock (a manual clock that the producer reads
  // between the show's steps, a driver with coarse timestamps) would carry the same time; the
  // later one is put a nanosecond after the earlier, so presentation order is capture order.
  if (last != INT64_MIN && pts <= last) {
    pts = last + 1;
    frame->pts = Nanos{pts};
  }
  lastKeptPts_.store(pts, std::memory_order_relaxed);
  delivered_.fetch_add(1, std::memory_order_relaxed);
  if (FrameTap* tap = tap_.load(std::memory_order_acquire)) tap->onFrame(id_, frame);
  queue_.pushDroppingOldest(std::move(frame));
  return true;
}

void VideoSource::reportLost(Error why, bool recovering) {
  {
    std::lock_guard lock(mutex_);
    lostReason_ = std::move(why);
  }
  recovering_.store(recovering, std::memory_order_release);
  lost_.store(true, std::memory_order_release);
  if (recovering) {
    queue_.clear();
    setState(DeviceState::kLost);
  }
}

void VideoSource::reportRecovered() {
  lost_.store(false, std::memory_order_release);
  recovering_.store(false, std::memory_order_release);
  setState(DeviceState::kLive);
}

void VideoSource::setMode(const VideoMode& mode) {
  std::lock_guard lock(mutex_);
  mode_ = mode;
}

void VideoSource::setModes(std::vector<VideoMode> modes) {
  std::lock_guard lock(mutex_);
  modes_ = std::move(modes);
}

}  // namespace basalt::devices
