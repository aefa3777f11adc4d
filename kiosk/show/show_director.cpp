#include "kiosk/show/show_director.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <fstream>
#include <functional>
#include <limits>
#include <mutex>
#include <thread>

#include <fmt/format.h>
#include <fmt/std.h>

#include "kiosk/loop/display_views.h"
#include "runtime/log.h"

namespace basalt::kiosk {

BASALT_LOG_CATEGORY(Director, "kiosk");

namespace {

/// True when `file` is there but holds nothing but white space: read as a show it would be the
/// built-in default, which a reload must not put in place of the show playing (a manifest
/// emptied by mistake, or caught between an editor's truncate and its write).
bool blankManifest(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return false;  // missing or unreadable: the reader says so
  char c = 0;
  while (in.get(c)) {
    if (c != ' ' && c != '\t' && c != '\n' && c != '\r') return false;
  }
  return true;
}

constexpr Nanos kSaveEvery = std::chrono::seconds(2);

}  // namespace

ShowDirector::ShowDirector(DirectorContext context, ShowFactories factories)
    : context_(context),
      factories_(std::move(factories)),
      devices_(std::make_unique<devices::DeviceManager>(context_.clock, context_.events)) {
  context_.board.setShowClock(context_.clock);
  input_.reserve(context_.events.capacity());
  inputLater_.reserve(context_.events.capacity());
}

ShowDirector::~ShowDirector() {
  if (udev_) udev_->stop();
  devices_->stop();  // an open still running ends first; then every device is closed
  if (loader_.joinable()) loader_.join();
  if (textureLoader_.joinable()) textureLoader_.join();
  for (PendingRestart& r : restarts_)
    r.reply->answer(503, fmt::format("'{}' was not restarted: the show stopped", r.name));
  if (policy_ && context_.state) {
    context_.state->save(policy_->resumePoint(context_.clock.now()));
    context_.state->flush();
  }
}

void ShowDirector::noteHotplug() { devices_->notifyHotplug({devices::HotplugEvent::Action::kAdded, {}, {}}); }

void ShowDirector::setReplayInput(runtime::Bindings* bindings, std::vector<DeviceId> devices) {
  replayBindings_ = bindings;
  replayDevices_ = std::move(devices);
}

void ShowDirector::install(std::unique_ptr<LoadedShow> show, Nanos now, const std::optional<ResumePoint>& resume) {
  takeOver(std::move(show), now, resume);
  if (resume && policy_->current().item && policy_->current().item->name == resume->item &&
      resume->position > Nanos{0}) {
    log::info(kLogDirector, "resuming '{}' at {:.1f} s, where the show was before it stopped", resume->item,
              toSeconds(resume->position));
  }
}

void ShowDirector::takeOver(std::unique_ptr<LoadedShow> show, Nanos now, const std::optional<ResumePoint>& resume) {
  if (show_) {
    for (const LoadedTexture& t : show_->textures) context_.renderer.textures().remove(t.name);
  }
  // The old show's devices go back to the manager, which closes them on its own thread (an open
  // still running there ends first: the frame loop never waits for it). Their events still
  // queued carry ids no slot has any more: they are dropped when they come due.
  for (const std::string& name : requested_) devices_->withdraw(name);
  requested_.clear();
  player_ = nullptr;
  itemKey_.clear();  // the new show's players are new: what the old item uploaded goes
  std::unique_ptr<LoadedShow> old = std::move(show_);
  show_ = std::move(show);
  reportedFailures_.clear();
  const WallTime wall = context_.clock.wallNow();
  for (DeviceSlot& slot : show_->devices) slot.since = wall;
  requestDevices();
  // The facet views' viewer follows the show's tracker; without one it stands where the views
  // put it (a follower's comes from the leader with every frame).
  head_.reset();
  headFrames_ = 0;
  if (!follower_ && !show_->manifest.viewer.tracker.empty()) head_.emplace(show_->manifest.viewer);
  if (!follower_) context_.show.head() = {};
  context_.board.publishTracker(head_ ? &head_->figures() : nullptr);
  for (LoadedTexture& t : show_->textures) {
    if (t.image) {
      if (auto r = context_.renderer.textures().setImage(t.name, *t.image); !r) {
        log::warn(kLogDirector, "texture '{}': {}", t.name, r.error().describe());
      }
    }
    t.live = false;
    t.since = wall;
  }
  ++showGeneration_;
  // Images not read yet (start-up) are read once the first frame is on screen, so that decoding
  // them never delays it.
  texturesPending_ = true;
  policy_ = std::make_unique<KioskPolicy>(show_->manifest, show_->schedule);
  scheduleForStatus_ = show_->schedule ? std::make_shared<const Schedule>(*show_->schedule) : nullptr;
  policy_->start(now, wall, resume);
  appliedGeneration_ = 0;
  // A leader's streams start with its show; a follower keeps the leader's start (it comes with
  // every frame, and a reload of the leader brings a new one).
  if (!follower_) mediaStart_ = now;
  if (locked_) alignStreams();
  applyProgramme(now);
  publishDevices();
  publishStreams();
  watchHotplug();
  // On the system clock devices open on the manager's thread, never the frame loop's.
  if (!context_.clock.isManual()) devices_->start();
  old.reset();  // after the new show is on: its players and streams go now
}

bool ShowDirector::cameraShown(const std::string& device) const {
  return std::ranges::any_of(show_->textures, [&](const LoadedTexture& t) {
    const MediaSpec* media = t.stream && !t.source.empty() ? show_->manifest.findMedia(t.source) : nullptr;
    return media && media->kind == MediaKind::kCamera && media->device == device;
  });
}

void ShowDirector::requestDevices() {
  for (DeviceSlot& slot : show_->devices) {
    if (!slot.unavailable.empty() || !slot.source.provider) continue;
    const bool camera = slot.spec.kind == DeviceKind::kCamera;
    // A camera opens only when a texture shows it (or the scripts' VCR asks for it).
    if (camera && !cameraShown(slot.spec.name)) continue;
    // A follower draws the leader's viewer: its own tracker stays closed.
    if (follower_ && slot.spec.kind == DeviceKind::kTracker) {
      slot.message = "not read on a frame-locked follower: the leader's viewer is drawn";
      continue;
    }
    const std::string name = slot.spec.name;
    auto id = devices_->request(std::move(slot.source.request), std::move(slot.source.provider), slot.source.upkeep);
    // The scripts' VCR may hold the camera already: the show shares it.
    if (!id && camera) id = devices_->share(name);
    if (!id) {
      slot.unavailable = id.error().message();
      slot.message = slot.unavailable;
      log::warn(kLogDirector, "device '{}': {}", name, slot.unavailable);
      continue;
    }
    slot.id = *id;
    requested_.push_back(name);
  }
  // Camera textures find their camera in the manager by name.
  for (LoadedTexture& t : show_->textures) {
    if (t.stream) t.stream->useDevices(*devices_);
  }
}

void ShowDirector::watchHotplug() {
  if (udev_ || context_.clock.isManual()) return;
  const bool hardware = std::ranges::any_of(show_->devices, [](const DeviceSlot& slot) {
    return slot.id != 0 && slot.spec.kind == DeviceKind::kDialBox &&
           (slot.spec.backend == DeviceBackend::kHid || slot.spec.backend == DeviceBackend::kSerial);
  });
  if (!hardware) return;
  auto monitor = devices::UdevMonitor::create({"hidraw", "usb", "tty"});
  if (!monitor) {
    log::info(kLogDirector, "no udev hotplug ({}): absent dial boxes are tried again on their back-off only",
              monitor.error().describe());
    return;
  }
  udev_ = std::move(*monitor);
  // An added node retries what is not live at once; a removed one loses the device on it.
  udev_->start([this](const devices::HotplugEvent& e) { devices_->notifyHotplug(e); });
}

void ShowDirector::loadTexturesInBackground() {
  std::vector<std::pair<std::string, std::filesystem::path>> wanted;
  for (const LoadedTexture& t : show_->textures) {
    if (!t.image && !t.imageFile.empty()) wanted.emplace_back(t.name, t.imageFile);
  }
  if (wanted.empty()) return;
  if (textureLoader_.joinable()) textureLoader_.join();
  textureLoader_ = std::thread([this, wanted = std::move(wanted), generation = showGeneration_] {
    std::vector<std::pair<std::string, std::optional<Image>>> images;
    for (const auto& [name, file] : wanted) images.emplace_back(name, readTextureImage(name, file));
    {
      std::lock_guard lock(reloadMutex_);
      textures_ = std::move(images);
      texturesFor_ = generation;
      texturesReady_ = true;
    }
    context_.loop.wake();
  });
}

void ShowDirector::pollTextures() {
  std::vector<std::pair<std::string, std::optional<Image>>> images;
  {
    std::lock_guard lock(reloadMutex_);
    if (!texturesReady_) return;
    texturesReady_ = false;
    if (texturesFor_ != showGeneration_) return;  // read for a show that has been replaced since
    images = std::move(textures_);
  }
  for (auto& [name, image] : images) {
    if (!image) continue;
    for (LoadedTexture& t : show_->textures) {
      if (t.name != name) continue;
      t.image = std::move(*image);
      if (!t.live) {
        if (auto r = context_.renderer.textures().setImage(t.name, *t.image); !r) {
          log::warn(kLogDirector, "texture '{}': {}", t.name, r.error().describe());
        }
      }
    }
  }
}

void ShowDirector::requestReload() {
  if (!show_ || show_->manifest.file.empty()) {
    log::info(kLogDirector, "reload asked, but the built-in default show has no manifest to re-read");
    return;
  }
  if (loading_) {
    log::info(kLogDirector, "reload asked while one is under way; the newer manifest is read when it ends");
    return;
  }
  if (loader_.joinable()) loader_.join();
  loading_ = true;
  if (context_.supervisor) context_.supervisor->reloading();
  log::info(kLogDirector, "reloading {}; the current show plays on until the new one is ready", show_->manifest.file);
  const std::filesystem::path file = show_->manifest.file;
  loader_ = std::thread([this, file] {
    Diagnostics diagnostics;
    Result<std::unique_ptr<LoadedShow>> loaded =
        blankManifest(file)
            ? fail(Errc::kParse, "the manifest is empty; save the show again (an empty file is not read as a show)",
                   file.string())
            : readAndLoadShow(file, context_.clock, factories_, diagnostics);
    {
      std::lock_guard lock(reloadMutex_);
      reloadReady_ = true;
      if (loaded) {
        reloaded_ = std::move(*loaded);
        for (const Diagnostic& d : diagnostics.items()) {
          if (d.severity == Severity::kWarning) log::warn(kLogDirector, "{}", d.format());
        }
      } else {
        reloadError_ = loaded.error().describe();
        // The status shows the first error itself, so that /health says why, not only how many.
        bool first = true;
        for (const Diagnostic& d : diagnostics.items()) {
          if (d.severity != Severity::kError) continue;
          log::error(kLogDirector, "{}", d.format());
          if (first) reloadError_ += ": " + d.format();
          first = false;
        }
      }
    }
    context_.loop.wake();
  });
}

void ShowDirector::pollReload(const FrameContext& frame) {
  if (!loading_) return;
  std::unique_ptr<LoadedShow> next;
  std::string error;
  {
    std::lock_guard lock(reloadMutex_);
    if (!reloadReady_) return;
    reloadReady_ = false;
    next = std::move(reloaded_);
    error = std::move(reloadError_);
  }
  loading_ = false;
  loader_.join();
  const Nanos now = frame.time;
  if (!next) {
    ++reloadsFailed_;
    log::error(kLogDirector, "reload failed: {}; the current show plays on", error);
    context_.board.noteReload(false, "failed: " + error);
    if (context_.supervisor) context_.supervisor->reloaded("reload failed: " + error + "; " + policy_->describe());
    return;
  }
  const auto resume = policy_ ? std::optional<ResumePoint>(policy_->resumePoint(now)) : std::nullopt;
  takeOver(std::move(next), now, resume);
  ++reloadsApplied_;
  commands_.restart(static_cast<std::uint32_t>(reloadsApplied_));  // the log starts with the show
  lastReloadFrame_ = frame.frame;
  context_.board.noteReloadApplied(frame.frame);
  context_.board.noteReload(true, fmt::format("reloaded at frame {}", frame.frame));
  log::info(kLogDirector, "reloaded {}: {}", show_->manifest.file, policy_->describe());
  if (context_.supervisor) context_.supervisor->reloaded(policy_->describe());
}

void ShowDirector::handleControls(const FrameContext& frame) {
  const Nanos now = frame.time;
  const bool lockLeader = locked_ && !follower_;
  bool commandRun = false;
  ControlRequest request;
  for (;;) {
    if (deferredCommand_) {
      request = std::move(*deferredCommand_);
      deferredCommand_.reset();
    } else if (!context_.board.controls().pop(request)) {
      break;
    }
    if (request.kind == ControlKind::kRunCommand && lockLeader && commandRun) {
      // A frame carries one command to the followers: the next one waits for the next frame,
      // and so do the requests after it, which keep their order.
      deferredCommand_ = std::move(request);
      break;
    }
    auto& reply = *request.reply;
    switch (request.kind) {
      case ControlKind::kNext:
      case ControlKind::kPrevious: {
        if (follower_) {
          // One director for the group: the leader's. Moving one node would part it from the others.
          reply.answer(409,
                       "this node follows its frame-lock leader, which decides what plays: send the request "
                       "to the leader's control server");
          break;
        }
        const bool moved = request.kind == ControlKind::kNext ? policy_->next(now) : policy_->previous(now);
        if (moved) {
          applyProgramme(now);
          reply.answer(200, policy_->describe());
        } else {
          reply.answer(409, "nothing to move to: " + policy_->describe());
        }
        break;
      }
      case ControlKind::kReload:
        if (!show_ || show_->manifest.file.empty()) {
          reply.answer(409, "the built-in default show has no manifest to reload");
        } else {
          requestReload();
          reply.answer(202, "reloading " + show_->manifest.file.string());
        }
        break;
      case ControlKind::kRunCommand:
        commandRun = lockLeader;
        runCommand(frame, request);
        break;
      case ControlKind::kRestartDevice: {
        auto it = std::find_if(show_->devices.begin(), show_->devices.end(),
                               [&](const DeviceSlot& s) { return s.spec.name == request.argument; });
        if (it == show_->devices.end()) {
          reply.answer(404, fmt::format("no device '{}' in this show", request.argument));
        } else if (it->id == 0) {
          reply.answer(
              409, fmt::format("'{}' cannot be restarted: {}", request.argument,
                               it->unavailable.empty() ? "no texture shows it, so it is not open" : it->unavailable));
        } else {
          // The manager closes and reopens it (on its thread on the system clock); the answer
          // goes out when it is done.
          std::uint32_t before = 0;
          for (const devices::DeviceStatus& st : devices_->status()) {
            if (st.id == it->id) before = st.restarts;
          }
          (void)devices_->restart(request.argument);
          restarts_.push_back({request.argument, it->id, before, request.reply});
        }
        break;
      }
      case ControlKind::kAction:
      case ControlKind::kResetView: {
        if (follower_) {
          // The leader's show is the group's: a move here alone would part this node's picture.
          reply.answer(409,
                       "this node follows its frame-lock leader, whose show every node draws: send the control to "
                       "the leader");
          break;
        }
        // A visitor's move (OSC from a show controller or a fader) counts as activity, as a dial's.
        if (policy_->noteInput(now)) applyProgramme(now);
        if (request.kind == ControlKind::kResetView) {
          context_.show.resetTransforms();
          reply.answer(200, "view reset");
        } else if (runtime::applyAction(request.action, request.amount, context_.show)) {
          reply.answer(200, fmt::format("{} {}", runtime::actionName(request.action), request.amount));
        } else {
          reply.answer(400, fmt::format("'{}' does not move the show", runtime::actionName(request.action)));
        }
        break;
      }
      case ControlKind::kSetup: {
        const auto toggle = runtime::parseSetupToggle(request.argument);
        if (!toggle) {
          reply.answer(400, fmt::format("'{}' is not a set-up toggle; use cave, stereo, fog, smooth, lighting, "
                                        "filled, points, wireframe, normals, light-tokens, pause, control or exit",
                                        request.argument));
          break;
        }
        reply.answer(200, applySetup(*toggle));
        break;
      }
      case ControlKind::kCalibrate: {
        if (!views_) {
          reply.answer(409, "this show has no facet views to calibrate (add [[views]] with kind = \"facet\")");
          break;
        }
        auto out = views_->calibrate(request.view, request.argument, request.save);
        if (out) {
          reply.answer(200, *out);
        } else {
          const Errc code = out.error().code();
          reply.answer(code == Errc::kNotFound ? 404 : code == Errc::kIo ? 500 : 400, out.error().describe());
        }
        break;
      }
    }
  }
}

void ShowDirector::serviceDevices(Nanos now) {
  // Under a ManualClock a run repeats frame by frame: the manager opens, retries and services
  // the devices here, before the frame's input is applied. On the system clock its own thread
  // does, and the frame loop only hears what became of them.
  if (context_.clock.isManual()) devices_->step(now);
  mirrorDevices();
}

void ShowDirector::mirrorDevices() {
  const std::uint64_t version = devices_->statusVersion();
  if (version == devicesSeen_) return;
  devicesSeen_ = version;
  const std::vector<devices::DeviceStatus> all = devices_->status();
  const WallTime wall = context_.clock.wallNow();
  const Nanos now = context_.clock.now();
  bool changed = false;
  for (DeviceSlot& slot : show_->devices) {
    if (slot.id == 0) continue;
    const auto st = std::ranges::find_if(all, [&](const devices::DeviceStatus& d) { return d.id == slot.id; });
    if (st == all.end()) continue;
    const bool dialBox = slot.spec.kind == DeviceKind::kDialBox;
    const bool live = st->state == devices::DeviceState::kLive;
    if (st->state != slot.state) {
      if (dialBox && slot.state == devices::DeviceState::kLive) {
        log::warn(kLogDirector, "device '{}' is {}; its bindings are quiet until it comes back", slot.spec.name,
                  devices::deviceStateName(st->state));
      } else if (dialBox && live) {
        log::info(kLogDirector, "device '{}' is live ({})", slot.spec.name, st->device.name);
      }
      slot.state = st->state;
      // The manager's time of the change, on the wall clock.
      slot.since = wall - std::chrono::duration_cast<WallTime::duration>(std::max(Nanos{0}, now - st->since));
      changed = true;
    }
    const std::string message = live ? std::string() : st->lastError;
    if (message != slot.message) {
      if (dialBox && st->attempts > 0 && !message.empty()) {
        log::warn(kLogDirector, "device '{}' ({}): {}; retrying every {} s at most", slot.spec.name,
                  deviceBackendName(slot.spec.backend), message, toSeconds(kDialBoxBackoff.max));
      }
      slot.message = message;
      changed = true;
    }
    if (!st->device.name.empty() && st->device.name != slot.deviceName) {
      slot.deviceName = st->device.name;
      changed = true;
    }
  }
  answerRestarts(all);
  if (changed) publishDevices();
}

void ShowDirector::answerRestarts(const std::vector<devices::DeviceStatus>& all) {
  for (auto it = restarts_.begin(); it != restarts_.end();) {
    const auto st = std::ranges::find_if(all, [&](const devices::DeviceStatus& d) { return d.id == it->id; });
    if (st == all.end()) {
      it->reply->answer(409, fmt::format("'{}' was not restarted: the show was replaced first; ask again", it->name));
      it = restarts_.erase(it);
      continue;
    }
    if (st->restarts <= it->before) {
      ++it;
      continue;
    }
    const bool live = st->state == devices::DeviceState::kLive;
    log::info(kLogDirector, "device '{}' restarted by the control server: {}", it->name,
              live ? std::string("live") : st->lastError);
    // A device that is not there is not the server's fault: 503, and the manager retries.
    it->reply->answer(
        live ? 200 : 503,
        live ? fmt::format("'{}' restarted", it->name)
             : fmt::format("'{}' could not be reopened: {}; it is retried every few seconds", it->name, st->lastError));
    it = restarts_.erase(it);
  }
}

DeviceSlot* ShowDirector::slotFor(DeviceId id) {
  if (id == 0) return nullptr;
  for (DeviceSlot& slot : show_->devices) {
    if (slot.id == id) return &slot;
  }
  return nullptr;
}

void ShowDirector::applyInput(Nanos until) {
  // The run's one queue: the show's devices and a replayed trace push into it; this is where
  // their events leave it, in the order of their times.
  takeDueInput(context_.events, until, input_, inputLater_);
  for (const Event& e : input_) applyEvent(e, until);
}

void ShowDirector::applyEvent(const Event& e, Nanos now) {
  if (replayBindings_ && std::ranges::find(replayDevices_, e.device) != replayDevices_.end()) {
    // A replayed trace turns the show through LAVA's table; it is not a visitor.
    replayBindings_->apply(e, context_.show);
    return;
  }
  DeviceSlot* slot = slotFor(e.device);
  if (!slot) return;  // a device of a show that was replaced
  if (e.kind == EventKind::kDeviceState) {
    // Its bindings let go when it is lost: a shuttle held when the cable was pulled stops turning.
    slot->dials.apply(e, context_.show);
    return;
  }
  if (e.kind != EventKind::kDialDelta && e.kind != EventKind::kButton && e.kind != EventKind::kDialAbsolute &&
      e.kind != EventKind::kShuttle) {
    return;
  }
  // A visitor touched something: wake the exhibit, and count as activity.
  if (!follower_ && policy_->noteInput(now)) applyProgramme(now);
  if (!player_) return;
  if (e.kind == EventKind::kButton) {
    if (e.value < 0.5 || e.index >= slot->buttons.size()) return;
    if (follower_ && slot->buttons[e.index] != KioskAction::kResetView) return;
    switch (slot->buttons[e.index]) {
      case KioskAction::kNextItem:
        if (policy_->next(now)) applyProgramme(now);
        break;
      case KioskAction::kPreviousItem:
        if (policy_->previous(now)) applyProgramme(now);
        break;
      case KioskAction::kResetView: context_.show.resetTransforms(); break;
      case KioskAction::kNone: break;
    }
    return;
  }
  slot->dials.apply(e, context_.show);  // bindings keep state (acceleration, shuttles)
}

void ShowDirector::applyOutputInput(Nanos now) {
  std::array<Event, 64> input;
  const auto apply = [&](std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) {
      Event& e = input[i];
      e.time = now;
      // A visitor at the keyboard or mouse counts as activity (a press or a move, not a release).
      if ((e.kind == EventKind::kPointerMotion || e.value > 0.5) && !follower_ && policy_->noteInput(now)) {
        applyProgramme(now);
      }
      if (const auto toggle = setup_.key(e)) {
        applySetup(*toggle);
        continue;
      }
      if (e.kind == EventKind::kKey && setup_.controlMode() && views_ && views_->applyKey(e)) continue;
      if (e.kind == EventKind::kPointerButton) {
        pointerHeld_ = e.value > 0.5;
        continue;
      }
      // The pointer turns the viewer while a button is held (dragging), so that a pointer merely
      // crossing the window leaves the view alone.
      if (e.kind == EventKind::kPointerMotion && !pointerHeld_) continue;
      navigator_.apply(e, context_.show);
    }
  };
  while (const std::size_t n = context_.output.takeInput(input)) {
    apply(n);
    if (n < input.size()) break;
  }
  // Keyboards and mice of a KMS kiosk (evdev): the same way as the window's.
  if (keyboardsAndMice_) {
    while (const std::size_t n = keyboardsAndMice_->takeInput(input)) {
      apply(n);
      if (n < input.size()) break;
    }
  }
  if (lastNavigate_.count() >= 0 && now > lastNavigate_) {
    navigator_.advance(std::chrono::duration<double>(now - lastNavigate_).count(), context_.show);
  }
  lastNavigate_ = now;
}

