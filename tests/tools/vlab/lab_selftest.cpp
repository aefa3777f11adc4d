// The virtual lab's self-tests: run inside the lab (ctest `vlab/basalt_vlab_selftest/...`),
// they check from the guest that every fixture of the environment contract (tools/vlab/README.md)
// is really there and works, so that a real-backend test that fails in the lab fails because of
// Basalt, not because of the lab. Outside the lab each test skips, saying so.
//
// External tools they use are Debian's (scripts/packages-test.txt): v4l2-ctl (v4l-utils) for V4L2,
// kmscube for KMS, cam (libcamera-tools) for libcamera, so that the lab is checked by programs
// other than Basalt's own backends.

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "runtime/unique_fd.h"
#include "sim/hid_recording.h"
#include "sim/jpeg_encoder.h"
#include "support/process.h"
#include "support/test_paths.h"
#include "tools/vlab/uhid_device.h"
#include "tools/vlab/uvc/test_picture.h"
#include "tools/vlab/uvc/uvc_camera.h"

namespace basalt {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

#define NEED_LAB()                                                                                        \
  do {                                                                                                    \
    if (!std::getenv("BASALT_VLAB")) GTEST_SKIP() << "needs the virtual lab (make vlab): not in the lab"; \
  } while (false)

std::string env(const char* name) {
  const char* v = std::getenv(name);
  return v ? v : "";
}

std::string readText(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string trimmed(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
  return s;
}

/// The fixture line "ok|fail|unsupported NAME detail" the lab wrote for `name`.
std::string fixtureLine(const std::string& name) {
  std::istringstream in(readText(fs::path(env("BASALT_VLAB_RESULTS")) / "fixtures"));
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream w(line);
    std::string status;
    std::string fixture;
    w >> status >> fixture;
    if (fixture == name) return line;
  }
  return "(no line for " + name + " in the lab's fixtures file)";
}

/// /dev/hidrawN whose HID_ID has this bus, vendor and product; nullopt when there is none.
std::optional<fs::path> hidrawById(unsigned bus, unsigned vendor, unsigned product) {
  char wanted[64];
  std::snprintf(wanted, sizeof wanted, "HID_ID=%04X:%08X:%08X", bus, vendor, product);
  std::error_code ec;
  for (const auto& e : fs::directory_iterator("/sys/class/hidraw", ec)) {
    std::istringstream in(readText(e.path() / "device" / "uevent"));
    std::string line;
    while (std::getline(in, line)) {
      if (line == wanted) return fs::path("/dev") / e.path().filename();
    }
  }
  return std::nullopt;
}

std::vector<std::uint8_t> sysfsDescriptor(const fs::path& hidraw) {
  const std::string d = readText(fs::path("/sys/class/hidraw") / hidraw.filename() / "device" / "report_descriptor");
  return {d.begin(), d.end()};
}

/// The host-side USB device folder with these ids, or empty.
fs::path usbDevice(const std::string& vendor, const std::string& product) {
  std::error_code ec;
  for (const auto& e : fs::directory_iterator("/sys/bus/usb/devices", ec)) {
    if (trimmed(readText(e.path() / "idVendor")) == vendor && trimmed(readText(e.path() / "idProduct")) == product) {
      return e.path();
    }
  }
  return {};
}

/// Reads one report from a hidraw fd within `limit`; empty on time-out.
std::vector<std::uint8_t> readReport(int fd, std::chrono::milliseconds limit) {
  pollfd p{fd, POLLIN, 0};
  if (::poll(&p, 1, static_cast<int>(limit.count())) <= 0) return {};
  std::vector<std::uint8_t> buf(4096);
  const ssize_t n = ::read(fd, buf.data(), buf.size());
  if (n <= 0) return {};
  buf.resize(static_cast<std::size_t>(n));
  return buf;
}

void drain(int fd) {
  while (!readReport(fd, 0ms).empty()) {
  }
}

bool waitFor(const auto& condition, std::chrono::milliseconds limit) {
  const auto end = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < end) {
    if (condition()) return true;
    std::this_thread::sleep_for(50ms);
  }
  return condition();
}

test::ProcessResult gadgetCtl(const std::string& action, const std::string& device) {
  return test::run({env("BASALT_VLAB_GADGET_CTL"), action, device}, {}, 30s);
}

