#pragma once

/// \file
/// \brief The `v4l2` backend: webcams and HDMI capture cards through Video4Linux2. Includes no
/// kernel header: linux/videodev2.h stays in devices/v4l2/*.cpp.

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "devices/device_manager.h"
#include "devices/video_source.h"

namespace basalt::devices {

/// \brief One input (port) of a V4L2 device: a camera sensor, a composite or HDMI connector.
struct V4l2Input {
  int index = 0;
  std::string name;
  bool camera = false;     ///< V4L2_INPUT_TYPE_CAMERA
  bool dvTimings = false;  ///< HDMI-style input with the DV timings API (signal detection)
  bool noSignal = false;   ///< the driver reports no signal now
};

/// \brief What a V4L2 capture node offers (for `basalt devices`, tests and mode choice).
struct V4l2Description {
  std::string path;
  std::string card;
  std::string driver;
  std::string busInfo;
  std::uint16_t vendor = 0;  ///< from sysfs for USB devices
  std::uint16_t product = 0;
  std::vector<V4l2Input> inputs;
  int currentInput = 0;
  std::vector<VideoMode> modes;           ///< formats Basalt handles, with discrete sizes and rates
  std::vector<std::string> otherFormats;  ///< fourccs Basalt does not handle
  bool streaming = false;                 ///< V4L2_CAP_STREAMING
  bool multiplanar = false;
};

/// \brief Queries a node (QUERYCAP, ENUMINPUT, ENUM_FMT, ENUM_FRAMESIZES, ENUM_FRAMEINTERVALS).
/// Fails for nodes that are not video capture devices.
[[nodiscard]] Result<V4l2Description> describeV4l2Device(const std::string& path);

/// \brief How to open a V4L2 camera. Unset values keep what the device does now.
struct V4l2Options {
  std::optional<PixelFormat> format;  ///< YUYV, UYVY, NV12, NV21, YU12 (I420), YV12, RGB, BGRA, GREY, MJPEG
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  double fps = 0;
  int input = -1;
  bool exportDmabuf = true;  ///< VIDIOC_EXPBUF each buffer so the renderer can import it
  unsigned buffers = 4;
};

/// \brief Parses the request options `format`, `size` (WxH), `fps`, `input`, `dmabuf`
/// (true/false) and `buffers` into V4l2Options.
[[nodiscard]] Result<V4l2Options> v4l2OptionsFrom(const DeviceRequest& request);

/// \brief Opens a capture node as a video source (streams on open()).
[[nodiscard]] std::shared_ptr<VideoSource> makeV4l2Camera(const std::string& path, V4l2Options options,
                                                          const Clock& clock, DeviceInfo info = {});

/// \brief Sets the control named `name` (as VIDIOC_QUERYCTRL reports it, e.g. vivid's "DV Timings
/// Signal Mode") to `value` (a menu index for menu controls). For tests and operators' tools.
[[nodiscard]] Result<void> setV4l2ControlByName(const std::string& path, const std::string& name, int value);

/// \brief The `v4l2` backend: every /dev/video* node that captures video.
class V4l2Provider final : public DeviceProvider {
 public:
  /// \brief Lists the video* nodes of `folder` (another folder only in tests).
  explicit V4l2Provider(std::filesystem::path folder = "/dev") : folder_(std::move(folder)) {}
  [[nodiscard]] std::string_view backend() const override { return "v4l2"; }
  std::vector<DeviceCandidate> enumerate() override;
  Result<std::shared_ptr<VideoSource>> openVideoSource(const DeviceCandidate& candidate, const DeviceRequest& request,
                                                       const Clock& clock) override;

 private:
  std::filesystem::path folder_;
};

}  // namespace basalt::devices
