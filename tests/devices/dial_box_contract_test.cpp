// The DialBox contract, run against every backend (STYLE.md "Device adapters"): the state
// machine, event tagging and ordering, closing, and a full queue. Instantiated for the synthetic
// and replay backends and the SGI serial box (over a pseudo-terminal pair) always; for hidraw
// (a configfs HID gadget or a uhid device) and the PowerMate (libusb) in the virtual lab, skipping
// with the reason elsewhere.
// Example failures: a backend that pushes events before open() or after close(); events
// arriving out of time order; a full queue blocking the backend's reader thread; close() hanging
// on a reader blocked in read().

#include <gtest/gtest.h>

#include <fcntl.h>
#include <linux/uhid.h>
#include <poll.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <functional>
#include <memory>
#include <ostream>
#include <string>
#include <thread>

#include "devices/dial_box.h"
#include "devices/hid/dial_decoder.h"
#include "devices/hid/hid_backend.h"
#include "devices/midi/midi_backend.h"
#include "devices/midi/midi_decoder.h"
#include "devices/serial/sgi_dial_box.h"
#include "runtime/unique_fd.h"
#include "sim/replay.h"
#include "sim/synthetic_dial.h"
#include "vlab.h"

namespace basalt::devices {
namespace {

using namespace std::chrono_literals;

/// Something that makes the device produce input while the test runs (a fake SGI box on the far
/// end of a pty, a gadget writer); stopped before the device is destroyed.
class Feeder {
 public:
  virtual ~Feeder() = default;
};

/// A thread that calls `step` every 20 ms until destroyed.
class ThreadFeeder final : public Feeder {
 public:
  explicit ThreadFeeder(std::function<bool()> step) {
    thread_ = std::thread([this, step = std::move(step)] {
      while (!stop_.load()) {
        if (!step()) return;
        std::this_thread::sleep_for(20ms);
      }
    });
  }
  ~ThreadFeeder() override {
    stop_.store(true);
    thread_.join();
  }