// The lab's dial box report descriptor, as documented in tools/vlab/README.md: 8 buttons, then 8
// relative signed-byte dials X, Y, Z, Rx, Ry, Rz, Dial, Wheel.
const std::vector<std::uint8_t> kDialDescriptor = {
    0x05, 0x01, 0x09, 0x08, 0xa1, 0x01, 0x05, 0x09, 0x19, 0x01, 0x29, 0x08, 0x15, 0x00, 0x25, 0x01, 0x75,
    0x01, 0x95, 0x08, 0x81, 0x02, 0x05, 0x01, 0x09, 0x30, 0x09, 0x31, 0x09, 0x32, 0x09, 0x33, 0x09, 0x34,
    0x09, 0x35, 0x09, 0x37, 0x09, 0x38, 0x15, 0x81, 0x25, 0x7f, 0x75, 0x08, 0x95, 0x08, 0x81, 0x06, 0xc0};

// Makes sure the lab exports every variable of the environment contract, well formed. Example
// failure: a fixture that failed to set up leaves its variable unset, and the real-backend tests
// would skip instead of run.
TEST(LabEnvironment, EveryContractVariableIsSetAndWellFormed) {
  NEED_LAB();
  EXPECT_EQ(env("BASALT_VLAB"), "1");
  for (const char* node :
       {"BASALT_VLAB_V4L2_WEBCAM", "BASALT_VLAB_V4L2_HDMI", "BASALT_VLAB_V4L2_INPUTS", "BASALT_VLAB_V4L2_UVC",
        "BASALT_VLAB_HID_DIAL_GADGET", "BASALT_VLAB_HID_POWERMATE_GADGET", "BASALT_VLAB_DRM"}) {
    struct stat st{};
    EXPECT_EQ(::stat(env(node).c_str(), &st), 0) << node << "=" << env(node);
    EXPECT_TRUE(S_ISCHR(st.st_mode)) << node << "=" << env(node) << " is not a character device";
  }
  EXPECT_EQ(env("BASALT_VLAB_HID_DIAL"), "1209:0001");
  EXPECT_EQ(env("BASALT_VLAB_HID_POWERMATE"), "077d:0410");
  EXPECT_EQ(env("BASALT_VLAB_UHID"), "1");
  EXPECT_EQ(::access(env("BASALT_VLAB_GADGET_CTL").c_str(), X_OK), 0) << env("BASALT_VLAB_GADGET_CTL");
  EXPECT_NE(env("BASALT_VLAB_DRM").find("/dev/dri/card"), std::string::npos);
  EXPECT_EQ(env("BASALT_VLAB_UDEV"), "1") << fixtureLine("udev");
  EXPECT_TRUE(fs::is_directory(env("BASALT_VLAB_VHCI"))) << fixtureLine("vhci");
  EXPECT_FALSE(env("BASALT_VLAB_UVC_CONTROL").empty()) << fixtureLine("uvc");
  EXPECT_EQ(env("BASALT_VLAB_LOOPBACK"), "1") << fixtureLine("loopback");
}

// Makes sure vivid's webcam input is a webcam and streams frames through mmap. Example failure:
// vivid loaded with the wrong input_types, so the "webcam" node is a TV tuner.
TEST(LabV4l2, WebcamIsVividAndStreamsFrames) {
  NEED_LAB();
  const std::string dev = env("BASALT_VLAB_V4L2_WEBCAM");
  ASSERT_FALSE(dev.empty()) << fixtureLine("webcam");
  const auto info = test::run({"/usr/bin/v4l2-ctl", "-d", dev, "--info", "--get-input", "--list-inputs"});
  ASSERT_EQ(info.exitCode, 0) << info.output;
  EXPECT_NE(info.output.find("vivid"), std::string::npos) << info.output;
  EXPECT_NE(info.output.find("Camera"), std::string::npos) << "input 0 is not a camera:\n" << info.output;
  const fs::path out = fs::path("/tmp") / "vlab-webcam.raw";
  const auto stream = test::run(
      {"/usr/bin/v4l2-ctl", "-d", dev, "--stream-mmap", "--stream-count=2", "--stream-to=" + out.string()}, {}, 60s);
  ASSERT_EQ(stream.exitCode, 0) << stream.output;
  std::error_code ec;
  EXPECT_GT(fs::file_size(out, ec), 0U) << "no frame data from " << dev;
}

