#pragma once

/// \file
/// \brief The DeviceManager (DESIGN.md §3): finds the devices a show asks for, by plain match
/// rules, and runs each through absent -> opening -> live -> lost -> reopening -> live, on
/// hotplug notifications and read errors, with exponential back-off. Losing a device never stops
/// the show: its events stop (and a kDeviceState event tells the bindings), its video stream
/// reports lost so that the texture shows the fallback, and status() says which device and since
/// when.

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "devices/device.h"
#include "devices/dial_box.h"
#include "devices/video_source.h"
#include "runtime/bounded_queue.h"
#include "runtime/clock.h"
#include "runtime/error.h"
#include "runtime/event.h"
#include "runtime/frame_queue.h"

namespace basalt::devices {

/// \brief How a show picks a device: every rule that is set must hold. Plain data, so that the
/// show manifest (`[[device]] backend = "hid", match = "077d:0410"`) fills it directly.
struct DeviceMatch {
  std::string backend;  ///< "hid", "serial", "v4l2", "libcamera", "replay", "synthetic"; empty: any
  std::optional<std::uint16_t> vendor;
  std::optional<std::uint16_t> product;
  std::string name;    ///< case-insensitive substring of the product name
  std::string path;    ///< the exact node, port, trace file or synthetic name
  std::string serial;  ///< exact serial number

  [[nodiscard]] bool matches(const DeviceInfo& info) const;
  /// \brief "hid 077d:0410", "v4l2 at /dev/video0", "any device".
  [[nodiscard]] std::string describe() const;
};

/// \brief Parses "VVVV:PPPP" (hex) into a match's vendor and product.
[[nodiscard]] Result<void> parseVendorProduct(std::string_view text, DeviceMatch& match);

/// \brief One device a show uses.
struct DeviceRequest {
  std::string name;  ///< the show's name for it ("dials", "camera"); unique
  DeviceKind kind = DeviceKind::kDialBox;
  DeviceMatch match;
  /// Backend options as text ("loop" = "true", "format" = "YUYV", "size" = "640x360",
  /// "pattern" = "bars"). Each backend documents the ones it reads.
  std::map<std::string, std::string> options;
  VideoControls controls;  ///< for video sources
};

/// \brief A device a backend can see now.
struct DeviceCandidate {
  DeviceInfo info;
  DeviceKind kind = DeviceKind::kDialBox;
  /// Why it cannot be opened, if known in advance ("permission denied: see configs/udev/...").
  std::string problem;
  /// What Basalt would use it as ("Griffin PowerMate: 1 dial, 1 button", "YUYV 640x480 ...").
  std::string usage;
};

/// \brief A hotplug notification (from libudev, or from tests and simulated backends).
struct HotplugEvent {
  enum class Action : std::uint8_t { kAdded, kRemoved, kChanged };
  Action action = Action::kAdded;
  std::string subsystem;  ///< "hidraw", "video4linux", "usb", "tty", "sim", ...
  std::string devnode;    ///< "/dev/hidraw3", or the path a simulated device uses
};

/// \brief One backend: lists the devices it can see and opens them. Implementations live in
/// devices/hid, devices/v4l2, devices/libcamera, devices/serial and sim/.
///
/// Threading: called on the DeviceManager's thread only.
class DeviceProvider {
 public:
  virtual ~DeviceProvider() = default;
  [[nodiscard]] virtual std::string_view backend() const = 0;
  /// \brief The devices present now. May do I/O (sysfs, ioctls); never waits on a device.
  virtual std::vector<DeviceCandidate> enumerate() = 0;
  [[nodiscard]] virtual Result<std::unique_ptr<DialBox>> openDialBox(const DeviceCandidate& candidate,
                                                                     const DeviceRequest& request, const Clock& clock);
  [[nodiscard]] virtual Result<std::shared_ptr<VideoSource>> openVideoSource(const DeviceCandidate& candidate,
                                                                             const DeviceRequest& request,
                                                                             const Clock& clock);
  /// \brief Backends with hotplug signals of their own (libcamera) report through `notify`
  /// (thread-safe; called by DeviceManager::addProvider).
  virtual void watchHotplug(const std::function<void(HotplugEvent)>& notify) { (void)notify; }
};

/// \brief What the status server and `basalt devices` show for one requested device.
struct DeviceStatus {
  std::string name;
  DeviceKind kind = DeviceKind::kDialBox;
  DeviceState state = DeviceState::kAbsent;
  Nanos since{0};                              ///< Clock time of the last state change
  DeviceId id = 0;                             ///< the id its events carry
  DeviceInfo device;                           ///< the device in use, or the last one used
  std::string match;                           ///< the rule, described
  std::string lastError;                       ///< why it is not live, if it is not
  std::uint32_t attempts = 0;                  ///< failed opens since it was last live
  Nanos nextAttempt{0};                        ///< when it is tried again (absent or lost)
  std::vector<std::uint8_t> reportDescriptor;  ///< a live dial box's (for recording)
  std::optional<VideoMode> mode;               ///< a live video source's
};

/// \brief A video source as the renderer sees it: stable for the life of the manager while the
/// device behind it is unplugged, replaced and reopened. Reports waiting/lost through health().
class ManagedVideoStream final : public FrameSource {
 public:
  FrameRef frameAt(Nanos showTime) override;
  [[nodiscard]] SourceHealth health() const override;
  /// \brief The mode of the live device, if any.
  [[nodiscard]] std::optional<VideoMode> mode() const;
  [[nodiscard]] bool mirrorInRenderer() const;

