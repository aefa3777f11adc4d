#pragma once

/// \file
/// \brief The `libcamera` backend: cameras that libcamera manages (CSI sensors behind an ISP,
/// UVC webcams through its uvcvideo pipeline), with libcamera's own hotplug signals. Includes no
/// libcamera header: those stay in devices/libcamera/*.cpp.

#include <memory>
#include <string>
#include <vector>

#include "devices/device_manager.h"

namespace basalt::devices {

/// \brief The `libcamera` backend. The process has one libcamera CameraManager, started by the
/// first provider and shared. Device paths are libcamera camera ids.
///
/// Request options: `format` (YUYV, NV12, I420, MJPEG, ...), `size` (WxH), `fps`.
class LibcameraProvider final : public DeviceProvider {
 public:
  LibcameraProvider();
  ~LibcameraProvider() override;
  [[nodiscard]] std::string_view backend() const override { return "libcamera"; }
  std::vector<DeviceCandidate> enumerate() override;
  Result<std::shared_ptr<VideoSource>> openVideoSource(const DeviceCandidate& candidate, const DeviceRequest& request,
                                                       const Clock& clock) override;
  void watchHotplug(const std::function<void(HotplugEvent)>& notify) override;
  /// \brief Why libcamera could not start, if it could not (then enumerate() is empty).
  [[nodiscard]] std::string startError() const;

  struct State;  ///< the shared CameraManager (defined in the .cpp)

 private:
  std::shared_ptr<State> state_;
};

}  // namespace basalt::devices
