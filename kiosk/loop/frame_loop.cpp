#include "kiosk/loop/frame_loop.h"

#include <chrono>
#include <functional>
#include <optional>

#include <fmt/format.h>

#include "kiosk/loop/display_views.h"
#include "runtime/log.h"

namespace basalt::kiosk {

BASALT_LOG_CATEGORY(Kiosk, "kiosk");

FrameLoop::FrameLoop(const FrameLoopConfig& config, const Clock& clock, ManualClock* manual, runtime::EventLoop& loop,
                     runtime::Show& show, render::Output& output, render::Renderer& renderer)
    : config_(config), clock_(clock), manual_(manual), loop_(loop), show_(show), output_(output), renderer_(renderer) {}

void takeDueInput(BoundedQueue<Event>& events, Nanos until, std::vector<Event>& batch, std::vector<Event>& later) {
  batch.clear();
  std::size_t kept = 0;
  for (const Event& e : later) {
    if (e.time <= until) {
      batch.push_back(e);
    } else {
      later[kept++] = e;
    }
  }
  later.resize(kept);
  events.drainWhile([](const Event&) { return true; },
                    [&](Event e) {
                      if (e.time <= until) {
                        batch.push_back(e);
                      } else {
                        later.push_back(e);
                      }
                    });
  // Insertion sort: stable (one device's events keep their order when they share a time), no
  // allocation, and about one pass for a batch that is nearly in order already.
  for (std::size_t i = 1; i < batch.size(); ++i) {
    const Event e = batch[i];
    std::size_t j = i;
    for (; j > 0 && batch[j - 1].time > e.time; --j) batch[j] = batch[j - 1];
    batch[j] = e;
  }
}

Result<void> FrameLoop::renderFrame(FrameContext& context) {
  for (FrameParticipant* p : participants_) {
    if (auto r = p->beforeDraw(context); !r) return r;
  }
  if (auto r = output_.beginFrame(); !r) return r;
  const render::Size size = output_.size();
  // The view adjustment reaches the renderer as a std::function: its lambda captures one pointer,
  // which std::function keeps in place (a larger capture would allocate on every frame).
  struct Adjustment {
    FrameLoop* loop;
    FrameContext* context;
    render::Size size;
  } adjustment{this, &context, size};
  const std::function<void(runtime::ViewTransforms&)> adjust = [a = &adjustment](runtime::ViewTransforms& view) {
    for (FrameParticipant* p : a->loop->participants_) p->adjustView(*a->context, view, a->size);
  };
  if (viewDrawer_) {
    viewDrawer_->drawViews(show_, size, adjust);
  } else {
    renderer_.drawShow(show_, {0, 0, size.width, size.height}, adjust);
  }
  for (FrameParticipant* p : participants_) {
    if (auto r = p->afterDraw(context, output_); !r) return r;
  }
  if (!context.last && participantWantsStop()) context.last = true;
  if (hook_) {
    if (auto r = hook_(context.frame, context.last, output_); !r) return r;
  }
  return output_.present();
}

bool FrameLoop::participantWantsStop() const {
  for (const FrameParticipant* p : participants_) {
    if (p->wantsStop()) return true;
  }
  return false;
}

Result<void> FrameLoop::waitForOutput() {
  // A KMS output is not ready while its last page flip is pending; the flip's event arrives on
  // paceFd(), which the event loop watches. A flip that never completes is a driver fault: say
  // so rather than hang (the watchdog would restart us, without a message).
  const SystemClock wall;
  const Nanos giveUp = wall.now() + std::chrono::seconds(2);
  while (!output_.readyForFrame() && !stopRequested_) {
    if (wall.now() > giveUp) {
      return fail(Errc::kTimeout, fmt::format("the {} output did not finish presenting within 2 s", output_.kind()));
    }
    if (auto r = loop_.dispatch(std::chrono::milliseconds(100)); !r) return std::unexpected(r.error());
  }
  return {};
}

Result<FrameLoopStats> FrameLoop::run() {
  FrameLoopStats stats;
  const SystemClock wall;
  const Nanos wallStart = wall.now();
  const Nanos start = clock_.now();
  std::optional<runtime::EventLoop::Handle> pace;
  if (output_.paceFd() >= 0) {
    auto watched = loop_.watchFd(output_.paceFd(), EPOLLIN, [this](std::uint32_t) { output_.onPaceReady(); });
    if (!watched) return std::unexpected(watched.error());
    pace = *watched;
  }
  struct Unwatch {
    runtime::EventLoop& loop;
    std::optional<runtime::EventLoop::Handle>& handle;
    ~Unwatch() {
      if (handle) loop.unwatch(*handle);
    }
  } unwatch{loop_, pace};
  std::int64_t drawn = 0;
  for (std::int64_t frame = 0; config_.maxFrames < 0 || drawn < config_.maxFrames; ++frame) {
    if (auto r = waitForOutput(); !r) return std::unexpected(r.error());
    Nanos due = start + frameTime(frame, config_.fps);
    if (gate_) {
      // A follower: the leader says which frame comes next and when it is; none for a while
      // keeps the last picture on the output.
      std::optional<GatedFrame> next;
      while (!next && !stopRequested_) {
        auto got = gate_->nextFrame(loop_, std::chrono::milliseconds(100));
        if (!got) return std::unexpected(got.error());
        next = *got;
        if (!next) {
          for (FrameParticipant* p : participants_) p->whileHolding();
        }
      }
      if (!next || next->end) break;
      frame = next->frame;
      due = next->time;
      if (manual_) manual_->set(due);
    } else if (manual_) {
      manual_->set(due);
      // Signals and wake-ups still get through; the manual clock never waits.
      if (auto r = loop_.dispatch(Nanos{0}); !r) return std::unexpected(r.error());
    } else {
      // Sleep in the event loop until the frame is due, serving fds and signals meanwhile.
      while (!stopRequested_) {
        const Nanos now = clock_.now();
        if (now >= due) break;
        if (auto r = loop_.dispatch(due - now); !r) return std::unexpected(r.error());
      }
      if (clock_.now() - due > frameTime(1, config_.fps)) ++stats.lateFrames;
    }
    const bool last =
        stopRequested_ || participantWantsStop() || (config_.maxFrames >= 0 && drawn + 1 == config_.maxFrames);
    FrameContext context{frame, due, last};
    // From here to the participants' afterPresent the loop works for this frame: a watcher
    // that sees it busy too long knows the loop is stuck (waiting for the due time is not).
    watch_.frameBegan(frame, wall.now());
    if (auto r = renderFrame(context); !r) {
      watch_.frameEnded();
      return std::unexpected(r.error());
    }
    if (drawn == 0) stats.firstFrameSeconds = toSeconds(wall.now() - wallStart);
    ++drawn;
    stats.frames = drawn;
    stats.showTime = due - start;
    // LAVA's performance meter: this frame's counts, rates over real time.
    show_.performance().recordFrame(renderer_.takeFrameCounts(), wall.now());
    show_.advanceFrame();
    for (FrameParticipant* p : participants_) p->afterPresent(context);
    watch_.frameEnded();
    if (context.last) break;
  }
  stats.wallSeconds = toSeconds(wall.now() - wallStart);
  return stats;
}

}  // namespace basalt::kiosk
