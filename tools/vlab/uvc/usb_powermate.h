#pragma once

/// \file
/// \brief A Griffin PowerMate (077d:0410) emulated in user space for the virtual lab: one HID
/// interface with a 6-byte interrupt IN report (byte 0 the button, byte 1 the signed rotation),
/// and the vendor control request that sets its LED (request type 0x41, request 0x01; wValue
/// selects the setting: 1 static brightness, 3 pulse on or off; wIndex is the value). The Linux
/// HID core ignores these ids, so, as with the real knob, only libusb reaches it. Plugged into the
/// guest's vhci_hcd with VhciAttachment, it answers what Basalt's PowerMate backend asks and
/// remembers the LED settings it was sent, which a configfs HID gadget cannot do (it stalls
/// vendor requests).

#include <cstdint>
#include <deque>
#include <mutex>
#include <span>
#include <string>
#include <vector>

#include "tools/vlab/uvc/usb_device.h"

namespace basalt::sim::vlab {

class UsbPowerMate final : public UsbDevice {
 public:
  UsbPowerMate();

  /// \brief Queues one input report (sent on the next IN transfer). Any thread.
  void pushReport(std::uint8_t button, std::int8_t rotation);
  /// \brief The LED as the host last set it: brightness 0..255 and pulse. Any thread.
  struct Led {
    int brightness = -1;  ///< -1 until the host set it
    int pulse = -1;
    int requests = 0;  ///< vendor requests received
  };
  [[nodiscard]] Led led() const;

  [[nodiscard]] const UsbIdentity& identity() const override { return identity_; }
  void reset() override;
  ControlReply control(const UsbSetup& setup, std::span<const std::uint8_t> data, Nanos now) override;
  std::optional<InCompletion> transferIn(std::uint8_t endpoint, std::span<std::uint8_t> buffer, Nanos now) override;
  [[nodiscard]] Nanos readyAt() const override;
  [[nodiscard]] std::string describe() const override { return "077d:0410 Griffin PowerMate (emulated)"; }

  /// \brief The HID report descriptor it serves (a vendor-defined 6-byte input report).
  static const std::vector<std::uint8_t>& reportDescriptor();

 private:
  ControlReply standardRequest(const UsbSetup& s);

  UsbIdentity identity_;
  std::vector<std::uint8_t> deviceDescriptor_;
  std::vector<std::uint8_t> configDescriptor_;
  std::vector<std::vector<std::uint8_t>> strings_;
  std::uint8_t configuration_ = 0;
  mutable std::mutex mutex_;
  std::deque<std::array<std::uint8_t, 6>> reports_;  // guarded by mutex_
  Led led_;                                          // guarded by mutex_
};

}  // namespace basalt::sim::vlab
