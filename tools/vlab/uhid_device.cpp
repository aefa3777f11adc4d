// The virtual lab's uhid devices. Linux only: /dev/uhid (CONFIG_UHID), protocol from
// <linux/uhid.h>: UHID_CREATE2 makes the device, UHID_INPUT2 sends reports, closing the fd
// destroys it. The kernel's GET_REPORT/SET_REPORT requests are answered with EIO (a recording
// has no feature reports to give), so that no driver waits out its time-out on them.

#include "tools/vlab/uhid_device.h"

#include <fcntl.h>
#include <linux/uhid.h>
#include <poll.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <thread>

namespace basalt::sim::vlab {
namespace {

std::atomic<unsigned> gCounter{0};

/// Copies a string into one of uhid's fixed, NUL-terminated fields (of `size` bytes).
void copyString(void* dest, std::size_t size, const std::string& src) {
  std::memset(dest, 0, size);
  std::memcpy(dest, src.data(), std::min(src.size(), size - 1));
}

Result<void> writeEvent(int fd, const uhid_event& ev) {
  const ssize_t n = ::write(fd, &ev, sizeof ev);
  if (n < 0) return fail(Errc::kIo, systemErrorText("writing to /dev/uhid", errno));
  if (static_cast<std::size_t>(n) != sizeof ev) return fail(Errc::kIo, "short write to /dev/uhid");
  return {};
}

}  // namespace

Result<UhidDevice> UhidDevice::create(UhidIdentity identity, const std::filesystem::path& uhid) {
  if (identity.descriptor.empty() || identity.descriptor.size() > HID_MAX_DESCRIPTOR_SIZE) {
    return failf(Errc::kInvalidArgument, "a uhid report descriptor must have 1 to {} bytes, not {}",
                 HID_MAX_DESCRIPTOR_SIZE, identity.descriptor.size());
  }
  if (identity.uniq.empty()) {
    identity.uniq = fmt::format("basalt-vlab-{}-{}", ::getpid(), gCounter.fetch_add(1));
  }
  const int raw = ::open(uhid.c_str(), O_RDWR | O_CLOEXEC | O_NONBLOCK);
  if (raw < 0) {
    const int err = errno;
    return fail(err == EACCES || err == EPERM ? Errc::kPermissionDenied : Errc::kNotFound,
                systemErrorText("opening " + uhid.string() + " (is the uhid module loaded?)", err));
  }
  UniqueFd fd(raw);
  uhid_event ev{};
  ev.type = UHID_CREATE2;
  copyString(ev.u.create2.name, sizeof ev.u.create2.name, identity.name);
  copyString(ev.u.create2.phys, sizeof ev.u.create2.phys, identity.phys);
  copyString(ev.u.create2.uniq, sizeof ev.u.create2.uniq, identity.uniq);
  ev.u.create2.rd_size = static_cast<__u16>(identity.descriptor.size());
  ev.u.create2.bus = identity.bus;
  ev.u.create2.vendor = identity.vendor;
  ev.u.create2.product = identity.product;
  ev.u.create2.version = identity.version;
  std::memcpy(ev.u.create2.rd_data, identity.descriptor.data(), identity.descriptor.size());
  if (auto ok = writeEvent(fd.get(), ev); !ok) {
    return std::unexpected(ok.error().withContext("creating the uhid device '" + identity.name + "'"));
  }
  return UhidDevice(std::move(fd), std::move(identity));
}

bool UhidDevice::pump(int timeoutMs) {
  pollfd p{fd_.get(), POLLIN, 0};
  if (::poll(&p, 1, timeoutMs) <= 0) return false;
  uhid_event ev{};
  const ssize_t n = ::read(fd_.get(), &ev, sizeof ev);
  if (n <= 0) return false;
  switch (ev.type) {
    case UHID_START: started_ = true; break;
    case UHID_STOP: started_ = false; break;
    case UHID_OPEN:
      opened_ = true;
      everOpened_ = true;
      break;
    case UHID_CLOSE: opened_ = false; break;
    case UHID_OUTPUT: {
      const std::size_t size = std::min<std::size_t>(ev.u.output.size, UHID_DATA_MAX);
      std::vector<std::uint8_t> bytes(size);
      std::memcpy(bytes.data(), &ev.u.output.data[0], size);
      outputs_.push_back(std::move(bytes));
      break;
    }
    case UHID_GET_REPORT: {
      uhid_event reply{};
      reply.type = UHID_GET_REPORT_REPLY;
      reply.u.get_report_reply.id = ev.u.get_report.id;
      reply.u.get_report_reply.err = EIO;
      if (!writeEvent(fd_.get(), reply)) ++failedReplies_;
      break;
    }
    case UHID_SET_REPORT: {
      uhid_event reply{};
      reply.type = UHID_SET_REPORT_REPLY;
      reply.u.set_report_reply.id = ev.u.set_report.id;
      reply.u.set_report_reply.err = EIO;
      if (!writeEvent(fd_.get(), reply)) ++failedReplies_;
      break;
    }
    default: break;
  }
  return true;
}

void UhidDevice::service() {
  while (pump(0)) {
  }
}

Result<void> UhidDevice::sendInput(std::span<const std::uint8_t> report) {
  if (report.empty() || report.size() > UHID_DATA_MAX) {
    return failf(Errc::kInvalidArgument, "an input report must have 1 to {} bytes, not {}", UHID_DATA_MAX,
                 report.size());
  }
  service();
  uhid_event ev{};
  ev.type = UHID_INPUT2;
  ev.u.input2.size = static_cast<__u16>(report.size());
  std::memcpy(ev.u.input2.data, report.data(), report.size());
  return writeEvent(fd_.get(), ev);
}

Result<void> UhidDevice::waitOpened(std::chrono::milliseconds limit) {
  const auto end = std::chrono::steady_clock::now() + limit;
  while (!opened_) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(end - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      return fail(Errc::kTimeout,
                  fmt::format("nobody opened the uhid device '{}' within {} ms", identity_.name, limit.count()));
    }
    pump(static_cast<int>(left.count()));
  }
  return {};
}

Result<std::filesystem::path> UhidDevice::hidrawNode(std::chrono::milliseconds limit) {
  const auto end = std::chrono::steady_clock::now() + limit;
  const std::string wanted = "HID_UNIQ=" + identity_.uniq;
  for (;;) {
    service();
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator("/sys/class/hidraw", ec)) {
      std::ifstream uevent(entry.path() / "device" / "uevent");
      std::string line;
      while (std::getline(uevent, line)) {
        if (line == wanted) return std::filesystem::path("/dev") / entry.path().filename();
      }
    }
    if (std::chrono::steady_clock::now() >= end) {
      return fail(Errc::kNotFound, fmt::format("the kernel made no hidraw node for the uhid device '{}' within {} ms",
                                               identity_.name, limit.count()));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

}  // namespace basalt::sim::vlab