std::string ShowDirector::applySetup(runtime::SetupToggle toggle) {
  using runtime::SetupToggle;
  std::string what;
  if (toggle == SetupToggle::kCaveMode) {
    if (views_ && views_->hasFacetViews()) {
      views_->setCaveMode(!views_->caveMode());
      what = views_->caveMode() ? "cave mode on: facet views show their facets"
                                : "cave mode off: facet views show the plain view";
    } else {
      what = "cave mode: this show has no facet views";
    }
  } else if (toggle == SetupToggle::kExit) {
    exitRequested_ = true;
    what = "exit: the run ends after this frame";
  } else {
    what = setup_.apply(toggle, context_.show);
  }
  log::info(kLogDirector, "set-up: {}", what);
  return what;
}

void ShowDirector::advanceShuttles(Nanos now) {
  // Shuttle rings held off-centre turn the show by the show time since the last frame.
  if (lastAdvance_.count() >= 0 && now > lastAdvance_) {
    if (player_) {
      for (DeviceSlot& slot : show_->devices) slot.dials.advance(now - lastAdvance_, context_.show);
    }
    if (replayBindings_) replayBindings_->advance(now - lastAdvance_, context_.show);
  }
  lastAdvance_ = now;
}

void ShowDirector::applyProgramme(Nanos now) {
  // An item that fails moves the policy on; at most one round of the list per call.
  for (std::size_t attempt = 0; attempt < 64; ++attempt) {
    const Programme& p = policy_->current();
    if (p.generation == appliedGeneration_) return;
    appliedGeneration_ = p.generation;
    player_ = nullptr;
    commands_.markShowReset();  // every item starts its own Show: the commands so far no longer act
    const bool wantOff = p.display == DisplayState::kOff;
    if (wantOff && displayOn_ && !displayOffUnsupported_) {
      if (auto r = context_.output.setDisplayPower(false); r) {
        displayOn_ = false;
      } else {
        displayOffUnsupported_ = true;
        log::warn(kLogDirector, "cannot switch the display off ({}); showing black instead", r.error().message());
      }
    } else if (!wantOff && !displayOn_) {
      if (auto r = context_.output.setDisplayPower(true); !r) {
        log::error(kLogDirector, "cannot switch the display back on: {}", r.error().describe());
      }
      displayOn_ = true;
    }
    if (!p.item || p.display != DisplayState::kOn) {
      releaseItemTextures({});
      context_.show = runtime::Show();
    } else {
      const std::string key = entryKey(p.item->entry);
      releaseItemTextures(key);
      const auto found = show_->players.find(key);
      Result<void> started = fail(Errc::kInternal, "no player");
      if (found == show_->players.end()) {
        const auto why = show_->unplayable.find(key);
        started = std::unexpected(why != show_->unplayable.end() ? why->second
                                                                 : Error(Errc::kInternal, "item was not prepared"));
      } else {
        found->second->useTextures(context_.renderer.textures());
        found->second->setPlayback(playbackFor(p));
        started = found->second->start(context_.show, now - p.itemStart, context_.fps);
      }
      if (!started) {
        if (reportedFailures_.insert(key).second) {
          log::error(kLogDirector, "'{}' cannot play: {}; {}", p.item->name, started.error().describe(),
                     follower_ ? "showing the scene without it until the leader moves on" : "moving on");
        }
        if (follower_) break;  // the leader decides what plays next
        policy_->itemFailed(now);
        continue;
      }
      player_ = found->second.get();
    }
    log::info(kLogDirector, "{}", policy_->describe());
    if (context_.supervisor) context_.supervisor->status(policy_->describe());
    publishShow();
    saveState(now);
  }
}

