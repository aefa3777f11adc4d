// The replay backend's tracker: plays a hid-recorder file of a tracker (recorded from a HID
// tracker, or from a synthetic or fed one as Basalt's virtual tracker). No hardware; reads
// nothing but the recording. Loops (the next lap starts one mean report interval after the
// last report) or plays once.

#include "sim/replay_tracker.h"

#include "devices/hid/report_descriptor.h"

namespace basalt::sim {

Result<std::unique_ptr<ReplayTracker>> ReplayTracker::create(devices::DeviceInfo info,
                                                             const HidRecordedDevice& recording, const Clock& clock,
                                                             bool loop) {
  auto parsed = devices::hid::parseReportDescriptor(recording.descriptor, info.path);
  if (!parsed) return std::unexpected(parsed.error());
  auto decoder = devices::TrackerDecoder::create(*parsed, info.path);
  if (!decoder) return std::unexpected(decoder.error());
  return std::unique_ptr<ReplayTracker>(
      new ReplayTracker(std::move(info), recording, std::move(*decoder), clock, loop));
}

ReplayTracker::ReplayTracker(devices::DeviceInfo info, const HidRecordedDevice& recording,
                             devices::TrackerDecoder decoder, const Clock& clock, bool loop)
    : Tracker(std::move(info), true),
      reports_(recording.reports),
      decoder_(std::move(decoder)),
      clock_(clock),
      loop_(loop) {
  setReportDescriptor(recording.descriptor);
}

Result<void> ReplayTracker::doOpen() {
  next_ = 0;
  finished_ = false;
  origin_ = clock_.now();
  return {};
}

void ReplayTracker::doClose() {}

void ReplayTracker::doService(Nanos now) {
  while (!reports_.empty()) {
    if (next_ >= reports_.size()) {
      if (!loop_) {
        finished_ = true;
        return;
      }
      const Nanos gap = reports_.size() > 1 ? (reports_.back().time - reports_.front().time) /
                                                  static_cast<std::int64_t>(reports_.size() - 1)
                                            : Nanos{std::chrono::milliseconds(1)};
      origin_ += reports_.back().time + std::max(gap, Nanos{1});
      next_ = 0;
    }
    const HidReport& r = reports_[next_];
    const Nanos due = origin_ + r.time;
    if (due > now) return;
    tapReport(due, r.bytes);
    if (auto sample = decoder_.decode(r.bytes, due)) emit(*sample);
    ++next_;
  }
}

}  // namespace basalt::sim
