#pragma once

/// \file
/// \brief The SGI dial and button box on a serial line (RS-232, 9600 8N1): 8 dials with a
/// 16-bit wrapping count (200 per turn) and 32 lit buttons.

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "devices/device_manager.h"
#include "devices/dial_box.h"
#include "runtime/unique_fd.h"

namespace basalt::devices {

inline constexpr double kSgiCountsPerTurn = 200;

/// \brief The box's byte protocol, as a decoder: feed bytes in any pieces, get events.
///
/// Dial: `0x30+n XX YY`, the new absolute count of dial n, big-endian, wrapping at 16 bits (the
/// counters start at 0 after a reset). Buttons, one byte each: press D8-DF = 0-7, D0-D7 = 8-15,
/// C8-CF = 16-23, C0-C7 = 24-31; release F8-FF, F0-F7, E8-EF, E0-E7 likewise. 0x20 answers a
/// reset (all counters back to 0).
class SgiBoxDecoder {
 public:
  /// \brief Decodes `bytes`, appending events (time and device left 0) to `out` up to its size;
  /// returns how many were written. Unknown bytes are skipped and counted.
  std::size_t feed(std::span<const std::uint8_t> bytes, std::span<Event> out);
  void reset();
  [[nodiscard]] std::uint64_t unknownBytes() const { return unknown_; }

 private:
  std::array<std::uint16_t, 8> counts_{};
  std::uint8_t pending_[3] = {};
  int have_ = 0;
  std::uint64_t unknown_ = 0;
};

/// \brief The box on a tty. Opening resets it and waits up to `resetTimeout` for the answer, so
/// that a port with nothing on it gives a clear error; a reader thread then decodes its bytes. A
/// read error or hang-up (the USB serial adapter unplugged) reports the box lost.
class SgiDialBox final : public DialBox {
 public:
  SgiDialBox(std::string path, const Clock& clock, Nanos resetTimeout = std::chrono::milliseconds(1000));
  ~SgiDialBox() override;

 private:
  Result<void> doOpen() override;
  void doClose() override;
  Result<void> doSetLight(int index, double level, bool pulse) override;
  void readLoop();

  std::string path_;
  const Clock& clock_;
  Nanos resetTimeout_;
  UniqueFd fd_;
  UniqueFd stopFd_;  // eventfd: wakes the reader thread for close()
  std::thread reader_;
  std::atomic<std::uint32_t> lights_{0};
};

/// \brief The `serial` backend: the SGI box on the ports it is given, and on USB serial adapters
/// (/dev/ttyUSB*, /dev/ttyACM*). Request option `reset_timeout_ms` (default 1000).
class SerialProvider final : public DeviceProvider {
 public:
  explicit SerialProvider(std::vector<std::string> ports = {});
  [[nodiscard]] std::string_view backend() const override { return "serial"; }
  std::vector<DeviceCandidate> enumerate() override;
  Result<std::unique_ptr<DialBox>> openDialBox(const DeviceCandidate& candidate, const DeviceRequest& request,
                                               const Clock& clock) override;

 private:
  std::vector<std::string> ports_;
};

}  // namespace basalt::devices
