#pragma once

/// \file
/// \brief The frame loop (DESIGN.md §2): one thread owns EGL and GL; each frame takes its time
/// from the Clock, applies the input due by then, draws every view and presents.

#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "kiosk/loop/frame_watch.h"
#include "render/output.h"
#include "render/renderer.h"
#include "runtime/bounded_queue.h"
#include "runtime/clock.h"
#include "runtime/event.h"
#include "runtime/event_loop.h"
#include "runtime/show/show.h"

namespace basalt::kiosk {

class ViewDrawer;  // kiosk/loop/display_views.h

/// \brief Takes every event due by `until` into `batch` (emptied first), in the order of their
/// times: the devices' threads push in the order they run, not in the order of their events, so
/// one device's event that is not due yet must not hold back another's that is. Those not due
/// wait in `later` (the caller keeps it from frame to frame) and come first when they are.
/// Allocates only when a vector must grow. The one way input leaves a run's queue: the show
/// director applies what it returns.
void takeDueInput(BoundedQueue<Event>& events, Nanos until, std::vector<Event>& batch, std::vector<Event>& later);

/// \brief What a participant learns about the frame being made.
struct FrameContext {
  std::int64_t frame = 0;  ///< frame number, from 0
  Nanos time{0};           ///< the frame's presentation time on the show's Clock
  bool last = false;       ///< the loop will stop after this frame
};

/// \brief Something that takes part in every frame: the script interpreter, the device manager,
/// texture streams, the kiosk controller, the recorder, the status server's metrics.
///
/// The loop calls participants in the order they were added, on the frame loop's thread. They
/// must not block: anything slow runs on its own thread and hands results over through queues.
class FrameParticipant {
 public:
  virtual ~FrameParticipant() = default;
  /// \brief Step 2-4 of the frame (after input): change the show, pick stream frames.
  /// Returning an error stops the run with that error.
  virtual Result<void> beforeDraw(const FrameContext& frame) {
    (void)frame;
    return {};
  }
  /// \brief Between computing the view and drawing: may change how this frame is seen (a
  /// script's sub-pixel jitter). `size` is the output's size in pixels.
  virtual void adjustView(const FrameContext& frame, runtime::ViewTransforms& view, render::Size size) {
    (void)frame;
    (void)view;
    (void)size;
  }
  /// \brief After drawing, before presenting: read-back users (snapshots, recording, tests).
  virtual Result<void> afterDraw(const FrameContext& frame, render::Output& output) {
    (void)frame;
    (void)output;
    return {};
  }
  /// \brief After presenting and after the show advanced: metrics, watchdog pings.
  virtual void afterPresent(const FrameContext& frame) { (void)frame; }
  /// \brief Called about every 100 ms while the loop has no frame to draw and the output holds
  /// its last picture (a frame-locked follower waiting for its leader): nothing is presented, but
  /// the service manager's watchdog must still hear that the loop is alive.
  virtual void whileHolding() {}
  /// \brief True when this participant wants the loop to end after the current frame (a
  /// script's `quit`, the end of a recording). Asked before each frame and again after the
  /// participants' afterDraw(), so that a frame can become the last one while it is made.
  [[nodiscard]] virtual bool wantsStop() const { return false; }
};

/// \brief A frame a follower's gate hands the loop: the leader's number and show time.
struct GatedFrame {
  std::int64_t frame = 0;
  Nanos time{0};
  bool end = false;  ///< the group ends: draw nothing more
};

/// \brief Where a frame-locked follower's frames come from (kiosk/lock/frame_lock.h): with a gate, the
/// loop draws the frames it hands over, numbered and timed as the leader's, instead of pacing
/// itself on the clock.
class FrameGate {
 public:
  virtual ~FrameGate() = default;
  /// \brief Waits at most `patience`, serving `loop`, for the next frame to draw; nothing when
  /// none came (the loop asks again and the output keeps its last picture).
  virtual Result<std::optional<GatedFrame>> nextFrame(runtime::EventLoop& loop, Nanos patience) = 0;
};

struct FrameLoopConfig {
  double fps = 60;
  std::int64_t maxFrames = -1;  ///< stop after this many frames; -1 runs until stopped
};

/// \brief What a run did, for the summary line and the status server.
struct FrameLoopStats {
  std::int64_t frames = 0;
  std::int64_t lateFrames = 0;   ///< frames that started after their due time (paced runs)
  Nanos showTime{0};             ///< Clock time from the first frame to the last
  double wallSeconds = 0;        ///< real time the loop ran
  double firstFrameSeconds = 0;  ///< real time from loop start to the first frame presented
};

/// \brief Runs frames until the frame budget is spent or stop is requested.
///
/// Threading: everything runs on the calling thread. Devices feed the run's event queue from
/// their threads and wake `loop`; the show director drains it (takeDueInput) in its beforeDraw;
/// the loop never waits on a device.
class FrameLoop {
 public:
  /// \brief Called after a frame is drawn and before it is presented: snapshots, recording,
  /// tests. `last` is true for the final frame of the run.
  using FrameHook = std::function<Result<void>(std::int64_t frame, bool last, render::Output& output)>;

  /// With a manual clock (`manual` non-null) each frame advances it by exactly 1/fps and the
  /// loop never sleeps; otherwise frames are paced on `clock`.
  FrameLoop(const FrameLoopConfig& config, const Clock& clock, ManualClock* manual, runtime::EventLoop& loop,
            runtime::Show& show, render::Output& output, render::Renderer& renderer);

  void setFrameHook(FrameHook hook) { hook_ = std::move(hook); }
  /// \brief Adds a participant (borrowed: it must outlive the loop's run()).
  void addParticipant(FrameParticipant& participant) { participants_.push_back(&participant); }
  /// \brief Draws the frame's views instead of the one plain view (a manifest's `[[views]]`:
  /// facets, eyes, tiles); borrowed, null for the plain view.
  void setViewDrawer(ViewDrawer* drawer) { viewDrawer_ = drawer; }
  /// \brief Takes frame numbers and times from `gate` (a frame-locked follower); borrowed, null
  /// to pace on the clock. `maxFrames` then counts the frames drawn.
  void setGate(FrameGate* gate) { gate_ = gate; }

  /// \brief Runs until done; the error is the first failure of drawing, presenting or a hook.
  Result<FrameLoopStats> run();
  /// \brief Asks the loop to finish the next frame and return (safe from loop callbacks).
  void requestStop() { stopRequested_ = true; }
  /// \brief The frame in progress, for watchers on other threads (the status board).
  [[nodiscard]] const FrameWatch& watch() const { return watch_; }

 private:
  /// Waits, serving the event loop, until the output can take the next frame (paced outputs).
  Result<void> waitForOutput();
  /// Draws one frame; `context.last` becomes true when a participant asks to stop during it.
  Result<void> renderFrame(FrameContext& context);
  [[nodiscard]] bool participantWantsStop() const;

  FrameLoopConfig config_;
  const Clock& clock_;
  ManualClock* manual_;
  runtime::EventLoop& loop_;
  runtime::Show& show_;
  render::Output& output_;
  render::Renderer& renderer_;
  FrameHook hook_;
  std::vector<FrameParticipant*> participants_;
  ViewDrawer* viewDrawer_ = nullptr;
  FrameGate* gate_ = nullptr;
  bool stopRequested_ = false;
  FrameWatch watch_;
};

}  // namespace basalt::kiosk
