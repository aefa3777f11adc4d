// Keyboards and mice through the kernel (devices/evdev): the test makes a virtual keyboard, mouse
// and power button with uinput, and Basalt's reader must see the keyboard's keys and the mouse's
// motion and buttons through /dev/input, leave the power button (and the lab's HID dial box)
// alone, and follow the keyboard being pulled (uinput device destroyed) and plugged again. Needs
// /dev/uinput: runs in the virtual lab (BASALT_VLAB_UINPUT), skips elsewhere with the reason.

#include <gtest/gtest.h>
#include <linux/input.h>

#include <chrono>
#include <cstring>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "devices/evdev/evdev_input.h"
#include "runtime/clock.h"
#include "support/uinput_device.h"
#include "vlab.h"

namespace basalt::devices {
namespace {

using test::UinputDevice;

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
  auto keyboard = UinputDevice::create(*uinput, "Basalt Lab Keyboard", UinputDevice::keyboardKeys(), false, why);
  ASSERT_TRUE(keyboard) << why;
  auto mouse = UinputDevice::create(*uinput, "Basalt Lab Mouse", {BTN_LEFT, BTN_RIGHT, BTN_MIDDLE}, true, why);
  ASSERT_TRUE(mouse) << why;
  auto power = UinputDevice::create(*uinput, "Basalt Lab Power Button", {KEY_POWER}, false, why);
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
  if (test::vlabEnv("BASALT_VLAB_HID_DIAL")) {
    EXPECT_TRUE(sawDialBox) << "the dial box's input node was not seen";
  }

  ASSERT_TRUE(keyboard->emit(EV_KEY, KEY_LEFT, 1));
  ASSERT_TRUE(keyboard->sync());
  ASSERT_TRUE(keyboard->emit(EV_KEY, KEY_LEFT, 0));
  ASSERT_TRUE(keyboard->sync());
  ASSERT_TRUE(mouse->emit(EV_REL, REL_X, 7));
  ASSERT_TRUE(mouse->emit(EV_REL, REL_Y, -3));
  ASSERT_TRUE(mouse->sync());
  ASSERT_TRUE(mouse->emit(EV_KEY, BTN_RIGHT, 1));
  ASSERT_TRUE(mouse->sync());
  ASSERT_TRUE(mouse->emit(EV_KEY, BTN_RIGHT, 0));
  ASSERT_TRUE(mouse->sync());
  ASSERT_TRUE(power->emit(EV_KEY, KEY_POWER, 1));
  ASSERT_TRUE(power->sync());
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
  ASSERT_TRUE(keyboard->emit(EV_KEY, KEY_UP, 1));
  ASSERT_TRUE(keyboard->sync());
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
  auto again = UinputDevice::create(*uinput, "Basalt Lab Keyboard", UinputDevice::keyboardKeys(), false, why);
  ASSERT_TRUE(again) << why;
  ASSERT_TRUE(waitUntil([&] {
    auto k = findDevice(input, "Basalt Lab Keyboard");
    return k && k->read;
  })) << "the replugged keyboard was not opened";
  ASSERT_TRUE(again->emit(EV_KEY, KEY_KPPLUS, 1));
  ASSERT_TRUE(again->sync());
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
