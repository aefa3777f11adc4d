#pragma once

/// \file
/// \brief DeviceProviders for the simulated backends: `synthetic` (scripted dials, test-pattern
/// cameras, plugged and unplugged at will) and `replay` (the devices of a trace folder or of
/// hid-recorder files).

#include <filesystem>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "devices/device_manager.h"
#include "sim/hid_recording.h"
#include "sim/synthetic_camera.h"
#include "sim/synthetic_dial.h"
#include "sim/synthetic_tracker.h"
#include "sim/trace.h"
#include "sim/trace_video.h"

namespace basalt::sim {

/// \brief The `synthetic` backend. By default it has one dial box ("synthetic:dial", LAVA's
/// demo turns) and one camera ("synthetic:camera", 640x360 YUYV colour bars at 30 fps).
///
/// Request options it reads: dial boxes `loop` (true/false); cameras `format` (YUYV, NV12,
/// I420, RGBA, ..., or MJPEG: JPEG-encoded 4:2:2 like a webcam's), `size` (WxH), `fps`, `pattern` (bars, gradient,
/// checker, solid), `moving` (true/false), `faults` (see applyCameraOptions).
///
/// Tests plug and unplug devices with plug()/unplug(): an unplugged device's live object fails
/// its next read, and a device plugged at the same path may be a different one.
/// Threading: plug()/unplug() from any thread; the rest on the manager's thread.
class SyntheticProvider final : public devices::DeviceProvider {
 public:
  struct Device {
    devices::DeviceCandidate candidate;
    std::vector<ScriptedInput> script;  ///< dial boxes
    bool loop = true;
    SyntheticCameraConfig camera;  ///< cameras
    TrackerPath tracker;           ///< trackers
  };

  /// \brief With the default dial box and camera.
  SyntheticProvider();
  /// \brief With exactly `devices`.
  explicit SyntheticProvider(std::vector<Device> devices);

  /// \brief Adds (or replaces) the device at its path.
  void plug(Device device);
  /// \brief Removes the device at `path`; an open one fails its next read.
  void unplug(const std::string& path);

  /// \brief LAVA's demo: each of dials 0-6 turns a little in turn, once a second.
  static std::vector<ScriptedInput> demoScript();

  [[nodiscard]] std::string_view backend() const override { return "synthetic"; }
  std::vector<devices::DeviceCandidate> enumerate() override;
  Result<std::unique_ptr<devices::DialBox>> openDialBox(const devices::DeviceCandidate& candidate,
                                                        const devices::DeviceRequest& request,
                                                        const Clock& clock) override;
  Result<std::shared_ptr<devices::VideoSource>> openVideoSource(const devices::DeviceCandidate& candidate,
                                                                const devices::DeviceRequest& request,
                                                                const Clock& clock) override;
  Result<std::unique_ptr<devices::Tracker>> openTracker(const devices::DeviceCandidate& candidate,
                                                        const devices::DeviceRequest& request,
                                                        const Clock& clock) override;

 private:
  struct Entry {
    Device device;
    PresenceFlag present;
  };
  mutable std::mutex mutex_;    // guards entries_
  std::vector<Entry> entries_;  // guarded by mutex_
};

/// \brief Applies a camera request's options (format, size, fps, pattern, moving, faults:
/// "unplug@NS,signal_lost@NS+NS,stall@NS+NS,corrupt@NS" in nanoseconds after opening; corrupt,
/// MJPEG only, damages the frame due then) to `config`.
[[nodiscard]] Result<void> applyCameraOptions(const devices::DeviceRequest& request, SyntheticCameraConfig& config);

/// \brief The `replay` backend: the devices recorded in trace folders and hid-recorder files.
/// Each device's path is `FILE` (single-device files) or `FILE#N` (device D:N of a multi-device
/// file); its name, vendor and product are the recorded ones.
///
/// Request options it reads: `loop` (true/false, default true). A recording whose descriptor
/// has absolute X, Y and Z (a tracker's, or Basalt's virtual tracker) is offered as a tracker.
class ReplayProvider final : public devices::DeviceProvider {
 public:
  /// \brief `videoReader` opens trace videos (default: .bvraw only; the kiosk injects media's
  /// Matroska reader).
  explicit ReplayProvider(TraceVideoReaderFactory videoReader = {});

  /// \brief Adds every device of a trace folder. Errors name the file and line.
  [[nodiscard]] Result<void> addTrace(const std::filesystem::path& folder);
  /// \brief Adds a Standard MIDI File (Basalt's, or one from arecordmidi) as a MIDI dial box.
  [[nodiscard]] Result<void> addMidiFile(const std::filesystem::path& file);
  /// \brief Adds every device of an hid-recorder file (a .mid file: addMidiFile()).
  [[nodiscard]] Result<void> addHidRecording(const std::filesystem::path& file);

  /// \brief One request per recorded device, named as recorded, matched by path.
  [[nodiscard]] std::vector<devices::DeviceRequest> requests() const;

  [[nodiscard]] std::string_view backend() const override { return "replay"; }
  std::vector<devices::DeviceCandidate> enumerate() override;
  Result<std::unique_ptr<devices::DialBox>> openDialBox(const devices::DeviceCandidate& candidate,
                                                        const devices::DeviceRequest& request,
                                                        const Clock& clock) override;
  Result<std::shared_ptr<devices::VideoSource>> openVideoSource(const devices::DeviceCandidate& candidate,
                                                                const devices::DeviceRequest& request,
                                                                const Clock& clock) override;
  Result<std::unique_ptr<devices::Tracker>> openTracker(const devices::DeviceCandidate& candidate,
                                                        const devices::DeviceRequest& request,
                                                        const Clock& clock) override;

 private:
  struct Entry {
    std::string requestName;
    devices::DeviceCandidate candidate;
    HidRecordedDevice hid;        // dial boxes and trackers
    std::filesystem::path video;  // video sources
  };
  TraceVideoReaderFactory videoReader_;
  std::vector<Entry> entries_;
};

/// \brief "true"/"false" option with a default; an error for other text.
[[nodiscard]] Result<bool> boolOption(const devices::DeviceRequest& request, const std::string& key, bool fallback);

}  // namespace basalt::sim