// Makes sure vivid's second instance is an HDMI input with DV timings that streams. Example
// failure: the node has no DV timings API, so the HDMI tests cannot change or drop the signal.
TEST(LabV4l2, HdmiInputHasDvTimingsAndStreams) {
  NEED_LAB();
  const std::string dev = env("BASALT_VLAB_V4L2_HDMI");
  ASSERT_FALSE(dev.empty()) << fixtureLine("hdmi");
  const auto inputs = test::run({"/usr/bin/v4l2-ctl", "-d", dev, "--list-inputs", "--query-dv-timings"});
  ASSERT_EQ(inputs.exitCode, 0) << inputs.output;
  EXPECT_NE(inputs.output.find("HDMI"), std::string::npos) << inputs.output;
  EXPECT_NE(inputs.output.find("Active width"), std::string::npos) << "no DV timings:\n" << inputs.output;
  const auto stream = test::run({"/usr/bin/v4l2-ctl", "-d", dev, "--stream-mmap", "--stream-count=1"}, {}, 60s);
  EXPECT_EQ(stream.exitCode, 0) << stream.output;
}

// Makes sure a report written to the dial gadget's /dev/hidgN arrives, unchanged, on the host
// side's hidraw node (usbhid over dummy_hcd), and that the host sees the documented descriptor.
// Example failure: the descriptor reached configfs in pieces, so usbhid cannot parse it and no
// hidraw node exists.
TEST(LabHid, DialGadgetReportArrivesOnHidraw) {
  NEED_LAB();
  ASSERT_FALSE(env("BASALT_VLAB_HID_DIAL_GADGET").empty()) << fixtureLine("dial");
  const auto node = hidrawById(3, 0x1209, 0x0001);
  ASSERT_TRUE(node) << "no hidraw node for 1209:0001";
  EXPECT_EQ(sysfsDescriptor(*node), kDialDescriptor);
  UniqueFd host(::open(node->c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC));
  ASSERT_TRUE(host) << "cannot open " << *node;
  drain(host.get());
  UniqueFd gadget(::open(env("BASALT_VLAB_HID_DIAL_GADGET").c_str(), O_WRONLY | O_CLOEXEC));
  ASSERT_TRUE(gadget);
  const std::vector<std::uint8_t> report = {0x05, 1, 0xff, 3, 0x80, 0x7f, 0, 2, 0xfe};
  ASSERT_EQ(::write(gadget.get(), report.data(), report.size()), static_cast<ssize_t>(report.size()));
  EXPECT_EQ(readReport(host.get(), 5s), report);
}

// Makes sure the PowerMate gadget enumerates on the host side with the PowerMate's ids and
// interrupt endpoint, and that (as with the real knob) the HID core leaves it alone: no hidraw.
// Example failure: usbhid binds it, so the libusb path under test would find it busy.
TEST(LabHid, PowerMateEnumeratesWithoutHidraw) {
  NEED_LAB();
  ASSERT_FALSE(env("BASALT_VLAB_HID_POWERMATE_GADGET").empty()) << fixtureLine("powermate");
  const fs::path dev = usbDevice("077d", "0410");
  ASSERT_FALSE(dev.empty()) << "no USB device 077d:0410 on the host side";
  EXPECT_EQ(trimmed(readText(dev / "product")), "Griffin PowerMate");
  EXPECT_FALSE(hidrawById(3, 0x077d, 0x0410)) << "the HID core bound the PowerMate";
  const fs::path ep = dev / (dev.filename().string() + ":1.0") / "ep_81";
  EXPECT_EQ(trimmed(readText(ep / "type")), "Interrupt");
  EXPECT_EQ(trimmed(readText(ep / "wMaxPacketSize")), "0006");
}

// Makes sure the gadget control program unplugs and re-plugs each device, and that the host side
// sees both. Example failure: `plug` returns before the device is back, so a hotplug test
// races its own fixture.
TEST(LabHotplug, GadgetCtlUnplugsAndReplugsEachDevice) {
  NEED_LAB();
  ASSERT_FALSE(env("BASALT_VLAB_GADGET_CTL").empty());

  auto unplug = gadgetCtl("unplug", "dial");
  ASSERT_EQ(unplug.exitCode, 0) << unplug.output;
  EXPECT_FALSE(hidrawById(3, 0x1209, 0x0001)) << "the dial's hidraw node is still there";
  auto plug = gadgetCtl("plug", "dial");
  ASSERT_EQ(plug.exitCode, 0) << plug.output;
  const auto node = hidrawById(3, 0x1209, 0x0001);
  ASSERT_TRUE(node);
  EXPECT_EQ(trimmed(plug.output), node->string());

  unplug = gadgetCtl("unplug", "powermate");
  ASSERT_EQ(unplug.exitCode, 0) << unplug.output;
  EXPECT_TRUE(usbDevice("077d", "0410").empty());
  plug = gadgetCtl("plug", "powermate");
  ASSERT_EQ(plug.exitCode, 0) << plug.output;
  EXPECT_FALSE(usbDevice("077d", "0410").empty());

  unplug = gadgetCtl("unplug", "vivid");
  ASSERT_EQ(unplug.exitCode, 0) << unplug.output;
  EXPECT_FALSE(fs::exists(env("BASALT_VLAB_V4L2_WEBCAM")));
  plug = gadgetCtl("plug", "vivid");
  ASSERT_EQ(plug.exitCode, 0) << plug.output;
  EXPECT_EQ(trimmed(plug.output), env("BASALT_VLAB_V4L2_WEBCAM") + "\n" + env("BASALT_VLAB_V4L2_HDMI"));

  const auto bad = gadgetCtl("plug", "toaster");
  EXPECT_EQ(bad.exitCode, 2) << bad.output;
  EXPECT_NE(bad.output.find("usage"), std::string::npos) << bad.output;
}

