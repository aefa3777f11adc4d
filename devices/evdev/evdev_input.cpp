// EvdevInput: keyboards, mice and touchpads read from the kernel's evdev nodes, for a kiosk on
// KMS where no window system delivers keys.
//
// Hardware: any keyboard, numeric pad, mouse, trackball or touchpad the kernel has an input
// driver for (USB and Bluetooth HID, PS/2, i8042 touchpads), and uinput devices (the tests).
// Limits: touchscreens, tablets, joysticks, power buttons and the HID dial boxes' own input nodes
// are left alone (devices/evdev/evdev_decoder.h: classifyEvdev); keys are Linux key codes, not
// characters (no keymap: the show's keys are positions, as the thesis' are); devices are not
// grabbed, so the console underneath sees the keys as well.
// Configuration: EvdevOptions (the manifest's [input] section); the node needs read permission
// for the show's user: the `input` group (configs/systemd/basalt.service, configs/udev).

#include "devices/evdev/evdev_input.h"

#include <fcntl.h>
#include <linux/input.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include <fmt/format.h>

#include "devices/evdev/evdev_decoder.h"
#include "devices/udev/udev_monitor.h"
#include "runtime/bounded_queue.h"
#include "runtime/log.h"
#include "runtime/unique_fd.h"

BASALT_LOG_CATEGORY(Evdev, "devices");

namespace basalt::devices {

namespace {

constexpr std::size_t kQueueCapacity = 1024;

bool isEventNode(const std::filesystem::path& path) { return path.filename().string().starts_with("event"); }

/// The name sysfs gives the node's device: readable by everyone, also where the node is not.
std::string sysfsName(const std::filesystem::path& node) {
  std::ifstream in("/sys/class/input/" + node.filename().string() + "/device/name");
  std::string name;
  std::getline(in, name);
  return name;
}

template <std::size_t N>
bool readBits(int fd, unsigned type, std::bitset<N>& bits) {
  std::array<std::uint8_t, (N + 7) / 8> bytes{};
  if (::ioctl(fd, EVIOCGBIT(type, bytes.size()), bytes.data()) < 0) return false;
  bits = EvdevCapabilities::fromBytes<N>(bytes);
  return true;
}

struct OpenDevice {
  std::filesystem::path path;
  std::string name;
  UniqueFd fd;
  EvdevDecoder decoder;
  ino_t inode = 0;
};

}  // namespace

std::string evdevOpenProblem(const std::string& path, const std::string& name, int errnum) {
  const std::string who = name.empty() ? path : fmt::format("{} ('{}')", path, name);
  if (errnum == EACCES || errnum == EPERM) {
    return fmt::format(
        "cannot read input device {}: permission denied; keyboards and mice reach the show only when its user may "
        "read /dev/input/event*: add the user to the 'input' group (adduser basalt input; the unit "
        "configs/systemd/basalt.service has SupplementaryGroups=input and DeviceAllow=char-input) and install "
        "configs/udev/70-basalt.rules",
        who);
  }
  if (errnum == ENOENT || errnum == ENODEV) {
    return fmt::format("input device {} is gone (unplugged while it was opened)", who);
  }
  return systemErrorText(fmt::format("cannot open input device {}", who), errnum);
}

struct EvdevInput::Impl {
  const Clock& clock;
  EvdevOptions options;
  BoundedQueue<Event> queue;
  std::unique_ptr<UdevMonitor> udev;
  UniqueFd stopFd;     // written by stop()
  UniqueFd hotplugFd;  // written by the udev thread when an event node was added
  std::thread thread;
  std::atomic<bool> stopping{false};

  // Reader thread only.
  std::vector<std::unique_ptr<OpenDevice>> open;
  std::map<std::string, ino_t> leftAlone;  // nodes not read, by path, with the inode they had
  std::set<std::string> warned;            // nodes whose open failure was reported
  std::uint32_t nextId = 0;

  // Guarded by infoMutex: what devices() returns.
  mutable std::mutex infoMutex;
  std::vector<EvdevDeviceInfo> info;

  Impl(const Clock& c, EvdevOptions o, std::function<void()> wake)
      : clock(c), options(std::move(o)), queue(kQueueCapacity, std::move(wake)) {}

  void push(std::span<const Event> events) {
    const Nanos now = clock.now();
    for (Event e : events) {
      e.time = now;
      queue.push(e);
    }
  }

  void setInfo(EvdevDeviceInfo entry) {
    std::lock_guard lock(infoMutex);
    auto it = std::find_if(info.begin(), info.end(), [&](const EvdevDeviceInfo& i) { return i.path == entry.path; });
    if (it != info.end()) {
      *it = std::move(entry);
    } else {
      info.push_back(std::move(entry));
    }
  }

  void removeInfo(const std::string& path) {
    std::lock_guard lock(infoMutex);
    std::erase_if(info, [&](const EvdevDeviceInfo& i) { return i.path == path; });
  }

  bool wanted(const std::string& name) const {
    if (options.names.empty()) return true;
    return std::any_of(options.names.begin(), options.names.end(),
                       [&](const std::string& n) { return name.find(n) != std::string::npos; });
  }

