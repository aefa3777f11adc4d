// SyntheticDial: a dial box with no hardware behind it.
//
// Serves demos and tests: plays a list of scripted turns and presses on the injected Clock.
// Limits: 8 dials and 32 buttons, like LAVA's box; events are only produced from service().
// Its events are recorded as reports of Basalt's virtual dial box descriptor.

#include "sim/synthetic_dial.h"

namespace basalt::sim {

devices::DeviceInfo SyntheticDial::defaultInfo() {
  return devices::DeviceInfo{"Synthetic dial box", "synthetic", "virtual", 0, 0, "synthetic:dial", ""};
}

SyntheticDial::SyntheticDial(std::vector<ScriptedInput> script, const Clock& clock, bool loop)
    : SyntheticDial(defaultInfo(), std::move(script), clock, loop, nullptr) {}

SyntheticDial::SyntheticDial(devices::DeviceInfo info, std::vector<ScriptedInput> script, const Clock& clock, bool loop,
                             PresenceFlag present)
    : DialBox(std::move(info), 8, 32),
      script_(std::move(script)),
      clock_(clock),
      loop_(loop),
      present_(std::move(present)) {}

Result<void> SyntheticDial::doOpen() {
  if (present_ && !present_->load()) {
    return fail(Errc::kNotFound, "the synthetic device is unplugged", info().path);
  }
  next_ = 0;
  origin_ = clock_.now();
  return {};
}

void SyntheticDial::doClose() { next_ = script_.size(); }

void SyntheticDial::doService(Nanos now) {
  while (!script_.empty()) {
    if (present_ && !present_->load()) {
      reportLost(Error(Errc::kDeviceLost, "unplugged during a read", info().path));
      return;
    }
    if (next_ >= script_.size()) {
      if (!loop_) return;
      // Start the next lap after the last event's time.
      origin_ += script_.back().time + Nanos{1};
      next_ = 0;
    }
    const ScriptedInput& in = script_[next_];
    const Nanos due = origin_ + in.time;
    if (due > now) return;
    emit(Event{due, 0, in.kind, in.index, in.value});
    ++next_;
  }
}

}  // namespace basalt::sim
