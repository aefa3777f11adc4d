#pragma once

/// \file
/// \brief usbredir for an emulated device: the protocol of qemu's `usb-redir` device (the
/// "USB network redirection protocol", version 0.7, of the usbredir project: little-endian
/// packed headers; hello, ep_info, interface_info and device_connect from the device side, then
/// control, bulk and configuration packets). qemu plugs the device into the guest's emulated
/// USB controller (qemu-xhci here), so the guest sees it behind a PCI host controller with an
/// ACPI node, as it would see a webcam on a real machine. Closing the connection unplugs it.
///
/// Limits: no isochronous streams, no interrupt endpoints, no bulk streams, no buffered bulk
/// receiving (the lab's camera needs none of them; such requests are answered with an error).

#include <cstdint>
#include <string>
#include <vector>

#include "tools/vlab/uvc/usb_link.h"

namespace basalt::sim::vlab {

namespace usbredir {

// Packet types.
constexpr std::uint32_t kHello = 0;
constexpr std::uint32_t kDeviceConnect = 1;
constexpr std::uint32_t kDeviceDisconnect = 2;
constexpr std::uint32_t kReset = 3;
constexpr std::uint32_t kInterfaceInfo = 4;
constexpr std::uint32_t kEpInfo = 5;
constexpr std::uint32_t kSetConfiguration = 6;
constexpr std::uint32_t kGetConfiguration = 7;
constexpr std::uint32_t kConfigurationStatus = 8;
constexpr std::uint32_t kSetAltSetting = 9;
constexpr std::uint32_t kGetAltSetting = 10;
constexpr std::uint32_t kAltSettingStatus = 11;
constexpr std::uint32_t kStartIsoStream = 12;
constexpr std::uint32_t kStopIsoStream = 13;
constexpr std::uint32_t kIsoStreamStatus = 14;
constexpr std::uint32_t kStartInterruptReceiving = 15;
constexpr std::uint32_t kStopInterruptReceiving = 16;
constexpr std::uint32_t kInterruptReceivingStatus = 17;
constexpr std::uint32_t kAllocBulkStreams = 18;
constexpr std::uint32_t kFreeBulkStreams = 19;
constexpr std::uint32_t kBulkStreamsStatus = 20;
constexpr std::uint32_t kCancelDataPacket = 21;
constexpr std::uint32_t kFilterReject = 22;
constexpr std::uint32_t kFilterFilter = 23;
constexpr std::uint32_t kDeviceDisconnectAck = 24;
constexpr std::uint32_t kStartBulkReceiving = 25;
constexpr std::uint32_t kStopBulkReceiving = 26;
constexpr std::uint32_t kBulkReceivingStatus = 27;
constexpr std::uint32_t kControlPacket = 100;
constexpr std::uint32_t kBulkPacket = 101;
constexpr std::uint32_t kIsoPacket = 102;
constexpr std::uint32_t kInterruptPacket = 103;
constexpr std::uint32_t kBufferedBulkPacket = 104;

// Capability bits.
constexpr std::uint32_t kCapBulkStreams = 1U << 0U;
constexpr std::uint32_t kCapConnectDeviceVersion = 1U << 1U;
constexpr std::uint32_t kCapFilter = 1U << 2U;
constexpr std::uint32_t kCapDeviceDisconnectAck = 1U << 3U;
constexpr std::uint32_t kCapEpInfoMaxPacketSize = 1U << 4U;
constexpr std::uint32_t kCap64BitIds = 1U << 5U;
constexpr std::uint32_t kCap32BitBulkLength = 1U << 6U;
constexpr std::uint32_t kCapBulkReceiving = 1U << 7U;

/// \brief What this side announces: device version in device_connect, max packet sizes in
/// ep_info, 64-bit ids, 32-bit bulk lengths.
constexpr std::uint32_t kOurCaps =
    kCapConnectDeviceVersion | kCapEpInfoMaxPacketSize | kCap64BitIds | kCap32BitBulkLength;

// Status codes.
constexpr std::uint8_t kSuccess = 0;
constexpr std::uint8_t kCancelled = 1;
constexpr std::uint8_t kInval = 2;
constexpr std::uint8_t kIoError = 3;
constexpr std::uint8_t kStall = 4;

std::uint8_t statusCode(UsbStatus status);

/// \brief The header of every packet: 12 bytes, or 16 once both sides have 64-bit ids.
struct Header {
  std::uint32_t type = 0;
  std::uint32_t length = 0;  ///< bytes after the header
  std::uint64_t id = 0;
};

/// \brief Appends a header with 32-bit or 64-bit id.
void appendHeader(std::vector<std::uint8_t>& out, const Header& h, bool ids64);

}  // namespace usbredir

/// \brief Serves a UsbDevice to qemu's usb-redir device over a connected stream socket.
class UsbredirLink final : public UsbLink {
 public:
  UsbredirLink(UniqueFd socket, UsbDevice& device, const Clock& clock) : UsbLink(std::move(socket), device, clock) {}

  /// \brief Sends our hello; the device is announced once qemu's hello has come.
  [[nodiscard]] Result<void> start();
  /// \brief Whether qemu's hello has come and the device has been announced.
  [[nodiscard]] bool connected() const { return connected_; }
  [[nodiscard]] std::uint32_t peerCaps() const { return peerCaps_; }
  [[nodiscard]] const std::string& peerVersion() const { return peerVersion_; }

 private:
  Result<std::size_t> handleMessage(std::span<const std::uint8_t> buffered) override;
  Result<void> sendCompletion(const PendingIn& transfer, UsbStatus status, std::span<const std::uint8_t> data) override;
  [[nodiscard]] bool both(std::uint32_t cap) const { return (peerCaps_ & cap) != 0 && (usbredir::kOurCaps & cap) != 0; }
  [[nodiscard]] std::size_t headerSize() const { return both(usbredir::kCap64BitIds) ? 16 : 12; }
  Result<void> sendPacket(std::uint32_t type, std::uint64_t id, std::span<const std::uint8_t> body,
                          std::span<const std::uint8_t> data = {});
  Result<void> announceDevice();
  Result<void> sendEndpointsAndInterfaces();
  Result<void> handle(const usbredir::Header& h, std::span<const std::uint8_t> body);
  Result<void> handleControl(const usbredir::Header& h, std::span<const std::uint8_t> body);
  Result<void> handleBulk(const usbredir::Header& h, std::span<const std::uint8_t> body);

  bool helloReceived_ = false;
  bool connected_ = false;
  std::uint32_t peerCaps_ = 0;
  std::string peerVersion_;
  std::vector<std::uint8_t> out_;
};

}  // namespace basalt::sim::vlab
