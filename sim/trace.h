#pragma once

/// \file
/// \brief Traces (DESIGN.md §5): a folder `NAME.trace/` with `trace.toml` (when, where, each
/// device's identity and file, the frame rate), one hid-recorder file per dial box and one video
/// file per video source. TraceRecorder writes one from live devices; readTrace() reads it back
/// for the replay backend.

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "devices/device.h"
#include "devices/video_source.h"
#include "runtime/clock.h"
#include "runtime/error.h"
#include "runtime/unique_fd.h"
#include "sim/hid_comments.h"
#include "sim/hid_recording.h"
#include "sim/trace_video.h"

namespace basalt::sim {

/// \brief One recorded device, as trace.toml lists it.
struct TraceDevice {
  std::string name;  ///< the show's name for it ("dials")
  devices::DeviceKind kind = devices::DeviceKind::kDialBox;
  devices::DeviceInfo info;              ///< identity at recording time
  std::string file;                      ///< relative to the trace folder
  std::vector<std::uint8_t> descriptor;  ///< dial boxes and trackers: the report descriptor
  devices::VideoMode mode;               ///< video sources
};

struct TraceInfo {
  std::filesystem::path folder;
  std::string recorded;  ///< ISO 8601 UTC
  std::string host;
  std::string basalt;  ///< version that wrote it
  double fps = 0;      ///< the show's frame rate while recording
  double seconds = 0;  ///< length
  std::vector<TraceDevice> devices;
};

/// \brief Reads `folder/trace.toml`. Errors name the file and line.
[[nodiscard]] Result<TraceInfo> readTrace(const std::filesystem::path& folder);
/// \brief Parses the text of a trace.toml (for tests and the fuzzer).
[[nodiscard]] Result<TraceInfo> parseTraceToml(std::string_view text, std::string_view name = "trace.toml");
/// \brief The text of trace.toml for `info`.
std::string formatTraceToml(const TraceInfo& info);

/// \brief Taps live devices into a trace folder.
///
/// Threading: addDialBox()/addVideoSource()/finish() from the owner's thread; onReport() and
/// onFrame() from device threads (reports are written under `mutex_`; frames are queued for the
/// writer thread, at most 8, so that a slow disk drops recorded frames instead of stalling the
/// camera).
class TraceRecorder final : public devices::ReportTap, public devices::FrameTap {
 public:
  struct Options {
    std::string host;
    std::string basaltVersion;
    double fps = 60;
    TraceVideoWriterFactory videoWriter;  ///< default: raw .bvraw files
  };

  /// \brief Creates `folder` and starts the recording clock. The folder must not exist, be
  /// empty, or hold an unfinished trace: the files a recording that never finished left (no
  /// trace.toml, only .hid, .mkv and .bvraw files and its `.recording` mark), which are removed
  /// (replacedFiles() names them). A folder that holds a finished trace, other files, or a
  /// recording in progress (another process holds its `.recording` mark) is refused with a
  /// message that names the folder and what to do.
  [[nodiscard]] static Result<std::unique_ptr<TraceRecorder>> create(const std::filesystem::path& folder,
                                                                     const Clock& clock, Options options);
  ~TraceRecorder() override;

  /// \brief Records device `id` (the DeviceManager's id) as `name`.
  [[nodiscard]] Result<void> addDialBox(DeviceId id, const std::string& name, const devices::DeviceInfo& info,
                                        const std::vector<std::uint8_t>& descriptor);
  /// \brief Records tracker `id` as `name`: its reports (a HID tracker's own, or the virtual
  /// tracker's) into a hid-recorder file, as a dial box's.
  [[nodiscard]] Result<void> addTracker(DeviceId id, const std::string& name, const devices::DeviceInfo& info,
                                        const std::vector<std::uint8_t>& descriptor);
  [[nodiscard]] Result<void> addVideoSource(DeviceId id, const std::string& name, const devices::DeviceInfo& info,
                                            const devices::VideoMode& mode);

  void onReport(DeviceId device, Nanos time, std::span<const std::uint8_t> report) override;
  void onFrame(DeviceId device, const FrameRef& frame) override;

  /// \brief Waits until every frame queued so far is written (at most `timeout`). A recording
  /// under a ManualClock runs faster than real time; calling this once per frame keeps the
  /// camera's frame pool from running dry while the writer catches up.
  bool drain(std::chrono::milliseconds timeout = std::chrono::seconds(5));

  /// \brief Stops, flushes every file and writes trace.toml. The first write error, if any.
  [[nodiscard]] Result<TraceInfo> finish();
  /// \brief For a trace that cannot be finished: stops and removes every file of the recording,
  /// and the folder when create() made it. Idempotent; after finish() too.
  void discard();

  /// \brief The files of an earlier, unfinished recording that create() removed.
  [[nodiscard]] const std::vector<std::string>& replacedFiles() const { return replaced_; }
  /// \brief Bytes in the trace's files now (what they take on disk as far as written).
  [[nodiscard]] std::uint64_t bytesWritten() const;

  [[nodiscard]] std::uint64_t reportsWritten() const;
  [[nodiscard]] std::uint64_t framesWritten() const;
  [[nodiscard]] std::uint64_t framesDropped() const;

 private:
  TraceRecorder(std::filesystem::path folder, const Clock& clock, Options options, UniqueFd mark, bool madeFolder,
                std::vector<std::string> replaced);
  [[nodiscard]] Result<void> addHidDevice(DeviceId id, const std::string& name, const devices::DeviceInfo& info,
                                          const std::vector<std::uint8_t>& descriptor, devices::DeviceKind kind);
  void stopWriting();
  void writerLoop();
  void noteError(const Error& e);

  struct DialFile {
    std::ofstream out;
    std::size_t index = 0;       // in info_.devices
    HidComments comments;        // decodes each report into the comment before its E: line
    bool midi = false;           // a MIDI dial box: its messages are kept and written as a Standard MIDI File
    HidRecordedDevice messages;  // MIDI dial boxes: the messages so far
  };
  struct VideoFile {
    std::unique_ptr<TraceVideoWriter> writer;
    std::size_t index = 0;
  };
  struct PendingFrame {
    DeviceId device = 0;
    FrameRef frame;
  };

  std::filesystem::path folder_;
  const Clock& clock_;
  Options options_;
  UniqueFd mark_;    // `.recording`, locked (flock) while this recording runs
  bool madeFolder_;  // create() made the folder (discard() removes it)
  std::vector<std::string> replaced_;
  bool discarded_ = false;
  Nanos start_{0};
  mutable std::mutex mutex_;  // guards everything below
  TraceInfo info_;
  std::map<DeviceId, DialFile> dials_;
  std::map<DeviceId, VideoFile> videos_;
  std::deque<PendingFrame> frames_;
  std::condition_variable framesReady_;
  std::condition_variable framesDone_;
  bool writing_ = false;  // the writer thread holds a frame outside the lock
  bool stopping_ = false;
  std::optional<Error> firstError_;
  std::uint64_t reports_ = 0;
  std::uint64_t framesWritten_ = 0;
  std::uint64_t framesDropped_ = 0;
  Nanos lastTime_{0};
  std::thread writer_;
};

}  // namespace basalt::sim