 private:
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

struct Made {
  std::unique_ptr<Feeder> feeder;  // destroyed after the device (declared first)
  std::unique_ptr<DialBox> device;
};

/// A way to make a backend for the contract, or the reason it cannot run here.
struct DialBackend {
  std::string name;
  /// Makes a device that produces at least 3 dial events within 1 s of Clock time (and of real
  /// time for backends with reader threads).
  std::function<Made(const Clock&, std::string& skipReason)> make;
  bool threaded = false;
};

/// Names the backend in test output (instead of the parameter's bytes).
void PrintTo(const DialBackend& backend, std::ostream* os) { *os << backend.name; }

Made makeSynthetic(const Clock& clock, std::string&) {
  std::vector<sim::ScriptedInput> script = {
      {100ms, EventKind::kDialDelta, 0, 0.1},
      {200ms, EventKind::kDialDelta, 1, -0.2},
      {300ms, EventKind::kButton, 2, 1},
      {400ms, EventKind::kDialDelta, 7, 0.05},
  };
  return {nullptr, std::make_unique<sim::SyntheticDial>(std::move(script), clock)};
}

Made makeReplay(const Clock& clock, std::string& reason) {
  // A recording of Basalt's virtual dial box: four reports, 100 ms apart.
  sim::HidRecordedDevice rec;
  rec.name = "Recorded dial box";
  rec.bus = 6;
  rec.descriptor = virtualDialBoxDescriptor();
  VirtualReportEncoder enc;
  int i = 0;
  for (const Event& e :
       {Event{Nanos{0}, 0, EventKind::kDialDelta, 0, 0.1}, Event{Nanos{0}, 0, EventKind::kDialDelta, 1, -0.2},
        Event{Nanos{0}, 0, EventKind::kButton, 2, 1}, Event{Nanos{0}, 0, EventKind::kDialDelta, 7, 0.05}}) {
    ++i;
    enc.encode(e, [&](std::span<const std::uint8_t> r) {
      rec.reports.push_back({std::chrono::milliseconds(100 * i), {r.begin(), r.end()}});
    });
  }
  auto box =
      sim::ReplayDialBox::create({"Recorded dial box", "replay", "virtual", 0, 0, "memory.hid", ""}, rec, clock, false);
  if (!box) {
    reason = box.error().describe();
    return {};
  }
  return {nullptr, std::move(*box)};
}

/// The SGI box, its far end played by a thread on the master side of a pseudo-terminal.
Made makeSerialPty(const Clock& clock, std::string& reason) {
  UniqueFd master(::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC));
  if (!master || ::grantpt(master.get()) != 0 || ::unlockpt(master.get()) != 0) {
    reason = "no pseudo-terminals here (/dev/ptmx)";
    return {};
  }
  const std::string slave = ::ptsname(master.get());
  auto fd = std::make_shared<UniqueFd>(std::move(master));
  auto count = std::make_shared<std::uint16_t>(0);
  auto feeder = std::make_unique<ThreadFeeder>([fd, count] {
    std::uint8_t buf[64];
    pollfd p{fd->get(), POLLIN, 0};
    if (::poll(&p, 1, 0) > 0 && (p.revents & POLLIN)) {
      const ssize_t n = ::read(fd->get(), buf, sizeof buf);
      for (ssize_t i = 0; i < n; ++i) {
        if (buf[i] == 0x20) {
          const std::uint8_t answer = 0x20;  // the reset's answer
          if (::write(fd->get(), &answer, 1) != 1) return false;
          *count = 0;
        }
      }
    }
    *count = static_cast<std::uint16_t>(*count + 5);
    const std::uint8_t dial[] = {0x32, static_cast<std::uint8_t>(*count >> 8),
                                 static_cast<std::uint8_t>(*count & 0xff)};
    return ::write(fd->get(), dial, sizeof dial) == 3 || errno == EAGAIN || errno == EIO;
  });
  return {std::move(feeder), std::make_unique<SgiDialBox>(slave, clock, 500ms)};
}

/// A configfs HID gadget on dummy_hcd, bound by usbhid: reports written to its /dev/hidgN arrive
/// on the host side's hidraw node.
Made makeHidGadget(const Clock& clock, std::string& reason) {
  const auto ids = test::vlabEnv("BASALT_VLAB_HID_DIAL");
  const auto gadget = test::vlabEnv("BASALT_VLAB_HID_DIAL_GADGET");
  if (!ids || !gadget) {
    reason = test::needsVlab("BASALT_VLAB_HID_DIAL and BASALT_VLAB_HID_DIAL_GADGET (a configfs HID dial gadget)");
    return {};
  }
  HidProvider provider;
  DeviceMatch match;
  if (auto r = parseVendorProduct(*ids, match); !r) {
    reason = r.error().describe();
    return {};
  }
  for (const DeviceCandidate& c : provider.enumerate()) {
    if (!match.matches(c.info) || c.info.path.starts_with("usb:")) continue;
    auto box = openHidrawDialBox(c.info.path, clock);
    if (!box) {
      reason = box.error().describe();
      return {};
    }
    const std::vector<std::uint8_t> report = test::makeDialReport((*box)->reportDescriptor(), 3);
    // Non-blocking: once the host side is closed, usbhid stops polling the interrupt endpoint and
    // a blocking write to the gadget would wait for it forever (and the feeder could not stop).
    auto out = std::make_shared<UniqueFd>(::open(gadget->c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC));
    if (report.empty() || !*out) {
      reason = "cannot write dial reports to " + *gadget;
      return {};
    }
    auto feeder = std::make_unique<ThreadFeeder>([out, report] {
      return ::write(out->get(), report.data(), report.size()) == static_cast<ssize_t>(report.size()) ||
             errno == EAGAIN;  // the host has not read the previous report yet
    });
    return {std::move(feeder), std::move(*box)};
  }
  reason = "no hidraw node for " + *ids + " (is usbhid bound to the gadget?)";
  return {};
}

/// A HID dial created through /dev/uhid by the test itself.
Made makeUhid(const Clock& clock, std::string& reason) {
  if (!test::vlabEnv("BASALT_VLAB_UHID")) {
    reason = test::needsVlab("BASALT_VLAB_UHID=1 (/dev/uhid usable)");
    return {};
  }
  auto fd = std::make_shared<UniqueFd>(::open("/dev/uhid", O_RDWR | O_CLOEXEC));
  if (!*fd) {
    reason = "cannot open /dev/uhid";
    return {};
  }
  const auto& desc = virtualDialBoxDescriptor();
  uhid_event create{};
  create.type = UHID_CREATE2;
  std::snprintf(reinterpret_cast<char*>(create.u.create2.name), sizeof create.u.create2.name, "Basalt uhid dial");
  create.u.create2.rd_size = static_cast<std::uint16_t>(desc.size());
  create.u.create2.bus = 0x05;  // BUS_BLUETOOTH: hidapi lists only USB, Bluetooth, I2C and SPI devices
  create.u.create2.vendor = 0x1d6b;
  create.u.create2.product = 0xba5a;
  std::memcpy(create.u.create2.rd_data, desc.data(), desc.size());
  if (::write(fd->get(), &create, sizeof create) != static_cast<ssize_t>(sizeof create)) {
    reason = "UHID_CREATE2 failed";
    return {};
  }
  HidProvider provider;
  for (int tries = 0; tries < 100; ++tries) {
    for (const DeviceCandidate& c : provider.enumerate()) {
      if (c.info.vendor != 0x1d6b || c.info.product != 0xba5a) continue;
      auto box = openHidrawDialBox(c.info.path, clock);
      if (!box) {
        reason = box.error().describe();
        return {};
      }
      auto feeder = std::make_unique<ThreadFeeder>([fd] {
        uhid_event in{};
        in.type = UHID_INPUT2;
        const std::uint8_t report[21] = {1, 30, 0};  // dial 0: +30 counts
        in.u.input2.size = sizeof report;
        std::memcpy(in.u.input2.data, report, sizeof report);
        return ::write(fd->get(), &in, sizeof in) == static_cast<ssize_t>(sizeof in);
      });
      return {std::move(feeder), std::move(*box)};
    }
    std::this_thread::sleep_for(20ms);
  }
  reason = "the uhid device never got a hidraw node";
  return {};
}

/// A gadget with the PowerMate's ids and report format, reached through libusb.
Made makePowerMateGadget(const Clock& clock, std::string& reason) {
  const auto gadget = test::vlabEnv("BASALT_VLAB_HID_POWERMATE_GADGET");
  if (!test::vlabEnv("BASALT_VLAB_HID_POWERMATE") || !gadget) {
    reason = test::needsVlab("BASALT_VLAB_HID_POWERMATE and BASALT_VLAB_HID_POWERMATE_GADGET (a 077d:0410 gadget)");
    return {};
  }
  auto box = openPowerMate("", clock);
  if (!box) {
    reason = box.error().describe();
    return {};
  }
  // Non-blocking, as for the dial gadget: nobody polls the endpoint while the device is closed.
  auto out = std::make_shared<UniqueFd>(::open(gadget->c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC));
  if (!*out) {
    reason = "cannot open " + *gadget;
    return {};
  }
  auto feeder = std::make_unique<ThreadFeeder>([out] {
    const std::uint8_t report[6] = {0, 2, 0, 0, 0, 0};
    return ::write(out->get(), report, sizeof report) == 6 || errno == EAGAIN;
  });
  return {std::move(feeder), std::move(*box)};
}

/// An X-Touch Mini in MC mode played by a port of the test's own on ALSA's sequencer (the kernel's
/// snd-seq): Basalt's MIDI backend subscribes to it through the kernel as to a USB controller.
Made makeMidiSequencer(const Clock& clock, std::string& reason) {
  auto port = VirtualMidiPort::create("X-TOUCH MINI");
  if (!port) {
    reason = "needs ALSA's sequencer (snd-seq, /dev/snd/seq; the virtual lab loads it): " + port.error().describe();
    return {};
  }
  auto box = openMidiDialBox((*port)->address(), {{"profile", "xtouch-mini-mc"}}, clock);
  if (!box) {
    reason = box.error().describe();
    return {};
  }
  std::shared_ptr<VirtualMidiPort> shared(std::move(*port));
  auto feeder = std::make_unique<ThreadFeeder>([shared] {
    const std::uint8_t turn[] = {0xB0, 0x10, 0x02};  // V-Pot 1 clockwise by 2 (sign-magnitude)
    return static_cast<bool>(shared->send(turn));
  });
  return {std::move(feeder), std::move(*box)};
}

class DialBoxContract : public ::testing::TestWithParam<DialBackend> {
 protected:
  void SetUp() override {
    std::string reason;
    made_ = GetParam().make(clock_, reason);
    if (!made_.device) GTEST_SKIP() << GetParam().name << " backend cannot run here: " << reason;
  }
  void TearDown() override {
    if (made_.device) made_.device->close();
    made_.feeder.reset();
    made_.device.reset();
  }
  /// Advances the clock and lets reader threads run.
  void tick() {
    clock_.advance(10ms);
    if (GetParam().threaded) std::this_thread::sleep_for(2ms);
    made_.device->service(clock_.now());
  }
  DialBox& device() { return *made_.device; }

