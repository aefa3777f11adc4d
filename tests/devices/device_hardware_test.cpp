// Real hardware paths the contract suites do not cover, run in the virtual lab (skipping with the
// reason elsewhere): an HDMI input that loses its signal, gets it back and changes resolution
// renegotiates by itself (vivid's "DV Timings Signal Mode" control); USB gadgets unplugged and
// replugged from their UDC, and vivid unbound from its driver and bound again, drive the
// DeviceManager through lost and back to live through udev;
// V4L2 enumeration describes vivid's nodes.
// Example failures: a capture thread stuck in DQBUF after the signal went; a stream that stays
// lost after the cable is back; a dial box that needs a restart after a replug.

#include <gtest/gtest.h>

#include <poll.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <mutex>
#include <thread>

#include "devices/device_manager.h"
#include "devices/hid/hid_backend.h"
#include "devices/libcamera/libcamera_camera.h"
#include "devices/udev/udev_monitor.h"
#include "devices/v4l2/v4l2_camera.h"
#include "tools/vlab/uvc/usb_powermate.h"
#include "tools/vlab/uvc/usbip.h"
#include "vlab.h"
#include "vlab_uvc.h"

namespace basalt::devices {
namespace {

using namespace std::chrono_literals;

/// Runs `step` every 10 ms until `done` or `limit` of real time.
template <typename Step, typename Done>
bool waitFor(Step step, Done done, std::chrono::milliseconds limit) {
  const auto end = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < end) {
    step();
    if (done()) return true;
    std::this_thread::sleep_for(10ms);
  }
  return false;
}

TEST(V4l2Hardware, HdmiSignalLossAndResolutionChangeRenegotiate) {
  const auto node = test::vlabEnv("BASALT_VLAB_V4L2_HDMI");
  if (!node) GTEST_SKIP() << test::needsVlab("BASALT_VLAB_V4L2_HDMI (vivid HDMI input)");
  SystemClock clock;
  auto source = makeV4l2Camera(*node, {}, clock);
  ASSERT_TRUE(source->open(1));
  auto serviceAndDrain = [&] {
    source->service(clock.now());
    (void)source->frameAt(clock.now());
  };
  ASSERT_TRUE(waitFor(serviceAndDrain, [&] { return source->framesDelivered() > 2; }, 5s)) << "no frames";
  const VideoMode before = source->mode();
  // vivid: "DV Timings Signal Mode" 1 = no signal, 0 = current timings, 4 = selected timings.
  ASSERT_TRUE(setV4l2ControlByName(*node, "DV Timings Signal Mode", 1));
  EXPECT_TRUE(waitFor(
      serviceAndDrain, [&] { return source->health().state == SourceState::kLost; }, 5s))
      << "the signal went but the source stayed live";
  EXPECT_TRUE(source->recovering());
  ASSERT_TRUE(setV4l2ControlByName(*node, "DV Timings Signal Mode", 0));
  const auto delivered = source->framesDelivered();
  EXPECT_TRUE(waitFor(
      serviceAndDrain,
      [&] { return source->health().state == SourceState::kLive && source->framesDelivered() > delivered + 2; }, 10s))
      << "the signal came back but the stream did not";
  // Another resolution: pick a different entry of the "DV Timings" menu, then select it.
  bool changed = false;
  for (int entry = 1; entry < 8 && !changed; ++entry) {
    if (!setV4l2ControlByName(*node, "DV Timings", entry)) continue;
    if (!setV4l2ControlByName(*node, "DV Timings Signal Mode", 4)) break;
    changed = waitFor(
        serviceAndDrain,
        [&] { return source->mode().width != before.width && source->health().state == SourceState::kLive; }, 5s);
  }
  EXPECT_TRUE(changed) << "no resolution change was renegotiated; lost: "
                       << (source->lostReason() ? source->lostReason()->describe() : "no");
  source->close();
  // The input as the lab's other cases expect it: a steady signal on the current timings.
  EXPECT_TRUE(setV4l2ControlByName(*node, "DV Timings Signal Mode", 0));
}

TEST(V4l2Hardware, EnumerationDescribesTheWebcam) {
  const auto node = test::vlabEnv("BASALT_VLAB_V4L2_WEBCAM");
  if (!node) GTEST_SKIP() << test::needsVlab("BASALT_VLAB_V4L2_WEBCAM (vivid webcam input)");
  auto d = describeV4l2Device(*node);
  ASSERT_TRUE(d) << d.error().describe();
  EXPECT_FALSE(d->modes.empty());
  EXPECT_TRUE(d->streaming);
  V4l2Provider provider;
  bool listed = false;
  for (const auto& c : provider.enumerate()) listed = listed || c.info.path == *node;
  EXPECT_TRUE(listed);
}

// Every format vivid's webcam offers that Basalt handles, each streamed with plain mmap buffers
// and with buffers exported as dmabufs: the frames come in that format and size, with its planes,
// in order, their driver timestamps rising on the frame interval's scale and close to now on the
// show's clock. Example failures: a format whose planes are laid out wrongly; dmabuf export that
// silently falls back to mmap; timestamps from another clock.
TEST(V4l2Hardware, WebcamStreamsEachFormatWithMmapAndDmabuf) {
  const auto node = test::vlabEnv("BASALT_VLAB_V4L2_WEBCAM");
  if (!node) GTEST_SKIP() << test::needsVlab("BASALT_VLAB_V4L2_WEBCAM (vivid webcam input)");
  auto d = describeV4l2Device(*node);
  ASSERT_TRUE(d) << d.error().describe();
  std::vector<PixelFormat> formats;
  for (const VideoMode& m : d->modes) {
    if (std::find(formats.begin(), formats.end(), m.format) == formats.end()) formats.push_back(m.format);
  }
  ASSERT_GE(formats.size(), 3u) << "vivid offers YUYV, NV12 and more";
  SystemClock clock;
  for (const PixelFormat format : formats) {
    for (const bool dmabuf : {false, true}) {
      SCOPED_TRACE(std::string(pixelFormatName(format)) + (dmabuf ? " with dmabuf export" : " with mmap"));
      V4l2Options options;
      options.format = format;
      options.width = 640;
      options.height = 360;
      options.exportDmabuf = dmabuf;
      auto source = makeV4l2Camera(*node, options, clock);
      auto opened = source->open(1);
      ASSERT_TRUE(opened) << opened.error().describe();
      EXPECT_EQ(source->mode().format, format);
      std::vector<FrameRef> frames;
      const auto start = std::chrono::steady_clock::now();
      while (frames.size() < 4 && std::chrono::steady_clock::now() - start < 10s) {
        source->service(clock.now());
        if (FrameRef f = source->frameAt(clock.now())) frames.push_back(std::move(f));
        std::this_thread::sleep_for(5ms);
      }
      ASSERT_GE(frames.size(), 4u) << "frames in 10 s";
      const VideoMode mode = source->mode();
      const Nanos interval = mode.fps > 0 ? Nanos{static_cast<std::int64_t>(1e9 / mode.fps)} : Nanos{0};
      for (std::size_t i = 0; i < frames.size(); ++i) {
        const Frame& f = *frames[i];
        EXPECT_EQ(f.format, format);
        EXPECT_EQ(f.width, mode.width);
        EXPECT_EQ(f.height, mode.height);
        EXPECT_GE(f.planeCount, 1);
        for (int p = 0; p < f.planeCount; ++p) {
          const Plane& plane = f.planes[static_cast<std::size_t>(p)];
          EXPECT_NE(plane.data, nullptr) << "plane " << p;
          EXPECT_EQ(plane.dmabufFd >= 0, dmabuf) << "plane " << p;
        }
        // Driver timestamps (CLOCK_MONOTONIC) on the show's clock: in the last few seconds.
        EXPECT_LE(f.captureTime, clock.now());
        EXPECT_GT(f.captureTime, clock.now() - 15s);
        if (i == 0) continue;
        const Nanos step = f.captureTime - frames[i - 1]->captureTime;
        EXPECT_GT(step, Nanos{0}) << "timestamps rise";
      }
      if (interval.count() > 0) {
        // On the frame interval's scale (nanoseconds, not another unit): the mean step is between
        // half an interval and a few (frames the test missed under emulation make whole ones;
        // vivid's timestamps jitter with the host's load).
        const Nanos span = frames.back()->captureTime - frames.front()->captureTime;
        const double intervals = static_cast<double>(span.count()) / static_cast<double>(interval.count()) /
                                 static_cast<double>(frames.size() - 1);
        EXPECT_GE(intervals, 0.5) << "mean step " << intervals << " frame intervals";
        EXPECT_LE(intervals, 6.0) << "mean step " << intervals << " frame intervals";
      }
      frames.clear();
      source->close();
    }
  }
}

/// Unplugs and replugs a gadget with the lab's control program.
bool gadgetCtl(const std::string& what, const std::string& gadget) {
  const auto ctl = test::vlabEnv("BASALT_VLAB_GADGET_CTL");
  if (!ctl) return false;
  const std::string cmd = *ctl + " " + what + " " + gadget;
  return std::system(cmd.c_str()) == 0;
}

/// The cable of gadget `name`: pulled (false) and plugged in (true).
std::function<bool(bool)> gadget(const std::string& name) {
  return [name](bool plug) { return gadgetCtl(plug ? "plug" : "unplug", name); };
}

/// The number of file descriptors this process has open.
std::size_t openFds() {
  std::size_t n = 0;
  std::error_code ec;
  for (auto it = std::filesystem::directory_iterator("/proc/self/fd", ec);
       !ec && it != std::filesystem::directory_iterator(); it.increment(ec)) {
    ++n;
  }
  return n;
}

/// Unbinds or binds (plug) a platform device from its driver through sysfs, as a driver reload
/// or a capture card's firmware reset does.
bool platformBind(const std::string& driver, const std::string& device, bool plug) {
  std::ofstream out("/sys/bus/platform/drivers/" + driver + (plug ? "/bind" : "/unbind"));
  out << device;
  out.flush();
  return static_cast<bool>(out);
}

void hotplugRoundTrip(DeviceKind kind, const std::function<bool(bool plug)>& cable, DeviceMatch match,
                      std::unique_ptr<DeviceProvider> provider) {
  SystemClock clock;
  BoundedQueue<Event> events(4096);
  DeviceManager manager(clock, events);
  manager.addProvider(std::move(provider));
  DeviceRequest r;
  r.name = "device";
  r.kind = kind;
  r.match = std::move(match);
  ASSERT_TRUE(manager.request(r));
  auto monitor = UdevMonitor::create();
  if (monitor) (*monitor)->start([&](HotplugEvent e) { manager.notifyHotplug(std::move(e)); });
  manager.start(10ms);
  auto state = [&] { return manager.status()[0].state; };
  auto idle = [] {};
  ASSERT_TRUE(waitFor(idle, [&] { return state() == DeviceState::kLive; }, 10s)) << manager.status()[0].lastError;
  const std::size_t fdsLive = openFds();
  ASSERT_TRUE(cable(false));
  EXPECT_TRUE(waitFor(idle, [&] { return state() == DeviceState::kLost || state() == DeviceState::kReopening; }, 10s));
  ASSERT_TRUE(cable(true));
  EXPECT_TRUE(waitFor(
      idle, [&] { return state() == DeviceState::kLive; }, 20s))
      << "not live again after the replug: " << manager.status()[0].lastError;
  // Live again with what it held before: the lost device's descriptors were all closed.
  EXPECT_TRUE(waitFor(
      idle, [&] { return openFds() <= fdsLive; }, 5s))
      << openFds() << " descriptors open, " << fdsLive << " before the unplug";
  manager.stop();
  if (monitor) (*monitor)->stop();
}

TEST(HotplugHardware, DialGadgetUnpluggedAndReplugged) {
  const auto ids = test::vlabEnv("BASALT_VLAB_HID_DIAL");
  if (!ids || !test::vlabEnv("BASALT_VLAB_GADGET_CTL")) {
    GTEST_SKIP() << test::needsVlab("BASALT_VLAB_HID_DIAL and BASALT_VLAB_GADGET_CTL");
  }
  DeviceMatch m;
  m.backend = "hid";
  ASSERT_TRUE(parseVendorProduct(*ids, m));
  hotplugRoundTrip(DeviceKind::kDialBox, gadget("dial"), m, std::make_unique<HidProvider>());
}

TEST(HotplugHardware, PowerMateGadgetUnpluggedAndReplugged) {
  if (!test::vlabEnv("BASALT_VLAB_HID_POWERMATE") || !test::vlabEnv("BASALT_VLAB_GADGET_CTL")) {
    GTEST_SKIP() << test::needsVlab("BASALT_VLAB_HID_POWERMATE and BASALT_VLAB_GADGET_CTL");
  }
  DeviceMatch m;
  m.backend = "hid";
  m.vendor = 0x077d;
  m.product = 0x0410;
  hotplugRoundTrip(DeviceKind::kDialBox, gadget("powermate"), m, std::make_unique<HidProvider>());
}

TEST(HotplugHardware, UvcGadgetUnpluggedAndReplugged) {
  const auto node = test::labUvcNode();
  if (!node || !test::vlabEnv("BASALT_VLAB_GADGET_CTL")) {
    GTEST_SKIP() << test::needsVlab("BASALT_VLAB_V4L2_UVC and BASALT_VLAB_GADGET_CTL");
  }
  DeviceMatch m;
  m.backend = "v4l2";
  m.name = "";
  auto d = describeV4l2Device(*node);
  ASSERT_TRUE(d) << d.error().describe();
  m.name = d->card;  // the node may get another number after the replug: match by name
  hotplugRoundTrip(DeviceKind::kVideoSource, gadget("uvc"), m, std::make_unique<V4l2Provider>());
}

/// Passes everything to the libcamera backend and keeps the hotplug events its signals send.
class RecordingLibcameraProvider final : public DeviceProvider {
 public:
  explicit RecordingLibcameraProvider(std::shared_ptr<std::vector<HotplugEvent>> seen) : seen_(std::move(seen)) {}
  [[nodiscard]] std::string_view backend() const override { return inner_.backend(); }
  std::vector<DeviceCandidate> enumerate() override { return inner_.enumerate(); }
  Result<std::shared_ptr<VideoSource>> openVideoSource(const DeviceCandidate& c, const DeviceRequest& r,
                                                       const Clock& clock) override {
    return inner_.openVideoSource(c, r, clock);
  }
  void watchHotplug(const std::function<void(HotplugEvent)>& notify) override {
    inner_.watchHotplug([seen = seen_, mutex = mutex_, notify](HotplugEvent e) {
      {
        std::lock_guard lock(*mutex);
        seen->push_back(e);
      }
      notify(std::move(e));
    });
  }
  [[nodiscard]] std::shared_ptr<std::mutex> mutex() const { return mutex_; }

