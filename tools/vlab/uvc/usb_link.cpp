#include "tools/vlab/uvc/usb_link.h"

#include <sys/socket.h>

#include <algorithm>
#include <cerrno>

namespace basalt::sim::vlab {

UsbLink::UsbLink(UniqueFd socket, UsbDevice& device, const Clock& clock)
    : device_(device), socket_(std::move(socket)), clock_(clock) {}

Result<void> UsbLink::onReadable() {
  std::uint8_t chunk[65536];
  for (;;) {
    const ssize_t n = ::recv(socket_.get(), chunk, sizeof chunk, MSG_DONTWAIT);
    if (n == 0) return fail(Errc::kDeviceLost, "the host side closed the connection");
    if (n < 0) {
      if (errno == EINTR) continue;
      if (errno == EAGAIN) break;  // (EWOULDBLOCK is EAGAIN on Linux)
      if (errno == ECONNRESET) return fail(Errc::kDeviceLost, "the host side reset the connection");
      return fail(Errc::kIo, systemErrorText("reading from the host side", errno));
    }
    in_.insert(in_.end(), chunk, chunk + n);
    if (static_cast<std::size_t>(n) < sizeof chunk) break;
  }
  while (inStart_ < in_.size()) {
    auto used = handleMessage(std::span<const std::uint8_t>(in_).subspan(inStart_));
    if (!used) return std::unexpected(used.error());
    if (*used == 0) break;
    inStart_ += *used;
    ++messagesIn_;
  }
  if (inStart_ == in_.size()) {
    in_.clear();
    inStart_ = 0;
  } else if (inStart_ > in_.size() / 2) {
    in_.erase(in_.begin(), in_.begin() + static_cast<std::ptrdiff_t>(inStart_));
    inStart_ = 0;
  }
  return serviceTransfers();
}

Result<void> UsbLink::serviceTransfers() {
  // Per endpoint, transfers complete in the order they were queued; an endpoint whose first
  // transfer gets no data holds its others back.
  std::uint32_t blocked = 0;  // bit per endpoint number, IN endpoints only
  for (auto it = pending_.begin(); it != pending_.end();) {
    const std::uint32_t bit = 1U << (it->endpoint & 0x0fU);
    if ((blocked & bit) != 0) {
      ++it;
      continue;
    }
    transfer_.resize(it->length);
    const auto done = device_.transferIn(it->endpoint, transfer_, clock_.now());
    if (!done) {
      blocked |= bit;
      ++it;
      continue;
    }
    const PendingIn p = *it;
    it = pending_.erase(it);
    ++transfersCompleted_;
    if (auto sent = sendCompletion(p, done->status, std::span<const std::uint8_t>(transfer_).first(done->length));
        !sent) {
      return sent;
    }
  }
  return {};
}

Nanos UsbLink::nextDeadline() const { return pending_.empty() ? Nanos::max() : device_.readyAt(); }

Result<void> UsbLink::send(std::span<const std::uint8_t> head, std::span<const std::uint8_t> body) {
  for (auto part : {head, body}) {
    while (!part.empty()) {
      const ssize_t n = ::send(socket_.get(), part.data(), part.size(), MSG_NOSIGNAL);
      if (n < 0) {
        if (errno == EINTR) continue;
        if (errno == EPIPE || errno == ECONNRESET) {
          return fail(Errc::kDeviceLost, "the host side closed the connection");
        }
        return fail(Errc::kIo, systemErrorText("writing to the host side", errno));
      }
      part = part.subspan(static_cast<std::size_t>(n));
    }
  }
  return {};
}

bool UsbLink::queueIn(const PendingIn& transfer) {
  if (pending_.size() >= kMaxPending) return false;
  pending_.push_back(transfer);
  return true;
}

bool UsbLink::cancelIn(std::uint64_t id, PendingIn* removed) {
  const auto it = std::find_if(pending_.begin(), pending_.end(), [&](const PendingIn& p) { return p.id == id; });
  if (it == pending_.end()) return false;
  if (removed) *removed = *it;
  pending_.erase(it);
  return true;
}

}  // namespace basalt::sim::vlab
