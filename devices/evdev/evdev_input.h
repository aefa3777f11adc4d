#pragma once

/// \file
/// \brief Keyboards and mice read straight from the kernel (evdev, /dev/input/event*), for
/// outputs without a window system (KMS): their keys, motion and buttons become the same
/// `kKey`, `kPointerMotion` and `kPointerButton` events a window gives. Includes no kernel
/// header: linux/input.h stays in devices/evdev.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "runtime/clock.h"
#include "runtime/error.h"
#include "runtime/event.h"

namespace basalt::devices {

/// \brief The device ids evdev keyboards and mice get: this base plus a count (mod 256).
inline constexpr DeviceId kEvdevDeviceIdBase = 0xFFFF'FE00U;

/// \brief Which input devices to read.
struct EvdevOptions {
  bool keyboards = true;  ///< read keyboards (and numeric pads)
  bool pointers = true;   ///< read mice, trackballs and touchpads
  /// \brief Only devices whose name contains one of these (case-sensitive); empty: every
  /// keyboard and pointer.
  std::vector<std::string> names;
  std::filesystem::path folder = "/dev/input";  ///< where the event nodes are
  /// \brief Learn of plugged devices from udev; without udev (or when it cannot be reached)
  /// the folder is scanned every `rescanPeriod`. Pulled devices are noticed by their read error.
  bool udev = true;
  Nanos rescanPeriod{std::chrono::seconds(2)};
};

/// \brief One event node as the reader saw it.
struct EvdevDeviceInfo {
  std::string path;   ///< /dev/input/eventN
  std::string name;   ///< as the device reports it (EVIOCGNAME)
  std::string role;   ///< "keyboard", "pointer", ... or why it is not read ("not a keyboard or pointer")
  bool read = false;  ///< true: its events go to the show
  DeviceId id = 0;    ///< the id its events carry (read devices only)
};

/// \brief The text for an event node that cannot be opened: what to change, by errno
/// (EACCES: the udev rule and the `input` group; ENOENT: gone).
[[nodiscard]] std::string evdevOpenProblem(const std::string& path, const std::string& name, int errnum);

/// \brief Reads every keyboard and pointer under `options.folder` on a thread of its own,
/// following hotplug (udev's "input" subsystem, or rescans), and keeps their events in a
/// bounded queue the frame loop's thread empties with takeInput().
///
/// Reads are non-blocking and happen on the reader's thread only; the frame loop never waits
/// on a device. Devices are not grabbed: the console underneath sees the keys too (Ctrl+Alt+Fn
/// still switches terminals). Nodes that cannot be opened are reported once each, as warnings.
///
/// Threading: create(), start(), stop() and the destructor on the owner's thread; takeInput()
/// and dropped() on one consumer thread; devices() from any thread.
class EvdevInput {
 public:
  /// \brief Sets up (the udev monitor where asked and available); opens nothing yet.
  /// `wake` is called from the reader's thread when events arrive for an empty queue.
  [[nodiscard]] static Result<std::unique_ptr<EvdevInput>> create(const Clock& clock, EvdevOptions options,
                                                                  std::function<void()> wake = {});
  ~EvdevInput();
  EvdevInput(const EvdevInput&) = delete;
  EvdevInput& operator=(const EvdevInput&) = delete;

  /// \brief Scans the folder and starts the reader thread.
  void start();
  /// \brief Stops the thread and closes every device (held keys are released in the queue).
  void stop();

  /// \brief Moves queued events into `into` (as many as fit) and returns how many; `time` is
  /// the show's clock when the reader read them.
  std::size_t takeInput(std::span<Event> into);
  /// \brief Events lost because the queue (1024) was full.
  [[nodiscard]] std::uint64_t dropped() const;
  /// \brief Every event node seen and what became of it: read, or left alone and why.
  [[nodiscard]] std::vector<EvdevDeviceInfo> devices() const;
  /// \brief True when hotplug comes from udev (false: rescans every rescanPeriod).
  [[nodiscard]] bool hotplugFromUdev() const;

 private:
  struct Impl;
  explicit EvdevInput(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace basalt::devices
