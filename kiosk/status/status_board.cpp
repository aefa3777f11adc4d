#include "kiosk/status/status_board.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include <fmt/format.h>

namespace basalt::kiosk {

void ControlReply::answer(int httpStatus, std::string text) {
  {
    std::lock_guard lock(mutex);
    answered = true;
    status = httpStatus;
    message = std::move(text);
  }
  done.notify_all();
}

bool ControlReply::wait(std::chrono::milliseconds timeout) {
  std::unique_lock lock(mutex);
  return done.wait_for(lock, timeout, [this] { return answered; });
}

void SnapshotRequest::answer(bool success, Image picture, std::string why) {
  {
    std::lock_guard lock(mutex);
    answered = true;
    ok = success;
    image = std::move(picture);
    error = std::move(why);
  }
  done.notify_all();
}

bool SnapshotRequest::wait(std::chrono::milliseconds timeout) {
  std::unique_lock lock(mutex);
  return done.wait_for(lock, timeout, [this] { return answered; });
}

/// Counts warnings and errors for the metrics.
class StatusBoard::CountingSink final : public log::Sink {
 public:
  void write(const log::Record& record) override {
    if (record.level >= log::Level::kError) errors_.fetch_add(1, std::memory_order_relaxed);
  }
  [[nodiscard]] std::uint64_t errors() const { return errors_.load(std::memory_order_relaxed); }

