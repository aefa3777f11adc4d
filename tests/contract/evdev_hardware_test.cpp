// Keyboards and mice through the kernel (devices/evdev): the test makes a virtual keyboard, mouse
// and power button with uinput, and Basalt's reader must see the keyboard's keys and the mouse's
// motion and buttons through /dev/input, leave the power button (and the lab's HID dial box)
// alone, and follow the keyboard being pulled (uinput device destroyed) and plugged again. Needs
// /dev/uinput: runs in the virtual lab (BASALT_VLAB_UINPUT), skips elsewhere with the reason.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <linux/uinput.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "devices/evdev/evdev_input.h"
#include "runtime/clock.h"
#include "runtime/unique_fd.h"
#include "vlab.h"

namespace basalt::devices {
namespace {

/// A uinput device: exists from create() until destroyed (the kernel then removes its node).
class VirtualDevice {
 public:
  static std::optional<VirtualDevice> create(const std::string& path, const std::string& name,
                                             const std::vector<int>& keys, bool relative, std::string& why) {
    VirtualDevice d;
    d.fd_.reset(::open(path.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC));
    if (!d.fd_) {
      why = std::string("cannot open ") + path + ": " + std::strerror(errno);
      return std::nullopt;
    }
    const int fd = d.fd_.get();
    bool ok = ::ioctl(fd, UI_SET_EVBIT, EV_KEY) == 0;
    for (int k : keys) ok = ok && ::ioctl(fd, UI_SET_KEYBIT, k) == 0;
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
      why = std::string("uinput setup of '") + name + "' failed: " + std::strerror(errno);
      return std::nullopt;
    }
    d.created_ = true;
    return d;
  }
  VirtualDevice() = default;
  VirtualDevice(VirtualDevice&& o) noexcept : fd_(std::move(o.fd_)), created_(std::exchange(o.created_, false)) {}
  VirtualDevice& operator=(VirtualDevice&&) = delete;
  VirtualDevice(const VirtualDevice&) = delete;
  VirtualDevice& operator=(const VirtualDevice&) = delete;
  ~VirtualDevice() { destroy(); }

  void destroy() {
    if (created_) (void)::ioctl(fd_.get(), UI_DEV_DESTROY);
    created_ = false;
    fd_.reset();
  }
  void emit(std::uint16_t type, std::uint16_t code, std::int32_t value) const {
    input_event e{};
    e.type = type;
    e.code = code;
    e.value = value;
    ASSERT_EQ(::write(fd_.get(), &e, sizeof e), static_cast<ssize_t>(sizeof e)) << std::strerror(errno);
  }
  void sync() const { emit(EV_SYN, SYN_REPORT, 0); }

 private:
  UniqueFd fd_;
  bool created_ = false;
};

std::vector<int> keyboardKeys() {
  std::vector<int> keys;
  for (int k = KEY_ESC; k <= KEY_KPDOT; ++k) keys.push_back(k);
  for (int k : {KEY_UP, KEY_DOWN, KEY_LEFT, KEY_RIGHT}) keys.push_back(k);
  return keys;
}

bool waitUntil(const std::function<bool()>& done, std::chrono::milliseconds limit = std::chrono::seconds(10)) {
  const auto end = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < end) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return done();
}

std::optional<EvdevDeviceInfo> findDevice(const EvdevInput& input, const std::string& name) {
  for (const EvdevDeviceInfo& d : input.devices()) {
    if (d.name == name) return d;
  }
  return std::nullopt;
}

/// Collects events until `count` have arrived or the time is up.
std::vector<Event> takeEvents(EvdevInput& input, std::size_t count) {
  std::vector<Event> got;
  (void)waitUntil([&] {
    std::array<Event, 32> batch{};
    const std::size_t n = input.takeInput(batch);
    got.insert(got.end(), batch.begin(), batch.begin() + static_cast<std::ptrdiff_t>(n));
    return got.size() >= count;
  });
  return got;
}

