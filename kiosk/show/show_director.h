#pragma once

/// \file
/// \brief The show director: the frame participant that runs a loaded show. Each frame it takes
/// a reloaded show over when one is ready, answers control requests, hears from its
/// devices::DeviceManager what became of the show's devices, applies the run's input (visitor
/// activity, dial bindings, button actions, a replayed trace), lets the kiosk policy decide what
/// plays and switches items, display power and textures accordingly, feeds the playing item its
/// frame, and saves where the show is.

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "devices/device_manager.h"
#include "devices/evdev/evdev_input.h"
#include "devices/udev/udev_monitor.h"
#include "kiosk/lock/frame_lock.h"
#include "kiosk/loop/frame_loop.h"
#include "kiosk/policy/kiosk_policy.h"
#include "kiosk/policy/state_store.h"
#include "kiosk/policy/supervisor.h"
#include "kiosk/show/head_follower.h"
#include "kiosk/show/show_loader.h"
#include "kiosk/status/status_board.h"
#include "render/output.h"
#include "render/renderer.h"
#include "runtime/bounded_queue.h"
#include "runtime/event.h"
#include "runtime/event_loop.h"
#include "runtime/navigation.h"
#include "runtime/setup_keys.h"
#include "runtime/show/show.h"

namespace basalt::kiosk {

/// \brief What the director works with; everything is borrowed and outlives it.
class DisplayViews;

struct DirectorContext {
  const Clock& clock;
  runtime::EventLoop& loop;
  runtime::Show& show;
  render::Renderer& renderer;
  render::Output& output;
  StatusBoard& board;
  BoundedQueue<Event>& events;
  Supervisor* supervisor = nullptr;  ///< null when not supervised
  StateStore* state = nullptr;       ///< null when resuming is off
  double fps = 60;
};

/// \brief Runs a show on the frame loop.
///
/// Threading: everything on the frame loop's thread, except the reload, which reads and loads
/// the manifest on a thread of its own and hands the result over through `reloadMutex_`.
class ShowDirector final : public FrameParticipant, public LockedDirector {
 public:
  /// \brief A director that reloads shows with `factories` (what the first show was loaded with)
  /// and runs control commands with its command runner.
  ShowDirector(DirectorContext context, ShowFactories factories);
  ~ShowDirector() override;
  ShowDirector(const ShowDirector&) = delete;
  ShowDirector& operator=(const ShowDirector&) = delete;

  /// \brief Installs the first show at `now`, resuming at `resume` when it still fits.
  void install(std::unique_ptr<LoadedShow> show, Nanos now, const std::optional<ResumePoint>& resume);
  /// \brief Says that a device came (udev): devices that are not live are tried again at once
  /// instead of after their back-off. Any thread.
  void noteHotplug();
  /// \brief The manager that runs the show's devices (its dial boxes and the cameras its
  /// textures show), for what else shows a device of the show (the scripts' VCR camera).
  [[nodiscard]] devices::DeviceManager& devices() { return *devices_; }
  /// \brief Devices a run adds beside its show's (`basalt run --replay`): they push into the
  /// same queue, and their events turn the show through `bindings` (borrowed: LAVA's table, the
  /// Zoom dials) without counting as a visitor. Their ids must not be the show's
  /// (DeviceWiring numbers them apart).
  void setReplayInput(runtime::Bindings* bindings, std::vector<DeviceId> devices);
  /// \brief Re-reads the manifest on a loader thread; the current show plays on until the new
  /// one is ready, and stays when the new one has errors.
  void requestReload();
  /// \brief The show's views, for the calibration control (null: no `[[views]]`). Borrowed:
  /// they must outlive the director's frames.
  void setViews(DisplayViews* views) { views_ = views; }
  /// \brief Keyboards and mice read from evdev (a KMS output has no window to deliver them):
  /// their events go where the window's go. Borrowed; null: none.
  void setKeyboardsAndMice(devices::EvdevInput* input) { keyboardsAndMice_ = input; }
  /// \brief Frame-locked nodes ([lock]): the show's movie streams play on a timeline that starts
  /// at a show time the leader gives (its show's start), so that every node shows the same video
  /// frame; a follower (`leader` false) waits up to `patience` for the frame due, and plays the
  /// leader's programme (followProgramme) instead of deciding its own.
  void setLocked(bool leader, std::chrono::milliseconds patience);

