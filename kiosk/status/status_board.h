#pragma once

/// \file
/// \brief What the status and control server reports and how it reaches the frame loop: frame
/// figures published every frame (without allocating), the show's, devices' and streams' state
/// published when they change, a ring of recent log records, and the queues that carry control
/// requests and snapshot requests to the frame loop.

#include <array>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "kiosk/lock/lock_figures.h"
#include "kiosk/loop/frame_watch.h"
#include "kiosk/policy/schedule.h"
#include "kiosk/status/machine_facts.h"
#include "runtime/bindings.h"
#include "runtime/bounded_queue.h"
#include "runtime/clock.h"
#include "runtime/image.h"
#include "runtime/log.h"
#include "runtime/show/show.h"

namespace basalt::kiosk {

/// \brief One device as the operator sees it.
struct DeviceStatus {
  std::string name;
  std::string kind;     ///< "dial_box", "camera"
  std::string backend;  ///< "hid", "synthetic", ...
  std::string state;    ///< "live", "absent", "lost", ...
  std::string message;  ///< why it is not live, or what it is
  WallTime since{};
};

/// \brief One stream (movie, camera texture) as the operator sees it.
struct StreamStatus {
  std::string name;
  std::string kind;
  std::string state;  ///< "playing", "absent", ...
  std::string message;
  WallTime since{};
};

/// \brief The show's state, published when it changes.
struct ShowStatus {
  std::string name;
  std::string manifest;   ///< path, or "" for the built-in default show
  std::string output;     ///< Output::describe()
  bool open = true;       ///< within opening hours
  std::string mode;       ///< "closed", "attract", "active"
  std::string display;    ///< "on", "black", "off"
  std::string item;       ///< the item's name, "" when none
  std::size_t index = 0;  ///< 1-based place in its list, 0 when none
  std::size_t count = 0;
  std::string description;                     ///< KioskPolicy::describe()
  std::optional<WallTime> nextScheduleChange;  ///< filled by StatusBoard::snapshot()
  /// The show's opening hours (immutable, shared), so that the server works out the next change
  /// on its own thread rather than the frame loop's.
  std::shared_ptr<const Schedule> schedule;
};

/// \brief Upper bounds (seconds) of the frame interval histogram's buckets: just above the frame
/// periods of 60, 50, 30 and 25 Hz displays (16.7, 20, 33.3 and 40 ms), 1.5 periods at 60 Hz
/// (late), and multiples up to 2.5 s. Fixed, so that the series stay the same across shows.
inline constexpr std::array<double, 14> kFrameIntervalBuckets{0.005, 0.01,   0.0175, 0.021, 0.025, 0.035, 0.042,
                                                              0.05,  0.0675, 0.1,    0.25,  0.5,   1.0,   2.5};
/// \brief A count per bucket of kFrameIntervalBuckets.
using IntervalBuckets = std::array<std::uint64_t, kFrameIntervalBuckets.size()>;

/// \brief A tracked viewer's figures (`[viewer] tracker`), published every frame it moves.
struct TrackerFigures {
  std::string tracker;        ///< the device's name in the manifest
  std::uint64_t samples = 0;  ///< samples applied
  std::uint64_t dropped = 0;  ///< samples dropped before the frame loop took them
  /// Sample time to the frame that first draws with it (show clock): the newest sample a frame
  /// uses, against the frame's time. Zero until a sample arrives.
  Nanos lastLatency{0};
  Nanos maxLatency{0};
  double latencySum = 0;     ///< seconds, over `frames`
  std::uint64_t frames = 0;  ///< frames that took new samples
};

/// \brief Figures derived from the recent frames, and totals since the start.
struct FrameFigures {
  std::int64_t frames = 0;
  std::int64_t lateFrames = 0;      ///< a present more than 1.5 frame periods after the previous
  std::int64_t missedAtReload = 0;  ///< late frames in the three frames after a reload swap
  std::uint64_t inputDropped = 0;   ///< input events lost to a full queue
  /// Display refreshes that got no new frame: a present that came k frame periods after the
  /// previous one dropped k - 1 frames (the screen showed the old picture meanwhile).
  std::int64_t droppedFrames = 0;
  double framesPerSecond = 0;                                                 ///< over the recent window
  double intervalP50 = 0, intervalP90 = 0, intervalP99 = 0, intervalMax = 0;  ///< seconds, present to present
  double workP50 = 0, workP90 = 0, workP99 = 0, workMax = 0;  ///< seconds of the loop's own work per frame
  double workMean = 0;                                        ///< seconds, over the window
  double cpuMean = 0;          ///< seconds of the loop thread's CPU time per frame, over the window
  double longestAtReload = 0;  ///< seconds: the longest present-to-present in the frames after a reload
  std::size_t window = 0;      ///< frames the percentiles are over
  // Since the start (never decreasing, as Prometheus' counters, histograms and summaries are):
  /// Present-to-present intervals at or under each of kFrameIntervalBuckets (cumulative, as a
  /// histogram's `le` buckets are); the first frame's start-up is not an interval.
  IntervalBuckets intervalBuckets{};
  std::uint64_t intervalCount = 0;  ///< intervals in all
  double intervalSum = 0;           ///< seconds
  std::uint64_t workCount = 0;      ///< frames measured
  double workSum = 0;               ///< seconds of the loop's own work
  double cpuSum = 0;                ///< seconds of the loop thread's CPU time
};

/// \brief How the status server itself is set up, for the page (what to show, what to hide).
struct ServerFacts {
  bool controls = false;   ///< POST /control/... is on (a token is configured and readable)
  bool snapshot = true;    ///< GET /snapshot.png serves the frame on screen
  bool readToken = false;  ///< GETs from other machines need the read token
};

/// \brief What the OSC input (kiosk/osc) counted since the start: messages by outcome, and the
/// output's messages. None of the refused ones changed the show.
struct OscFigures {
  std::string listen;               ///< "udp+tcp 127.0.0.1:9000", "" when not listening
  std::uint64_t received = 0;       ///< messages taken apart (a bundle's count each)
  std::uint64_t acted = 0;          ///< handed to the frame loop as a control
  std::uint64_t unmatched = 0;      ///< `unmatched`: no binding's address
  std::uint64_t wrongTypes = 0;     ///< `wrong_types`: arguments not of the binding's types, or not finite
  std::uint64_t badArgument = 0;    ///< `bad_argument`: a string a command cannot take, a command too long
  std::uint64_t refusedSender = 0;  ///< `refused_sender`: a sender not in osc.allow
  std::uint64_t rateLimited = 0;    ///< `rate_limited`: over osc.messages_per_second
  std::uint64_t queueFull = 0;      ///< `queue_full`: the controls' queue was full
  std::uint64_t malformed = 0;      ///< `malformed`: packets liblo could not take apart
  std::uint64_t sent = 0;           ///< messages sent to [[osc.send]] destinations
  std::uint64_t sendFailed = 0;     ///< messages that could not be sent
  [[nodiscard]] std::uint64_t refused() const {
    return unmatched + wrongTypes + badArgument + refusedSender + rateLimited + queueFull + malformed;
  }
};

/// \brief Everything the server reports, copied at one moment.
struct StatusSnapshot {
  WallTime now{};
  WallTime startedAt{};
  ShowStatus show;
  FrameFigures frames;
  std::vector<DeviceStatus> devices;
  std::vector<StreamStatus> streams;
  std::int64_t reloads = 0;
  std::int64_t reloadFailures = 0;
  std::string lastReload;  ///< the last reload's outcome
  /// Why the node is degraded whatever its devices say: the show's errors at start (it plays its
  /// last good copy or the problem card) and a reload that failed. Empty when none.
  std::vector<std::string> problems;
  std::vector<log::Record> logTail;     ///< recent records, oldest first
  std::vector<log::Record> lastErrors;  ///< recent warnings and errors
  std::uint64_t errorsLogged = 0;
  runtime::PerformanceMeter performance;  ///< LAVA's meter, as last sampled (updates == 0: not yet)
  std::optional<FrameLockFigures> lock;   ///< a frame-locked node's figures ([lock]); none otherwise
  std::optional<OscFigures> osc;          ///< the OSC input's and output's counts ([osc]); none otherwise
  std::optional<TrackerFigures> tracker;  ///< a tracked viewer's figures; none without one
  // Filled by the status server when it reports, not by the board:
  std::optional<ProcessFigures> process;  ///< the process's own figures
  std::optional<ServerFacts> server;      ///< the server's set-up (/health)
  std::optional<MachineFacts> machine;    ///< the machine's facts (/health)
};

/// \brief A request from the control server to the frame loop, answered through `reply`.
/// kAction moves the show as a dial would (`action` by `amount`, runtime::applyAction), kResetView
/// puts its transforms back; both come from OSC (kiosk/osc). kSetup: one of the thesis' set-up
/// toggles (Appendix B) by name, for kiosks without a keyboard.
enum class ControlKind : std::uint8_t {
  kNext,
  kPrevious,
  kReload,
  kRunCommand,
  kRestartDevice,
  kCalibrate,
  kAction,
  kResetView,
  kSetup
};

struct ControlReply {
  std::mutex mutex;
  std::condition_variable done;
  bool answered = false;  // guarded by mutex
  int status = 0;         // HTTP-like: 200, 202, 400, 404, 409, 501; guarded by mutex
  std::string message;    // guarded by mutex
  /// \brief Sets the answer and wakes the waiter (the frame loop calls this).
  void answer(int httpStatus, std::string text);
  /// \brief Waits up to `timeout` for the answer; false on time-out.
  bool wait(std::chrono::milliseconds timeout);
};

struct ControlRequest {
  ControlKind kind = ControlKind::kNext;
  std::string argument;  ///< the command, the device's name, calibration statements or a set-up toggle
  std::string view;      ///< kCalibrate: the facet view ("" = the first)
  bool save = false;     ///< kCalibrate: write the calibration back to the cave file
  runtime::Action action = runtime::Action::kNone;  ///< kAction
  float amount = 0;                                 ///< kAction: in the action's units (runtime::applyAction)
  std::shared_ptr<ControlReply> reply;
};

/// \brief A request for the frame on screen, filled by the frame loop after it draws.
struct SnapshotRequest {
  std::mutex mutex;
  std::condition_variable done;
  bool answered = false;  // guarded by mutex
  bool ok = false;        // guarded by mutex
  Image image;            // guarded by mutex
  std::string error;      // guarded by mutex
  void answer(bool success, Image picture, std::string why);
  bool wait(std::chrono::milliseconds timeout);
};

/// \brief A frame that takes this long is reported as the frame loop being stuck (a 60 Hz frame
/// takes 17 ms; loading and reloading run off the loop's thread).
inline constexpr std::chrono::seconds kStuckFrameAfter{3};

/// \brief The meeting point of the frame loop and the status server.
///
/// Threading: record*/publish*/set* come from the frame loop's thread; snapshot() and the
/// queues from any thread. `mutex_` guards the published state; the frame figures are plain
/// fixed-size arrays written under it, so publishing a frame never allocates.
class StatusBoard {
 public:
  /// \brief `logCapacity` records are kept for the log tail.
  StatusBoard(WallTime startedAt, double nominalFps, std::size_t logCapacity = 200);
  ~StatusBoard();
  StatusBoard(const StatusBoard&) = delete;
  StatusBoard& operator=(const StatusBoard&) = delete;

