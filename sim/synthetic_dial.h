#pragma once

/// \file
/// \brief A dial box that turns by itself on a schedule: for demos, tests and benchmarks.

#include <vector>

#include "devices/dial_box.h"

namespace basalt::sim {

/// \brief One scripted input: at `time` after opening, dial `dial` turns by `turns`
/// (or, for a button, `pressed` 1/0).
struct ScriptedInput {
  Nanos time{0};
  EventKind kind = EventKind::kDialDelta;
  std::uint16_t index = 0;
  double value = 0;
};

/// \brief A synthetic 8-dial, 32-button box that plays a script of inputs on the show's Clock.
/// Events are produced by service() when their time has come, so under a ManualClock the
/// stream is exact and reproducible.
class SyntheticDial final : public devices::DialBox {
 public:
  SyntheticDial(std::vector<ScriptedInput> script, const Clock& clock, bool loop = false);

 private:
  Result<void> doOpen() override;
  void doClose() override;
  void doService(Nanos now) override;

  std::vector<ScriptedInput> script_;
  const Clock& clock_;
  bool loop_;
  std::size_t next_ = 0;
  Nanos origin_{0};
};

}  // namespace basalt::sim
