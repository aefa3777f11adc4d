#include "devices/dial_box.h"

namespace basalt::devices {

Result<void> DialBox::open(DeviceId id, BoundedQueue<Event>& events) {
  if (state_ == DeviceState::kLive) return {};
  const DeviceState before = state_;
  state_ = before == DeviceState::kLost ? DeviceState::kReopening : DeviceState::kOpening;
  id_ = id;
  events_ = &events;
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
  doClose();
  events_ = nullptr;
  state_ = DeviceState::kAbsent;
}

void DialBox::service(Nanos now) {
  if (state_ == DeviceState::kLive) doService(now);
}

bool DialBox::emit(Event event) {
  if (!events_) return false;
  event.device = id_;
  return events_->push(event);
}

}  // namespace basalt::devices
