#pragma once

/// \file
/// \brief The DeviceManager (DESIGN.md §3): finds the devices a show asks for, by plain match
/// rules, and runs each through absent -> opening -> live -> lost -> reopening -> live, on
/// hotplug notifications and read errors, with exponential back-off. Losing a device never stops
/// the show: its events stop (and a kDeviceState event tells the bindings), its video stream
/// reports lost so that the texture shows the fallback, and status() says which device and since
/// when.
///
/// It is the one owner of a device's life: nothing else opens, retries or closes a device that
/// was requested from it. Its users ask it (request(), share(), withdraw(), restart()) and are
/// told through it (the kDeviceState events in the queue, status(), the video streams).

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
#include "devices/tracker.h"
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

/// \brief How long a device that cannot be opened waits before the next try: `first` after the
/// first failure, doubling up to `max`. A hotplug "add" tries at once and starts over.
struct Backoff {
  Nanos first = std::chrono::milliseconds(250);
  Nanos max = std::chrono::seconds(8);
};

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

/// \brief How the manager keeps a requested device, where the requester has a say.
struct Upkeep {
  /// The back-off between failed opens; unset: the manager's (DeviceManager::Config).
  std::optional<Backoff> backoff;
  /// The requester logs what happens to the device in its own words (it watches status()); the
  /// manager then logs nothing for it.
  bool quiet = false;
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
  [[nodiscard]] virtual Result<std::unique_ptr<Tracker>> openTracker(const DeviceCandidate& candidate,
                                                                     const DeviceRequest& request, const Clock& clock);
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
  std::uint32_t restarts = 0;                  ///< restarts asked with restart() and done
};

/// \brief A video source as the renderer sees it: stable for the life of the manager while the
/// device behind it is unplugged, replaced and reopened. Reports waiting/lost through health().
/// Several readers may share one: each asking for the same show time gets the same frame.
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
  FrameRef last_;                                       // what frameAt(lastAt_) gave, for other readers
  Nanos lastAt_{-1};
};

/// \brief Matches requests to devices and keeps them open.
///
/// Threading: addProvider() and step() run on one thread (the manager's: either the caller's,
/// stepping once per frame under a ManualClock, or the thread start() makes); addProvider()
/// before the first step. request(), share(), withdraw(), restart(), notifyHotplug(),
/// addFrameTap(), removeFrameTap(), status(), videoStream(), setTaps() and stop() may be called
/// from any thread: what they ask is done at the next step, and the thread is woken for it.
class DeviceManager {
 public:
  struct Config {
    Nanos firstBackoff = std::chrono::milliseconds(250);
    Nanos maxBackoff = std::chrono::seconds(8);
    /// The id of the first request; the next ones count up. Managers whose devices feed one
    /// queue number them apart, so that every event names its device.
    DeviceId firstId = 1;
  };

  DeviceManager(const Clock& clock, BoundedQueue<Event>& events);
  DeviceManager(const Clock& clock, BoundedQueue<Event>& events, Config config);
  ~DeviceManager();
  DeviceManager(const DeviceManager&) = delete;
  DeviceManager& operator=(const DeviceManager&) = delete;

  /// \brief A backend every request without a provider of its own is looked for in.
  void addProvider(std::unique_ptr<DeviceProvider> provider);
  /// \brief Asks for a device; it is looked for at the next step(). Returns the id its events
  /// will carry; ids are never used twice. Names are unique among the requests held now (an
  /// error otherwise). With `provider` the device is looked for there only (a show's device
  /// with its own backend: a replay of one trace, one serial port); otherwise in every
  /// provider added with addProvider() of the request's backend.
  [[nodiscard]] Result<DeviceId> request(DeviceRequest request, std::unique_ptr<DeviceProvider> provider = nullptr,
                                         Upkeep upkeep = {});
  /// \brief Holds a request someone else made, so that it stays until both withdraw it. Returns
  /// its id; an error when no request has that name.
  [[nodiscard]] Result<DeviceId> share(std::string_view name);
  /// \brief Gives a request (or a share of it) up; when none holds it any more, its device is
  /// closed at the next step and its name is free at once. Its events that are still queued
  /// carry an id no request has.
  void withdraw(std::string_view name);
  /// \brief Closes the device (a live one counts as lost) and opens it again at the next step,
  /// whatever its back-off; status().restarts counts it once done. False for unknown names.
  bool restart(std::string_view name);

  /// \brief Advances every device's state machine to `now`: requests made and withdrawn,
  /// hotplug notifications, restarts, opens that are due, losses reported by backends, and
  /// service() for simulated devices. Never waits on a device, but opening one does the
  /// backend's open (ioctls); run it off the frame loop's thread with start() when real devices
  /// are used.
  void step(Nanos now);
  /// \brief Thread-safe: queues a hotplug notification for the next step (and wakes the thread).
  void notifyHotplug(HotplugEvent event);

