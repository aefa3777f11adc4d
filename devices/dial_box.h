#pragma once

/// \file
/// \brief A box of dials and buttons (LAVA §4.1): the interface every backend implements.

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <vector>

#include "devices/device.h"
#include "runtime/bounded_queue.h"
#include "runtime/clock.h"
#include "runtime/error.h"
#include "runtime/event.h"

namespace basalt::devices {

class VirtualReportEncoder;

/// \brief A dial box, whatever its backend. The public API is non-virtual: it owns the state
/// machine and checks the contract, and calls the backend's private hooks (NVI).
///
/// Events go into the queue given to open(); backends push from their own reader thread or from
/// service(), never call into the show. Threading: open(), close(), service(), state() and
/// lostReason() are called from the thread that owns the device (the DeviceManager's). A
/// backend's reader thread may call emit(), tapReport() and reportLost() between doOpen() and
/// the end of doClose() (which must join that thread).
class DialBox {
 public:
  virtual ~DialBox();
  DialBox(const DialBox&) = delete;
  DialBox& operator=(const DialBox&) = delete;

  /// \brief Opens the device; events then flow into `events` tagged with `id`.
  /// Allowed when absent or lost; the state is live on success and unchanged on failure.
  [[nodiscard]] Result<void> open(DeviceId id, BoundedQueue<Event>& events);
  /// \brief Stops events and releases the device. Safe in any state.
  void close();
  /// \brief Notices a loss reported by the backend (live -> lost, the device is closed), then
  /// lets backends without a thread of their own do their work up to `now` (simulated devices
  /// produce the events due by then). Never blocks.
  void service(Nanos now);

  [[nodiscard]] DeviceState state() const { return state_; }
  [[nodiscard]] const DeviceInfo& info() const { return info_; }
  [[nodiscard]] int dialCount() const { return dialCount_; }
  [[nodiscard]] int buttonCount() const { return buttonCount_; }
  /// \brief Why the device was lost (last read error, unplug), if it was.
  [[nodiscard]] std::optional<Error> lostReason() const;

  /// \brief The HID report descriptor that describes the reports passed to a ReportTap: the
  /// device's own for HID devices, Basalt's virtual dial box descriptor for the others (their
  /// events are encoded as reports of that descriptor, so that every dial box records into the
  /// hid-recorder format and replays).
  [[nodiscard]] const std::vector<std::uint8_t>& reportDescriptor() const { return descriptor_; }
  /// \brief Sends every raw input report to `tap` (null stops). Any thread.
  void setReportTap(ReportTap* tap) { tap_.store(tap, std::memory_order_release); }

  /// \brief Sets light `index` (PowerMate LED: 0) to `level` 0..1, pulsing when `pulse`.
  [[nodiscard]] Result<void> setLight(int index, double level, bool pulse = false);

 protected:
  /// `rawReports`: the backend passes its device's own input reports to tapReport(); when false
  /// the events it emits are encoded as virtual reports instead.
  DialBox(DeviceInfo info, int dials, int buttons, bool rawReports = false);

  /// \brief Backends call this when the device vanishes or a read fails. Any thread; the next
  /// service() closes the device and the DeviceManager reopens it with back-off.
  void reportLost(Error why);
  /// \brief Pushes one event, stamped with the device id; false when the queue is full.
  bool emit(Event event);
  /// \brief Passes one raw input report to the tap, if any (HID backends).
  void tapReport(Nanos time, std::span<const std::uint8_t> report);
  /// \brief Sets the descriptor of the raw reports (HID backends, before or in doOpen()).
  void setReportDescriptor(std::vector<std::uint8_t> descriptor) { descriptor_ = std::move(descriptor); }
  /// \brief Backends that learn their shape on open (generic HID) set it there.
  void setShape(int dials, int buttons) {
    dialCount_ = dials;
    buttonCount_ = buttons;
  }
  void setInfo(DeviceInfo info) { info_ = std::move(info); }

 private:
  [[nodiscard]] virtual Result<void> doOpen() = 0;
  virtual void doClose() = 0;
  virtual void doService(Nanos now) { (void)now; }
  [[nodiscard]] virtual Result<void> doSetLight(int index, double level, bool pulse);

  DeviceInfo info_;
  int dialCount_;
  int buttonCount_;
  bool rawReports_;
  std::vector<std::uint8_t> descriptor_;
  DeviceState state_ = DeviceState::kAbsent;
  DeviceId id_ = 0;
  BoundedQueue<Event>* events_ = nullptr;  // set before doOpen(), cleared after doClose()
  std::atomic<ReportTap*> tap_{nullptr};
  std::atomic<bool> lost_{false};                  // set by reportLost() on any thread, read by service()
  mutable std::mutex lostMutex_;                   // guards lostReason_
  std::optional<Error> lostReason_;                // guarded by lostMutex_
  std::unique_ptr<VirtualReportEncoder> encoder_;  // used by emit() when !rawReports_
};

}  // namespace basalt::devices
