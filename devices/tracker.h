#pragma once

/// \file
/// \brief A tracker (thesis §4.4.3's head tracking): the position and orientation of a head or
/// an object, as timestamped samples. The interface every backend implements, and the bounded
/// buffer its samples go into.

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <vector>

#include "devices/device.h"
#include "runtime/clock.h"
#include "runtime/error.h"
#include "runtime/head_tracking.h"

namespace basalt::devices {

using runtime::TrackerSample;

/// \brief The samples of one tracker, between its backend and the frame loop: bounded (the
/// oldest is dropped and counted when full), never blocking, stable while the device behind it
/// is unplugged and reopened. Any thread may push; the reader takes the samples due by a
/// frame's time, in time order.
class TrackerSamples {
 public:
  explicit TrackerSamples(std::size_t capacity = 256);
  /// \brief Adds one sample; when full the oldest goes (counted in dropped()). Any thread.
  void push(const TrackerSample& sample);
  /// \brief Calls `take(sample)` for each sample with time <= `until`, oldest first, and
  /// removes them; later samples stay. Holds the lock while it calls: keep `take` short.
  template <typename Take>
  std::size_t takeDue(Nanos until, Take&& take) {
    std::lock_guard lock(mutex_);
    std::size_t n = 0;
    while (size_ > 0 && ring_[head_].time <= until) {
      take(ring_[head_]);
      head_ = (head_ + 1) % ring_.size();
      --size_;
      ++n;
    }
    return n;
  }
  /// \brief The newest sample pushed, if any (for status and tests).
  [[nodiscard]] std::optional<TrackerSample> newest() const;
  [[nodiscard]] std::uint64_t dropped() const { return dropped_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::size_t size() const;

 private:
  mutable std::mutex mutex_;         // guards ring_, head_, size_, newest_
  std::vector<TrackerSample> ring_;  // fixed capacity, sized once
  std::size_t head_ = 0;             // the oldest sample
  std::size_t size_ = 0;
  std::optional<TrackerSample> newest_;
  std::atomic<std::uint64_t> dropped_{0};
};

/// \brief A tracker, whatever its backend. As DialBox: the public API is non-virtual, owns the
/// state machine (absent -> opening -> live -> lost -> reopening) and checks the contract; the
/// backend implements the private hooks (NVI).
///
/// Threading: open(), close(), service(), state() and lostReason() are called from the thread
/// that owns the device (the DeviceManager's). A backend's reader thread, or whoever feeds it
/// (FedTracker::push), may call emit(), tapReport() and reportLost() between doOpen() and the end
/// of doClose() (which must join a thread it started).
class Tracker {
 public:
  virtual ~Tracker();
  Tracker(const Tracker&) = delete;
  Tracker& operator=(const Tracker&) = delete;

  /// \brief Opens the device; samples then flow into `samples`. Allowed when absent or lost;
  /// live on success, unchanged on failure.
  [[nodiscard]] Result<void> open(DeviceId id, TrackerSamples& samples);
  /// \brief Stops the samples and releases the device. Safe in any state.
  void close();
  /// \brief Notices a loss the backend reported (live -> lost, the device is closed), then lets
  /// backends without a thread produce the samples due by `now`. Never blocks.
  void service(Nanos now);

  [[nodiscard]] DeviceState state() const { return state_; }
  [[nodiscard]] const DeviceInfo& info() const { return info_; }
  [[nodiscard]] DeviceId id() const { return id_; }
  [[nodiscard]] std::optional<Error> lostReason() const;
  /// \brief The HID report descriptor of the reports passed to a ReportTap: the device's own for
  /// HID trackers, Basalt's virtual tracker descriptor for the others (their samples are encoded
  /// as its reports, so that every tracker records into the hid-recorder format and replays).
  [[nodiscard]] const std::vector<std::uint8_t>& reportDescriptor() const { return descriptor_; }
  /// \brief Sends every raw input report to `tap` (null stops). Any thread.
  void setReportTap(ReportTap* tap) { tap_.store(tap, std::memory_order_release); }
  /// \brief Samples emitted since the device was made.
  [[nodiscard]] std::uint32_t samplesEmitted() const { return sequence_.load(std::memory_order_relaxed); }

 protected:
  /// `rawReports`: the backend passes its device's own reports to tapReport(); when false,
  /// emitted samples are encoded as virtual tracker reports for the tap.
  explicit Tracker(DeviceInfo info, bool rawReports = false);

  /// \brief The device vanished or a read failed. Any thread; the next service() closes it.
  void reportLost(Error why);
  /// \brief Pushes one sample (its sequence number is set here); false when not live.
  bool emit(TrackerSample sample);
  /// \brief Passes one raw input report to the tap, if any (HID backends).
  void tapReport(Nanos time, std::span<const std::uint8_t> report);
  void setReportDescriptor(std::vector<std::uint8_t> descriptor) { descriptor_ = std::move(descriptor); }
  void setInfo(DeviceInfo info) { info_ = std::move(info); }

 private:
  [[nodiscard]] virtual Result<void> doOpen() = 0;
  virtual void doClose() = 0;
  virtual void doService(Nanos now) { (void)now; }

  DeviceInfo info_;
  bool rawReports_;
  std::vector<std::uint8_t> descriptor_;
  DeviceState state_ = DeviceState::kAbsent;
  DeviceId id_ = 0;
  std::atomic<TrackerSamples*> samples_{nullptr};  // set before doOpen(), cleared after doClose()
  std::atomic<ReportTap*> tap_{nullptr};
  std::atomic<bool> lost_{false};    // set by reportLost() on any thread, read by service()
  mutable std::mutex lostMutex_;     // guards lostReason_
  std::optional<Error> lostReason_;  // guarded by lostMutex_
  std::atomic<std::uint32_t> sequence_{0};
};

/// \brief A tracker fed by another part of Basalt rather than a device: whoever has samples
/// (an OSC `/tracker/...` receiver, a test) calls push() from its own thread. The seam for
/// trackers that arrive over the network; see devices/README.md.
///
/// Threading: push() and setPresent() from any thread; the rest as Tracker.
class FedTracker final : public Tracker {
 public:
  explicit FedTracker(DeviceInfo info);
  /// \brief Hands one sample over (stamped on the show's Clock by the caller); false while the
  /// tracker is not open (the sample is dropped).
  bool push(const TrackerSample& sample);
  /// \brief The feeder's source went away (false: the next service() reports the tracker lost)
  /// or came back (true: it may be opened again).
  void setPresent(bool present);

 private:
  Result<void> doOpen() override;
  void doClose() override;
  void doService(Nanos now) override;
  std::atomic<bool> open_{false};
  std::atomic<bool> present_{true};
};

}  // namespace basalt::devices
