// Keyboards and mice from evdev (devices/evdev): what counts as a keyboard or pointer, and the
// translation of the kernel's event frames into the show's events, from raw input_event
// sequences. The real kernel path (uinput devices read through /dev/input) is in the virtual lab:
// tests/devices/evdev_hardware_test.cpp.

#include <gtest/gtest.h>
#include <linux/input.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <thread>
#include <vector>

#include "devices/evdev/evdev_decoder.h"
#include "devices/evdev/evdev_input.h"
#include "runtime/clock.h"

namespace basalt::devices {
namespace {

input_event ev(std::uint16_t type, std::uint16_t code, std::int32_t value) {
  input_event e{};
  e.type = type;
  e.code = code;
  e.value = value;
  return e;
}
input_event syn() { return ev(EV_SYN, SYN_REPORT, 0); }

struct Out {
  EventKind kind;
  std::uint16_t index;
  double value;
  bool operator==(const Out&) const = default;
};

std::ostream& operator<<(std::ostream& os, const Out& o) {
  return os << "{kind " << static_cast<int>(o.kind) << ", index " << o.index << ", value " << o.value << "}";
}

/// Feeds a sequence and collects everything the decoder hands out.
std::vector<Out> run(EvdevDecoder& d, const std::vector<input_event>& events) {
  std::vector<Out> out;
  for (const input_event& e : events) {
    for (const Event& x : d.feed(e)) {
      EXPECT_EQ(x.device, d.device());
      out.push_back({x.kind, x.index, x.value});
    }
  }
  return out;
}

std::vector<Out> collect(std::span<const Event> events) {
  std::vector<Out> out;
  for (const Event& x : events) out.push_back({x.kind, x.index, x.value});
  return out;
}

EvdevCapabilities keyboardCaps() {
  EvdevCapabilities c;
  c.types.set(EV_KEY).set(EV_SYN).set(EV_MSC).set(EV_REP);
  for (int k = KEY_ESC; k <= KEY_KPDOT; ++k) c.keys.set(static_cast<std::size_t>(k));
  for (int k : {KEY_UP, KEY_DOWN, KEY_LEFT, KEY_RIGHT}) c.keys.set(static_cast<std::size_t>(k));
  return c;
}

EvdevCapabilities mouseCaps() {
  EvdevCapabilities c;
  c.types.set(EV_KEY).set(EV_REL).set(EV_SYN);
  for (int k : {BTN_LEFT, BTN_RIGHT, BTN_MIDDLE, BTN_SIDE, BTN_EXTRA}) c.keys.set(static_cast<std::size_t>(k));
  for (int r : {REL_X, REL_Y, REL_WHEEL}) c.relative.set(static_cast<std::size_t>(r));
  return c;
}

EvdevCapabilities touchpadCaps() {
  EvdevCapabilities c;
  c.types.set(EV_KEY).set(EV_ABS).set(EV_SYN);
  for (int k : {BTN_LEFT, BTN_TOUCH, BTN_TOOL_FINGER, BTN_TOOL_DOUBLETAP}) c.keys.set(static_cast<std::size_t>(k));
  for (int a : {ABS_X, ABS_Y, ABS_PRESSURE}) c.absolute.set(static_cast<std::size_t>(a));
  c.properties.set(INPUT_PROP_POINTER).set(INPUT_PROP_BUTTONPAD);
  c.resolutionX = 20;  // units per mm
  c.resolutionY = 20;
  return c;
}

std::array<std::uint8_t, (KEY_CNT + 7) / 8> keyState(std::initializer_list<int> down) {
  std::array<std::uint8_t, (KEY_CNT + 7) / 8> bytes{};
  for (int k : down) bytes[static_cast<std::size_t>(k) / 8] |= static_cast<std::uint8_t>(1U << (k % 8));
  return bytes;
}

// Makes sure keyboards and pointers are told apart from the other input devices of a kiosk.
// Example failure: the dial box's own input node (relative X and Y axes) moves the viewer, or
// the power button is read as a keyboard.
TEST(EvdevClassify, KeyboardsPointersAndTouchpadsOnly) {
  EXPECT_TRUE(classifyEvdev(keyboardCaps()).keyboard);
  EXPECT_FALSE(classifyEvdev(keyboardCaps()).pointer);
  EXPECT_TRUE(classifyEvdev(mouseCaps()).pointer);
  EXPECT_FALSE(classifyEvdev(mouseCaps()).keyboard);
  EXPECT_TRUE(classifyEvdev(touchpadCaps()).touchpad);
  EXPECT_STREQ(evdevRolesName(classifyEvdev(touchpadCaps())), "touchpad");

  EvdevCapabilities arrows;  // a four-key arrow pad
  arrows.types.set(EV_KEY);
  for (int k : {KEY_UP, KEY_DOWN, KEY_LEFT, KEY_RIGHT}) arrows.keys.set(static_cast<std::size_t>(k));
  EXPECT_TRUE(classifyEvdev(arrows).keyboard);

  EvdevCapabilities keypad;  // a numeric pad
  keypad.types.set(EV_KEY);
  for (int k : {KEY_KP0, KEY_KP1, KEY_KP2, KEY_KP3, KEY_KP4, KEY_KP5, KEY_KP6, KEY_KP7, KEY_KP8, KEY_KP9})
    keypad.keys.set(static_cast<std::size_t>(k));
  EXPECT_TRUE(classifyEvdev(keypad).keyboard);

  EvdevCapabilities power;  // ACPI power button
  power.types.set(EV_KEY);
  power.keys.set(KEY_POWER);
  EXPECT_FALSE(classifyEvdev(power).any());
  EXPECT_STREQ(evdevRolesName(classifyEvdev(power)), "not a keyboard or pointer");

  EvdevCapabilities dial;  // the lab's HID dial box through hid-generic: 8 relative axes, BTN_0..7
  dial.types.set(EV_KEY).set(EV_REL);
  for (int r : {REL_X, REL_Y, REL_Z, REL_RX, REL_RY, REL_RZ, REL_DIAL, REL_WHEEL})
    dial.relative.set(static_cast<std::size_t>(r));
  for (int b = BTN_0; b <= BTN_7; ++b) dial.keys.set(static_cast<std::size_t>(b));
  EXPECT_FALSE(classifyEvdev(dial).any());

  EvdevCapabilities screen = touchpadCaps();  // a touchscreen: direct touch
  screen.properties.set(INPUT_PROP_DIRECT);
  EXPECT_FALSE(classifyEvdev(screen).any());

  EvdevCapabilities volume;  // a remote's consumer keys
  volume.types.set(EV_KEY);
  for (int k : {KEY_VOLUMEUP, KEY_VOLUMEDOWN, KEY_MUTE}) volume.keys.set(static_cast<std::size_t>(k));
  EXPECT_FALSE(classifyEvdev(volume).any());
}

TEST(EvdevClassify, BitsFromTheKernelsByteArray) {
  const std::array<std::uint8_t, 3> bytes{0x02, 0x00, 0x81};  // bits 1, 16 and 23
  const auto bits = EvdevCapabilities::fromBytes<24>(bytes);
  EXPECT_EQ(bits.count(), 3U);
  EXPECT_TRUE(bits[1] && bits[16] && bits[23]);
}

// Makes sure a key arrives as the window's would: the Linux code, press 1, repeat 2, release 0,
// and only when its frame ends. Example failure: the scan code (MSC_SCAN) becomes a key, or a
// frame's events go out before its SYN_REPORT.
TEST(EvdevDecoder, KeysPressRepeatAndRelease) {
  EvdevDecoder d(classifyEvdev(keyboardCaps()), 7);
  EXPECT_TRUE(d.feed(ev(EV_MSC, MSC_SCAN, 0x70004)).empty());
  EXPECT_TRUE(d.feed(ev(EV_KEY, KEY_A, 1)).empty());
  EXPECT_EQ(collect(d.feed(syn())), (std::vector<Out>{{EventKind::kKey, KEY_A, 1}}));
  EXPECT_EQ(run(d, {ev(EV_KEY, KEY_A, 2), syn(), ev(EV_KEY, KEY_A, 0), syn()}),
            (std::vector<Out>{{EventKind::kKey, KEY_A, 2}, {EventKind::kKey, KEY_A, 0}}));
  // Two keys in one frame, in order; relative motion from a keyboard-only device is ignored.
  EXPECT_EQ(run(d, {ev(EV_KEY, KEY_LEFTSHIFT, 1), ev(EV_KEY, KEY_RIGHT, 1), ev(EV_REL, REL_X, 5), syn()}),
            (std::vector<Out>{{EventKind::kKey, KEY_LEFTSHIFT, 1}, {EventKind::kKey, KEY_RIGHT, 1}}));
  // A release of a key never seen down (held when the device was opened and resync missed it)
  // is not passed on; a repeat of an unseen key is.
  EXPECT_TRUE(run(d, {ev(EV_KEY, KEY_B, 0), syn()}).empty());
  EXPECT_EQ(run(d, {ev(EV_KEY, KEY_C, 2), syn()}), (std::vector<Out>{{EventKind::kKey, KEY_C, 2}}));
}

// Makes sure mouse motion and buttons use the window's units and numbering. Example failure:
// the right button arrives as 1 (the kernel's order BTN_LEFT, BTN_RIGHT, BTN_MIDDLE) and the
// calibration drag turns the wrong way, or every REL_X event is its own motion.
TEST(EvdevDecoder, MouseMotionAndButtons) {
  EvdevDecoder d(classifyEvdev(mouseCaps()), 9);
  EXPECT_EQ(run(d, {ev(EV_REL, REL_X, 3), ev(EV_REL, REL_X, 2), ev(EV_REL, REL_Y, -4), syn()}),
            (std::vector<Out>{{EventKind::kPointerMotion, 0, 5}, {EventKind::kPointerMotion, 1, -4}}));
  EXPECT_EQ(run(d, {ev(EV_KEY, BTN_LEFT, 1), ev(EV_REL, REL_Y, 2), syn(), ev(EV_KEY, BTN_MIDDLE, 1), syn(),
                    ev(EV_KEY, BTN_RIGHT, 1), syn(), ev(EV_KEY, BTN_SIDE, 1), ev(EV_REL, REL_WHEEL, 1), syn(),
                    ev(EV_KEY, BTN_LEFT, 0), ev(EV_KEY, BTN_RIGHT, 0), ev(EV_KEY, BTN_MIDDLE, 0), syn()}),
            (std::vector<Out>{{EventKind::kPointerButton, 0, 1},
                              {EventKind::kPointerMotion, 1, 2},
                              {EventKind::kPointerButton, 1, 1},
                              {EventKind::kPointerButton, 2, 1},
                              {EventKind::kPointerButton, 0, 0},
                              {EventKind::kPointerButton, 2, 0},
                              {EventKind::kPointerButton, 1, 0}}));
  // Keys of a pointer-only device (a mouse's extra keys as KEY_*) are not keyboard input.
  EXPECT_TRUE(run(d, {ev(EV_KEY, KEY_A, 1), syn()}).empty());
}

// Makes sure a buffer overrun (SYN_DROPPED) neither replays half a frame nor leaves a key held:
// everything up to the next SYN_REPORT is dropped, then the key state is taken from the kernel.
// Example failure: the arrow key's release was among the lost events and the viewer walks on
// for ever.
TEST(EvdevDecoder, SynDroppedDropsUntilTheNextReportThenResyncs) {
  EvdevDecoder d(classifyEvdev(keyboardCaps()), 1);
  EXPECT_EQ(run(d, {ev(EV_KEY, KEY_UP, 1), syn()}), (std::vector<Out>{{EventKind::kKey, KEY_UP, 1}}));
  EXPECT_TRUE(
      run(d, {ev(EV_KEY, KEY_A, 1), ev(EV_SYN, SYN_DROPPED, 0), ev(EV_KEY, KEY_B, 1), ev(EV_KEY, KEY_UP, 0), syn()})
          .empty());
  EXPECT_EQ(d.framesDropped(), 1U);
  ASSERT_TRUE(d.needsResync());
  // The kernel says: B is down, UP is up (changes come in key code order).
  const auto state = keyState({KEY_B});
  EXPECT_EQ(collect(d.resync(state)), (std::vector<Out>{{EventKind::kKey, KEY_B, 1}, {EventKind::kKey, KEY_UP, 0}}));
  EXPECT_FALSE(d.needsResync());
  // Afterwards frames pass again.
  EXPECT_EQ(run(d, {ev(EV_KEY, KEY_B, 0), syn()}), (std::vector<Out>{{EventKind::kKey, KEY_B, 0}}));
}

TEST(EvdevDecoder, SynDroppedDropsMotionAndResyncsButtons) {
  EvdevDecoder d(classifyEvdev(mouseCaps()), 2);
  EXPECT_EQ(run(d, {ev(EV_KEY, BTN_LEFT, 1), syn()}), (std::vector<Out>{{EventKind::kPointerButton, 0, 1}}));
  EXPECT_TRUE(run(d, {ev(EV_REL, REL_X, 40), ev(EV_SYN, SYN_DROPPED, 0), ev(EV_REL, REL_X, 7), syn()}).empty());
  ASSERT_TRUE(d.needsResync());
  EXPECT_EQ(collect(d.resync(keyState({}))), (std::vector<Out>{{EventKind::kPointerButton, 0, 0}}));
  EXPECT_EQ(run(d, {ev(EV_REL, REL_X, 1), syn()}), (std::vector<Out>{{EventKind::kPointerMotion, 0, 1}}));
}

TEST(EvdevDecoder, ReleaseAllLetsGoOfEverythingHeld) {
  EvdevRoles both;
  both.keyboard = both.pointer = true;
  EvdevDecoder d(both, 3);
  (void)run(d, {ev(EV_KEY, KEY_LEFT, 1), ev(EV_KEY, BTN_RIGHT, 1), syn()});
  EXPECT_EQ(collect(d.releaseAll()),
            (std::vector<Out>{{EventKind::kKey, KEY_LEFT, 0}, {EventKind::kPointerButton, 2, 0}}));
  EXPECT_TRUE(d.releaseAll().empty());
}

TEST(EvdevDecoder, AnOversizedFrameIsCutAndCounted) {
  EvdevDecoder d(classifyEvdev(keyboardCaps()), 4);
  std::vector<input_event> frame;
  for (int k = KEY_ESC; k < KEY_ESC + 100; ++k) frame.push_back(ev(EV_KEY, static_cast<std::uint16_t>(k), 1));
  frame.push_back(syn());
  EXPECT_EQ(run(d, frame).size(), EvdevDecoder::kMaxFrameEvents);
  EXPECT_EQ(d.framesTruncated(), 1U);
}

// Makes sure a touchpad moves the pointer by the finger's travel, only while touched, and that
// a new touch does not jump. Example failure: putting the finger down elsewhere swings the view.
TEST(EvdevDecoder, TouchpadFingerTravelBecomesMotion) {
  EvdevDecoder d(classifyEvdev(touchpadCaps()), 5, touchpadCaps());
  EXPECT_TRUE(run(d, {ev(EV_KEY, BTN_TOUCH, 1), ev(EV_KEY, BTN_TOOL_FINGER, 1), ev(EV_ABS, ABS_X, 1000),
                      ev(EV_ABS, ABS_Y, 500), syn()})
                  .empty());
  // 20 units per mm, 10 pixels per mm: 40 units = 20 pixels.
  EXPECT_EQ(run(d, {ev(EV_ABS, ABS_X, 1040), syn()}), (std::vector<Out>{{EventKind::kPointerMotion, 0, 20}}));
  // Slow travel adds up: 1 unit = half a pixel.
  EXPECT_TRUE(run(d, {ev(EV_ABS, ABS_Y, 501), syn()}).empty());
  EXPECT_EQ(run(d, {ev(EV_ABS, ABS_Y, 502), syn()}), (std::vector<Out>{{EventKind::kPointerMotion, 1, 1}}));
  // Lifted, then down far away: no jump.
  EXPECT_TRUE(
      run(d, {ev(EV_KEY, BTN_TOUCH, 0), syn(), ev(EV_KEY, BTN_TOUCH, 1), ev(EV_ABS, ABS_X, 3000), syn()}).empty());
  EXPECT_EQ(run(d, {ev(EV_ABS, ABS_X, 2998), syn()}), (std::vector<Out>{{EventKind::kPointerMotion, 0, -1}}));
  // A click of the pad is the left button.
  EXPECT_EQ(run(d, {ev(EV_KEY, BTN_LEFT, 1), syn()}), (std::vector<Out>{{EventKind::kPointerButton, 0, 1}}));
}

// Makes sure the operator is told what to change when the show's user may not read the nodes.
TEST(EvdevInputErrors, PermissionDeniedPointsAtTheGroupAndTheUdevRule) {
  const std::string text = evdevOpenProblem("/dev/input/event3", "Dell KB216", EACCES);
  EXPECT_NE(text.find("/dev/input/event3 ('Dell KB216')"), std::string::npos) << text;
  EXPECT_NE(text.find("permission denied"), std::string::npos) << text;
  EXPECT_NE(text.find("'input' group"), std::string::npos) << text;
  EXPECT_NE(text.find("configs/udev/70-basalt.rules"), std::string::npos) << text;
  EXPECT_NE(text.find("configs/systemd/basalt.service"), std::string::npos) << text;
  EXPECT_NE(evdevOpenProblem("/dev/input/event4", "", ENODEV).find("gone"), std::string::npos);
  EXPECT_NE(evdevOpenProblem("/dev/input/event4", "", EIO).find("cannot open input device /dev/input/event4"),
            std::string::npos);
}

// Makes sure the reader skips nodes that are not input devices, and follows nodes appearing and
// vanishing by rescanning where there is no udev. Example failure: a character device that
// answers no evdev ioctl stops the scan, or a node that comes back is never looked at again.
TEST(EvdevInputScan, NonInputNodesAreLeftAloneAndRescansFollowTheFolder) {
  const auto folder = std::filesystem::temp_directory_path() / ("basalt-evdev-" + std::to_string(::getpid()));
  std::filesystem::remove_all(folder);
  std::filesystem::create_directories(folder);
  if (::mknod((folder / "event0").c_str(), S_IFCHR | 0600, makedev(1, 3)) != 0) {  // /dev/null's numbers
    std::filesystem::remove_all(folder);
    GTEST_SKIP() << "cannot make a character device node here (mknod needs CAP_MKNOD): " << std::strerror(errno);
  }
  SystemClock clock;
  EvdevOptions options;
  options.folder = folder;
  options.udev = false;
  options.rescanPeriod = std::chrono::milliseconds(20);
  auto input = EvdevInput::create(clock, options);
  ASSERT_TRUE(input) << input.error().describe();
  EXPECT_FALSE((*input)->hotplugFromUdev());
  (*input)->start();
  auto devices = (*input)->devices();
  ASSERT_EQ(devices.size(), 1U);
  EXPECT_FALSE(devices[0].read);
  EXPECT_NE(devices[0].role.find("not an evdev device"), std::string::npos) << devices[0].role;

  auto waitFor = [&](std::size_t count) {
    for (int i = 0; i < 200 && (*input)->devices().size() != count; ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    return (*input)->devices().size();
  };
  ASSERT_EQ(::mknod((folder / "event1").c_str(), S_IFCHR | 0600, makedev(1, 5)), 0);  // /dev/zero's
  EXPECT_EQ(waitFor(2), 2U);
  std::filesystem::remove(folder / "event0");
  EXPECT_EQ(waitFor(1), 1U);
  EXPECT_EQ((*input)->devices().at(0).path, (folder / "event1").string());
  std::array<Event, 4> none{};
  EXPECT_EQ((*input)->takeInput(none), 0U);
  (*input)->stop();
  std::filesystem::remove_all(folder);
}

}  // namespace
}  // namespace basalt::devices