 private:
  friend class DeviceManager;
  void attach(std::shared_ptr<VideoSource> source);
  void detach(SourceState state, Nanos since);

  mutable std::mutex mutex_;                            // guards the fields below; held only briefly
  std::shared_ptr<VideoSource> source_;                 // the live device, or null
  SourceHealth idle_{SourceState::kWaiting, Nanos{0}};  // health while no device is attached
};

/// \brief Matches requests to devices and keeps them open.
///
/// Threading: request(), addProvider() and step() run on one thread (the manager's: either the
/// caller's, stepping once per frame under a ManualClock, or the thread start() makes).
/// notifyHotplug(), status(), videoStream() and stop() may be called from any thread.
class DeviceManager {
 public:
  struct Config {
    Nanos firstBackoff = std::chrono::milliseconds(250);
    Nanos maxBackoff = std::chrono::seconds(8);
  };

  DeviceManager(const Clock& clock, BoundedQueue<Event>& events);
  DeviceManager(const Clock& clock, BoundedQueue<Event>& events, Config config);
  ~DeviceManager();
  DeviceManager(const DeviceManager&) = delete;
  DeviceManager& operator=(const DeviceManager&) = delete;

  void addProvider(std::unique_ptr<DeviceProvider> provider);
  /// \brief Asks for a device; it is looked for at the next step(). Returns the id its events
  /// will carry. Requests with the same name are an error.
  [[nodiscard]] Result<DeviceId> request(DeviceRequest request);

  /// \brief Advances every device's state machine to `now`: hotplug notifications, opens that
  /// are due, losses reported by backends, and service() for simulated devices. Never waits on a
  /// device, but opening one does the backend's open (ioctls); run it off the frame loop's
  /// thread with start() when real devices are used.
  void step(Nanos now);
  /// \brief Thread-safe: queues a hotplug notification for the next step (and wakes the thread).
  void notifyHotplug(HotplugEvent event);

  /// \brief Runs step() on a thread of its own every `period` and at once on hotplug.
  void start(Nanos period = std::chrono::milliseconds(4));
  /// \brief Stops the thread and closes every device.
  void stop();

  [[nodiscard]] std::vector<DeviceStatus> status() const;
  /// \brief The stable stream for a video request (null for unknown names or dial boxes).
  [[nodiscard]] std::shared_ptr<ManagedVideoStream> videoStream(std::string_view name) const;
  /// \brief The live dial box of a request, or null (manager thread only).
  [[nodiscard]] DialBox* dialBox(std::string_view name) const;
  /// \brief The live video source of a request, or null (manager thread only).
  [[nodiscard]] std::shared_ptr<VideoSource> videoSource(std::string_view name) const;
  /// \brief Taps raw reports of every dial box and frames of every video source opened from
  /// now on (and those open now). Null stops. For trace recording.
  void setTaps(ReportTap* reports, FrameTap* frames);

 private:
  struct Slot {
    DeviceRequest request;
    DeviceId id = 0;
    DeviceState state = DeviceState::kAbsent;
    Nanos since{0};
    Nanos nextAttempt{0};
    Nanos backoff{0};
    std::uint32_t attempts = 0;
    std::string lastError;
    DeviceInfo device;
    std::unique_ptr<DialBox> dial;
    std::shared_ptr<VideoSource> video;
    std::shared_ptr<ManagedVideoStream> stream;
  };

  void publish();
  void transition(Slot& slot, DeviceState state, Nanos now);
  void tryOpen(Slot& slot, Nanos now);
  void markLost(Slot& slot, Nanos now, std::string why);
  void closeAll();
  bool pathInUse(const Slot& except, const std::string& path) const;

  const Clock& clock_;
  BoundedQueue<Event>& events_;
  Config config_;
  std::vector<std::unique_ptr<DeviceProvider>> providers_;  // manager thread
  std::vector<std::unique_ptr<Slot>> slots_;                // manager thread
  DeviceId nextId_ = 1;
  ReportTap* reportTap_ = nullptr;  // guarded by mutex_
  FrameTap* frameTap_ = nullptr;    // guarded by mutex_

  mutable std::mutex mutex_;           // guards the fields below
  std::vector<HotplugEvent> hotplug_;  // pending notifications (bounded: oldest dropped past 256)
  std::vector<DeviceStatus> status_;   // published after every step that changed something
  std::map<std::string, std::shared_ptr<ManagedVideoStream>, std::less<>> streams_;
  bool tapsChanged_ = false;
  std::condition_variable wake_;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace basalt::devices