  // ---- frame loop ----
  /// \brief One frame (numbered as the frame loop numbers them, for reload accounting): seconds
  /// of work, seconds since the previous present.
  void recordFrame(std::int64_t frame, double workSeconds, double intervalSeconds, double cpuSeconds = 0,
                   std::uint64_t inputDropped = 0);
  void setNominalFps(double fps);
  /// \brief The frame in which a reloaded show took over.
  void noteReloadApplied(std::int64_t frame);
  /// \brief A failed reload makes the node degraded until a reload succeeds; a successful
  /// reload also clears the problems set by setProblems().
  void noteReload(bool ok, std::string outcome);
  /// \brief What is wrong with the show as it started (its errors, what plays instead).
  void setProblems(std::vector<std::string> problems);
  /// \brief What is wrong with the display's views (DisplayViews::problems(): a view that draws
  /// nothing), published when it changes; a reload leaves them (the views outlive the show).
  void setViewProblems(std::vector<std::string> problems);
  void publishShow(ShowStatus status);
  void publishDevices(std::vector<DeviceStatus> devices);
  void publishStreams(std::vector<StreamStatus> streams);
  /// \brief LAVA's performance meter (Show::performance()), after it took a new sample.
  void publishPerformance(const runtime::PerformanceMeter& meter);
  /// \brief A frame-locked node's figures (kiosk/lock/frame_lock.h).
  void publishLock(const FrameLockFigures& figures);
  /// \brief A tracked viewer's figures (kiosk/show/head_follower.h); null clears them.
  void publishTracker(const TrackerFigures* figures);