  void leaveAlone(const std::filesystem::path& path, ino_t inode, const std::string& name, std::string why) {
    leftAlone[path.string()] = inode;
    setInfo({path.string(), name, std::move(why), false, 0});
  }

  /// Opens `path` when it is a keyboard or pointer the options want; otherwise notes why not.
  void consider(const std::filesystem::path& path) {
    const std::string key = path.string();
    struct stat st{};
    if (::stat(key.c_str(), &st) != 0 || !S_ISCHR(st.st_mode)) return;
    for (const auto& d : open) {
      if (d->path == path) {
        if (d->inode == st.st_ino) return;  // already reading it
      }
    }
    if (auto it = leftAlone.find(key); it != leftAlone.end() && it->second == st.st_ino) return;
    UniqueFd fd(::open(key.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC));
    if (!fd) {
      const int err = errno;
      const std::string name = sysfsName(path);
      if (warned.insert(key).second) log::warn(kLogEvdev, "{}", evdevOpenProblem(key, name, err));
      leaveAlone(path, st.st_ino, name, evdevOpenProblem(key, name, err));
      return;
    }
    warned.erase(key);
    std::array<char, 256> nameBuffer{};
    std::string name;
    if (::ioctl(fd.get(), EVIOCGNAME(nameBuffer.size() - 1), nameBuffer.data()) >= 0) name = nameBuffer.data();
    EvdevCapabilities caps;
    if (!readBits(fd.get(), 0, caps.types)) {
      leaveAlone(path, st.st_ino, name, "not an evdev device (EVIOCGBIT failed)");
      return;
    }
    (void)readBits(fd.get(), EV_KEY, caps.keys);
    (void)readBits(fd.get(), EV_REL, caps.relative);
    (void)readBits(fd.get(), EV_ABS, caps.absolute);
    std::array<std::uint8_t, (INPUT_PROP_CNT + 7) / 8> props{};
    if (::ioctl(fd.get(), EVIOCGPROP(props.size()), props.data()) >= 0) {
      caps.properties = EvdevCapabilities::fromBytes<INPUT_PROP_CNT>(props);
    }
    input_absinfo abs{};
    if (caps.absolute[ABS_X] && ::ioctl(fd.get(), EVIOCGABS(ABS_X), &abs) >= 0) caps.resolutionX = abs.resolution;
    if (caps.absolute[ABS_Y] && ::ioctl(fd.get(), EVIOCGABS(ABS_Y), &abs) >= 0) caps.resolutionY = abs.resolution;
    EvdevRoles roles = classifyEvdev(caps);
    if (!options.keyboards) roles.keyboard = false;
    if (!options.pointers) roles.pointer = roles.touchpad = false;
    if (!roles.any()) {
      leaveAlone(path, st.st_ino, name,
                 classifyEvdev(caps).any() ? std::string("not asked for (input.keyboards/pointers)")
                                           : std::string(evdevRolesName(roles)));
      return;
    }
    if (!wanted(name)) {
      leaveAlone(path, st.st_ino, name, "not named in input.names");
      return;
    }
    // A node reused by a new device: the old one is gone.
    std::erase_if(open, [&](const std::unique_ptr<OpenDevice>& d) { return d->path == path; });
    const DeviceId id = kEvdevDeviceIdBase + (nextId++ % 256);
    auto device =
        std::make_unique<OpenDevice>(OpenDevice{path, name, std::move(fd), EvdevDecoder(roles, id, caps), st.st_ino});
    // Keys already down when it is opened: the show learns of them as presses.
    std::array<std::uint8_t, (KEY_CNT + 7) / 8> keys{};
    if (::ioctl(device->fd.get(), EVIOCGKEY(keys.size()), keys.data()) >= 0) push(device->decoder.resync(keys));
    leftAlone.erase(key);
    log::info(kLogEvdev, "reading {} '{}' at {}", evdevRolesName(roles), name, key);
    setInfo({key, name, evdevRolesName(roles), true, id});
    open.push_back(std::move(device));
  }

  void scan() {
    std::error_code ec;
    std::vector<std::filesystem::path> nodes;
    for (const auto& entry : std::filesystem::directory_iterator(options.folder, ec)) {
      if (isEventNode(entry.path())) nodes.push_back(entry.path());
    }
    std::sort(nodes.begin(), nodes.end());
    for (const auto& node : nodes) consider(node);
    // Nodes left alone that are gone: forget them (their number may come back as another device).
    for (auto it = leftAlone.begin(); it != leftAlone.end();) {
      if (std::filesystem::exists(it->first, ec)) {
        ++it;
      } else {
        removeInfo(it->first);
        warned.erase(it->first);
        it = leftAlone.erase(it);
      }
    }
  }

  void close(std::size_t index, const std::string& why) {
    OpenDevice& d = *open[index];
    push(d.decoder.releaseAll());
    log::info(kLogEvdev, "{} '{}' at {}: {}", evdevRolesName(d.decoder.roles()), d.name, d.path.string(), why);
    removeInfo(d.path.string());
    open.erase(open.begin() + static_cast<std::ptrdiff_t>(index));
  }

