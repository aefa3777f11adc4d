#include "devices/tracker.h"

#include "devices/hid/tracker_decoder.h"

namespace basalt::devices {

TrackerSamples::TrackerSamples(std::size_t capacity) : ring_(capacity > 0 ? capacity : 1) {}

void TrackerSamples::push(const TrackerSample& sample) {
  std::lock_guard lock(mutex_);
  if (size_ == ring_.size()) {
    head_ = (head_ + 1) % ring_.size();
    --size_;
    dropped_.fetch_add(1, std::memory_order_relaxed);
  }
  ring_[(head_ + size_) % ring_.size()] = sample;
  ++size_;
  newest_ = sample;
}

std::optional<TrackerSample> TrackerSamples::newest() const {
  std::lock_guard lock(mutex_);
  return newest_;
}

std::size_t TrackerSamples::size() const {
  std::lock_guard lock(mutex_);
  return size_;
}

Tracker::Tracker(DeviceInfo info, bool rawReports) : info_(std::move(info)), rawReports_(rawReports) {
  if (!rawReports_) descriptor_ = virtualTrackerDescriptor();
}

Tracker::~Tracker() = default;

Result<void> Tracker::open(DeviceId id, TrackerSamples& samples) {
  if (state_ == DeviceState::kLive) return {};
  const DeviceState before = state_;
  state_ = before == DeviceState::kLost ? DeviceState::kReopening : DeviceState::kOpening;
  id_ = id;
  lost_.store(false, std::memory_order_release);
  {
    std::lock_guard lock(lostMutex_);
    lostReason_.reset();
  }
  samples_.store(&samples, std::memory_order_release);
  if (auto r = doOpen(); !r) {
    samples_.store(nullptr, std::memory_order_release);
    state_ = before;
    return r;
  }
  state_ = DeviceState::kLive;
  return {};
}

void Tracker::close() {
  if (state_ == DeviceState::kAbsent) return;
  if (state_ == DeviceState::kLive) doClose();
  samples_.store(nullptr, std::memory_order_release);
  state_ = DeviceState::kAbsent;
}

void Tracker::service(Nanos now) {
  if (state_ != DeviceState::kLive) return;
  if (!lost_.load(std::memory_order_acquire)) doService(now);
  if (lost_.load(std::memory_order_acquire)) {
    doClose();
    samples_.store(nullptr, std::memory_order_release);
    state_ = DeviceState::kLost;
  }
}

std::optional<Error> Tracker::lostReason() const {
  std::lock_guard lock(lostMutex_);
  return lostReason_;
}

void Tracker::reportLost(Error why) {
  {
    std::lock_guard lock(lostMutex_);
    if (!lostReason_) lostReason_ = std::move(why);
  }
  lost_.store(true, std::memory_order_release);
}

bool Tracker::emit(TrackerSample sample) {
  TrackerSamples* samples = samples_.load(std::memory_order_acquire);
  if (!samples || lost_.load(std::memory_order_acquire)) return false;
  sample.sequence = sequence_.fetch_add(1, std::memory_order_relaxed);
  if (!rawReports_) {
    if (ReportTap* tap = tap_.load(std::memory_order_acquire)) {
      const auto report = encodeVirtualTrackerReport(sample);
      tap->onReport(id_, sample.time, report);
    }
  }
  samples->push(sample);
  return true;
}

void Tracker::tapReport(Nanos time, std::span<const std::uint8_t> report) {
  if (ReportTap* tap = tap_.load(std::memory_order_acquire)) tap->onReport(id_, time, report);
}

FedTracker::FedTracker(DeviceInfo info) : Tracker(std::move(info)) {}

bool FedTracker::push(const TrackerSample& sample) {
  if (!open_.load(std::memory_order_acquire)) return false;
  return emit(sample);
}

void FedTracker::setPresent(bool present) { present_.store(present, std::memory_order_release); }

Result<void> FedTracker::doOpen() {
  if (!present_.load(std::memory_order_acquire)) {
    return fail(Errc::kUnavailable, "the tracker's feed is not there", describeDevice(info()));
  }
  open_.store(true, std::memory_order_release);
  return {};
}

void FedTracker::doClose() { open_.store(false, std::memory_order_release); }

void FedTracker::doService(Nanos now) {
  (void)now;
  if (!present_.load(std::memory_order_acquire)) {
    reportLost(Error(Errc::kUnavailable, "the tracker's feed went away"));
  }
}

}  // namespace basalt::devices