void ShowDirector::updateStreams(Nanos now) {
  bool changed = false;
  std::size_t movie = 0;  // as lockedMovieFrames() counts them
  for (LoadedTexture& t : show_->textures) {
    if (!t.stream) continue;
    if (follower_) {
      t.stream->setLeaderFrame(movie < leaderMovies_.textures.size() ? leaderMovies_.textures[movie] : -1);
      ++movie;
    }
    const bool live = t.stream->update(now, context_.renderer.textures(), t.name);
    if (follower_) countLeaderFrame(t.stream->leaderFrameResult());
    const std::optional<SourceState> device = t.stream->deviceState();
    const bool degraded = t.stream->degraded();
    if (live == t.live && device == t.deviceState && degraded == t.degraded) continue;
    t.deviceState = device;
    t.degraded = degraded;
    t.since = context_.clock.wallNow();
    changed = true;
    if (live == t.live) continue;
    t.live = live;
    if (!live && t.image) {
      if (auto r = context_.renderer.textures().setImage(t.name, *t.image); !r) {
        log::warn(kLogDirector, "texture '{}': {}", t.name, r.error().describe());
      }
    }
  }
  if (changed) {
    publishStreams();
    publishDevices();  // a camera's row follows the stream that shows it
  }
}

void ShowDirector::saveState(Nanos now) {
  lastSave_ = now;
  if (context_.state && show_->manifest.kiosk.resume) context_.state->save(policy_->resumePoint(now));
}