  /// Reads what the device has; false when it is gone.
  bool service(OpenDevice& d) {
    std::array<input_event, 64> events{};
    for (;;) {
      const ssize_t n = ::read(d.fd.get(), events.data(), sizeof events);
      if (n < 0) {
        if (errno == EINTR) continue;
        return errno == EAGAIN;  // ENODEV: unplugged
      }
      if (n == 0) return false;
      const auto count = static_cast<std::size_t>(n) / sizeof(input_event);
      for (std::size_t i = 0; i < count; ++i) {
        push(d.decoder.feed(events[i]));
        if (d.decoder.needsResync()) {
          std::array<std::uint8_t, (KEY_CNT + 7) / 8> keys{};
          if (::ioctl(d.fd.get(), EVIOCGKEY(keys.size()), keys.data()) < 0) return false;
          push(d.decoder.resync(keys));
        }
      }
      if (static_cast<std::size_t>(n) < sizeof events) return true;
    }
  }

  void run() {
    std::vector<pollfd> fds;
    const bool rescans = !udev;
    for (;;) {
      fds.clear();
      fds.push_back({stopFd.get(), POLLIN, 0});
      fds.push_back({hotplugFd.get(), POLLIN, 0});
      for (const auto& d : open) fds.push_back({d->fd.get(), POLLIN, 0});
      const int timeout =
          rescans
              ? static_cast<int>(std::chrono::duration_cast<std::chrono::milliseconds>(options.rescanPeriod).count())
              : -1;
      const int ready = ::poll(fds.data(), fds.size(), timeout);
      if (ready < 0) {
        if (errno == EINTR) continue;
        log::error(kLogEvdev, "{}; keyboards and mice are no longer read", systemErrorText("poll", errno));
        return;
      }
      if (fds[0].revents != 0 || stopping.load()) return;
      // Devices first (their fds are at 2.. in the order of `open`), then hotplug.
      for (std::size_t i = fds.size(); i-- > 2;) {
        if (fds[i].revents == 0) continue;
        const bool error = (fds[i].revents & (POLLERR | POLLHUP | POLLNVAL)) != 0;
        if (!service(*open[i - 2]) || error) close(i - 2, "unplugged");
      }
      if (ready == 0 || fds[1].revents != 0) {
        std::uint64_t count = 0;
        (void)!::read(hotplugFd.get(), &count, sizeof count);
        scan();
      }
    }
  }
};

EvdevInput::EvdevInput(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

EvdevInput::~EvdevInput() { stop(); }

Result<std::unique_ptr<EvdevInput>> EvdevInput::create(const Clock& clock, EvdevOptions options,
                                                       std::function<void()> wake) {
  auto impl = std::make_unique<Impl>(clock, std::move(options), std::move(wake));
  impl->stopFd.reset(::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK));
  impl->hotplugFd.reset(::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK));
  if (!impl->stopFd || !impl->hotplugFd) {
    return fail(Errc::kResourceExhausted, systemErrorText("eventfd", errno), "keyboards and mice");
  }
  if (impl->options.udev) {
    if (auto monitor = UdevMonitor::create({"input"})) {
      impl->udev = std::move(*monitor);
    } else {
      log::info(kLogEvdev, "{}; input devices are looked for every {} ms", monitor.error().message(),
                std::chrono::duration_cast<std::chrono::milliseconds>(impl->options.rescanPeriod).count());
    }
  }
  return std::unique_ptr<EvdevInput>(new EvdevInput(std::move(impl)));
}

void EvdevInput::start() {
  Impl& s = *impl_;
  if (s.thread.joinable()) return;
  if (s.udev) {
    const std::filesystem::path folder = s.options.folder;
    const int fd = s.hotplugFd.get();
    s.udev->start([folder, fd](const HotplugEvent& e) {
      const std::filesystem::path node(e.devnode);
      if (e.action != HotplugEvent::Action::kAdded || node.parent_path() != folder || !isEventNode(node)) return;
      const std::uint64_t one = 1;
      (void)!::write(fd, &one, sizeof one);
    });
  }
  s.scan();  // what is plugged in now, before the first frame
  s.thread = std::thread([impl = impl_.get()] { impl->run(); });
}

void EvdevInput::stop() {
  if (!impl_) return;
  Impl& s = *impl_;
  if (s.udev) s.udev->stop();
  if (s.thread.joinable()) {
    s.stopping.store(true);
    const std::uint64_t one = 1;
    (void)!::write(s.stopFd.get(), &one, sizeof one);
    s.thread.join();
  }
  while (!s.open.empty()) s.close(s.open.size() - 1, "closed");
}

std::size_t EvdevInput::takeInput(std::span<Event> into) {
  std::size_t n = 0;
  while (n < into.size() && impl_->queue.pop(into[n])) ++n;
  return n;
}

std::uint64_t EvdevInput::dropped() const { return impl_->queue.dropped(); }

std::vector<EvdevDeviceInfo> EvdevInput::devices() const {
  std::lock_guard lock(impl_->infoMutex);
  return impl_->info;
}

bool EvdevInput::hotplugFromUdev() const { return impl_->udev != nullptr; }

}  // namespace basalt::devices
