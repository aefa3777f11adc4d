#pragma once

/// \file
/// \brief Where the virtual lab's UVC camera is now. The lab names its capture node at boot
/// (BASALT_VLAB_V4L2_UVC), but a case that unplugs and replugs the camera may leave it at another
/// node: the kernel gives the returning camera a new number while the old one is still held open
/// (libcamera keeps it until its camera is released). Cases that use the camera after such a case
/// find it again by its USB identity.

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "devices/v4l2/v4l2_camera.h"
#include "vlab.h"

namespace basalt::test {

/// The lab's webcam: basalt-vlab-uvc-camera, plugged in as USB 1209:0002 (tools/vlab/guest/uvc_camera.sh).
inline constexpr std::uint16_t kLabUvcVendor = 0x1209;
inline constexpr std::uint16_t kLabUvcProduct = 0x0002;

/// \brief The capture node of the lab's UVC camera: the node the lab named at boot while it is
/// still the camera, otherwise the /dev/video* node that is, waiting up to `wait` for one to
/// appear (udev may still be making it after a replug). nullopt outside the lab, or when no node
/// is the camera.
inline std::optional<std::string> labUvcNode(std::chrono::milliseconds wait = std::chrono::seconds(10)) {
  const auto booted = vlabEnv("BASALT_VLAB_V4L2_UVC");
  if (!booted) return std::nullopt;
  const auto isCamera = [](const std::string& path) {
    const auto d = devices::describeV4l2Device(path);
    return d && d->vendor == kLabUvcVendor && d->product == kLabUvcProduct;
  };
  const auto until = std::chrono::steady_clock::now() + wait;
  for (;;) {
    if (isCamera(*booted)) return booted;
    std::vector<std::string> nodes;
    std::error_code ec;
    for (std::filesystem::directory_iterator it("/dev", ec), end; !ec && it != end; it.increment(ec)) {
      if (it->path().filename().string().starts_with("video")) nodes.push_back(it->path().string());
    }
    std::sort(nodes.begin(), nodes.end());
    for (const std::string& node : nodes) {
      if (isCamera(node)) return node;
    }
    if (std::chrono::steady_clock::now() >= until) return std::nullopt;
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
  }
}

}  // namespace basalt::test
