#pragma once

/// \file
/// \brief A USB device emulated in user space, as the virtual lab's transports see it. A device
/// model (the lab's UVC camera) answers control transfers and IN transfers; a transport (USB/IP
/// to the kernel's vhci_hcd, usbredir to qemu's emulated xHCI) carries the host's requests to
/// it and the answers back. Nothing here knows about sockets.

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "runtime/clock.h"

namespace basalt::sim::vlab {

/// \brief USB 2.0 chapter 9: the standard requests and descriptor types the lab's device
/// models answer.
namespace usb {
constexpr std::uint8_t kGetStatus = 0x00;
constexpr std::uint8_t kClearFeature = 0x01;
constexpr std::uint8_t kSetFeature = 0x03;
constexpr std::uint8_t kSetAddress = 0x05;
constexpr std::uint8_t kGetDescriptor = 0x06;
constexpr std::uint8_t kGetConfiguration = 0x08;
constexpr std::uint8_t kSetConfiguration = 0x09;
constexpr std::uint8_t kGetInterface = 0x0a;
constexpr std::uint8_t kSetInterface = 0x0b;
constexpr std::uint8_t kDescDevice = 1;
constexpr std::uint8_t kDescConfiguration = 2;
constexpr std::uint8_t kDescString = 3;
constexpr std::uint8_t kDescInterface = 4;
constexpr std::uint8_t kDescEndpoint = 5;
constexpr std::uint8_t kDescInterfaceAssociation = 11;
constexpr std::uint16_t kFeatureEndpointHalt = 0;
constexpr std::uint16_t kFeatureRemoteWakeup = 1;
}  // namespace usb

/// \brief The 8-byte SETUP packet of a control transfer (USB 2.0, 9.3).
struct UsbSetup {
  std::uint8_t requestType = 0;  ///< bmRequestType: bit 7 direction (1 = IN), bits 5-6 type, 0-4 recipient
  std::uint8_t request = 0;      ///< bRequest
  std::uint16_t value = 0;       ///< wValue
  std::uint16_t index = 0;       ///< wIndex
  std::uint16_t length = 0;      ///< wLength: bytes of the data stage

  [[nodiscard]] bool isIn() const { return (requestType & 0x80U) != 0; }
  /// \brief 0 standard, 1 class, 2 vendor.
  [[nodiscard]] unsigned type() const { return (requestType >> 5U) & 3U; }
  /// \brief 0 device, 1 interface, 2 endpoint, 3 other.
  [[nodiscard]] unsigned recipient() const { return requestType & 0x1fU; }

  /// \brief The SETUP packet as it goes over the bus (little-endian words).
  [[nodiscard]] std::array<std::uint8_t, 8> bytes() const;
  static UsbSetup fromBytes(std::span<const std::uint8_t, 8> bytes);
};

/// \brief How a transfer ended, in the terms every transport can express.
enum class UsbStatus : std::uint8_t {
  kOk,
  kStall,      ///< the device refused the request (a STALL handshake)
  kCancelled,  ///< the host cancelled (unlinked) the transfer
  kError,      ///< the transfer failed otherwise
};

/// \brief The answer to a control transfer: a status and, for IN transfers, the data stage.
struct ControlReply {
  UsbStatus status = UsbStatus::kOk;
  std::vector<std::uint8_t> data;  ///< at most UsbSetup::length bytes; empty for OUT transfers

  static ControlReply stall() { return {UsbStatus::kStall, {}}; }
};

/// \brief An IN control transfer's answer: `data`, cut to the `wLength` the host asked for.
ControlReply controlReply(std::vector<std::uint8_t> data, std::uint16_t wLength);
/// \brief A string descriptor of `text` (ASCII, as UTF-16LE).
std::vector<std::uint8_t> stringDescriptor(const std::string& text);

/// \brief The result of an IN transfer that completed: how many bytes of the buffer it filled.
struct InCompletion {
  UsbStatus status = UsbStatus::kOk;
  std::size_t length = 0;
};

enum class UsbSpeed : std::uint8_t { kLow, kFull, kHigh, kSuper };
enum class UsbEndpointType : std::uint8_t { kControl = 0, kIsochronous = 1, kBulk = 2, kInterrupt = 3 };

/// \brief An endpoint of the active configuration (what usbredir's ep_info announces).
struct UsbEndpointInfo {
  std::uint8_t address = 0;  ///< bEndpointAddress: bit 7 set for IN
  UsbEndpointType type = UsbEndpointType::kBulk;
  std::uint16_t maxPacketSize = 0;
  std::uint8_t interval = 0;
  std::uint8_t interfaceNumber = 0;
};

/// \brief An interface of the active configuration (what usbredir's interface_info announces).
struct UsbInterfaceInfo {
  std::uint8_t number = 0;
  std::uint8_t interfaceClass = 0;
  std::uint8_t interfaceSubClass = 0;
  std::uint8_t interfaceProtocol = 0;
};

/// \brief What a transport tells the host before any descriptor is read.
struct UsbIdentity {
  UsbSpeed speed = UsbSpeed::kHigh;
  std::uint8_t deviceClass = 0;
  std::uint8_t deviceSubClass = 0;
  std::uint8_t deviceProtocol = 0;
  std::uint16_t vendor = 0;
  std::uint16_t product = 0;
  std::uint16_t bcdDevice = 0;
  std::vector<UsbInterfaceInfo> interfaces;
  std::vector<UsbEndpointInfo> endpoints;  ///< not endpoint 0
};

/// \brief A USB device model. One thread (the transport's) calls it; `now` is the transport's
/// clock reading, so that a model's timing runs on any Clock.
class UsbDevice {
 public:
  virtual ~UsbDevice() = default;

  [[nodiscard]] virtual const UsbIdentity& identity() const = 0;
  /// \brief A bus reset: address 0, unconfigured, every stream stopped.
  virtual void reset() = 0;
  /// \brief A control transfer on endpoint 0: the SETUP packet and, for OUT transfers, the data
  /// stage the host sent.
  virtual ControlReply control(const UsbSetup& setup, std::span<const std::uint8_t> data, Nanos now) = 0;
  /// \brief An IN transfer (bulk or interrupt) of up to `buffer.size()` bytes on `endpoint`.
  /// Returns how it completes now, having filled the front of `buffer`, or nothing when the
  /// device has no data yet (the host keeps asking, as a NAKed transfer stays queued).
  virtual std::optional<InCompletion> transferIn(std::uint8_t endpoint, std::span<std::uint8_t> buffer, Nanos now) = 0;
  /// \brief When an IN transfer that got nothing may complete: `now` or earlier means at once,
  /// Nanos::max() not before the next control transfer.
  [[nodiscard]] virtual Nanos readyAt() const = 0;
  /// \brief A one-line description of the device for logs ("1209:0002 Basalt Lab Camera").
  [[nodiscard]] virtual std::string describe() const = 0;
};

}  // namespace basalt::sim::vlab