// Makes sure a HID device made up through /dev/uhid appears with its hidraw node and delivers
// what it sends. Example failure: the uhid module is missing, so tests that make their own HID
// devices cannot run.
TEST(LabUhid, MadeUpDeviceDeliversReports) {
  NEED_LAB();
  ASSERT_EQ(env("BASALT_VLAB_UHID"), "1") << fixtureLine("uhid");
  sim::vlab::UhidIdentity id;
  id.name = "Basalt lab self-test dial";
  id.vendor = 0x1209;
  id.product = 0x0003;
  id.descriptor = kDialDescriptor;
  auto dev = sim::vlab::UhidDevice::create(id);
  ASSERT_TRUE(dev) << dev.error().describe();
  auto node = dev->hidrawNode(10s);
  ASSERT_TRUE(node) << node.error().describe();
  EXPECT_EQ(sysfsDescriptor(*node), kDialDescriptor);
  UniqueFd fd(::open(node->c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC));
  ASSERT_TRUE(fd);
  ASSERT_TRUE(dev->waitOpened(5s));
  const std::vector<std::uint8_t> report = {0x01, 0x10, 0, 0, 0, 0, 0, 0, 0xf0};
  ASSERT_TRUE(dev->sendInput(report));
  EXPECT_EQ(readReport(fd.get(), 5s), report);
}

// Makes sure virtio-gpu does a modeset and page flips through GBM on Mesa's software renderer,
// as Debian's kmscube does it (legacy KMS). Example failure: qemu started with bochs instead of
// virtio-gpu, whose modeset fails with EINVAL, and every KmsOutput test fails for the lab's sake.
TEST(LabDrm, VirtioGpuModesetsAndFlips) {
  NEED_LAB();
  const std::string card = env("BASALT_VLAB_DRM");
  ASSERT_FALSE(card.empty()) << fixtureLine("drm");
  EXPECT_EQ(trimmed(readText(fs::path("/sys/class/drm") / fs::path(card).filename() / "device" / "driver" / "module" /
                             "initstate")),
            "live");
  // kmscube stops at the first byte on stdin: give it a FIFO opened read-write, which never has
  // one and never reaches end of file.
  const auto run =
      test::run({"/bin/sh", "-c",
                 "rm -f /tmp/kmscube.in; mkfifo /tmp/kmscube.in; exec kmscube -D " + card + " -c 5 <>/tmp/kmscube.in"},
                {}, 240s);
  EXPECT_EQ(run.exitCode, 0) << run.output;
  EXPECT_EQ(run.output.find("failed to set mode"), std::string::npos) << run.output;
  EXPECT_EQ(run.output.find("user interrupted"), std::string::npos) << run.output;
}

// ---- the UVC camera -------------------------------------------------------------------------

std::vector<std::uint8_t> readBytes(const fs::path& p) {
  const std::string s = readText(p);
  return {s.begin(), s.end()};
}

/// The sysfs folder of a /dev/videoN.
fs::path videoSysfs(const std::string& dev) { return fs::path("/sys/class/video4linux") / fs::path(dev).filename(); }

/// Captures `count` frames of `format` at width x height from `dev` into a file with v4l2-ctl.
test::ProcessResult capture(const std::string& dev, int width, int height, const std::string& format, int count,
                            const fs::path& out) {
  return test::run({"/usr/bin/v4l2-ctl", "-d", dev,
                    "--set-fmt-video=width=" + std::to_string(width) + ",height=" + std::to_string(height) +
                        ",pixelformat=" + format,
                    "--stream-mmap", "--stream-count=" + std::to_string(count), "--stream-to=" + out.string()},
                   {}, 120s);
}

