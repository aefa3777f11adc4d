#pragma once

/// \file
/// \brief Trackers fed by OSC: a manifest's `kind = "tracker"`, `backend = "osc"` device takes
/// its samples from `/tracker/NAME` messages that the run's OSC input receives. One
/// `OscTrackerFeeds` per run is both the OSC input's tracker sink and the device provider of
/// those trackers, so that they open, go lost and come back through the DeviceManager's states
/// like every device.

#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "devices/device_manager.h"
#include "devices/tracker.h"
#include "kiosk/manifest/manifest.h"
#include "kiosk/osc/osc_router.h"
#include "kiosk/show/show_loader.h"
#include "runtime/clock.h"

namespace basalt::kiosk {

/// \brief How long a fed tracker may go without a message before it is lost (and what a closed
/// one must have had within, to open).
inline constexpr Nanos kOscTrackerSilence = std::chrono::seconds(2);

/// \brief The OSC side of fed trackers. Messages, in tracker units and degrees:
/// - `/tracker/NAME x y z` and `/tracker/NAME x y z rx ry rz`: a whole sample (the rotation stays
///   as it was when only the position comes);
/// - `/tracker/NAME/position x y z` and `/tracker/NAME/rotation rx ry rz`: either half.
/// Rotations are Euler angles in degrees, applied X, then Y, then Z, as a scene's viewer.
/// Numbers may be OSC i, h, f or d. A message for another name, or with other arguments, is not
/// used (the OSC input counts it `wrong_types`).
///
/// Threading: take() runs on the OSC input's thread; the provider side on the DeviceManager's.
/// Samples are stamped with the show's Clock when they arrive.
class OscTrackerFeeds final : public OscTrackerSink {
 public:
  /// \brief Feeds for the trackers named (the OSC names), stamped on `clock` (which outlives this).
  OscTrackerFeeds(const std::vector<std::string>& names, const Clock& clock);

  bool take(const OscMessage& message) override;

  /// \brief A provider of these trackers for one DeviceManager (backend "osc"); it shares the
  /// feeds, so it may outlive this object.
  [[nodiscard]] std::unique_ptr<devices::DeviceProvider> provider() const;

  /// \brief The device path a fed tracker is found at: "osc:/tracker/NAME".
  [[nodiscard]] static std::string pathFor(const std::string& name);
  /// \brief The OSC name of a manifest's osc tracker: its `match.name`, else the device's name.
  [[nodiscard]] static std::string nameOf(const DeviceSpec& spec);
  /// \brief The names of the manifest's osc trackers.
  [[nodiscard]] static std::vector<std::string> namesIn(const Manifest& show);
  /// \brief What the loader opens an osc tracker with: this run's provider and a request that
  /// finds it. For the run's ShowFactories::devices, in front of makeDeviceSource().
  [[nodiscard]] DeviceSource sourceFor(const DeviceSpec& spec) const;

  struct Feed;

 private:
  const Clock& clock_;
  std::map<std::string, std::shared_ptr<Feed>, std::less<>> feeds_;  // fixed after construction
};

}  // namespace basalt::kiosk
