#pragma once

/// \file
/// \brief A box of dials and buttons (LAVA §4.1): the interface every backend implements.

#include <cstdint>

#include "devices/device.h"
#include "runtime/bounded_queue.h"
#include "runtime/clock.h"
#include "runtime/error.h"
#include "runtime/event.h"

namespace basalt::devices {

/// \brief A dial box, whatever its backend. The public API is non-virtual: it owns the state
/// machine and checks the contract, and calls the backend's private hooks (NVI).
///
/// Events go into the queue given to open(); backends push from their own thread or from
/// service(), never call into the show. Threading: open(), close(), service() and state() are
/// called from the thread that owns the device manager.
class DialBox {
 public:
  virtual ~DialBox() = default;
  DialBox(const DialBox&) = delete;
  DialBox& operator=(const DialBox&) = delete;

  /// \brief Opens the device; events then flow into `events` tagged with `id`.
  /// Allowed when absent or lost; the state is live on success and unchanged on failure.
  [[nodiscard]] Result<void> open(DeviceId id, BoundedQueue<Event>& events);
  /// \brief Stops events and releases the device. Safe in any state.
  void close();
  /// \brief Lets backends without a thread of their own do their work, up to `now`
  /// (simulated devices produce the events due by then). Never blocks.
  void service(Nanos now);

  [[nodiscard]] DeviceState state() const { return state_; }
  [[nodiscard]] const DeviceInfo& info() const { return info_; }
  [[nodiscard]] int dialCount() const { return dialCount_; }
  [[nodiscard]] int buttonCount() const { return buttonCount_; }

 protected:
  DialBox(DeviceInfo info, int dials, int buttons) : info_(std::move(info)), dialCount_(dials), buttonCount_(buttons) {}
  /// \brief Backends call this when the device vanishes or a read fails.
  void markLost() { state_ = DeviceState::kLost; }
  /// \brief Pushes one event, stamped with the device id; false when the queue is full.
  bool emit(Event event);

 private:
  [[nodiscard]] virtual Result<void> doOpen() = 0;
  virtual void doClose() = 0;
  virtual void doService(Nanos now) { (void)now; }

  DeviceInfo info_;
  int dialCount_;
  int buttonCount_;
  DeviceState state_ = DeviceState::kAbsent;
  DeviceId id_ = 0;
  BoundedQueue<Event>* events_ = nullptr;
};

}  // namespace basalt::devices
