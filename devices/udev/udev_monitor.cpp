// Hotplug through libudev: a netlink monitor filtered by subsystem, read on a thread that also
// watches an eventfd for stop(). Limits: events come from udevd ("udev" source); where udevd is
// not running (containers, initramfs) create() fails and the DeviceManager's retries find devices.

#include "devices/udev/udev_monitor.h"

#include <libudev.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <thread>

#include "runtime/unique_fd.h"

namespace basalt::devices {

namespace {
struct UdevUnref {
  void operator()(udev* u) const { udev_unref(u); }
};
struct MonitorUnref {
  void operator()(udev_monitor* m) const { udev_monitor_unref(m); }
};
struct DeviceUnref {
  void operator()(udev_device* d) const { udev_device_unref(d); }
};
}  // namespace

struct UdevMonitor::Impl {
  std::unique_ptr<struct udev, UdevUnref> context;
  std::unique_ptr<udev_monitor, MonitorUnref> monitor;
  UniqueFd stopFd;
  std::thread thread;
};

UdevMonitor::UdevMonitor(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

UdevMonitor::~UdevMonitor() { stop(); }

Result<std::unique_ptr<UdevMonitor>> UdevMonitor::create(std::vector<std::string> subsystems) {
  if (subsystems.empty()) subsystems = {"hidraw", "video4linux", "usb", "tty"};
  auto impl = std::make_unique<Impl>();
  impl->context.reset(udev_new());
  if (!impl->context) return fail(Errc::kUnavailable, "libudev could not start", "udev");
  impl->monitor.reset(udev_monitor_new_from_netlink(impl->context.get(), "udev"));
  if (!impl->monitor) {
    return fail(Errc::kUnavailable, "no udev netlink socket (is udevd running?); devices are found by retrying",
                "udev");
  }
  for (const std::string& s : subsystems) {
    udev_monitor_filter_add_match_subsystem_devtype(impl->monitor.get(), s.c_str(), nullptr);
  }
  if (udev_monitor_enable_receiving(impl->monitor.get()) < 0) {
    return fail(Errc::kUnavailable, "cannot listen to udev events; devices are found by retrying", "udev");
  }
  impl->stopFd.reset(::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK));
  if (!impl->stopFd) return fail(Errc::kResourceExhausted, systemErrorText("eventfd", errno), "udev");
  return std::unique_ptr<UdevMonitor>(new UdevMonitor(std::move(impl)));
}

void UdevMonitor::start(std::function<void(HotplugEvent)> notify) {
  if (impl_->thread.joinable()) return;
  impl_->thread = std::thread([impl = impl_.get(), notify = std::move(notify)] {
    const int fd = udev_monitor_get_fd(impl->monitor.get());
    for (;;) {
      pollfd fds[2] = {{fd, POLLIN, 0}, {impl->stopFd.get(), POLLIN, 0}};
      if (::poll(fds, 2, -1) < 0) {
        if (errno == EINTR) continue;
        return;
      }
      if (fds[1].revents) return;
      std::unique_ptr<udev_device, DeviceUnref> dev(udev_monitor_receive_device(impl->monitor.get()));
      if (!dev) continue;
      const char* action = udev_device_get_action(dev.get());
      const char* node = udev_device_get_devnode(dev.get());
      const char* subsystem = udev_device_get_subsystem(dev.get());
      HotplugEvent e;
      const std::string a = action ? action : "";
      if (a == "add" || a == "bind") {
        e.action = HotplugEvent::Action::kAdded;
      } else if (a == "remove" || a == "unbind") {
        e.action = HotplugEvent::Action::kRemoved;
      } else {
        e.action = HotplugEvent::Action::kChanged;
      }
      e.subsystem = subsystem ? subsystem : "";
      e.devnode = node ? node : "";
      notify(std::move(e));
    }
  });
}

void UdevMonitor::stop() {
  if (!impl_ || !impl_->thread.joinable()) return;
  const std::uint64_t one = 1;
  (void)!::write(impl_->stopFd.get(), &one, sizeof one);
  impl_->thread.join();
}

}  // namespace basalt::devices
