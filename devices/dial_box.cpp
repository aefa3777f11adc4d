#include "devices/dial_box.h"

#include "devices/hid/dial_decoder.h"

namespace basalt::devices {

DialBox::DialBox(DeviceInfo info, int dials, int buttons, bool rawReports)
    : info_(std::move(info)), dialCount_(dials), buttonCount_(buttons), rawReports_(rawReports) {
  if (!rawReports_) {
    descriptor_ = virtualDialBoxDescriptor();
    encoder_ = std::make_unique<VirtualReportEncoder>();
  }
}

DialBox::~DialBox() = default;

Result<void> DialBox::open(DeviceId id, BoundedQueue<Event>& events) {
  if (state_ == DeviceState::kLive) return {};
  const DeviceState before = state_;
  state_ = before == DeviceState::kLost ? DeviceState::kReopening : DeviceState::kOpening;
  id_ = id;
  events_ = &events;
  lost_.store(false, std::memory_order_release);
  {
    std::lock_guard lock(lostMutex_);
    lostReason_.reset();
  }
  if (encoder_) encoder_->reset();
  if (auto r = doOpen(); !r) {
    state_ = before;
    events_ = nullptr;
    return r;
  }
  state_ = DeviceState::kLive;
  return {};
}

void DialBox::close() {
  if (state_ == DeviceState::kAbsent) return;
  if (state_ == DeviceState::kLive) doClose();
  events_ = nullptr;
  state_ = DeviceState::kAbsent;
}

void DialBox::service(Nanos now) {
  if (state_ != DeviceState::kLive) return;
  if (!lost_.load(std::memory_order_acquire)) doService(now);
  if (lost_.load(std::memory_order_acquire)) {
    doClose();
    events_ = nullptr;
    state_ = DeviceState::kLost;
  }
}

std::optional<Error> DialBox::lostReason() const {
  std::lock_guard lock(lostMutex_);
  return lostReason_;
}

Result<void> DialBox::setLight(int index, double level, bool pulse) {
  if (state_ != DeviceState::kLive) {
    return fail(Errc::kUnavailable, "the dial box is not connected", describeDevice(info_));
  }
  return doSetLight(index, level, pulse);
}

Result<void> DialBox::doSetLight(int, double, bool) {
  return fail(Errc::kUnsupported, "this dial box has no lights", describeDevice(info_));
}

void DialBox::reportLost(Error why) {
  {
    std::lock_guard lock(lostMutex_);
    if (!lostReason_) lostReason_ = std::move(why);
  }
  lost_.store(true, std::memory_order_release);
}

bool DialBox::emit(Event event) {
  if (!events_ || lost_.load(std::memory_order_acquire)) return false;
  event.device = id_;
  if (encoder_) {
    if (ReportTap* tap = tap_.load(std::memory_order_acquire)) {
      encoder_->encode(event, [&](std::span<const std::uint8_t> report) { tap->onReport(id_, event.time, report); });
    }
  }
  return events_->push(event);
}

void DialBox::tapReport(Nanos time, std::span<const std::uint8_t> report) {
  if (ReportTap* tap = tap_.load(std::memory_order_acquire)) tap->onReport(id_, time, report);
}

}  // namespace basalt::devices
