#pragma once

/// \file
/// \brief USB/IP for an emulated device: the kernel's virtual host controller (vhci_hcd, in
/// usbip-core and vhci-hcd) takes one end of a socket pair through its sysfs `attach` file, as
/// the `usbip attach` tool hands it a TCP connection, and from then on speaks the USB/IP URB
/// protocol (Documentation/usb/usbip_protocol.rst: CMD_SUBMIT, RET_SUBMIT, CMD_UNLINK,
/// RET_UNLINK; big-endian 48-byte headers) over it; UsbipLink answers with a UsbDevice. The
/// device then appears on a root-hub port of vhci_hcd, inside the same machine.
///
/// Limits: no isochronous transfers (the lab's camera streams over bulk); vhci_hcd is a platform
/// device with no firmware node, which libcamera 0.0.3's UVC pipeline handler needs to name a
/// camera (tools/vlab/README.md).

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "runtime/error.h"
#include "tools/vlab/uvc/usb_link.h"

namespace basalt::sim::vlab {

namespace usbip {

constexpr std::size_t kHeaderSize = 48;
constexpr std::uint32_t kCmdSubmit = 1;
constexpr std::uint32_t kCmdUnlink = 2;
constexpr std::uint32_t kRetSubmit = 3;
constexpr std::uint32_t kRetUnlink = 4;
constexpr std::uint32_t kDirOut = 0;
constexpr std::uint32_t kDirIn = 1;

/// \brief A USB/IP header as the client (vhci_hcd) sends it.
struct Command {
  std::uint32_t command = 0;
  std::uint32_t seqnum = 0;
  std::uint32_t devid = 0;
  std::uint32_t direction = 0;
  std::uint32_t ep = 0;
  // CMD_SUBMIT
  std::uint32_t transferFlags = 0;
  std::int32_t transferBufferLength = 0;
  std::int32_t startFrame = 0;
  std::int32_t numberOfPackets = 0;
  std::int32_t interval = 0;
  std::array<std::uint8_t, 8> setup{};
  // CMD_UNLINK
  std::uint32_t unlinkSeqnum = 0;

  static Command parse(std::span<const std::uint8_t, kHeaderSize> bytes);
  [[nodiscard]] std::array<std::uint8_t, kHeaderSize> bytes() const;
};

/// \brief The RET_SUBMIT header for a URB: status is 0 or a negative errno, as Linux uses it.
std::array<std::uint8_t, kHeaderSize> retSubmit(std::uint32_t seqnum, std::int32_t status, std::uint32_t actualLength,
                                                std::int32_t numberOfPackets);
/// \brief The RET_UNLINK header: status -ECONNRESET when the URB was unlinked, 0 when it had completed.
std::array<std::uint8_t, kHeaderSize> retUnlink(std::uint32_t seqnum, std::int32_t status);
/// \brief The errno a USB/IP RET_SUBMIT reports for a status (0 for kOk).
std::int32_t statusErrno(UsbStatus status);

}  // namespace usbip

/// \brief Serves a UsbDevice to vhci_hcd over a connected stream socket.
class UsbipLink final : public UsbLink {
 public:
  UsbipLink(UniqueFd socket, UsbDevice& device, const Clock& clock) : UsbLink(std::move(socket), device, clock) {}

 private:
  Result<std::size_t> handleMessage(std::span<const std::uint8_t> buffered) override;
  Result<void> sendCompletion(const PendingIn& transfer, UsbStatus status, std::span<const std::uint8_t> data) override;
};

/// \brief A device attached to a port of vhci_hcd; detached when this goes.
class VhciAttachment {
 public:
  static constexpr const char* kDefaultController = "/sys/devices/platform/vhci_hcd.0";

  /// \brief Makes a socket pair, hands one end to a free port of vhci_hcd for `device` (at its
  /// speed: a high-speed port for USB 2.0 devices) and returns the link serving the other end.
  /// Fails with kNotFound when vhci_hcd is not loaded, kResourceExhausted when every port of
  /// that speed is in use, kPermissionDenied without root.
  [[nodiscard]] static Result<VhciAttachment> attach(UsbDevice& device, const Clock& clock,
                                                     const std::filesystem::path& controller = kDefaultController);

  VhciAttachment(VhciAttachment&& other) noexcept;
  VhciAttachment& operator=(VhciAttachment&& other) noexcept;
  VhciAttachment(const VhciAttachment&) = delete;
  VhciAttachment& operator=(const VhciAttachment&) = delete;
  /// Unplugs: writes the port to `detach` (ignoring a port the kernel already let go).
  ~VhciAttachment();

  [[nodiscard]] UsbipLink& link() const { return *link_; }
  [[nodiscard]] int port() const { return port_; }
  /// \brief Unplugs now (the kernel disconnects the device as if its cable were pulled).
  void detach();

 private:
  VhciAttachment(std::unique_ptr<UsbipLink> link, int port, std::filesystem::path controller)
      : link_(std::move(link)), port_(port), controller_(std::move(controller)) {}

  std::unique_ptr<UsbipLink> link_;
  int port_ = -1;
  std::filesystem::path controller_;
};

/// \brief The first free port of vhci_hcd's `status` text for a device of `speed` (hs ports for
/// USB 2.0 speeds, ss ports for SuperSpeed); nothing when none is free. Reads both the layout with
/// a hub column ("hs  0000 004 ...") and the older one without.
std::optional<int> freeVhciPort(const std::string& statusText, UsbSpeed speed);

}  // namespace basalt::sim::vlab
