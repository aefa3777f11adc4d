#pragma once

/// \file
/// \brief A dial box that turns by itself on a schedule: for demos, tests and benchmarks.

#include <atomic>
#include <memory>
#include <vector>

#include "devices/dial_box.h"

namespace basalt::sim {

/// \brief One scripted input: at `time` after opening, dial `index` turns by `value` turns
/// (or, for a button, `value` 1 pressed / 0 released).
struct ScriptedInput {
  Nanos time{0};
  EventKind kind = EventKind::kDialDelta;
  std::uint16_t index = 0;
  double value = 0;
};

/// \brief Set to false to "unplug" a simulated device: its next service() reports it lost, in the
/// middle of a batch of events if need be. Shared between a SyntheticProvider and its devices.
using PresenceFlag = std::shared_ptr<std::atomic<bool>>;

/// \brief A synthetic 8-dial, 32-button box that plays a script of inputs on the show's Clock.
/// Events are produced by service() when their time has come, so under a ManualClock the
/// stream is exact and reproducible.
class SyntheticDial final : public devices::DialBox {
 public:
  SyntheticDial(std::vector<ScriptedInput> script, const Clock& clock, bool loop = false);
  SyntheticDial(devices::DeviceInfo info, std::vector<ScriptedInput> script, const Clock& clock, bool loop,
                PresenceFlag present);

  /// \brief The identity synthetic dials have by default ("synthetic:dial").
  static devices::DeviceInfo defaultInfo();

 private:
  Result<void> doOpen() override;
  void doClose() override;
  void doService(Nanos now) override;

  std::vector<ScriptedInput> script_;
  const Clock& clock_;
  bool loop_;
  PresenceFlag present_;
  std::size_t next_ = 0;
  Nanos origin_{0};
};

}  // namespace basalt::sim
