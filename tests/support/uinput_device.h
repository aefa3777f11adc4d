#pragma once

/// \file
/// \brief A virtual input device made through /dev/uinput, for tests that read keyboards and
/// mice through the kernel (the virtual lab's BASALT_VLAB_UINPUT). Header-only; Linux only.

#include <fcntl.h>
#include <linux/uinput.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "runtime/unique_fd.h"

namespace basalt::test {

/// \brief A uinput device: it exists from create() until destroy() or destruction (the kernel
/// then removes its /dev/input node, as if it were unplugged).
class UinputDevice {
 public:
  /// \brief Makes a device called `name` with these EV_KEY codes and, when `relative`, REL_X
  /// and REL_Y. Empty with `why` set when uinput refuses.
  static std::optional<UinputDevice> create(const std::string& uinputPath, const std::string& name,
                                            const std::vector<int>& keys, bool relative, std::string& why) {
    UinputDevice d;
    d.fd_.reset(::open(uinputPath.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC));
    if (!d.fd_) {
      why = "cannot open " + uinputPath + ": " + std::strerror(errno);
      return std::nullopt;
    }
    const int fd = d.fd_.get();
    bool ok = ::ioctl(fd, UI_SET_EVBIT, EV_KEY) == 0;
    for (const int k : keys) ok = ok && ::ioctl(fd, UI_SET_KEYBIT, k) == 0;
    if (relative) {
      ok = ok && ::ioctl(fd, UI_SET_EVBIT, EV_REL) == 0 && ::ioctl(fd, UI_SET_RELBIT, REL_X) == 0 &&
           ::ioctl(fd, UI_SET_RELBIT, REL_Y) == 0;
    }
    uinput_setup setup{};
    setup.id.bustype = BUS_VIRTUAL;
    setup.id.vendor = 0x1209;
    setup.id.product = 0x0003;
    std::strncpy(setup.name, name.c_str(), UINPUT_MAX_NAME_SIZE - 1);
    ok = ok && ::ioctl(fd, UI_DEV_SETUP, &setup) == 0 && ::ioctl(fd, UI_DEV_CREATE) == 0;
    if (!ok) {
      why = "uinput setup of '" + name + "' failed: " + std::strerror(errno);
      return std::nullopt;
    }
    d.created_ = true;
    return d;
  }

  /// \brief Every key of a full keyboard with arrows and keypad (KEY_ESC..KEY_KPDOT, arrows).
  static std::vector<int> keyboardKeys() {
    std::vector<int> keys;
    for (int k = KEY_ESC; k <= KEY_KPDOT; ++k) keys.push_back(k);
    for (const int k : {KEY_UP, KEY_DOWN, KEY_LEFT, KEY_RIGHT}) keys.push_back(k);
    return keys;
  }

  UinputDevice() = default;
  UinputDevice(UinputDevice&& o) noexcept : fd_(std::move(o.fd_)), created_(std::exchange(o.created_, false)) {}
  UinputDevice& operator=(UinputDevice&&) = delete;
  UinputDevice(const UinputDevice&) = delete;
  UinputDevice& operator=(const UinputDevice&) = delete;
  ~UinputDevice() { destroy(); }

  void destroy() {
    if (created_) (void)::ioctl(fd_.get(), UI_DEV_DESTROY);
    created_ = false;
    fd_.reset();
  }
  /// \brief Writes one event; false when the kernel refused it.
  bool emit(std::uint16_t type, std::uint16_t code, std::int32_t value) const {
    input_event e{};
    e.type = type;
    e.code = code;
    e.value = value;
    return ::write(fd_.get(), &e, sizeof e) == static_cast<ssize_t>(sizeof e);
  }
  bool sync() const { return emit(EV_SYN, SYN_REPORT, 0); }
  /// \brief A key pressed (1) or released (0), with its frame's SYN_REPORT.
  bool key(std::uint16_t code, std::int32_t value) const { return emit(EV_KEY, code, value) && sync(); }

 private:
  UniqueFd fd_;
  bool created_ = false;
};

}  // namespace basalt::test
