#pragma once

/// \file
/// \brief Wiring devices into a run beside its show's: the backends (providers), a DeviceManager
/// that pushes into the run's one event queue, udev hotplug, and a FrameParticipant that steps
/// the manager on the frame loop's thread when the show runs on a ManualClock (on the
/// SystemClock the manager runs on its own thread). `basalt run --replay` (whose events the show
/// director applies with the show's own), `basalt record` and the benches use it.

#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "devices/device_manager.h"
#include "devices/udev/udev_monitor.h"
#include "kiosk/loop/frame_loop.h"
#include "runtime/bounded_queue.h"
#include "runtime/event.h"
#include "sim/trace_video.h"

namespace basalt::kiosk {

/// \brief Parses a device on the command line: `BACKEND[:MATCH]` where MATCH is VVVV:PPPP, a path
/// (starting with '/' or naming a file) or a name: `hid:077d:0410`, `serial:/dev/ttyUSB0`,
/// `v4l2:/dev/video0`, `libcamera`, `synthetic`, `v4l2:HD Pro Webcam`.
[[nodiscard]] Result<devices::DeviceRequest> parseDeviceSpec(std::string_view text, devices::DeviceKind kind,
                                                             std::string name);

/// \brief Every real backend (hid, serial, midi, v4l2, libcamera) and the synthetic one.
std::vector<std::unique_ptr<devices::DeviceProvider>> allProviders(const std::vector<std::string>& serialPorts = {});

/// \brief The first id of the devices a run adds beside its show's: the show director's manager
/// numbers the show's from 1, and both push into the run's one queue.
inline constexpr DeviceId kReplayFirstId = 0x10000;

/// \brief The devices of one run beside its show's.
class DeviceWiring {
 public:
  /// Events go into `events` (the run's queue, which wakes the loop; borrowed, it outlives the
  /// wiring), tagged with ids from `firstId` up.
  DeviceWiring(const Clock& clock, BoundedQueue<Event>& events, DeviceId firstId = 1);
  ~DeviceWiring();

  [[nodiscard]] BoundedQueue<Event>& events() { return events_; }
  [[nodiscard]] devices::DeviceManager& manager() { return manager_; }

  /// \brief Replays every device of a trace folder or an hid-recorder file, by its recorded name.
  /// `videoReader` reads trace videos other than .bvraw (media's Matroska reader). Returns the
  /// ids their events carry.
  [[nodiscard]] Result<std::vector<DeviceId>> addReplay(const std::filesystem::path& path, bool loop,
                                                        sim::TraceVideoReaderFactory videoReader = {});
  /// \brief Starts: on a manual clock the participant steps the manager each frame; otherwise a
  /// thread does, with udev hotplug when udev is there.
  void start(bool manualClock);
  void stop();

  /// \brief The FrameParticipant that steps the manager under a ManualClock.
  [[nodiscard]] FrameParticipant& participant() { return participant_; }

 private:
  class Stepper final : public FrameParticipant {
   public:
    explicit Stepper(DeviceWiring& wiring) : wiring_(wiring) {}
    Result<void> beforeDraw(const FrameContext& frame) override;

   private:
    DeviceWiring& wiring_;
  };

  const Clock& clock_;
  BoundedQueue<Event>& events_;
  devices::DeviceManager manager_;
  std::unique_ptr<devices::UdevMonitor> udev_;
  Stepper participant_{*this};
  bool manual_ = false;
  bool started_ = false;
};

}  // namespace basalt::kiosk