  [[nodiscard]] LockedProgramme lockedProgramme() const override;
  bool followProgramme(const LockedProgramme& programme, Nanos showTime) override;
  void leaderRestarted() override;
  [[nodiscard]] LockedMovieFrames lockedMovieFrames() const override;
  void followMovieFrames(const LockedMovieFrames& frames) override { leaderMovies_ = frames; }
  [[nodiscard]] LockedMovieCounts movieFrameCounts() const override { return movieCounts_; }
  [[nodiscard]] const LockCommandLog* commandLog() const override;
  [[nodiscard]] std::uint64_t showLoads() const override { return showGeneration_; }
  [[nodiscard]] bool loadingShow() const override { return loading_; }
  Result<std::string> runLeaderCommand(std::string_view command) override;

  Result<void> beforeDraw(const FrameContext& frame) override;
  Result<void> afterDraw(const FrameContext& frame, render::Output& output) override;
  void afterPresent(const FrameContext& frame) override;
  [[nodiscard]] bool wantsStop() const override { return context_.output.closeRequested() || exitRequested_; }
  /// \brief Applies one of the thesis' set-up toggles (Appendix B) to the playing show and the
  /// views, from a key or a control request; returns what it did (logged).
  std::string applySetup(runtime::SetupToggle toggle);
  [[nodiscard]] const runtime::SetupToggles& setupToggles() const { return setup_; }

  [[nodiscard]] const KioskPolicy* policy() const { return policy_.get(); }
  [[nodiscard]] const LoadedShow* loaded() const { return show_.get(); }
  [[nodiscard]] std::int64_t reloadsApplied() const { return reloadsApplied_; }
  [[nodiscard]] std::int64_t reloadsFailed() const { return reloadsFailed_; }
  /// \brief The frame in which the last reload took over (-1 when none did).
  [[nodiscard]] std::int64_t lastReloadFrame() const { return lastReloadFrame_; }

 private:
  /// A restart the control server asked for, answered once the manager did it.
  struct PendingRestart {
    std::string name;
    DeviceId id = 0;
    std::uint32_t before = 0;  // the device's restarts when it was asked
    std::shared_ptr<ControlReply> reply;
  };

  /// Asks the manager for the new show's devices (and tells the camera streams where they are).
  void requestDevices();
  /// Whether a texture of the show shows camera `device`.
  [[nodiscard]] bool cameraShown(const std::string& device) const;
  void watchHotplug();
  void takeOver(std::unique_ptr<LoadedShow> show, Nanos now, const std::optional<ResumePoint>& resume);
  void pollReload(const FrameContext& frame);
  void loadTexturesInBackground();
  void pollTextures();
  void handleControls(const FrameContext& frame);
  /// Runs a control request's script command (on a leader: logs it for the followers).
  void runCommand(const FrameContext& frame, ControlRequest& request);
  void serviceDevices(Nanos now);
  /// Takes what the manager says about the show's devices into their slots when it changed:
  /// the status lines, the log, the restarts asked for.
  void mirrorDevices();
  void answerRestarts(const std::vector<devices::DeviceStatus>& devices);
  void applyInput(Nanos until);
  void applyEvent(const Event& e, Nanos now);
  [[nodiscard]] DeviceSlot* slotFor(DeviceId id);
  /// Keys and pointer from the output's window and from evdev keyboards and mice: activity for the kiosk, the set-up
  /// toggles and (in control mode) the facet views' calibration keys (thesis Appendix B), then walking the viewer
  /// (Navigator): held keys move it per frame,
  /// dragging with a button held turns it.
  void applyOutputInput(Nanos now);
  void advanceShuttles(Nanos now);
  void applyProgramme(Nanos now);
  void updateStreams(Nanos now);
  void saveState(Nanos now);
  void publishShow();
  void publishDevices();
  void publishStreams();
  /// A camera's status row: the state of the stream that shows it.
  void cameraRow(DeviceStatus& d, const DeviceSlot& slot) const;
  /// Removes the textures the last item put in the registry, unless `nextKey` is that same item.
  void releaseItemTextures(const std::string& nextKey);
  /// Frame-locked follower: counts what a movie did with the leader's frame.
  void countLeaderFrame(LeaderFrameResult result);
  /// Frame-locked: puts every movie stream of the show on the timeline from mediaStart_.
  void alignStreams();
  /// How the item `p` plays: looped or once, exact offline, on the group's timeline when locked.
  [[nodiscard]] ItemPlayer::Playback playbackFor(const Programme& p) const;