// Makes sure Basalt reads real keyboards and mice through the kernel and follows a keyboard
// pulled and plugged in again, while other input devices stay untouched. Example failure: the
// reader's thread blocks on a node that vanished, or a replugged keyboard is never opened again.
TEST(EvdevHardware, UinputKeyboardAndMouseReachTheShowAndTheKeyboardReplugs) {
  const auto uinput = test::vlabEnv("BASALT_VLAB_UINPUT");
  if (!uinput) GTEST_SKIP() << test::needsVlab("BASALT_VLAB_UINPUT (/dev/uinput with evdev loaded)");
  std::string why;
  auto keyboard = VirtualDevice::create(*uinput, "Basalt Lab Keyboard", keyboardKeys(), false, why);
  ASSERT_TRUE(keyboard) << why;
  auto mouse = VirtualDevice::create(*uinput, "Basalt Lab Mouse", {BTN_LEFT, BTN_RIGHT, BTN_MIDDLE}, true, why);
  ASSERT_TRUE(mouse) << why;
  auto power = VirtualDevice::create(*uinput, "Basalt Lab Power Button", {KEY_POWER}, false, why);
  ASSERT_TRUE(power) << why;

  SystemClock clock;
  EvdevOptions options;
  options.rescanPeriod = std::chrono::milliseconds(200);  // used only where udev cannot be reached
  auto made = EvdevInput::create(clock, options);
  ASSERT_TRUE(made) << made.error().describe();
  EvdevInput& input = **made;
  input.start();
  std::cout << "hotplug from " << (input.hotplugFromUdev() ? "udev" : "rescans") << "\n";
  ASSERT_TRUE(waitUntil([&] {
    auto k = findDevice(input, "Basalt Lab Keyboard");
    auto m = findDevice(input, "Basalt Lab Mouse");
    return k && k->read && m && m->read;
  })) << "the uinput keyboard and mouse were not opened";
  const auto powerInfo = findDevice(input, "Basalt Lab Power Button");
  ASSERT_TRUE(powerInfo);
  EXPECT_FALSE(powerInfo->read);
  EXPECT_EQ(powerInfo->role, "not a keyboard or pointer");
  bool sawDialBox = false;
  for (const EvdevDeviceInfo& d : input.devices()) {
    std::cout << d.path << " '" << d.name << "': " << d.role << (d.read ? " (read)" : "") << "\n";
    if (d.name.find("Basalt Lab Dial Box") != std::string::npos) {
      sawDialBox = true;
      EXPECT_FALSE(d.read) << "the HID dial box's input node was taken as input";
    }
  }
  // The lab's dial box (hid-generic gives it relative X and Y axes and BTN_0..7) is left alone.
  if (test::vlabEnv("BASALT_VLAB_HID_DIAL")) EXPECT_TRUE(sawDialBox) << "the dial box's input node was not seen";

  keyboard->emit(EV_KEY, KEY_LEFT, 1);
  keyboard->sync();
  keyboard->emit(EV_KEY, KEY_LEFT, 0);
  keyboard->sync();
  mouse->emit(EV_REL, REL_X, 7);
  mouse->emit(EV_REL, REL_Y, -3);
  mouse->sync();
  mouse->emit(EV_KEY, BTN_RIGHT, 1);
  mouse->sync();
  mouse->emit(EV_KEY, BTN_RIGHT, 0);
  mouse->sync();
  power->emit(EV_KEY, KEY_POWER, 1);
  power->sync();
  const auto events = takeEvents(input, 6);
  auto has = [&](EventKind kind, std::uint16_t index, double value) {
    return std::any_of(events.begin(), events.end(),
                       [&](const Event& e) { return e.kind == kind && e.index == index && e.value == value; });
  };
  EXPECT_EQ(events.size(), 6U);
  EXPECT_TRUE(has(EventKind::kKey, KEY_LEFT, 1));
  EXPECT_TRUE(has(EventKind::kKey, KEY_LEFT, 0));
  EXPECT_TRUE(has(EventKind::kPointerMotion, 0, 7));
  EXPECT_TRUE(has(EventKind::kPointerMotion, 1, -3));
  EXPECT_TRUE(has(EventKind::kPointerButton, 2, 1));
  EXPECT_TRUE(has(EventKind::kPointerButton, 2, 0));
  EXPECT_FALSE(has(EventKind::kKey, KEY_POWER, 1)) << "the power button was read";

  // Pulled with a key held: the key is released for the show, the device leaves the list.
  keyboard->emit(EV_KEY, KEY_UP, 1);
  keyboard->sync();
  const auto held = takeEvents(input, 1);
  ASSERT_EQ(held.size(), 1U);
  EXPECT_EQ(held[0].index, KEY_UP);
  keyboard->destroy();
  EXPECT_TRUE(waitUntil([&] { return !findDevice(input, "Basalt Lab Keyboard"); }))
      << "the pulled keyboard is still listed";
  const auto released = takeEvents(input, 1);
  ASSERT_EQ(released.size(), 1U);
  EXPECT_EQ(released[0].kind, EventKind::kKey);
  EXPECT_EQ(released[0].index, KEY_UP);
  EXPECT_EQ(released[0].value, 0);

  // Plugged again: opened again, and its keys arrive.
  auto again = VirtualDevice::create(*uinput, "Basalt Lab Keyboard", keyboardKeys(), false, why);
  ASSERT_TRUE(again) << why;
  ASSERT_TRUE(waitUntil([&] {
    auto k = findDevice(input, "Basalt Lab Keyboard");
    return k && k->read;
  })) << "the replugged keyboard was not opened";
  again->emit(EV_KEY, KEY_KPPLUS, 1);
  again->sync();
  const auto after = takeEvents(input, 1);
  ASSERT_EQ(after.size(), 1U);
  EXPECT_EQ(after[0].kind, EventKind::kKey);
  EXPECT_EQ(after[0].index, KEY_KPPLUS);
  EXPECT_EQ(after[0].value, 1);
  EXPECT_EQ(input.dropped(), 0U);
  input.stop();
}

}  // namespace
}  // namespace basalt::devices