Result<void> ShowDirector::beforeDraw(const FrameContext& frame) {
  pollReload(frame);
  pollTextures();
  handleControls(frame);
  const Nanos now = frame.time;
  serviceDevices(now);
  applyInput(now);
  if (head_ && !follower_) {
    head_->update(now, *devices_, context_.show);
    if (head_->figures().frames != headFrames_) {
      headFrames_ = head_->figures().frames;
      context_.board.publishTracker(&head_->figures());
    }
  }
  applyOutputInput(now);
  advanceShuttles(now);
  // A frame-locked follower's programme is the leader's (followProgramme): it decides nothing.
  if (!follower_ && policy_->update(now, context_.clock.wallNow())) applyProgramme(now);
  if (player_) {
    // A follower's movie item shows the leader's movie frame (none on a leader: it decides).
    if (follower_) player_->setLeaderFrame(leaderMovies_.item);
    const Result<void> r = player_->beforeDraw(frame, context_.show);
    if (r && follower_) countLeaderFrame(player_->leaderFrameResult());
    if (!r) {
      log::error(kLogDirector, "'{}' stopped: {}; moving on", policy_->current().item->name, r.error().describe());
      if (follower_) {
        player_ = nullptr;
      } else {
        policy_->itemFailed(now);
        applyProgramme(now);
      }
    } else if (player_->ended() && !follower_) {
      policy_->itemEnded(now);
      applyProgramme(now);
    }
  }
  updateStreams(now);
  // Which movie frame the item and each texture show in which frame (BASALT_LOG=kiosk=debug):
  // frame-locked nodes are compared with it.
  if (player_ && policy_->current().item) {
    if (const std::int64_t shown = player_->shownFrame(); shown >= 0) {
      log::debug(kLogDirector, "frame {}: item '{}' shows movie frame {}", frame.frame, policy_->current().item->name,
                 shown);
    }
  }
  for (const LoadedTexture& t : show_->textures) {
    if (!t.stream) continue;
    if (const std::int64_t shown = t.stream->shownFrame(); shown >= 0) {
      log::debug(kLogDirector, "frame {}: texture '{}' shows movie '{}' frame {}", frame.frame, t.name, t.source,
                 shown);
    }
  }
  // Used up: the next frame brings its own (none: each movie keeps to its own timeline).
  leaderMovies_ = {};
  if (now - lastSave_ >= kSaveEvery) saveState(now);
  return {};
}