  DirectorContext context_;
  const ShowFactories factories_;  // read by the loader thread too: never changed after construction
  DisplayViews* views_ = nullptr;
  devices::EvdevInput* keyboardsAndMice_ = nullptr;
  // The one owner of the show's devices: opens, retries and closes them (on its own thread on
  // the system clock, stepped by serviceDevices() under a ManualClock) and pushes their events
  // into context_.events. Before show_, which its camera streams borrow it for.
  std::unique_ptr<devices::DeviceManager> devices_;
  std::vector<std::string> requested_;    // names the show holds in devices_
  std::uint64_t devicesSeen_ = 0;         // devices_->statusVersion() last mirrored
  std::vector<PendingRestart> restarts_;  // frame loop only
  std::vector<Event> input_;              // the frame's input, in time order (capacity kept)
  std::vector<Event> inputLater_;         // input taken from the queue before it was due
  runtime::Bindings* replayBindings_ = nullptr;
  std::vector<DeviceId> replayDevices_;
  std::unique_ptr<LoadedShow> show_;
  std::unique_ptr<devices::UdevMonitor> udev_;  // a device came: retry the absent at once
  std::unique_ptr<KioskPolicy> policy_;
  std::optional<HeadFollower> head_;  // the viewer's tracker ([viewer] tracker), if any
  std::uint64_t headFrames_ = 0;      // head_->figures().frames last published
  std::shared_ptr<const Schedule> scheduleForStatus_;
  ItemPlayer* player_ = nullptr;  // the playing item's player, owned by show_
  std::uint64_t appliedGeneration_ = 0;
  bool displayOn_ = true;
  bool displayOffUnsupported_ = false;
  std::set<std::string> reportedFailures_;
  Nanos lastSave_{0};
  Nanos lastAdvance_{-1};  // the show time shuttle rings last turned the show to
  // Keyboard and pointer of the output's window: set-up toggles first, then (in control mode)
  // calibration keys, then navigation.
  runtime::SetupToggles setup_;
  bool exitRequested_ = false;  // Esc or the exit toggle: the run ends after this frame
  runtime::Navigator navigator_;
  Nanos lastNavigate_{-1};    // the show time the navigator last moved the viewer to
  bool pointerHeld_ = false;  // a pointer button is down: motion turns the viewer

  // Reload hand-over: the loader thread writes, the frame loop reads.
  std::mutex reloadMutex_;
  std::thread loader_;
  bool loading_ = false;                  // frame loop only
  bool reloadReady_ = false;              // guarded by reloadMutex_
  std::unique_ptr<LoadedShow> reloaded_;  // guarded by reloadMutex_
  std::string reloadError_;               // guarded by reloadMutex_
  // Texture images read in the background after start-up, handed over the same way.
  std::thread textureLoader_;
  std::uint64_t showGeneration_ = 0;                                    // frame loop only
  bool texturesPending_ = false;                                        // frame loop only
  bool texturesReady_ = false;                                          // guarded by reloadMutex_
  std::uint64_t texturesFor_ = 0;                                       // guarded by reloadMutex_
  std::vector<std::pair<std::string, std::optional<Image>>> textures_;  // guarded by reloadMutex_
  std::int64_t reloadsApplied_ = 0;
  std::int64_t reloadsFailed_ = 0;
  std::int64_t lastReloadFrame_ = -1;
  // Textures that belong to the playing item: what the registry holds beyond these names (and
  // the manifest's textures) was put there by it. Frame loop only.
  std::string itemKey_;
  std::vector<std::string> texturesBeforeItem_;
  std::uint64_t performanceUpdates_ = 0;  // the meter's sample last published
  std::uint64_t viewProblemsSeen_ = 0;    // DisplayViews::problemsVersion() last published
  // Frame lock (frame loop only).
  bool locked_ = false;
  bool follower_ = false;  // plays the leader's programme, decides nothing itself
  std::chrono::milliseconds patience_{0};
  Nanos mediaStart_{0};  // show time the show's [media] streams start (leader: its show's take-over)
  std::optional<std::uint32_t> leaderReloads_;  // the leader's reload count last seen
  LockedMovieFrames leaderMovies_;              // follower: the leader's movie frames for this frame
  LockedMovieCounts movieCounts_;               // follower: what its movies did with them
  // Leader: the script commands run since the show was (re)loaded, which the lock sends to the
  // followers; at most one runs per frame, so that each frame carries the one it ran.
  LockCommandLog commands_;
  std::optional<ControlRequest> deferredCommand_;  // the next frame's command
};

}  // namespace basalt::kiosk
