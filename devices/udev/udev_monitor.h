#pragma once

/// \file
/// \brief Hotplug notifications from udev (libudev's netlink monitor): hidraw, video4linux, usb
/// and tty devices appearing and vanishing, turned into HotplugEvents for the DeviceManager.
/// Includes no libudev header: it stays in devices/udev/udev_monitor.cpp.

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "devices/device_manager.h"

namespace basalt::devices {

/// \brief A udev monitor on a thread of its own.
///
/// Threading: `notify` is called on the monitor's thread (DeviceManager::notifyHotplug is
/// thread-safe). start()/stop() from the owner's thread.
class UdevMonitor {
 public:
  /// \brief Subscribes to `subsystems` (default: hidraw, video4linux, usb, tty). Fails where udev
  /// has no netlink socket (some containers): then devices are found by retries alone.
  [[nodiscard]] static Result<std::unique_ptr<UdevMonitor>> create(std::vector<std::string> subsystems = {});
  ~UdevMonitor();
  UdevMonitor(const UdevMonitor&) = delete;
  UdevMonitor& operator=(const UdevMonitor&) = delete;

  void start(std::function<void(HotplugEvent)> notify);
  void stop();

 private:
  struct Impl;
  explicit UdevMonitor(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace basalt::devices