void ShowDirector::countLeaderFrame(LeaderFrameResult result) {
  if (result == LeaderFrameResult::kCorrected) ++movieCounts_.corrected;
  if (result == LeaderFrameResult::kLate) ++movieCounts_.late;
}

LockedMovieFrames ShowDirector::lockedMovieFrames() const {
  LockedMovieFrames l;
  const auto number = [](std::int64_t shown) {
    return shown >= 0 && shown <= std::numeric_limits<std::int32_t>::max() ? static_cast<std::int32_t>(shown) : -1;
  };
  if (player_ && policy_ && policy_->current().item) l.item = number(player_->shownFrame());
  if (!show_) return l;
  std::size_t movie = 0;
  for (const LoadedTexture& t : show_->textures) {
    if (!t.stream || movie == l.textures.size()) continue;
    l.textures[movie++] = number(t.stream->shownFrame());
  }
  return l;
}

void ShowDirector::runCommand(const FrameContext& frame, ControlRequest& request) {
  auto& reply = *request.reply;
  if (follower_) {
    // One show for the group: a command run here alone would part this node's picture from the others'.
    reply.answer(409,
                 "this node follows its frame-lock leader, which runs script commands on every node: send the "
                 "command to the leader's control server");
    return;
  }
  const bool lockLeader = locked_;
  if (lockLeader && request.argument.size() > kCommandTextBytes) {
    reply.answer(400, fmt::format("a frame-locked leader runs commands of at most {} bytes (it sends them to its "
                                  "followers); this one has {}",
                                  kCommandTextBytes, request.argument.size()));
    return;
  }
  auto out = runLeaderCommand(request.argument);
  if (!out) {
    reply.answer(out.error().code() == Errc::kUnsupported ? 501 : 400, out.error().describe());
    return;
  }
  if (lockLeader) {
    const std::uint32_t seq = commands_.add(request.argument);
    log::info(kLogDirector, "frame {}: runs command {} for the frame-locked group: {}", frame.frame, seq,
              request.argument);
  }
  reply.answer(200, *out);
}