  ManualClock clock_;
  Made made_;
};

TEST_P(DialBoxContract, OpensLiveAndClosesAbsent) {
  BoundedQueue<Event> events(64);
  EXPECT_EQ(device().state(), DeviceState::kAbsent);
  ASSERT_TRUE(device().open(7, events));
  EXPECT_EQ(device().state(), DeviceState::kLive);
  EXPECT_GT(device().dialCount(), 0);
  EXPECT_FALSE(device().reportDescriptor().empty()) << "every dial box can be recorded";
  EXPECT_TRUE(device().open(7, events)) << "opening a live device is a no-op, not an error";
  device().close();
  EXPECT_EQ(device().state(), DeviceState::kAbsent);
  device().close();  // closing twice is safe
}

TEST_P(DialBoxContract, EventsAreTaggedOrderedAndNeverEarly) {
  BoundedQueue<Event> events(256);
  ASSERT_TRUE(device().open(42, events));
  Nanos last{-1};
  int count = 0;
  for (int step = 0; step < 100; ++step) {
    tick();
    Event e;
    while (events.pop(e)) {
      EXPECT_EQ(e.device, 42u);
      EXPECT_GE(e.time, last) << "events out of time order";
      EXPECT_LE(e.time, clock_.now()) << "an event from the future";
      if (e.kind == EventKind::kDialDelta) {
        EXPECT_LT(e.index, device().dialCount());
        ++count;
      }
      last = e.time;
    }
  }
  EXPECT_GE(count, 3);
  EXPECT_EQ(device().state(), DeviceState::kLive);
}

TEST_P(DialBoxContract, NothingFlowsWhenClosed) {
  BoundedQueue<Event> events(64);
  ASSERT_TRUE(device().open(1, events));
  device().close();
  Event e;
  while (events.pop(e)) {
  }
  for (int i = 0; i < 20; ++i) tick();
  EXPECT_EQ(events.size(), 0u);
}

TEST_P(DialBoxContract, AFullQueueDropsInsteadOfBlocking) {
  BoundedQueue<Event> events(1);
  ASSERT_TRUE(device().open(1, events));
  for (int i = 0; i < 100 && events.dropped() == 0; ++i) tick();
  EXPECT_EQ(events.size(), 1u);
  EXPECT_GE(events.dropped(), 1u);
  device().close();  // must not hang on a reader blocked by the full queue
}

TEST_P(DialBoxContract, RawReportsReachTheTapAndDecodeToTheSameEvents) {
  struct Tap final : ReportTap {
    std::mutex mutex;
    std::vector<std::vector<std::uint8_t>> reports;
    void onReport(DeviceId, Nanos, std::span<const std::uint8_t> r) override {
      std::lock_guard lock(mutex);
      reports.emplace_back(r.begin(), r.end());
    }
  } tap;
  BoundedQueue<Event> events(256);
  device().setReportTap(&tap);
  ASSERT_TRUE(device().open(3, events));
  for (int i = 0; i < 100; ++i) tick();
  device().close();
  device().setReportTap(nullptr);
  std::vector<Event> direct;
  Event e;
  while (events.pop(e)) {
    if (e.kind == EventKind::kDialDelta || e.kind == EventKind::kButton) direct.push_back(e);
  }
  std::vector<Event> again;
  std::array<Event, DialDecoder::kMaxEventsPerReport> out;
  std::lock_guard lock(tap.mutex);
  if (isMidiDescriptor(device().reportDescriptor())) {
    // A MIDI dial box taps MIDI messages; its descriptor holds the profile that decodes them.
    auto profile = parseMidiDescriptor(device().reportDescriptor());
    ASSERT_TRUE(profile) << profile.error().describe();
    MidiDecoder decoder(std::move(*profile));
    for (const auto& r : tap.reports) {
      const std::size_t n = decoder.decode(r, out);
      for (std::size_t i = 0; i < n; ++i) again.push_back(out[i]);
    }
  } else {
    auto decoder = DialDecoder::create(device().info().vendor, device().info().product, device().reportDescriptor());
    ASSERT_TRUE(decoder) << decoder.error().describe();
    for (const auto& r : tap.reports) {
      const std::size_t n = decoder->decode(r, out);
      for (std::size_t i = 0; i < n; ++i) again.push_back(out[i]);
    }
  }
  ASSERT_FALSE(direct.empty());
  ASSERT_EQ(again.size(), direct.size()) << "recording the raw reports loses or invents events";
  for (std::size_t i = 0; i < direct.size(); ++i) {
    EXPECT_EQ(again[i].kind, direct[i].kind);
    EXPECT_EQ(again[i].index, direct[i].index);
    EXPECT_NEAR(again[i].value, direct[i].value, 1.0 / 3600);
  }
}

INSTANTIATE_TEST_SUITE_P(Backends, DialBoxContract,
                         ::testing::Values(DialBackend{"synthetic", makeSynthetic}, DialBackend{"replay", makeReplay},
                                           DialBackend{"serial_sgi_pty", makeSerialPty, true},
                                           DialBackend{"hid_gadget", makeHidGadget, true},
                                           DialBackend{"hid_uhid", makeUhid, true},
                                           DialBackend{"powermate_gadget", makePowerMateGadget, true},
                                           DialBackend{"midi_sequencer", makeMidiSequencer, true}),
                         [](const ::testing::TestParamInfo<DialBackend>& param) { return param.param.name; });

}  // namespace
}  // namespace basalt::devices