/// The JPEG files of an MJPEG capture, which v4l2-ctl writes back to back. Each of the camera's
/// frames starts with SOI and an APP0 segment; entropy-coded data never holds FF D8 FF.
std::vector<std::span<const std::uint8_t>> splitJpegs(const std::vector<std::uint8_t>& data) {
  std::vector<std::size_t> starts;
  for (std::size_t i = 0; i + 3 < data.size(); ++i) {
    if (data[i] == 0xff && data[i + 1] == 0xd8 && data[i + 2] == 0xff) starts.push_back(i);
  }
  std::vector<std::span<const std::uint8_t>> frames;
  for (std::size_t k = 0; k < starts.size(); ++k) {
    const std::size_t end = k + 1 < starts.size() ? starts[k + 1] : data.size();
    frames.push_back(std::span<const std::uint8_t>(data).subspan(starts[k], end - starts[k]));
  }
  return frames;
}

std::string uvcNode() {
  const std::string dev = env("BASALT_VLAB_V4L2_UVC");
  return dev;
}

// Makes sure the lab's camera is a webcam bound by uvcvideo, behind the guest's PCI USB
// controller (qemu-xhci), offering the lab camera's formats, sizes and frame rates. Example
// failure: the descriptors' frame intervals are in the wrong unit, and uvcvideo lists 3000 fps.
TEST(LabUvc, CameraIsAUvcvideoWebcamWithItsFormats) {
  NEED_LAB();
  const std::string dev = uvcNode();
  ASSERT_FALSE(dev.empty()) << fixtureLine("uvc");
  const auto info = test::run({"/usr/bin/v4l2-ctl", "-d", dev, "--info", "--list-formats-ext"});
  ASSERT_EQ(info.exitCode, 0) << info.output;
  EXPECT_NE(info.output.find("uvcvideo"), std::string::npos) << info.output;
  EXPECT_NE(info.output.find("Basalt Lab Camera"), std::string::npos) << info.output;
  for (const char* want :
       {"'YUYV'", "'MJPG'", "640x480", "320x240", "1280x720", "(30.000 fps)", "(15.000 fps)", "(5.000 fps)"}) {
    EXPECT_NE(info.output.find(want), std::string::npos) << "no " << want << " in\n" << info.output;
  }
  const fs::path usb = fs::canonical(videoSysfs(dev) / "device").parent_path();
  EXPECT_EQ(trimmed(readText(usb / "idVendor")) + ":" + trimmed(readText(usb / "idProduct")), "1209:0002");
  EXPECT_NE(usb.string().find("/pci"), std::string::npos) << "not behind a PCI controller: " << usb;
  EXPECT_EQ(trimmed(readText(usb / "speed")), "480") << "a high-speed device";
}

// Makes sure YUYV frames stream through uvcvideo with the negotiated size and format, whole,
// and with the camera's frame counter rising from frame to frame. Example failure: uvcvideo
// drops every frame as incomplete because a payload header is wrong, and the capture hangs.
TEST(LabUvc, StreamsYuyvWithAChangingFrameCounter) {
  NEED_LAB();
  const std::string dev = uvcNode();
  ASSERT_FALSE(dev.empty()) << fixtureLine("uvc");
  const fs::path out = "/tmp/vlab-uvc.yuyv";
  const auto stream = capture(dev, 320, 240, "YUYV", 6, out);
  ASSERT_EQ(stream.exitCode, 0) << stream.output;
  const auto fmt = test::run({"/usr/bin/v4l2-ctl", "-d", dev, "--get-fmt-video"});
  EXPECT_NE(fmt.output.find("320/240"), std::string::npos) << fmt.output;
  EXPECT_NE(fmt.output.find("'YUYV'"), std::string::npos) << fmt.output;
  const auto data = readBytes(out);
  constexpr std::size_t kFrame = std::size_t{320} * 240 * 2;
  ASSERT_EQ(data.size(), 6 * kFrame) << "six whole 320x240 YUYV frames";
  std::optional<std::uint32_t> last;
  for (std::size_t i = 0; i < 6; ++i) {
    const auto counter =
        sim::vlab::readFrameCounterYuyv(std::span<const std::uint8_t>(data).subspan(i * kFrame, kFrame), 320, 240);
    ASSERT_TRUE(counter) << "frame " << i << " has no readable counter";
    if (last) {
      EXPECT_GT(*counter, *last) << "frame " << i;
    }
    last = counter;
  }
}