Result<std::string> ShowDirector::runLeaderCommand(std::string_view command) {
  return runScriptCommand(factories_.commands, command,
                          {context_.show, &context_.renderer.textures(),
                           show_ ? show_->manifest.file.parent_path() : std::filesystem::path()});
}

const LockCommandLog* ShowDirector::commandLog() const { return locked_ && !follower_ ? &commands_ : nullptr; }

void ShowDirector::setLocked(bool leader, std::chrono::milliseconds patience) {
  locked_ = true;
  follower_ = !leader;
  patience_ = patience;
  if (follower_ && head_) {
    // The show was loaded before the lock: the follower's tracker goes, the leader's head comes.
    log::info(kLogDirector, "tracker '{}' is not read on a frame-locked follower: the leader's viewer is drawn",
              head_->tracker());
    devices_->withdraw(head_->tracker());
    std::erase(requested_, head_->tracker());
    head_.reset();
    context_.board.publishTracker(nullptr);
  }
  if (show_) alignStreams();
  // A leader's movie item that started with the show (before the lock) starts again on the
  // group's timeline, from the item's start: the followers place theirs there.
  const Programme* p = policy_ ? &policy_->current() : nullptr;
  if (leader && player_ && p && p->item && p->item->entry.kind == EntryKind::kMovie) {
    player_->setPlayback(playbackFor(*p));
    if (auto r = player_->start(context_.show, context_.clock.now() - p->itemStart, context_.fps); !r) {
      log::error(kLogDirector, "'{}' cannot play on the group's timeline: {}", p->item->name, r.error().describe());
    }
  }
}

