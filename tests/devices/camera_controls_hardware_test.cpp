// LAVA's "Hardware" panel on a real V4L2 device, in the virtual lab (skipping with the reason
// elsewhere): the input (port) a camera is opened on, and the JPEG quality control. vivid's
// webcam and HDMI instances have one input each and its third instance two (a camera switched
// between them); vivid has no JPEG quality control, and neither
// has the UVC gadget, so the "device that has it" case skips with that reason unless a lab camera
// offers one.
// Example failures: an input that does not exist opened silently on another one, or refused
// with a bare "Invalid argument"; a quality asked of a device without the control dropped
// without a word, or said only for the first camera of the show.

#include <gtest/gtest.h>

#include <fcntl.h>
#include <linux/videodev2.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <chrono>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "devices/v4l2/v4l2_camera.h"
#include "runtime/clock.h"
#include "runtime/log.h"
#include "vlab.h"
#include "vlab_uvc.h"

namespace basalt::devices {
namespace {

/// The lab's vivid nodes: {variable, node}.
std::vector<std::pair<std::string, std::string>> vividNodes() {
  std::vector<std::pair<std::string, std::string>> out;
  for (const char* v : {"BASALT_VLAB_V4L2_WEBCAM", "BASALT_VLAB_V4L2_HDMI", "BASALT_VLAB_V4L2_INPUTS"}) {
    if (auto node = test::vlabEnv(v)) out.emplace_back(v, *node);
  }
  return out;
}

/// Whether the node has a JPEG compression quality control.
bool hasJpegQuality(const std::string& node) {
  const int fd = ::open(node.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return false;
  v4l2_queryctrl q{};
  q.id = V4L2_CID_JPEG_COMPRESSION_QUALITY;
  const bool has = ::ioctl(fd, VIDIOC_QUERYCTRL, &q) == 0 && !(q.flags & V4L2_CTRL_FLAG_DISABLED);
  ::close(fd);
  return has;
}

/// The warnings logged while the sink is alive.
class Warnings {
 public:
  Warnings() { log::addSink(sink_); }
  ~Warnings() { log::removeSink(sink_); }
  Warnings(const Warnings&) = delete;
  Warnings& operator=(const Warnings&) = delete;
  [[nodiscard]] std::size_t count(const std::string& a, const std::string& b) const {
    std::size_t n = 0;
    for (const auto& r : sink_->snapshot(log::Level::kWarn)) {
      if (r.message.find(a) != std::string::npos && r.message.find(b) != std::string::npos) ++n;
    }
    return n;
  }

 private:
  std::shared_ptr<log::RingSink> sink_ = std::make_shared<log::RingSink>(256);
};

// Makes sure the input asked for is the one opened, and that one the device lacks is refused
// with its number and the inputs the device has.
TEST(V4l2Controls, InputThatExistsOpensAndOneThatDoesNotSaysWhich) {
  const auto nodes = vividNodes();
  if (nodes.empty()) GTEST_SKIP() << test::needsVlab("BASALT_VLAB_V4L2_WEBCAM or BASALT_VLAB_V4L2_HDMI (vivid)");
  SystemClock clock;
  for (const auto& [variable, node] : nodes) {
    SCOPED_TRACE(fmt::format("{} {}", variable, node));
    auto d = describeV4l2Device(node);
    ASSERT_TRUE(d) << d.error().describe();
    ASSERT_FALSE(d->inputs.empty());
    const int last = d->inputs.back().index;
    V4l2Options options;
    options.input = last;
    auto camera = makeV4l2Camera(node, options, clock);
    auto opened = camera->open(1);
    ASSERT_TRUE(opened) << opened.error().describe();
    auto now = describeV4l2Device(node);
    ASSERT_TRUE(now) << now.error().describe();
    EXPECT_EQ(now->currentInput, last);
    // And it streams from there.
    const auto start = std::chrono::steady_clock::now();
    while (camera->framesDelivered() < 3 && std::chrono::steady_clock::now() - start < std::chrono::seconds(10)) {
      camera->service(clock.now());
      (void)camera->frameAt(clock.now());
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    EXPECT_GE(camera->framesDelivered(), 3u) << "frames from input " << last;
    camera->close();
    if (last > 0) {
      // Back to the first input: a camera opened on input 0 switches the device there.
      options.input = 0;
      auto first = makeV4l2Camera(node, options, clock);
      ASSERT_TRUE(first->open(3));
      auto back = describeV4l2Device(node);
      ASSERT_TRUE(back) << back.error().describe();
      EXPECT_EQ(back->currentInput, 0);
      first->close();
    }

    options.input = static_cast<int>(d->inputs.size());  // one past the last
    auto missing = makeV4l2Camera(node, options, clock);
    auto refused = missing->open(2);
    ASSERT_FALSE(refused) << "input " << options.input << " does not exist, yet the camera opened";
    const std::string text = refused.error().describe();
    EXPECT_EQ(refused.error().code(), Errc::kNotFound) << text;
    EXPECT_NE(text.find("no input " + std::to_string(options.input)), std::string::npos) << text;
    EXPECT_NE(text.find("'" + d->inputs.front().name + "'"), std::string::npos)
        << "the message names the inputs there are: " << text;
    EXPECT_NE(text.find(node), std::string::npos) << text;
  }
}

// Makes sure a quality asked of a camera without the control is said once per camera: again for
// the second camera, not again when the same camera is asked twice.
TEST(V4l2Controls, JpegQualityWithoutTheControlWarnsOncePerCamera) {
  std::vector<std::string> without;
  for (const auto& [variable, node] : vividNodes()) {
    if (!hasJpegQuality(node)) without.push_back(node);
  }
  if (without.size() < 2) {
    GTEST_SKIP() << test::needsVlab(
        "two vivid nodes without a JPEG quality control (BASALT_VLAB_V4L2_WEBCAM, "
        "BASALT_VLAB_V4L2_HDMI)");
  }
  SystemClock clock;
  Warnings warnings;
  std::vector<std::shared_ptr<VideoSource>> cameras;
  for (const std::string& node : without) {
    V4l2Options options;
    auto camera = makeV4l2Camera(node, options, clock);
    auto opened = camera->open(static_cast<DeviceId>(cameras.size() + 1));
    ASSERT_TRUE(opened) << opened.error().describe();
    VideoControls controls;
    controls.quality = 80;
    auto set = camera->setControls(controls);
    EXPECT_TRUE(set) << "a missing quality control is no reason to fail: " << set.error().describe();
    controls.quality = 60;
    EXPECT_TRUE(camera->setControls(controls));
    EXPECT_EQ(warnings.count(node + ": ", "no JPEG quality control"), 1u) << node;
    cameras.push_back(std::move(camera));
  }
  for (auto& c : cameras) c->close();
}

// Makes sure a quality reaches a device that has the control.
TEST(V4l2Controls, JpegQualityIsSetWhereTheDeviceHasTheControl) {
  std::vector<std::string> candidates;
  for (const auto& [variable, node] : vividNodes()) candidates.push_back(node);
  if (auto uvc = test::labUvcNode()) candidates.push_back(*uvc);
  if (candidates.empty()) GTEST_SKIP() << test::needsVlab("a V4L2 camera (BASALT_VLAB_V4L2_*)");
  std::string node;
  for (const std::string& n : candidates) {
    if (hasJpegQuality(n)) node = n;
  }
  if (node.empty()) {
    GTEST_SKIP() << "no camera of the virtual lab has a JPEG compression quality control (vivid has none; "
                    "uvcvideo maps none for the UVC gadget): set it on a real MJPEG webcam that has one";
  }
  SystemClock clock;
  Warnings warnings;
  auto camera = makeV4l2Camera(node, {}, clock);
  ASSERT_TRUE(camera->open(1));
  VideoControls controls;
  controls.quality = 55;
  ASSERT_TRUE(camera->setControls(controls));
  EXPECT_EQ(warnings.count(node, "quality"), 0u);
  const int fd = ::open(node.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
  ASSERT_GE(fd, 0);
  v4l2_control c{};
  c.id = V4L2_CID_JPEG_COMPRESSION_QUALITY;
  EXPECT_EQ(::ioctl(fd, VIDIOC_G_CTRL, &c), 0);
  ::close(fd);
  EXPECT_NEAR(c.value, 55, 5) << "the driver may round to its step";
  camera->close();
}

}  // namespace
}  // namespace basalt::devices