 private:
  std::atomic<std::uint64_t> errors_{0};
};

StatusBoard::StatusBoard(WallTime startedAt, double nominalFps, std::size_t logCapacity)
    : startedAt_(startedAt),
      nominalFps_(nominalFps),
      ring_(std::make_shared<log::RingSink>(logCapacity)),
      counter_(std::make_shared<CountingSink>()) {
  log::addSink(ring_);
  log::addSink(counter_);
}

StatusBoard::~StatusBoard() {
  log::removeSink(ring_);
  log::removeSink(counter_);
}

void StatusBoard::recordFrame(std::int64_t frame, double workSeconds, double intervalSeconds, double cpuSeconds,
                              std::uint64_t inputDropped) {
  std::lock_guard lock(mutex_);
  inputDropped_ = inputDropped;
  work_[next_] = static_cast<float>(workSeconds);
  cpu_[next_] = static_cast<float>(cpuSeconds);
  intervals_[next_] = static_cast<float>(intervalSeconds);
  next_ = (next_ + 1) % kWindow;
  filled_ = std::min(filled_ + 1, kWindow);
  ++frames_;
  ++workCount_;
  workSum_ += workSeconds;
  cpuSum_ += cpuSeconds;
  if (frames_ > 1) {  // the first frame's "interval" is its start-up
    const auto bucket = std::find_if(kFrameIntervalBuckets.begin(), kFrameIntervalBuckets.end(),
                                     [intervalSeconds](double bound) { return intervalSeconds <= bound; });
    if (bucket != kFrameIntervalBuckets.end())
      ++intervalBuckets_[static_cast<std::size_t>(bucket - kFrameIntervalBuckets.begin())];
    ++intervalCount_;
    intervalSum_ += intervalSeconds;
  }
  const bool late = frames_ > 1 && intervalSeconds > 1.5 / nominalFps_;
  const bool atReload = frame >= reloadFrame_ && frame <= reloadFrame_ + 2;
  if (atReload) longestAtReload_ = std::max(longestAtReload_, intervalSeconds);
  if (late) {
    ++late_;
    droppedFrames_ += std::max<std::int64_t>(std::llround(intervalSeconds * nominalFps_) - 1, 1);
    if (atReload) ++missedAtReload_;
  }
}

void StatusBoard::publishPerformance(const runtime::PerformanceMeter& meter) {
  std::lock_guard lock(mutex_);
  performance_ = meter;
}

void StatusBoard::publishOsc(const OscFigures& figures) {
  std::lock_guard lock(mutex_);
  const std::uint64_t sent = osc_ ? osc_->sent : 0;
  const std::uint64_t failed = osc_ ? osc_->sendFailed : 0;
  osc_ = figures;
  osc_->sent = sent;
  osc_->sendFailed = failed;
}

void StatusBoard::publishOscSent(std::uint64_t sent, std::uint64_t failed) {
  std::lock_guard lock(mutex_);
  if (!osc_) osc_.emplace();
  osc_->sent = sent;
  osc_->sendFailed = failed;
}

ShowStatus StatusBoard::showStatus() const {
  std::lock_guard lock(mutex_);
  return show_;
}

std::vector<DeviceStatus> StatusBoard::deviceStatus() const {
  std::lock_guard lock(mutex_);
  return devices_;
}

std::optional<OscFigures> StatusBoard::oscFigures() const {
  std::lock_guard lock(mutex_);
  return osc_;
}

std::optional<FrameLockFigures> StatusBoard::lockFigures() const {
  std::lock_guard lock(mutex_);
  return lock_;
}

void StatusBoard::publishLock(const FrameLockFigures& figures) {
  std::lock_guard lock(mutex_);
  lock_ = figures;
}

void StatusBoard::publishTracker(const TrackerFigures* figures) {
  std::lock_guard lock(mutex_);
  if (!figures) {
    tracker_.reset();
  } else if (tracker_) {
    // Field by field into the one kept: the name's storage is reused, so a frame allocates nothing.
    tracker_->tracker.assign(figures->tracker);
    tracker_->samples = figures->samples;
    tracker_->dropped = figures->dropped;
    tracker_->lastLatency = figures->lastLatency;
    tracker_->maxLatency = figures->maxLatency;
    tracker_->latencySum = figures->latencySum;
    tracker_->frames = figures->frames;
  } else {
    tracker_ = *figures;
  }
}

void StatusBoard::setNominalFps(double fps) {
  std::lock_guard lock(mutex_);
  nominalFps_ = fps;
}

void StatusBoard::noteReloadApplied(std::int64_t frame) {
  std::lock_guard lock(mutex_);
  reloadFrame_ = frame;
}

void StatusBoard::noteReload(bool ok, std::string outcome) {
  std::lock_guard lock(mutex_);
  ++reloads_;
  if (!ok) ++reloadFailures_;
  if (ok) {
    problems_.clear();
    reloadProblem_.clear();
  } else {
    reloadProblem_ = "reload " + outcome + "; the previous show plays on";
  }
  lastReload_ = std::move(outcome);
}

void StatusBoard::setProblems(std::vector<std::string> problems) {
  std::lock_guard lock(mutex_);
  problems_ = std::move(problems);
}

void StatusBoard::setViewProblems(std::vector<std::string> problems) {
  std::lock_guard lock(mutex_);
  viewProblems_ = std::move(problems);
}

void StatusBoard::publishShow(ShowStatus status) {
  std::lock_guard lock(mutex_);
  show_ = std::move(status);
}

void StatusBoard::publishDevices(std::vector<DeviceStatus> devices) {
  std::lock_guard lock(mutex_);
  devices_ = std::move(devices);
}

void StatusBoard::publishStreams(std::vector<StreamStatus> streams) {
  std::lock_guard lock(mutex_);
  streams_ = std::move(streams);
}

void StatusBoard::setWake(std::function<void()> wake) { wake_ = std::move(wake); }

void StatusBoard::wake() const {
  if (wake_) wake_();
}

namespace {

void percentiles(std::vector<float>& values, double& p50, double& p90, double& p99, double& max) {
  if (values.empty()) return;
  std::sort(values.begin(), values.end());
  const auto at = [&](double q) {
    const auto i = static_cast<std::size_t>(std::lround(q * static_cast<double>(values.size() - 1)));
    return static_cast<double>(values[std::min(i, values.size() - 1)]);
  };
  p50 = at(0.50);
  p90 = at(0.90);
  p99 = at(0.99);
  max = static_cast<double>(values.back());
}

}  // namespace

FrameFigures StatusBoard::frameFigures() const {
  std::vector<float> intervals;
  std::vector<float> work;
  double cpuSum = 0;
  FrameFigures f;
  {
    std::lock_guard lock(mutex_);
    f.frames = frames_;
    f.lateFrames = late_;
    f.missedAtReload = missedAtReload_;
    f.longestAtReload = longestAtReload_;
    f.inputDropped = inputDropped_;
    f.droppedFrames = droppedFrames_;
    f.window = filled_;
    std::uint64_t atOrUnder = 0;
    for (std::size_t i = 0; i < intervalBuckets_.size(); ++i) {
      atOrUnder += intervalBuckets_[i];
      f.intervalBuckets[i] = atOrUnder;
    }
    f.intervalCount = intervalCount_;
    f.intervalSum = intervalSum_;
    f.workCount = workCount_;
    f.workSum = workSum_;
    f.cpuSum = cpuSum_;
    intervals.assign(intervals_.begin(), intervals_.begin() + static_cast<std::ptrdiff_t>(filled_));
    work.assign(work_.begin(), work_.begin() + static_cast<std::ptrdiff_t>(filled_));
    for (std::size_t i = 0; i < filled_; ++i) cpuSum += static_cast<double>(cpu_[i]);
  }
  f.cpuMean = filled_ > 0 ? cpuSum / static_cast<double>(filled_) : 0;
  // The first frame's interval is its start-up time: not a frame interval.
  if (f.frames <= static_cast<std::int64_t>(kWindow) && !intervals.empty()) intervals.erase(intervals.begin());
  double sum = 0;
  for (const float v : intervals) sum += static_cast<double>(v);
  f.framesPerSecond = sum > 0 ? static_cast<double>(intervals.size()) / sum : 0;
  percentiles(intervals, f.intervalP50, f.intervalP90, f.intervalP99, f.intervalMax);
  double workSum = 0;
  for (const float v : work) workSum += static_cast<double>(v);
  f.workMean = work.empty() ? 0 : workSum / static_cast<double>(work.size());
  percentiles(work, f.workP50, f.workP90, f.workP99, f.workMax);
  return f;
}

std::vector<log::Record> StatusBoard::logRecords() const { return ring_->snapshot(); }

StatusSnapshot StatusBoard::snapshot(WallTime now) const {
  StatusSnapshot s;
  s.now = now;
  s.startedAt = startedAt_;
  s.frames = frameFigures();
  {
    std::lock_guard lock(mutex_);
    s.show = show_;
    s.devices = devices_;
    s.streams = streams_;
    s.reloads = reloads_;
    s.reloadFailures = reloadFailures_;
    s.lastReload = lastReload_;
    s.problems = problems_;
    if (!reloadProblem_.empty()) s.problems.push_back(reloadProblem_);
    s.problems.insert(s.problems.end(), viewProblems_.begin(), viewProblems_.end());
    if (const auto busy = frameWatch_ ? frameWatch_->busy() : std::nullopt) {
      const Nanos running = SystemClock().now() - busy->since;
      if (running >= kStuckFrameAfter) {
        s.problems.push_back(fmt::format(
            "the frame loop has been stuck in frame {} for {:.0f} s: something it called does not return; the "
            "service manager's watchdog restarts Basalt if it stays stuck",
            busy->frame, toSeconds(running)));
      }
    }
    s.performance = performance_;
    s.lock = lock_;
    s.osc = osc_;
    s.tracker = tracker_;
  }
  if (s.show.schedule)
    s.show.nextScheduleChange = s.show.schedule->nextChange(showClock_ ? showClock_->wallNow() : now);
  s.logTail = ring_->snapshot(log::Level::kInfo);
  s.lastErrors = ring_->snapshot(log::Level::kWarn);
  if (s.lastErrors.size() > 20) s.lastErrors.erase(s.lastErrors.begin(), s.lastErrors.end() - 20);
  s.errorsLogged = counter_->errors();
  return s;
}

}  // namespace basalt::kiosk