// Makes sure MJPEG frames stream through uvcvideo as whole JPEG files of the negotiated size,
// with rising frame numbers. The lab reads the number the camera writes into each frame's COM
// segment: decoding JPEG under TCG costs minutes, and the unit tests (uvc_camera_test.cpp) check
// with libjpeg that the picture carries the same counter. Example failure: the last payload of a
// frame lacks the end-of-frame bit, so uvcvideo glues two JPEG files into one buffer.
TEST(LabUvc, StreamsMjpegFramesThatAreWholeJpegs) {
  NEED_LAB();
  const std::string dev = uvcNode();
  ASSERT_FALSE(dev.empty()) << fixtureLine("uvc");
  const fs::path out = "/tmp/vlab-uvc.mjpg";
  const auto stream = capture(dev, 640, 480, "MJPG", 4, out);
  ASSERT_EQ(stream.exitCode, 0) << stream.output;
  const auto data = readBytes(out);
  const auto frames = splitJpegs(data);
  ASSERT_EQ(frames.size(), 4U) << data.size() << " bytes";
  std::optional<std::uint32_t> last;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const auto info = sim::inspectJpeg(frames[i]);
    ASSERT_TRUE(info) << "frame " << i << " is not a JPEG file";
    EXPECT_TRUE(info->complete) << "frame " << i << " does not end with EOI";
    EXPECT_EQ(info->width, 640U);
    EXPECT_EQ(info->height, 480U);
    const auto number = sim::vlab::mjpegFrameNumber(frames[i]);
    ASSERT_TRUE(number) << "frame " << i << " comment: " << info->comment;
    if (last) {
      EXPECT_GT(*number, *last) << "frame " << i;
    }
    last = number;
  }
}

// Makes sure a V4L2 control reaches the camera through uvcvideo's UVC requests and changes the
// picture. Example failure: the processing unit's descriptor is too short, uvcvideo drops the
// control, and brightness is not offered.
TEST(LabUvc, BrightnessControlReachesTheCamera) {
  NEED_LAB();
  const std::string dev = uvcNode();
  ASSERT_FALSE(dev.empty()) << fixtureLine("uvc");
  struct Restore {
    std::string dev;
    ~Restore() { test::run({"/usr/bin/v4l2-ctl", "-d", dev, "--set-ctrl=brightness=128"}); }
  } restore{dev};
  const auto set = test::run({"/usr/bin/v4l2-ctl", "-d", dev, "--set-ctrl=brightness=230"});
  ASSERT_EQ(set.exitCode, 0) << set.output;
  const auto get = test::run({"/usr/bin/v4l2-ctl", "-d", dev, "--get-ctrl=brightness"});
  EXPECT_EQ(trimmed(get.output), "brightness: 230");
  const fs::path out = "/tmp/vlab-uvc-bright.yuyv";
  const auto stream = capture(dev, 320, 240, "YUYV", 1, out);
  ASSERT_EQ(stream.exitCode, 0) << stream.output;
  const auto data = readBytes(out);
  ASSERT_EQ(data.size(), 320U * 240 * 2);
  // The last row is black (luma 16) at the default brightness; 230 lifts luma by (230 - 128) / 2.
  double sum = 0;
  for (std::size_t x = 0; x < 320; ++x) sum += data[(std::size_t{239} * 320 + x) * 2];
  EXPECT_NEAR(sum / 320, 16 + 51, 3);
  EXPECT_TRUE(sim::vlab::readFrameCounterYuyv(data, 320, 240)) << "the counter survives brightness";
}

// Makes sure gadget-ctl pulls the camera's cable and puts it back: the node goes, comes back
// under the same name, and streams again. Example failure: the camera program misses the
// request written from the guest (9p), and `unplug` times out.
TEST(LabHotplug, UvcCameraUnplugsAndReplugs) {
  NEED_LAB();
  const std::string dev = uvcNode();
  ASSERT_FALSE(dev.empty()) << fixtureLine("uvc");
  const auto unplug = gadgetCtl("unplug", "uvc");
  ASSERT_EQ(unplug.exitCode, 0) << unplug.output;
  EXPECT_FALSE(fs::exists(dev)) << dev << " is still there";
  const auto again = gadgetCtl("unplug", "uvc");
  EXPECT_EQ(again.exitCode, 1) << again.output;
  EXPECT_NE(again.output.find("already unplugged"), std::string::npos) << again.output;
  const auto plug = gadgetCtl("plug", "uvc");
  ASSERT_EQ(plug.exitCode, 0) << plug.output;
  EXPECT_EQ(trimmed(plug.output), dev);
  const auto stream = test::run({"/usr/bin/v4l2-ctl", "-d", dev, "--stream-mmap", "--stream-count=1"}, {}, 60s);
  EXPECT_EQ(stream.exitCode, 0) << stream.output;
}

