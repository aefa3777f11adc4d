#pragma once

/// \file
/// \brief The `replay` backend: plays recorded devices as if they were plugged in. A dial box
/// replays its hid-recorder reports through the same decoder as the real device; a camera replays
/// its trace video with the original timestamps. Both play on the show's Clock, in real time or as
/// fast as the frame loop runs under a ManualClock, looping or once.

#include <memory>
#include <variant>

#include "devices/dial_box.h"
#include "devices/hid/dial_decoder.h"
#include "devices/midi/midi_decoder.h"
#include "devices/video_source.h"
#include "sim/hid_recording.h"
#include "sim/trace_video.h"

namespace basalt::sim {

/// \brief A recorded HID device (or MIDI dial box: its descriptor is then a MIDI profile and its
/// reports MIDI messages) played back. Its raw reports go to the report tap unchanged, so
/// recording a replay gives the same file.
class ReplayDialBox final : public devices::DialBox {
 public:
  /// \brief Fails when the recording's descriptor has no dials (and it is not a PowerMate or
  /// Shuttle by its ids).
  [[nodiscard]] static Result<std::unique_ptr<ReplayDialBox>> create(devices::DeviceInfo info,
                                                                     const HidRecordedDevice& recording,
                                                                     const Clock& clock, bool loop);
  /// \brief True once a non-looping replay has played its last report.
  [[nodiscard]] bool finished() const { return finished_; }

 private:
  using Decoder = std::variant<devices::DialDecoder, devices::MidiDecoder>;
  ReplayDialBox(devices::DeviceInfo info, const HidRecordedDevice& recording, Decoder decoder, int dials, int buttons,
                const Clock& clock, bool loop);
  Result<void> doOpen() override;
  void doClose() override;
  void doService(Nanos now) override;

  std::vector<HidReport> reports_;
  Decoder decoder_;
  const Clock& clock_;
  bool loop_;
  std::size_t next_ = 0;
  Nanos origin_{0};
  bool finished_ = false;
};

/// \brief A recorded video source played back from a trace video reader.
class ReplayCamera final : public devices::VideoSource {
 public:
  ReplayCamera(devices::DeviceInfo info, std::unique_ptr<TraceVideoReader> reader, const Clock& clock, bool loop);
  [[nodiscard]] bool finished() const { return finished_; }

 private:
  Result<void> doOpen() override;
  void doClose() override;
  void doService(Nanos now) override;

  std::unique_ptr<TraceVideoReader> reader_;
  bool loop_;
  FrameRef pending_;  // read ahead: the next frame, not yet due
  Nanos origin_{0};
  Nanos lapLength_{0};
  Nanos lastPts_{0};
  bool finished_ = false;
};

}  // namespace basalt::sim