ItemPlayer::Playback ShowDirector::playbackFor(const Programme& p) const {
  ItemPlayer::Playback playback;
  // An item with a duration loops until it is up; so does the only item of its list. One
  // without, in a list of several, plays once and the list moves on at its end.
  playback.loop = (p.item && p.item->duration > Nanos{0}) || p.count <= 1;
  playback.manualClock = context_.clock.isManual();
  // Frame-locked, a movie's frames fall on the group's timeline from the item's start.
  if (locked_) playback.timelineStart = p.itemStart;
  playback.patience = patience_;
  return playback;
}

void ShowDirector::alignStreams() {
  for (LoadedTexture& t : show_->textures) {
    if (t.stream) t.stream->alignTo(mediaStart_, patience_);
  }
}

LockedProgramme ShowDirector::lockedProgramme() const {
  LockedProgramme l;
  l.present = true;
  const Programme& p = policy_->current();
  l.hasItem = p.item != nullptr;
  l.mode = static_cast<std::uint8_t>(p.mode);
  l.display = static_cast<std::uint8_t>(p.display);
  l.index = static_cast<std::uint32_t>(p.index);
  l.itemStartNs = p.itemStart.count();
  l.mediaStartNs = mediaStart_.count();
  l.reloads = static_cast<std::uint32_t>(reloadsApplied_);
  if (p.item) l.setItemName(p.item->name);
  std::size_t movie = 0;
  for (const LoadedTexture& t : show_->textures) {
    if (!t.stream || movie == l.moviePassNs.size()) continue;
    l.moviePassNs[movie++] = t.stream->passDuration().count();
  }
  return l;
}

void ShowDirector::leaderRestarted() {
  if (!follower_) return;
  // The leader's show started anew: so does this node's (the commands run on the old one are
  // gone on the leader), and the new leader's reload count is taken as it comes.
  log::info(kLogDirector, "the frame-lock leader restarted; reloading this node's show");
  leaderReloads_.reset();
  requestReload();
}

bool ShowDirector::followProgramme(const LockedProgramme& l, Nanos showTime) {
  if (!follower_ || !policy_) return false;
  // The leader reloaded its manifest: so does this node (its own copy of the show folder).
  if (leaderReloads_ && *leaderReloads_ != l.reloads) {
    log::info(kLogDirector, "the frame-lock leader reloaded its show; reloading this node's");
    requestReload();
  }
  leaderReloads_ = l.reloads;
  bool changed = false;
  std::size_t movie = 0;
  for (LoadedTexture& t : show_->textures) {
    if (!t.stream || movie == l.moviePassNs.size()) continue;
    t.stream->setLeaderPass(Nanos{l.moviePassNs[movie++]});
  }
  if (Nanos{l.mediaStartNs} != mediaStart_) {
    mediaStart_ = Nanos{l.mediaStartNs};
    alignStreams();
    changed = true;
  }
  if (l.mode > 2 || l.display > 2) return changed;  // decodeFrame rejects these
  const std::string item = l.itemName();
  if (policy_->follow(static_cast<KioskMode>(l.mode), static_cast<DisplayState>(l.display), l.hasItem, l.index, item,
                      Nanos{l.itemStartNs})) {
    const Programme& p = policy_->current();
    if (l.hasItem && (!p.item || p.item->name != item)) {
      log::warn(kLogDirector,
                "the frame-lock leader plays '{}' ({}), which this node's show does not have at that "
                "place; check that every node has the same show folder",
                item, l.index + 1);
    }
    applyProgramme(showTime);
    changed = true;
  }
  return changed;
}

void ShowDirector::releaseItemTextures(const std::string& nextKey) {
  if (!itemKey_.empty() && itemKey_ == nextKey) return;  // the same item again keeps its images
  render::TextureRegistry& textures = context_.renderer.textures();
  std::vector<std::string> now = textures.names();
  if (!itemKey_.empty() || !nextKey.empty()) {
    for (const std::string& name : now) {
      if (std::binary_search(texturesBeforeItem_.begin(), texturesBeforeItem_.end(), name)) continue;
      if (std::any_of(show_->textures.begin(), show_->textures.end(),
                      [&](const LoadedTexture& t) { return t.name == name; })) {
        continue;  // the manifest's: the director's own
      }
      textures.remove(name);
    }
  }
  itemKey_ = nextKey;
  texturesBeforeItem_ = textures.names();  // sorted
}

