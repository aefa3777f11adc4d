#pragma once

/// \file
/// \brief What the transports of an emulated USB device share: a connected stream socket to
/// the host side (the kernel's vhci_hcd, or qemu), the messages read from it, and the IN
/// transfers the host has queued and the device has not answered yet. A protocol (USB/IP,
/// usbredir) derives from UsbLink and codes its messages.
///
/// Threading: one thread drives a link: it polls fd(), calls onReadable() when it is readable
/// and serviceTransfers() at nextDeadline().

#include <cstddef>
#include <cstdint>
#include <deque>
#include <span>
#include <vector>

#include "runtime/clock.h"
#include "runtime/error.h"
#include "runtime/unique_fd.h"
#include "tools/vlab/uvc/usb_device.h"

namespace basalt::sim::vlab {

/// \brief An IN transfer the host queued on an endpoint, waiting for the device's data.
struct PendingIn {
  std::uint64_t id = 0;  ///< the protocol's request id (USB/IP seqnum, usbredir packet id)
  std::uint8_t endpoint = 0;
  std::uint32_t length = 0;
  std::uint32_t extra = 0;  ///< protocol-specific (USB/IP: number_of_packets to echo)
};

class UsbLink {
 public:
  /// \brief At most this many IN transfers wait at once; more are failed (uvcvideo queues 5).
  static constexpr std::size_t kMaxPending = 64;

  UsbLink(UniqueFd socket, UsbDevice& device, const Clock& clock);
  virtual ~UsbLink() = default;
  UsbLink(const UsbLink&) = delete;
  UsbLink& operator=(const UsbLink&) = delete;

  [[nodiscard]] int fd() const { return socket_.get(); }
  /// \brief Reads what the host sent and answers every complete message. Fails with
  /// kDeviceLost when the host closed the connection, kParse for a message that makes no sense
  /// (the link must then be dropped), kIo when the socket fails.
  [[nodiscard]] Result<void> onReadable();
  /// \brief Completes the queued IN transfers the device has data for now.
  [[nodiscard]] Result<void> serviceTransfers();
  /// \brief When serviceTransfers() has work: Nanos::max() when no transfer waits or the device
  /// waits for the host.
  [[nodiscard]] Nanos nextDeadline() const;
  [[nodiscard]] std::size_t pendingTransfers() const { return pending_.size(); }
  /// \brief Bytes and messages handled, for the program's summary.
  [[nodiscard]] std::uint64_t messagesIn() const { return messagesIn_; }
  [[nodiscard]] std::uint64_t transfersCompleted() const { return transfersCompleted_; }

 protected:
  /// \brief Handles the message at the front of `buffered`: returns the bytes it used, 0 when
  /// the message is not complete yet, or an error for garbage.
  [[nodiscard]] virtual Result<std::size_t> handleMessage(std::span<const std::uint8_t> buffered) = 0;
  /// \brief Sends the completion of an IN transfer; `data` is what the device filled.
  [[nodiscard]] virtual Result<void> sendCompletion(const PendingIn& transfer, UsbStatus status,
                                                    std::span<const std::uint8_t> data) = 0;

  /// \brief Writes the parts in order, whole (blocking until the peer has taken them).
  [[nodiscard]] Result<void> send(std::span<const std::uint8_t> head, std::span<const std::uint8_t> body = {});
  /// \brief Queues an IN transfer; false when too many wait.
  bool queueIn(const PendingIn& transfer);
  /// \brief Removes a queued transfer; false when it is not queued (already completed).
  bool cancelIn(std::uint64_t id, PendingIn* removed = nullptr);
  /// \brief Removes every queued transfer, calling `each` for it.
  template <typename F>
  void drainPending(const F& each) {
    while (!pending_.empty()) {
      const PendingIn p = pending_.front();
      pending_.pop_front();
      each(p);
    }
  }
  [[nodiscard]] Nanos now() const { return clock_.now(); }

  UsbDevice& device_;

 private:
  UniqueFd socket_;
  const Clock& clock_;
  std::vector<std::uint8_t> in_;  // received bytes; in_[inStart_..] not handled yet
  std::size_t inStart_ = 0;
  std::deque<PendingIn> pending_;
  std::vector<std::uint8_t> transfer_;
  std::uint64_t messagesIn_ = 0;
  std::uint64_t transfersCompleted_ = 0;
};

// Byte order helpers for the protocols.
inline std::uint32_t readBe32(std::span<const std::uint8_t> b, std::size_t at) {
  return (std::uint32_t{b[at]} << 24U) | (std::uint32_t{b[at + 1]} << 16U) | (std::uint32_t{b[at + 2]} << 8U) |
         std::uint32_t{b[at + 3]};
}
inline void writeBe32(std::span<std::uint8_t> b, std::size_t at, std::uint32_t v) {
  b[at] = static_cast<std::uint8_t>(v >> 24U);
  b[at + 1] = static_cast<std::uint8_t>(v >> 16U);
  b[at + 2] = static_cast<std::uint8_t>(v >> 8U);
  b[at + 3] = static_cast<std::uint8_t>(v);
}
inline std::uint16_t readLe16(std::span<const std::uint8_t> b, std::size_t at) {
  return static_cast<std::uint16_t>(b[at] | (b[at + 1] << 8U));
}
inline std::uint32_t readLe32(std::span<const std::uint8_t> b, std::size_t at) {
  return std::uint32_t{readLe16(b, at)} | (std::uint32_t{readLe16(b, at + 2)} << 16U);
}
inline std::uint64_t readLe64(std::span<const std::uint8_t> b, std::size_t at) {
  return std::uint64_t{readLe32(b, at)} | (std::uint64_t{readLe32(b, at + 4)} << 32U);
}
inline void appendLe16(std::vector<std::uint8_t>& v, unsigned x) {
  v.push_back(static_cast<std::uint8_t>(x));
  v.push_back(static_cast<std::uint8_t>(x >> 8U));
}
inline void appendLe32(std::vector<std::uint8_t>& v, std::uint32_t x) {
  appendLe16(v, x & 0xffffU);
  appendLe16(v, x >> 16U);
}

}  // namespace basalt::sim::vlab