  /// \brief Runs step() on a thread of its own every `period` and at once on hotplug and new
  /// requests. Does nothing when the thread runs.
  void start(Nanos period = std::chrono::milliseconds(4));
  /// \brief Stops the thread and closes every device; the requests stay.
  void stop();

  [[nodiscard]] std::vector<DeviceStatus> status() const;
  /// \brief Goes up whenever status() changes, so that a frame loop reads status() only then.
  [[nodiscard]] std::uint64_t statusVersion() const { return statusVersion_.load(std::memory_order_acquire); }
  /// \brief The stable stream for a video request (null for unknown names or dial boxes).
  [[nodiscard]] std::shared_ptr<ManagedVideoStream> videoStream(std::string_view name) const;
  /// \brief The samples of a tracker request, stable while its device is unplugged, replaced and
  /// reopened (null for unknown names and other kinds). Any thread.
  [[nodiscard]] std::shared_ptr<TrackerSamples> trackerSamples(std::string_view name) const;
  /// \brief The live tracker of a request, or null (manager thread only).
  [[nodiscard]] Tracker* tracker(std::string_view name) const;
  /// \brief The live dial box of a request, or null (manager thread only).
  [[nodiscard]] DialBox* dialBox(std::string_view name) const;
  /// \brief The live video source of a request, or null (manager thread only).
  [[nodiscard]] std::shared_ptr<VideoSource> videoSource(std::string_view name) const;
  /// \brief Taps raw reports of every dial box and frames of every video source opened from
  /// now on (and those open now). Null stops. For trace recording.
  void setTaps(ReportTap* reports, FrameTap* frames);
  /// \brief Hands every frame of the video request `name` to `tap` too, on the producer's
  /// thread (a camera's MJPEG decoder). Kept until removed or the request is withdrawn; no-op
  /// for unknown names.
  void addFrameTap(std::string_view name, std::shared_ptr<FrameTap> tap);
  void removeFrameTap(std::string_view name, const FrameTap* tap);

 private:
  class FrameFanOut;
  struct Slot {
    DeviceRequest request;
    Upkeep upkeep;
    std::unique_ptr<DeviceProvider> provider;  // its own backend, or null: the shared ones
    DeviceId id = 0;
    DeviceState state = DeviceState::kAbsent;
    Nanos since{0};
    Nanos nextAttempt{0};
    Nanos backoff{0};
    std::uint32_t attempts = 0;
    std::uint32_t restarts = 0;
    std::string lastError;
    DeviceInfo device;
    DeviceProvider* foundBy = nullptr;  // the provider of the device in use
    std::unique_ptr<DialBox> dial;
    std::unique_ptr<Tracker> tracker;
    std::shared_ptr<TrackerSamples> samples;  // tracker requests: outlives each device
    std::shared_ptr<VideoSource> video;
    std::shared_ptr<ManagedVideoStream> stream;
    std::shared_ptr<FrameFanOut> frames;  // installed on every video source of the request
  };
  struct Held {
    DeviceId id = 0;
    std::uint32_t users = 1;
    std::shared_ptr<FrameFanOut> frames;
  };

  void publish();
  [[nodiscard]] DeviceStatus statusOf(const Slot& slot) const;
  void transition(Slot& slot, DeviceState state, Nanos now);
  void tryOpen(Slot& slot, Nanos now);
  void markLost(Slot& slot, Nanos now, std::string why);
  void closeDevice(Slot& slot, SourceState streamState, Nanos now);
  void closeAll();
  [[nodiscard]] bool pathInUse(const Slot& except, const DeviceProvider* provider, const std::string& path) const;
  [[nodiscard]] Slot* slotNamed(std::string_view name) const;

  const Clock& clock_;
  BoundedQueue<Event>& events_;
  Config config_;
  std::vector<std::unique_ptr<DeviceProvider>> providers_;  // manager thread
  std::vector<std::unique_ptr<Slot>> slots_;                // manager thread
  ReportTap* reportTap_ = nullptr;                          // guarded by mutex_
  std::atomic<FrameTap*> frameTap_{nullptr};                // the recorder's; read by every FrameFanOut
  std::atomic<std::uint64_t> statusVersion_{0};             // bumped after status_ changes

  mutable std::mutex mutex_;                       // guards the fields below
  DeviceId nextId_;                                // the next request's id
  std::map<std::string, Held, std::less<>> held_;  // the requests held now, by name
  std::vector<std::unique_ptr<Slot>> incoming_;    // requested, not yet stepped
  std::vector<DeviceId> withdrawn_;                // withdrawn, not yet closed
  std::vector<DeviceId> restarts_;                 // restarts asked, not yet done
  std::vector<HotplugEvent> hotplug_;              // pending notifications (bounded: oldest dropped past 256)
  std::vector<DeviceStatus> status_;               // published after every step that changed something
  std::map<std::string, std::shared_ptr<ManagedVideoStream>, std::less<>> streams_;
  std::map<std::string, std::shared_ptr<TrackerSamples>, std::less<>> samples_;  // tracker requests
  bool tapsChanged_ = false;
  std::condition_variable wake_;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace basalt::devices