// Makes sure libcamera 0.0.3's UVC pipeline handler finds the camera and captures from it, as
// Basalt's libcamera backend will: the camera is named after the ACPI node of its PCI USB
// controller, and frames arrive with the camera's frame numbers. Example failure: udev does not
// run in the lab, libcamera (which lists only devices udev processed) sees no camera, and every
// libcamera backend test would skip.
TEST(LabLibcamera, CamListsAndCapturesTheUvcCamera) {
  NEED_LAB();
  if (!fs::exists("/usr/bin/cam")) GTEST_SKIP() << "libcamera's cam is not installed (Debian package libcamera-tools)";
  if (env("BASALT_VLAB_UDEV") != "1") {
    GTEST_SKIP() << "libcamera lists only devices udev has processed, and udev does not run in this lab: "
                 << fixtureLine("udev");
  }
  ASSERT_FALSE(uvcNode().empty()) << fixtureLine("uvc");
  test::run({"/usr/bin/udevadm", "settle", "--timeout=30"}, {}, 40s);
  const auto list = test::run({"/usr/bin/cam", "-l"}, {}, 60s);
  ASSERT_EQ(list.exitCode, 0) << list.output;
  EXPECT_NE(list.output.find("Basalt Lab Camera"), std::string::npos) << list.output;
  EXPECT_NE(list.output.find("1209:0002"), std::string::npos) << list.output;
  EXPECT_NE(list.output.find("\\_SB_"), std::string::npos) << "named after the controller's ACPI node:\n"
                                                           << list.output;
  const fs::path dir = "/tmp/vlab-cam/";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const auto run = test::run({"/usr/bin/cam", "-c", "1", "--capture=3", "--file=" + dir.string()}, {}, 120s);
  ASSERT_EQ(run.exitCode, 0) << run.output;
  EXPECT_NE(run.output.find("seq: 000002"), std::string::npos) << run.output;
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir)) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  ASSERT_EQ(files.size(), 3U) << run.output;
  std::optional<std::uint32_t> last;
  for (const auto& f : files) {
    const auto data = readBytes(f);
    const auto info = sim::inspectJpeg(data);
    ASSERT_TRUE(info) << f << " is not the camera's MJPEG frame (cam's default is its largest MJPEG size)";
    const auto number = sim::vlab::mjpegFrameNumber(data);
    ASSERT_TRUE(number) << f;
    if (last) {
      EXPECT_GT(*number, *last) << f;
    }
    last = number;
  }
}

// Makes sure the camera also works through USB/IP, plugged into the guest's own vhci_hcd (as
// `basalt-vlab-uvc-camera --vhci` does on any Linux machine): uvcvideo binds it and it streams;
// SIGTERM unplugs it. libcamera 0.0.3 cannot name a camera on vhci_hcd (a platform device with no
// firmware node: "Can not find controller ID"), which is why the lab's camera goes through qemu.
// Example failure: the attach is refused because the socket pair's end is closed too early.
TEST(LabUvc, UsbipCameraOnVhciStreams) {
  NEED_LAB();
  const std::string vhci = env("BASALT_VLAB_VHCI");
  ASSERT_FALSE(vhci.empty()) << fixtureLine("vhci");
  const std::string program = (test::binaryDir() / "tools" / "vlab" / "basalt-vlab-uvc-camera").string();
  auto camera = test::Process::start({program, "--vhci", vhci});
  ASSERT_TRUE(camera.started()) << program;
  ASSERT_TRUE(camera.waitForOutput("plugged:", 30s)) << camera.outputSoFar();
  std::string dev;
  ASSERT_TRUE(waitFor(
      [&] {
        std::error_code ec;
        for (const auto& e : fs::directory_iterator("/sys/class/video4linux", ec)) {
          if (trimmed(readText(e.path() / "index")) != "0") continue;
          const fs::path usb = fs::canonical(e.path() / "device", ec).parent_path();
          if (usb.string().find("vhci_hcd") == std::string::npos) continue;
          if (trimmed(readText(usb / "idVendor")) != "1209") continue;
          dev = (fs::path("/dev") / e.path().filename()).string();
          return true;
        }
        return false;
      },
      30s))
      << "no uvcvideo node on vhci_hcd; camera: " << camera.outputSoFar();
  const fs::path out = "/tmp/vlab-uvc-vhci.yuyv";
  const auto stream = capture(dev, 320, 240, "YUYV", 3, out);
  ASSERT_EQ(stream.exitCode, 0) << stream.output;
  const auto data = readBytes(out);
  ASSERT_EQ(data.size(), 3U * 320 * 240 * 2);
  constexpr std::size_t kFrame = std::size_t{320} * 240 * 2;
  const auto first = sim::vlab::readFrameCounterYuyv(std::span<const std::uint8_t>(data).first(kFrame), 320, 240);
  const auto third = sim::vlab::readFrameCounterYuyv(std::span<const std::uint8_t>(data).last(kFrame), 320, 240);
  ASSERT_TRUE(first && third);
  EXPECT_GT(*third, *first);
  camera.signal(SIGTERM);
  const auto done = camera.wait(30s);
  EXPECT_EQ(done.exitCode, 0) << done.output;
  EXPECT_TRUE(waitFor([&] { return !fs::exists(dev); }, 15s)) << dev << " is still there after SIGTERM";
}