  // ---- any thread ----
  /// \brief The OSC input's counts (its thread publishes them when they change); the sent
  /// counts are the output's (publishOscSent), kept as they are.
  void publishOsc(const OscFigures& figures);
  /// \brief The OSC output's counts (its thread publishes them).
  void publishOscSent(std::uint64_t sent, std::uint64_t failed);
  [[nodiscard]] StatusSnapshot snapshot(WallTime now) const;
  /// \brief Copies of parts of snapshot(), for readers that poll often (the OSC output).
  [[nodiscard]] ShowStatus showStatus() const;
  [[nodiscard]] std::vector<DeviceStatus> deviceStatus() const;
  [[nodiscard]] std::optional<FrameLockFigures> lockFigures() const;
  [[nodiscard]] std::optional<OscFigures> oscFigures() const;
  [[nodiscard]] FrameFigures frameFigures() const;
  BoundedQueue<ControlRequest>& controls() { return controls_; }
  BoundedQueue<std::shared_ptr<SnapshotRequest>>& snapshotRequests() { return snapshots_; }
  /// \brief The show's Clock, whose calendar time the schedule is read in (any thread reads it).
  void setShowClock(const Clock& clock) { showClock_ = &clock; }
  /// \brief The frame loop's progress (borrowed, set before the server starts): a frame busy
  /// for kStuckFrameAfter or longer makes snapshot() report a problem, so `/health` is
  /// "degraded" while the loop is stuck.
  void setFrameWatch(const FrameWatch& watch) { frameWatch_ = &watch; }
  /// \brief A folder whose file system's free space the page shows ("state"); set before the
  /// server starts. The show's own folder is added by the server.
  void watchFolder(std::string name, std::filesystem::path path) {
    folders_.push_back({std::move(name), std::move(path)});
  }
  [[nodiscard]] const std::vector<FolderToWatch>& watchedFolders() const { return folders_; }
  /// \brief Every record the log ring holds (the last `logCapacity`), oldest first.
  [[nodiscard]] std::vector<log::Record> logRecords() const;
  /// \brief Set by the run to wake the frame loop when a request arrives.
  void setWake(std::function<void()> wake);
  void wake() const;

