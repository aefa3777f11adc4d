// The KMS output on a real DRM driver (virtio-gpu in the virtual lab, BASALT_VLAB_DRM): a
// modeset, page flips paced by their events, then the buffer the CRTC scans out read back and
// compared with the headless render of the same frame; legacy and atomic paths; DPMS off and on.
// Outside the lab it skips, saying so (no DRM device exists on build machines).
// Example failures: a flip that never completes (the loop would hang waiting for it); the first
// frame shown but later flips ignored (the scan-out stays at frame 0); depending on native fence
// fds, which software rendering lacks; colours swapped by a wrong framebuffer format.

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "render/kms_output.h"
#include "render/output.h"
#include "render/renderer.h"
#include "runtime/show/show.h"
#include "support/golden.h"

namespace basalt::render {
namespace {

constexpr int kFrames = 30;

std::string vlabDrm() {
  const char* env = std::getenv("BASALT_VLAB_DRM");
  return env && *env ? env : "";
}

#define REQUIRE_VLAB_DRM()                                                                                     \
  if (vlabDrm().empty()) {                                                                                     \
    GTEST_SKIP() << "needs the virtual lab (make vlab): BASALT_VLAB_DRM names the virtio-gpu /dev/dri/cardN, " \
                    "and this machine has no DRM device";                                                      \
  }

void drawFrame(Output& output, Renderer& renderer, const runtime::Show& show) {
  ASSERT_TRUE(output.beginFrame());
  const Size size = output.size();
  renderer.draw(show, runtime::computeView(show, static_cast<float>(size.width) / static_cast<float>(size.height)),
                size);
}

/// Modesets, flips kFrames frames of the default show, and returns what the CRTC scans out.
Image runOnKms(bool legacy, Size& size, bool& atomic) {
  if (legacy) {
    ::setenv("BASALT_KMS_LEGACY", "1", 1);
  } else {
    ::unsetenv("BASALT_KMS_LEGACY");
  }
  OutputRequest request;
  request.kind = OutputKind::kKms;
  request.drmDevice = vlabDrm();
  auto kms = KmsOutput::open(request);
  ::unsetenv("BASALT_KMS_LEGACY");
  EXPECT_TRUE(kms) << kms.error().describe();
  if (!kms) return {};
  KmsOutput& out = **kms;
  size = out.size();
  atomic = out.atomic();
  EXPECT_GT(out.paceFd(), 0);
  auto renderer = Renderer::create();
  EXPECT_TRUE(renderer) << renderer.error().describe();
  runtime::Show show = runtime::Show::makeDefault();
  for (int frame = 0; frame < kFrames; ++frame) {
    // Paced by the flip events: wait for the previous flip before drawing the next frame.
    EXPECT_TRUE(out.waitForFlip(2000)) << "frame " << frame;
    EXPECT_TRUE(out.readyForFrame());
    drawFrame(out, **renderer, show);
    EXPECT_TRUE(out.present()) << "frame " << frame;
    if (frame > 0) {
      EXPECT_FALSE(out.readyForFrame()) << "a flip is pending until its event arrives";
    }
    if (frame + 1 < kFrames) show.advanceFrame();
  }
  EXPECT_TRUE(out.waitForFlip(2000));
  EXPECT_EQ(out.flipsCompleted(), static_cast<std::uint64_t>(kFrames - 1)) << "the first frame is the modeset";
  Image scanout;
  const auto read = out.readScanout(scanout);
  EXPECT_TRUE(read) << (read ? "" : read.error().describe());
  // DPMS off and on again, where the connector can.
  if (auto off = out.setDisplayPower(false); off) {
    EXPECT_TRUE(out.present()) << "presenting while off drops the frame quietly";
    EXPECT_TRUE(out.setDisplayPower(true));
  } else {
    EXPECT_EQ(off.error().code(), Errc::kUnsupported) << off.error().describe();
  }
  return scanout;
}

/// The kernel driver behind a DRM node ("virtio_gpu"), from sysfs; "" when unknown.
std::string drmDriver(const std::string& node) {
  std::error_code ec;
  const auto link = std::filesystem::read_symlink(
      std::filesystem::path("/sys/class/drm") / std::filesystem::path(node).filename() / "device" / "driver", ec);
  return ec ? std::string() : link.filename().string();
}

Image headlessFrame(Size size) {
  auto output = createHeadlessOutput(size);
  EXPECT_TRUE(output) << output.error().describe();
  if (!output) return {};
  auto renderer = Renderer::create();
  runtime::Show show = runtime::Show::makeDefault();
  for (int frame = 0; frame + 1 < kFrames; ++frame) show.advanceFrame();
  drawFrame(**output, **renderer, show);
  Image image;
  EXPECT_TRUE((*output)->readBack(image));
  return image;
}

void expectSameAsHeadless(const Image& scanout, Size size) {
  ASSERT_EQ(scanout.width, size.width);
  ASSERT_EQ(scanout.height, size.height);
  const Image reference = headlessFrame(size);
  const ImageDifference d = compareImages(scanout, reference, 3);
  EXPECT_LE(static_cast<double>(d.pixelsOverTolerance), 0.001 * size.width * size.height)
      << "scan-out differs from the headless render: max delta " << d.maxChannelDelta << ", " << d.pixelsOverTolerance
      << " pixels";
}

TEST(KmsOutput, LegacyPageFlipsShowTheHeadlessPicture) {
  REQUIRE_VLAB_DRM();
  Size size;
  bool atomic = true;
  const Image scanout = runOnKms(true, size, atomic);
  EXPECT_FALSE(atomic);
  expectSameAsHeadless(scanout, size);
}

TEST(KmsOutput, DefaultPathShowsTheHeadlessPicture) {
  REQUIRE_VLAB_DRM();
  Size size;
  bool atomic = false;
  const Image scanout = runOnKms(false, size, atomic);
  RecordProperty("atomic", atomic ? "yes" : "no");
  // virtio-gpu offers atomic modesetting: the default path must take it, flips paced by their
  // events and no native fence (software rendering has none to give).
  if (drmDriver(vlabDrm()) == "virtio_gpu") {
    EXPECT_TRUE(atomic) << "atomic modesetting was not used on virtio-gpu";
  }
  expectSameAsHeadless(scanout, size);
}

TEST(KmsOutput, AConnectorThatDoesNotExistIsOneClearError) {
  REQUIRE_VLAB_DRM();
  OutputRequest request;
  request.kind = OutputKind::kKms;
  request.drmDevice = vlabDrm();
  request.connector = "HDMI-A-9";
  const auto kms = KmsOutput::open(request);
  ASSERT_FALSE(kms);
  EXPECT_NE(kms.error().message().find("there is no connector 'HDMI-A-9'"), std::string::npos)
      << kms.error().describe();
}

TEST(KmsOutput, NoDeviceIsOneClearError) {
  OutputRequest request;
  request.kind = OutputKind::kKms;
  request.drmDevice = "/dev/dri/card99";
  const auto kms = KmsOutput::open(request);
  ASSERT_FALSE(kms);
  EXPECT_NE(kms.error().message().find("/dev/dri/card99"), std::string::npos) << kms.error().describe();
}

}  // namespace
}  // namespace basalt::render