// ---- uhid replay of the shared HID recordings: one case per file ---------------------------

class LabHidReplay : public testing::TestWithParam<const char*> {};

std::size_t totalReports(const std::vector<sim::HidRecordedDevice>& devices) {
  std::size_t n = 0;
  for (const auto& d : devices) n += d.reports.size();
  return n;
}

// Makes sure each recording in ../shared/testdata/hid replays as kernel devices with the
// recorded names, ids and descriptors, and that every recorded report arrives on its device's
// hidraw node, in order and unchanged. Example failure: the replay tool sends before the reader
// opened the node and the first reports are lost.
TEST_P(LabHidReplay, RecordingReplaysThroughHidraw) {
  NEED_LAB();
  const fs::path data = test::testdataDir();
  if (data.empty()) GTEST_SKIP() << "../shared/testdata is missing (BASALT_TESTDATA)";
  const fs::path file = data / "hid" / GetParam();
  auto read = sim::readHidRecording(file);
  ASSERT_TRUE(read) << read.error().describe();
  const std::vector<sim::HidRecordedDevice>* recording = &read->devices;
  std::string tool = env("BASALT_VLAB_HID_REPLAY");
  if (tool.empty()) tool = (test::binaryDir() / "tools" / "vlab" / "basalt-vlab-hid-replay").string();

  auto replay = test::Process::start({tool, "--wait-signal", "30", "--max-gap", "0.05", "--hold", "-1", file.string()});
  ASSERT_TRUE(replay.started()) << tool;
  const std::string last = "device " + std::to_string(recording->size() - 1) + " ";
  ASSERT_TRUE(replay.waitForOutput(last, 30s)) << replay.outputSoFar();
  ASSERT_TRUE(replay.waitForOutput("\n", 1s));
  std::vector<UniqueFd> fds;
  std::istringstream lines(replay.outputSoFar());
  std::string word;
  std::size_t index = 0;
  std::string node;
  for (std::size_t i = 0; i < recording->size(); ++i) {
    ASSERT_TRUE(lines >> word >> index >> node) << replay.outputSoFar();
    std::string name;
    std::getline(lines, name);
    const auto& rec = (*recording)[i];
    EXPECT_EQ(sysfsDescriptor(node), rec.descriptor) << "device " << i;
    const auto byId = hidrawById(rec.bus, rec.vendor, rec.product);
    EXPECT_TRUE(byId) << "device " << i << " has not the recorded ids";
    fds.emplace_back(::open(node.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC));
    ASSERT_TRUE(fds.back()) << node;
  }
  replay.signal(SIGUSR1);  // every node is open: replay
  for (std::size_t i = 0; i < recording->size(); ++i) {
    for (const auto& expected : (*recording)[i].reports) {
      EXPECT_EQ(readReport(fds[i].get(), 10s), expected.bytes)
          << "device " << i << ", report at " << expected.time.count() << " ns";
    }
  }
  ASSERT_TRUE(replay.waitForOutput("replayed", 30s)) << replay.outputSoFar();
  replay.signal(SIGTERM);  // done reading: the devices go
  const auto done = replay.wait(30s);
  EXPECT_EQ(done.exitCode, 0) << done.output;
  const std::string count = "replayed " + std::to_string(totalReports(*recording)) + " reports";
  EXPECT_NE(done.output.find(count), std::string::npos) << done.output;
}

INSTANTIATE_TEST_SUITE_P(SharedRecordings, LabHidReplay,
                         testing::Values("udev-hid-bpf/huion_dial2_q630m_rdescs.hid",
                                         "udev-hid-bpf/huion_keydial_mini050_bluetooth.hid",
                                         "udev-hid-bpf/microsoft_surface_dial_rdesc.hid"),
                         [](const testing::TestParamInfo<const char*>& param) {
                           std::string name = fs::path(param.param).stem().string();
                           for (char& c : name) {
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           }
                           return name;
                         });

}  // namespace
}  // namespace basalt