 private:
  class CountingSink;
  static constexpr std::size_t kWindow = 600;  // frames the percentiles are computed over

  mutable std::mutex mutex_;
  WallTime startedAt_;
  double nominalFps_;                       // guarded by mutex_
  std::array<float, kWindow> intervals_{};  // seconds; guarded by mutex_
  std::array<float, kWindow> work_{};       // seconds; guarded by mutex_
  std::array<float, kWindow> cpu_{};        // seconds; guarded by mutex_
  std::size_t next_ = 0;                    // guarded by mutex_
  std::size_t filled_ = 0;                  // guarded by mutex_
  std::int64_t frames_ = 0;                 // guarded by mutex_
  std::int64_t late_ = 0;                   // guarded by mutex_
  std::int64_t reloadFrame_ = -100;         // guarded by mutex_
  std::int64_t missedAtReload_ = 0;         // guarded by mutex_
  double longestAtReload_ = 0;              // guarded by mutex_
  std::uint64_t inputDropped_ = 0;          // guarded by mutex_
  std::int64_t droppedFrames_ = 0;          // guarded by mutex_
  IntervalBuckets intervalBuckets_{};       // per bucket; guarded by mutex_
  std::uint64_t intervalCount_ = 0;         // guarded by mutex_
  double intervalSum_ = 0;                  // guarded by mutex_
  std::uint64_t workCount_ = 0;             // guarded by mutex_
  double workSum_ = 0;                      // guarded by mutex_
  double cpuSum_ = 0;                       // guarded by mutex_
  runtime::PerformanceMeter performance_;   // guarded by mutex_
  std::optional<FrameLockFigures> lock_;    // guarded by mutex_
  std::optional<OscFigures> osc_;           // guarded by mutex_
  std::optional<TrackerFigures> tracker_;   // guarded by mutex_
  ShowStatus show_;                         // guarded by mutex_
  std::vector<DeviceStatus> devices_;       // guarded by mutex_
  std::vector<StreamStatus> streams_;       // guarded by mutex_
  std::int64_t reloads_ = 0;                // guarded by mutex_
  std::int64_t reloadFailures_ = 0;         // guarded by mutex_
  std::string lastReload_;                  // guarded by mutex_
  std::vector<std::string> problems_;       // guarded by mutex_
  std::string reloadProblem_;               // guarded by mutex_
  std::vector<std::string> viewProblems_;   // guarded by mutex_
  std::function<void()> wake_;              // set before the server starts
  const Clock* showClock_ = nullptr;        // set before the server starts
  const FrameWatch* frameWatch_ = nullptr;  // set before the server starts
  std::vector<FolderToWatch> folders_;      // set before the server starts
  std::shared_ptr<log::RingSink> ring_;
  std::shared_ptr<CountingSink> counter_;
  BoundedQueue<ControlRequest> controls_{16};
  BoundedQueue<std::shared_ptr<SnapshotRequest>> snapshots_{4};
};

}  // namespace basalt::kiosk