Result<void> ShowDirector::afterDraw(const FrameContext& frame, render::Output& output) {
  if (player_) {
    // Items that draw over the scene (a movie's picture) do it before anything reads the frame.
    if (auto r = player_->afterDraw(frame, output); !r) {
      log::error(kLogDirector, "'{}' stopped: {}; moving on", policy_->current().item->name, r.error().describe());
      policy_->itemFailed(frame.time);
      applyProgramme(frame.time);
    }
  }
  std::shared_ptr<SnapshotRequest> request;
  if (!context_.board.snapshotRequests().pop(request)) return {};
  Image image;
  const auto read = output.readBack(image);
  do {
    if (read) {
      request->answer(true, image, {});
    } else {
      request->answer(false, {}, read.error().describe());
    }
  } while (context_.board.snapshotRequests().pop(request));
  return {};
}

void ShowDirector::afterPresent(const FrameContext& /*frame*/) {
  // LAVA's performance meter, published when it has taken a new sample (every 2 s).
  const runtime::PerformanceMeter& meter = context_.show.performance();
  if (meter.updates != performanceUpdates_ && meter.updates > 0) {
    performanceUpdates_ = meter.updates;
    context_.board.publishPerformance(meter);
  }
  // A view that draws nothing: /health says so while it lasts (copied only when it changes).
  if (views_ && views_->problemsVersion() != viewProblemsSeen_) {
    viewProblemsSeen_ = views_->problemsVersion();
    context_.board.setViewProblems(views_->problems());
  }
  if (texturesPending_) {
    texturesPending_ = false;
    loadTexturesInBackground();
  }
}

void ShowDirector::publishShow() {
  const Programme& p = policy_->current();
  ShowStatus s;
  s.name = show_->manifest.name;
  s.manifest = show_->manifest.file.string();
  s.output = context_.output.describe();
  s.open = p.mode != KioskMode::kClosed;
  s.mode = std::string(kioskModeName(p.mode));
  s.display = std::string(displayStateName(p.display));
  s.item = p.item ? p.item->name : std::string();
  s.index = p.item ? p.index + 1 : 0;
  s.count = p.count;
  s.description = policy_->describe();
  s.schedule = scheduleForStatus_;
  context_.board.publishShow(std::move(s));
}

void ShowDirector::publishDevices() {
  std::vector<DeviceStatus> out;
  const WallTime wall = context_.clock.wallNow();
  for (const DeviceSlot& slot : show_->devices) {
    DeviceStatus d;
    d.name = slot.spec.name;
    d.kind = std::string(deviceKindName(slot.spec.kind));
    d.backend = std::string(deviceBackendName(slot.spec.backend));
    d.state = slot.id != 0 ? std::string(devices::deviceStateName(slot.state)) : "absent";
    d.message = !slot.message.empty() || slot.id == 0 ? slot.message
                                                      : (slot.deviceName.empty() ? slot.spec.name : slot.deviceName);
    d.since = slot.since;
    if (slot.spec.kind == DeviceKind::kCamera) cameraRow(d, slot);
    if (d.since == WallTime{}) d.since = wall;
    out.push_back(std::move(d));
  }
  context_.board.publishDevices(std::move(out));
}

void ShowDirector::cameraRow(DeviceStatus& d, const DeviceSlot& slot) const {
  // A camera is opened by the texture stream of the media that shows it: its row is that
  // stream's state.
  for (const LoadedTexture& t : show_->textures) {
    const MediaSpec* media = t.source.empty() ? nullptr : show_->manifest.findMedia(t.source);
    if (!media || media->kind != MediaKind::kCamera || media->device != slot.spec.name) continue;
    if (t.deviceState) {
      d.state =
          *t.deviceState == SourceState::kLive ? "live" : (*t.deviceState == SourceState::kLost ? "lost" : "absent");
    } else {
      d.state = t.live ? "live" : (t.stream ? "lost" : "absent");
    }
    d.message = t.stream ? fmt::format("shown by texture '{}': {}", t.name, t.stream->describe())
                         : fmt::format("texture '{}': {}", t.name, t.streamState);
    d.since = t.since;
    return;
  }
  if (!slot.unavailable.empty()) return;  // this build cannot open it: absent, saying why
  d.state = "idle";
  d.message =
      "no texture shows it (a [textures.NAME] with source = a camera [media] naming it); a LAVA script's "
      "video texture opens it itself";
}

void ShowDirector::publishStreams() {
  std::vector<StreamStatus> out;
  const WallTime wall = context_.clock.wallNow();
  for (const LoadedTexture& t : show_->textures) {
    if (t.source.empty()) continue;
    const MediaSpec* media = show_->manifest.findMedia(t.source);
    if (!media || media->kind == MediaKind::kImage) continue;
    StreamStatus s;
    s.name = t.source;
    s.kind = std::string(mediaKindName(media->kind));
    s.state = t.live ? "playing" : (t.stream ? "waiting" : "absent");
    // A camera that is gone while its texture shows the on_loss picture is not playing.
    if (t.deviceState == SourceState::kLost) s.state = "lost";
    if (t.deviceState == SourceState::kWaiting) s.state = "waiting";
    // Its content is broken (a movie file emptied, cut short or deleted): it waits for a good file.
    if (t.degraded) s.state = "degraded";
    s.message = t.stream ? t.stream->describe() : t.streamState;
    if (!t.live) s.message += t.image ? "; showing the fallback image" : "; showing black";
    s.since = t.since == WallTime{} ? wall : t.since;
    out.push_back(std::move(s));
  }
  context_.board.publishStreams(std::move(out));
}

}  // namespace basalt::kiosk