 private:
  LibcameraProvider inner_;
  std::shared_ptr<std::vector<HotplugEvent>> seen_;
  std::shared_ptr<std::mutex> mutex_ = std::make_shared<std::mutex>();  // guards *seen_
};

// The UVC camera through libcamera, unplugged and plugged in again while it streams: libcamera's
// cameraRemoved and cameraAdded signals reach the DeviceManager, which reports it lost and brings
// it back live without a restart. Example failures: a Camera whose disconnected signal is never
// connected (the stream stays "live" with no frames); a replugged camera that libcamera announces
// but Basalt never reopens.
TEST(HotplugHardware, LibcameraUvcUnpluggedAndReplugged) {
  if (!test::vlabEnv("BASALT_VLAB_V4L2_UVC") || !test::vlabEnv("BASALT_VLAB_GADGET_CTL")) {
    GTEST_SKIP() << test::needsVlab("BASALT_VLAB_V4L2_UVC and BASALT_VLAB_GADGET_CTL");
  }
  std::string model;
  // The camera may be coming back from the case before (udev processes it before libcamera
  // lists it): wait a while for it.
  for (int attempt = 0; attempt < 20 && model.empty(); ++attempt) {
    LibcameraProvider probe;
    if (!probe.startError().empty()) GTEST_SKIP() << probe.startError();
    const auto cameras = probe.enumerate();
    if (!cameras.empty()) {
      model = cameras.front().info.name;
    } else {
      std::this_thread::sleep_for(500ms);
    }
  }
  if (model.empty()) GTEST_SKIP() << "libcamera sees no camera after 10 s, not even the lab's UVC camera";
  DeviceMatch m;
  m.backend = "libcamera";
  m.name = model;
  auto seen = std::make_shared<std::vector<HotplugEvent>>();
  auto provider = std::make_unique<RecordingLibcameraProvider>(seen);
  const auto mutex = provider->mutex();
  hotplugRoundTrip(DeviceKind::kVideoSource, gadget("uvc"), m, std::move(provider));
  std::lock_guard lock(*mutex);
  const auto has = [&](HotplugEvent::Action a) {
    return std::any_of(seen->begin(), seen->end(),
                       [&](const HotplugEvent& e) { return e.action == a && e.subsystem == "libcamera"; });
  };
  EXPECT_TRUE(has(HotplugEvent::Action::kRemoved)) << "no cameraRemoved signal for the unplug";
  EXPECT_TRUE(has(HotplugEvent::Action::kAdded)) << "no cameraAdded signal for the replug";
}

// vivid's webcam instance unbound from its driver and bound again while Basalt streams it (what
// a driver reload does): lost, then live again through the DeviceManager and udev, matched by
// its card name; the node comes back where the lab's other cases expect it.
TEST(HotplugHardware, VividUnboundAndBoundAgain) {
  const auto node = test::vlabEnv("BASALT_VLAB_V4L2_WEBCAM");
  if (!node) GTEST_SKIP() << test::needsVlab("BASALT_VLAB_V4L2_WEBCAM (vivid webcam input)");
  if (!std::filesystem::exists("/sys/bus/platform/drivers/vivid/vivid.0")) {
    GTEST_SKIP() << "vivid.0 is not bound to the vivid driver here";
  }
  auto d = describeV4l2Device(*node);
  ASSERT_TRUE(d) << d.error().describe();
  DeviceMatch m;
  m.backend = "v4l2";
  m.name = d->card;
  hotplugRoundTrip(
      DeviceKind::kVideoSource, [](bool plug) { return platformBind("vivid", "vivid.0", plug); }, m,
      std::make_unique<V4l2Provider>());
  EXPECT_TRUE(waitFor([] {}, [&] { return std::filesystem::exists(*node); }, 10s))
      << *node << " did not come back (later cases use it)";
}

// A PowerMate emulated in user space and plugged into the guest's vhci_hcd (the HID core leaves
// it alone, as it does the real knob): Basalt's libusb backend sets its LED's brightness and pulse
// through the vendor request, which the knob records, and its turns and presses arrive as dial
// and button events. Example failures: a wrong request type or setting number (the knob would
// stall it or record nothing); a rotation byte read unsigned (a turn back goes forward).
TEST(PowerMateHardware, LightAndKnobOfAnEmulatedPowerMate) {
  const auto vhci = test::vlabEnv("BASALT_VLAB_VHCI");
  if (!vhci) GTEST_SKIP() << test::needsVlab("BASALT_VLAB_VHCI (the USB/IP virtual host controller)");
  SystemClock clock;
  HidProvider provider;
  auto powerMates = [&] {
    std::vector<std::string> paths;
    for (const DeviceCandidate& c : provider.enumerate()) {
      if (c.info.vendor == 0x077d && c.info.product == 0x0410 && c.info.path.starts_with("usb:")) {
        paths.push_back(c.info.path);
      }
    }
    return paths;
  };
  const std::vector<std::string> before = powerMates();  // the lab's gadget knob, if any

  sim::vlab::UsbPowerMate knob;
  auto attached = sim::vlab::VhciAttachment::attach(knob, clock, *vhci);
  ASSERT_TRUE(attached) << attached.error().describe();
  std::atomic<bool> stop{false};
  std::thread server([&] {
    auto& link = attached->link();
    while (!stop.load()) {
      pollfd p{link.fd(), POLLIN, 0};
      (void)::poll(&p, 1, 5);
      if ((p.revents & (POLLIN | POLLHUP | POLLERR)) != 0 && !link.onReadable()) break;
      if (!link.serviceTransfers()) break;
    }
  });
  struct Join {
    std::atomic<bool>& stop;
    std::thread& thread;
    ~Join() {
      stop = true;
      thread.join();
    }
  } join{stop, server};

  std::string path;
  ASSERT_TRUE(waitFor([] {},
                      [&] {
                        for (const std::string& p : powerMates()) {
                          if (std::find(before.begin(), before.end(), p) == before.end()) path = p;
                        }
                        return !path.empty();
                      },
                      15s))
      << "the emulated PowerMate did not enumerate";
  auto box = openPowerMate(path, clock);
  ASSERT_TRUE(box) << box.error().describe();
  BoundedQueue<Event> events(256);
  auto opened = (*box)->open(7, events);
  ASSERT_TRUE(opened) << opened.error().describe();

  ASSERT_TRUE((*box)->setLight(0, 0.5, false));
  EXPECT_EQ(knob.led().brightness, 128);
  EXPECT_EQ(knob.led().pulse, 0);
  ASSERT_TRUE((*box)->setLight(0, 1.0, true));
  EXPECT_EQ(knob.led().brightness, 255);
  EXPECT_EQ(knob.led().pulse, 1);
  EXPECT_FALSE((*box)->setLight(1, 1.0, false)) << "the PowerMate has one light";

  std::vector<Event> got;
  auto collect = [&](std::size_t n) {
    return waitFor(
        [&] {
          (*box)->service(clock.now());
          Event e;
          while (events.pop(e)) got.push_back(e);
        },
        [&] { return got.size() >= n; }, 5s);
  };
  knob.pushReport(0, 3);
  ASSERT_TRUE(collect(1)) << "a turn forward";
  EXPECT_EQ(got[0].kind, EventKind::kDialDelta);
  EXPECT_EQ(got[0].device, 7u);
  EXPECT_GT(got[0].value, 0.0);
  knob.pushReport(0, -2);
  ASSERT_TRUE(collect(2)) << "a turn back";
  EXPECT_EQ(got[1].kind, EventKind::kDialDelta);
  EXPECT_LT(got[1].value, 0.0);
  EXPECT_NEAR(got[1].value, -got[0].value * 2.0 / 3.0, 1e-9);
  knob.pushReport(1, 0);
  knob.pushReport(0, 0);
  ASSERT_TRUE(collect(4)) << "a press and a release";
  EXPECT_EQ(got[2].kind, EventKind::kButton);
  EXPECT_EQ(got[2].value, 1.0);
  EXPECT_EQ(got[3].kind, EventKind::kButton);
  EXPECT_EQ(got[3].value, 0.0);
  (*box)->close();
  // Unplugged: gone from the bus before the next case looks for a PowerMate.
  attached->detach();
  EXPECT_TRUE(waitFor([] {},
                      [&] {
                        const auto now = powerMates();
                        return std::find(now.begin(), now.end(), path) == now.end();
                      },
                      10s))
      << path << " is still listed after the unplug";
}

TEST(UdevHotplug, MonitorStartsOrSaysWhy) {
  auto monitor = UdevMonitor::create();
  if (!monitor) {
    EXPECT_NE(monitor.error().message().find("retry"), std::string::npos) << monitor.error().describe();
    GTEST_SKIP() << "no udev here: " << monitor.error().describe();
  }
  (*monitor)->start([](const HotplugEvent&) {});
  (*monitor)->stop();
  (*monitor)->stop();  // twice is safe
}

}  // namespace
}  // namespace basalt::devices
