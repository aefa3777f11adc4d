#pragma once

/// \file
/// \brief A HID device made by the kernel from user space (/dev/uhid), for the virtual lab:
/// replays of HID recordings, and devices that tests make up. The kernel binds it like any HID
/// device (hid-generic, hidraw), so Basalt's real hidraw backend reads it as it reads hardware.

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "runtime/error.h"
#include "runtime/unique_fd.h"

namespace basalt::sim::vlab {

/// \brief What the kernel is told about the device.
struct UhidIdentity {
  std::string name;
  std::string phys;
  /// Unique among the lab's uhid devices; create() fills one in when empty. It is how
  /// hidrawNode() finds this device's node among others with the same ids.
  std::string uniq;
  std::uint16_t bus = 3;  ///< BUS_USB
  std::uint16_t vendor = 0;
  std::uint16_t product = 0;
  std::uint32_t version = 0;
  std::vector<std::uint8_t> descriptor;
};

/// \brief One uhid device; destroyed (unplugged) when this object goes.
///
/// Threading: one thread uses an object at a time. The kernel's requests (open, close,
/// get/set report) are answered by service(), which the wait calls run too.
class UhidDevice {
 public:
  /// \brief Creates the device through `uhid` (default /dev/uhid). Fails with kNotFound or
  /// kPermissionDenied when uhid is missing, kInvalidArgument for a descriptor the kernel
  /// cannot take (empty or larger than 4096 bytes).
  [[nodiscard]] static Result<UhidDevice> create(UhidIdentity identity,
                                                 const std::filesystem::path& uhid = "/dev/uhid");

  UhidDevice(UhidDevice&&) noexcept = default;
  UhidDevice& operator=(UhidDevice&&) noexcept = default;
  UhidDevice(const UhidDevice&) = delete;
  UhidDevice& operator=(const UhidDevice&) = delete;
  ~UhidDevice() = default;  // closing /dev/uhid destroys the device

  /// \brief Sends one input report, as the device would over its interrupt endpoint.
  [[nodiscard]] Result<void> sendInput(std::span<const std::uint8_t> report);
  /// \brief Answers the kernel's pending requests without blocking.
  void service();
  /// \brief Waits until a reader opens the device (the kernel says UHID_OPEN).
  [[nodiscard]] Result<void> waitOpened(std::chrono::milliseconds limit);
  /// \brief The /dev/hidrawN the kernel made for this device, waiting up to `limit` for it.
  [[nodiscard]] Result<std::filesystem::path> hidrawNode(std::chrono::milliseconds limit);

  [[nodiscard]] const UhidIdentity& identity() const { return identity_; }
  [[nodiscard]] bool started() const { return started_; }
  [[nodiscard]] bool opened() const { return opened_; }
  /// \brief Whether a reader has opened the device at any time since it was made.
  [[nodiscard]] bool everOpened() const { return everOpened_; }
  /// \brief Replies to the kernel's get/set report requests that could not be written.
  [[nodiscard]] int failedReplies() const { return failedReplies_; }
  /// \brief Output reports the host sent (LEDs, haptics), oldest first.
  [[nodiscard]] const std::vector<std::vector<std::uint8_t>>& outputs() const { return outputs_; }

 private:
  UhidDevice(UniqueFd fd, UhidIdentity identity) : fd_(std::move(fd)), identity_(std::move(identity)) {}
  /// Reads and answers one kernel event if one is ready within `timeoutMs`.
  bool pump(int timeoutMs);

  UniqueFd fd_;
  UhidIdentity identity_;
  bool started_ = false;
  bool opened_ = false;
  bool everOpened_ = false;
  int failedReplies_ = 0;
  std::vector<std::vector<std::uint8_t>> outputs_;
};

}  // namespace basalt::sim::vlab
