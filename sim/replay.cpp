// Replay backends: recorded dial boxes (hid-recorder files) and cameras (trace videos).
//
// Timing: a report recorded at t plays at open time + t on the show's Clock; a looping replay
// starts its next lap one report interval (or one frame interval) after its last report, so that
// a lap has the recording's length. Limits: reports are replayed as recorded (no resampling);
// a video replays in its recorded mode.

#include "sim/replay.h"

#include <algorithm>

#include <fmt/format.h>

namespace basalt::sim {

Result<std::unique_ptr<ReplayDialBox>> ReplayDialBox::create(devices::DeviceInfo info,
                                                             const HidRecordedDevice& recording, const Clock& clock,
                                                             bool loop) {
  if (devices::isMidiDescriptor(recording.descriptor)) {
    auto profile = devices::parseMidiDescriptor(recording.descriptor);
    if (!profile) return std::unexpected(profile.error());
    const int dials = profile->dials;
    const int buttons = profile->buttons;
    return std::unique_ptr<ReplayDialBox>(new ReplayDialBox(
        std::move(info), recording, devices::MidiDecoder(std::move(*profile)), dials, buttons, clock, loop));
  }
  auto decoder = devices::DialDecoder::create(recording.vendor, recording.product, recording.descriptor, info.path);
  if (!decoder) return std::unexpected(decoder.error());
  const int dials = decoder->dialCount();
  const int buttons = decoder->buttonCount();
  return std::unique_ptr<ReplayDialBox>(
      new ReplayDialBox(std::move(info), recording, std::move(*decoder), dials, buttons, clock, loop));
}

ReplayDialBox::ReplayDialBox(devices::DeviceInfo info, const HidRecordedDevice& recording, Decoder decoder, int dials,
                             int buttons, const Clock& clock, bool loop)
    : DialBox(std::move(info), dials, buttons, true),
      reports_(recording.reports),
      decoder_(std::move(decoder)),
      clock_(clock),
      loop_(loop) {
  setReportDescriptor(recording.descriptor);
}

Result<void> ReplayDialBox::doOpen() {
  std::visit([](auto& d) { d.reset(); }, decoder_);
  next_ = 0;
  finished_ = false;
  origin_ = clock_.now();
  return {};
}

void ReplayDialBox::doClose() {}

void ReplayDialBox::doService(Nanos now) {
  std::array<Event, devices::DialDecoder::kMaxEventsPerReport> events;
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
      std::visit([](auto& d) { d.reset(); }, decoder_);
    }
    const HidReport& r = reports_[next_];
    const Nanos due = origin_ + r.time;
    if (due > now) return;
    tapReport(due, r.bytes);
    const std::size_t n = std::visit([&](auto& d) { return d.decode(r.bytes, events); }, decoder_);
    for (std::size_t i = 0; i < n; ++i) {
      events[i].time = due;
      emit(events[i]);
    }
    ++next_;
  }
}

ReplayCamera::ReplayCamera(devices::DeviceInfo info, std::unique_ptr<TraceVideoReader> reader, const Clock& clock,
                           bool loop)
    : VideoSource(std::move(info), clock), reader_(std::move(reader)), loop_(loop) {
  setModes({reader_->mode()});
}

Result<void> ReplayCamera::doOpen() {
  if (auto r = reader_->rewind(); !r) return r;
  pending_.reset();
  origin_ = clock().now();
  lastPts_ = Nanos{0};
  finished_ = false;
  const devices::VideoMode mode = reader_->mode();
  setMode(mode);
  lapLength_ = mode.fps > 0 ? fromSeconds(1.0 / mode.fps) : Nanos{std::chrono::milliseconds(33)};
  // A paused recording is not a stall: only a replay that has ended goes quiet.
  setStallTimeout(Nanos{std::chrono::hours(24 * 365)});
  return {};
}

void ReplayCamera::doClose() { pending_.reset(); }

void ReplayCamera::doService(Nanos now) {
  for (int guard = 0; guard < 1'000'000; ++guard) {
    if (!pending_) {
      if (finished_) return;
      auto next = reader_->next();
      if (!next) {
        reportLost(next.error());
        return;
      }
      if (!*next) {  // end of the recording
        if (!loop_) {
          finished_ = true;
          return;
        }
        if (auto r = reader_->rewind(); !r) {
          reportLost(r.error());
          return;
        }
        const Nanos interval = mode().fps > 0 ? fromSeconds(1.0 / mode().fps) : Nanos{std::chrono::milliseconds(33)};
        origin_ += lastPts_ + interval;
        auto first = reader_->next();
        if (!first || !*first) {
          finished_ = true;
          return;
        }
        pending_ = std::move(*first);
      } else {
        pending_ = std::move(*next);
      }
      lastPts_ = pending_->pts;
      pending_->pts = origin_ + pending_->pts;
      pending_->captureTime = pending_->pts;
    }
    if (pending_->pts > now) return;
    deliver(std::move(pending_));
  }
}

}  // namespace basalt::sim
