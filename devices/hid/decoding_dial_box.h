#pragma once

/// \file
/// \brief What the HID dial-box backends share: a reader thread that receives the device's raw
/// input reports (hidraw through hidapi, the PowerMate through libusb) and hands each one to
/// handleReport(), which taps, decodes and emits it.

#include <array>
#include <atomic>
#include <cstdint>
#include <span>
#include <thread>
#include <utility>

#include "devices/dial_box.h"
#include "devices/hid/dial_decoder.h"
#include "runtime/clock.h"

namespace basalt::devices {

/// \brief A DialBox fed by raw input reports on a reader thread of its own.
///
/// Threading: startReader()/stopReader() on the owner's thread (doOpen/doClose); readLoop() and
/// handleReport() on the reader thread; the decoder and the event buffer belong to the reader.
class DecodingDialBox : public DialBox {
 protected:
  /// \brief The dial and button counts are the decoder's (read before it moves into place: the
  /// base class is built first).
  DecodingDialBox(DeviceInfo info, DialDecoder decoder, const Clock& clock)
      : DialBox(std::move(info), decoder.dialCount(), decoder.buttonCount(), true),
        decoder_(std::move(decoder)),
        clock_(clock) {}

  /// \brief Forgets the decoder's state and starts readLoop() on the reader thread.
  void startReader() {
    decoder_.reset();
    stop_.store(false);
    reader_ = std::thread([this] { readLoop(); });
  }
  /// \brief Asks readLoop() to return (it polls stopping() at least every read timeout) and joins it.
  void stopReader() {
    stop_.store(true);
    if (reader_.joinable()) reader_.join();
  }
  [[nodiscard]] bool stopping() const { return stop_.load(); }

  /// \brief One input report as read: stamped now, passed to the tap, decoded and emitted.
  void handleReport(std::span<const std::uint8_t> report) {
    const Nanos now = clock_.now();
    tapReport(now, report);
    const std::size_t count = decoder_.decode(report, events_);
    for (std::size_t i = 0; i < count; ++i) {
      events_[i].time = now;
      emit(events_[i]);
    }
  }

 private:
  /// Reads reports until stopping() or a read fails (then reportLost()).
  virtual void readLoop() = 0;

  DialDecoder decoder_;
  const Clock& clock_;
  std::array<Event, DialDecoder::kMaxEventsPerReport> events_{};
  std::atomic<bool> stop_{false};
  std::thread reader_;
};

}  // namespace basalt::devices
