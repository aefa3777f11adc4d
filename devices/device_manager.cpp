#include "devices/device_manager.h"

#include <algorithm>
#include <cctype>
#include <charconv>

#include <fmt/format.h>

#include "runtime/log.h"

namespace basalt::devices {

BASALT_LOG_CATEGORY(Devices, "devices");

namespace {

bool containsNoCase(std::string_view haystack, std::string_view needle) {
  if (needle.empty()) return true;
  auto lower = [](char c) { return static_cast<char>(std::tolower(static_cast<unsigned char>(c))); };
  return std::search(haystack.begin(), haystack.end(), needle.begin(), needle.end(),
                     [&](char a, char b) { return lower(a) == lower(b); }) != haystack.end();
}

}  // namespace

bool DeviceMatch::matches(const DeviceInfo& info) const {
  if (!backend.empty() && backend != info.backend) return false;
  if (vendor && *vendor != info.vendor) return false;
  if (product && *product != info.product) return false;
  if (!containsNoCase(info.name, name)) return false;
  if (!path.empty() && path != info.path) return false;
  if (!serial.empty() && serial != info.serial) return false;
  return true;
}

std::string DeviceMatch::describe() const {
  std::string text = backend.empty() ? "any backend" : backend;
  if (vendor || product) {
    text += fmt::format(" {}:{}", vendor ? fmt::format("{:04x}", *vendor) : "*",
                        product ? fmt::format("{:04x}", *product) : "*");
  }
  if (!name.empty()) text += fmt::format(" named \"{}\"", name);
  if (!path.empty()) text += fmt::format(" at {}", path);
  if (!serial.empty()) text += fmt::format(" serial {}", serial);
  return text;
}

Result<void> parseVendorProduct(std::string_view text, DeviceMatch& match) {
  const auto colon = text.find(':');
  auto hex = [](std::string_view s, std::optional<std::uint16_t>& out) {
    if (s.empty() || s == "*") return true;
    unsigned v = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v, 16);
    if (ec != std::errc{} || end != s.data() + s.size() || v > 0xffff) return false;
    out = static_cast<std::uint16_t>(v);
    return true;
  };
  if (colon == std::string_view::npos || !hex(text.substr(0, colon), match.vendor) ||
      !hex(text.substr(colon + 1), match.product)) {
    return fail(Errc::kInvalidArgument,
                fmt::format("'{}' is not VENDOR:PRODUCT in hexadecimal, e.g. 077d:0410 (see 'basalt devices')", text));
  }
  return {};
}

Result<std::unique_ptr<DialBox>> DeviceProvider::openDialBox(const DeviceCandidate& candidate, const DeviceRequest&,
                                                             const Clock&) {
  return fail(Errc::kUnsupported, fmt::format("the {} backend has no dial boxes", backend()),
              describeDevice(candidate.info));
}

Result<std::shared_ptr<VideoSource>> DeviceProvider::openVideoSource(const DeviceCandidate& candidate,
                                                                     const DeviceRequest&, const Clock&) {
  return fail(Errc::kUnsupported, fmt::format("the {} backend has no video sources", backend()),
              describeDevice(candidate.info));
}

Result<std::unique_ptr<Tracker>> DeviceProvider::openTracker(const DeviceCandidate& candidate, const DeviceRequest&,
                                                             const Clock&) {
  return fail(Errc::kUnsupported, fmt::format("the {} backend has no trackers", backend()),
              describeDevice(candidate.info));
}

// ManagedVideoStream

FrameRef ManagedVideoStream::frameAt(Nanos showTime) {
  std::shared_ptr<VideoSource> source;
  {
    std::lock_guard lock(mutex_);
    if (!source_) return {};
    // Another reader (a second texture of the same camera) asked for this frame already.
    if (showTime == lastAt_) return last_;
    source = source_;
  }
  FrameRef frame = source->frameAt(showTime);
  std::lock_guard lock(mutex_);
  if (source_ == source) {
    last_ = frame;
    lastAt_ = showTime;
  }
  return frame;
}

SourceHealth ManagedVideoStream::health() const {
  std::lock_guard lock(mutex_);
  return source_ ? source_->health() : idle_;
}

std::optional<VideoMode> ManagedVideoStream::mode() const {
  std::lock_guard lock(mutex_);
  if (!source_) return std::nullopt;
  return source_->mode();
}

bool ManagedVideoStream::mirrorInRenderer() const {
  std::lock_guard lock(mutex_);
  return source_ && source_->mirrorInRenderer();
}

void ManagedVideoStream::attach(std::shared_ptr<VideoSource> source) {
  std::lock_guard lock(mutex_);
  source_ = std::move(source);
  last_.reset();
  lastAt_ = Nanos{-1};
}

void ManagedVideoStream::detach(SourceState state, Nanos since) {
  std::shared_ptr<VideoSource> old;
  FrameRef frame;
  {
    std::lock_guard lock(mutex_);
    old = std::move(source_);
    frame = std::move(last_);
    lastAt_ = Nanos{-1};
    idle_ = {state, since};
  }
}

// DeviceManager

/// Every frame of one video request goes to the recorder's tap (if any) and to the taps its
/// users added (a camera's MJPEG decoder). Called on the producer's thread.
class DeviceManager::FrameFanOut final : public FrameTap {
 public:
  explicit FrameFanOut(const std::atomic<FrameTap*>& recorder) : recorder_(recorder) {}

  void onFrame(DeviceId device, const FrameRef& frame) override {
    if (FrameTap* recorder = recorder_.load(std::memory_order_acquire)) recorder->onFrame(device, frame);
    std::lock_guard lock(mutex_);
    for (const auto& tap : taps_) tap->onFrame(device, frame);
  }
  void add(std::shared_ptr<FrameTap> tap) {
    std::lock_guard lock(mutex_);
    taps_.push_back(std::move(tap));
  }
  void remove(const FrameTap* tap) {
    std::lock_guard lock(mutex_);
    std::erase_if(taps_, [tap](const auto& t) { return t.get() == tap; });
  }

 private:
  const std::atomic<FrameTap*>& recorder_;
  std::mutex mutex_;                             // guards taps_
  std::vector<std::shared_ptr<FrameTap>> taps_;  // guarded by mutex_
};

DeviceManager::DeviceManager(const Clock& clock, BoundedQueue<Event>& events)
    : DeviceManager(clock, events, Config{}) {}

DeviceManager::DeviceManager(const Clock& clock, BoundedQueue<Event>& events, Config config)
    : clock_(clock), events_(events), config_(config), nextId_(config.firstId) {}

DeviceManager::~DeviceManager() { stop(); }

void DeviceManager::addProvider(std::unique_ptr<DeviceProvider> provider) {
  provider->watchHotplug([this](HotplugEvent e) { notifyHotplug(std::move(e)); });
  providers_.push_back(std::move(provider));
}

Result<DeviceId> DeviceManager::request(DeviceRequest request, std::unique_ptr<DeviceProvider> provider,
                                        Upkeep upkeep) {
  auto slot = std::make_unique<Slot>();
  slot->since = clock_.now();
  slot->frames = std::make_shared<FrameFanOut>(frameTap_);
  if (request.kind == DeviceKind::kVideoSource) {
    slot->stream = std::make_shared<ManagedVideoStream>();
    slot->stream->detach(SourceState::kWaiting, slot->since);
  }
  if (request.kind == DeviceKind::kTracker) slot->samples = std::make_shared<TrackerSamples>();
  if (provider) provider->watchHotplug([this](HotplugEvent e) { notifyHotplug(std::move(e)); });
  slot->provider = std::move(provider);
  slot->request = std::move(request);
  slot->upkeep = upkeep;
  DeviceId id = 0;
  {
    std::lock_guard lock(mutex_);
    const std::string& name = slot->request.name;
    if (held_.contains(name)) {
      return fail(Errc::kInvalidArgument,
                  fmt::format("two devices are named '{}'; give each device of the show its own name", name));
    }
    id = nextId_++;
    slot->id = id;
    held_.emplace(name, Held{id, 1, slot->frames});
    if (slot->stream) streams_[name] = slot->stream;
    if (slot->samples) samples_[name] = slot->samples;
    status_.push_back(statusOf(*slot));
    incoming_.push_back(std::move(slot));
  }
  statusVersion_.fetch_add(1, std::memory_order_acq_rel);
  wake_.notify_all();
  return id;
}

Result<DeviceId> DeviceManager::share(std::string_view name) {
  std::lock_guard lock(mutex_);
  const auto it = held_.find(name);
  if (it == held_.end()) return fail(Errc::kNotFound, fmt::format("no device '{}' is requested", name));
  ++it->second.users;
  return it->second.id;
}

void DeviceManager::withdraw(std::string_view name) {
  std::unique_ptr<Slot> unopened;  // destroyed after the lock: its provider may do I/O
  {
    std::lock_guard lock(mutex_);
    const auto it = held_.find(name);
    if (it == held_.end() || --it->second.users > 0) return;
    const DeviceId id = it->second.id;
    held_.erase(it);
    if (const auto s = streams_.find(name); s != streams_.end()) streams_.erase(s);
    if (const auto s = samples_.find(name); s != samples_.end()) samples_.erase(s);
    std::erase_if(status_, [id](const DeviceStatus& st) { return st.id == id; });
    const auto waiting = std::find_if(incoming_.begin(), incoming_.end(), [id](const auto& s) { return s->id == id; });
    if (waiting != incoming_.end()) {
      unopened = std::move(*waiting);
      incoming_.erase(waiting);
    } else {
      withdrawn_.push_back(id);
    }
  }
  statusVersion_.fetch_add(1, std::memory_order_acq_rel);
  wake_.notify_all();
}

bool DeviceManager::restart(std::string_view name) {
  {
    std::lock_guard lock(mutex_);
    const auto it = held_.find(name);
    if (it == held_.end()) return false;
    restarts_.push_back(it->second.id);
  }
  wake_.notify_all();
  return true;
}

void DeviceManager::notifyHotplug(HotplugEvent event) {
  {
    std::lock_guard lock(mutex_);
    if (hotplug_.size() >= 256) hotplug_.erase(hotplug_.begin());
    hotplug_.push_back(std::move(event));
  }
  wake_.notify_all();
}

void DeviceManager::setTaps(ReportTap* reports, FrameTap* frames) {
  {
    std::lock_guard lock(mutex_);
    reportTap_ = reports;
    tapsChanged_ = true;
  }
  frameTap_.store(frames, std::memory_order_release);
}

void DeviceManager::addFrameTap(std::string_view name, std::shared_ptr<FrameTap> tap) {
  std::lock_guard lock(mutex_);
  if (const auto it = held_.find(name); it != held_.end()) it->second.frames->add(std::move(tap));
}

void DeviceManager::removeFrameTap(std::string_view name, const FrameTap* tap) {
  std::lock_guard lock(mutex_);
  if (const auto it = held_.find(name); it != held_.end()) it->second.frames->remove(tap);
}

bool DeviceManager::pathInUse(const Slot& except, const DeviceProvider* provider, const std::string& path) const {
  // Only devices found through the same backend object can be the same device: a request with a
  // backend of its own (a synthetic script, a replayed file) has its devices to itself.
  return std::any_of(slots_.begin(), slots_.end(), [&](const auto& s) {
    return s.get() != &except && s->state == DeviceState::kLive && s->foundBy == provider && s->device.path == path;
  });
}

void DeviceManager::transition(Slot& slot, DeviceState state, Nanos now) {
  if (slot.state == state) return;
  slot.state = state;
  slot.since = now;
  if (state == DeviceState::kLive || state == DeviceState::kLost) {
    // Tell the bindings (a lost dial box goes quiet; shuttles stop) in the event stream itself.
    events_.push(Event{now, slot.id, EventKind::kDeviceState, 0, state == DeviceState::kLive ? 1.0 : 0.0});
  }
}

void DeviceManager::tryOpen(Slot& slot, Nanos now) {
  const bool wasLost = slot.state == DeviceState::kLost;
  transition(slot, wasLost ? DeviceState::kReopening : DeviceState::kOpening, now);
  publish();
  ReportTap* reportTap = nullptr;
  {
    std::lock_guard lock(mutex_);
    reportTap = reportTap_;
  }
  std::string reasons;  // why the devices that match cannot be used
  bool matched = false;
  const auto tryProvider = [&](DeviceProvider& provider) {
    for (const DeviceCandidate& c : provider.enumerate()) {
      if (c.kind != slot.request.kind || !slot.request.match.matches(c.info) ||
          pathInUse(slot, &provider, c.info.path)) {
        continue;
      }
      matched = true;
      if (!c.problem.empty()) {
        // Known in advance (not a dial, no permission): not worth an open.
        reasons += fmt::format("; {}: {}", describeDevice(c.info), c.problem);
        continue;
      }
      if (slot.request.kind == DeviceKind::kDialBox) {
        auto dial = provider.openDialBox(c, slot.request, clock_);
        if (!dial) {
          reasons += "; " + dial.error().describe();
          continue;
        }
        (*dial)->setReportTap(reportTap);
        if (auto r = (*dial)->open(slot.id, events_); !r) {
          reasons += "; " + r.error().describe();
          continue;
        }
        slot.dial = std::move(*dial);
        slot.device = slot.dial->info();
      } else if (slot.request.kind == DeviceKind::kTracker) {
        auto tracker = provider.openTracker(c, slot.request, clock_);
        if (!tracker) {
          reasons += "; " + tracker.error().describe();
          continue;
        }
        (*tracker)->setReportTap(reportTap);
        if (auto r = (*tracker)->open(slot.id, *slot.samples); !r) {
          reasons += "; " + r.error().describe();
          continue;
        }
        slot.tracker = std::move(*tracker);
        slot.device = slot.tracker->info();
      } else {
        auto video = provider.openVideoSource(c, slot.request, clock_);
        if (!video) {
          reasons += "; " + video.error().describe();
          continue;
        }
        (*video)->setFrameTap(slot.frames.get());
        auto r = (*video)->setControls(slot.request.controls);
        if (r) r = (*video)->open(slot.id);
        if (!r) {
          reasons += "; " + r.error().describe();
          continue;
        }
        slot.video = std::move(*video);
        slot.device = slot.video->info();
        slot.stream->attach(slot.video);
      }
      slot.foundBy = &provider;
      return true;
    }
    return false;
  };
  if (slot.provider) {
    (void)tryProvider(*slot.provider);
  } else {
    for (const auto& provider : providers_) {
      if (!slot.request.match.backend.empty() && provider->backend() != slot.request.match.backend) continue;
      if (tryProvider(*provider)) break;
    }
  }
  if (slot.dial || slot.video || slot.tracker) {
    if (!slot.upkeep.quiet) {
      log::info(kLogDevices, "{} '{}': {} is live{}", deviceKindName(slot.request.kind), slot.request.name,
                describeDevice(slot.device), wasLost ? " again" : "");
    }
    slot.attempts = 0;
    slot.backoff = Nanos{0};
    slot.lastError.clear();
    transition(slot, DeviceState::kLive, now);
    return;
  }
  const std::string rule = slot.request.match.backend.empty()
                               ? fmt::format("device ({})", slot.request.match.describe())
                               : slot.request.match.describe();
  std::string error =
      matched
          ? fmt::format("{} found but not usable{}", rule, reasons)
          : fmt::format("no {} is plugged in: no device matches it ('basalt devices' lists what is connected)", rule);
  if (!slot.upkeep.quiet && (slot.attempts == 0 || error != slot.lastError)) {
    log::warn(kLogDevices, "{} '{}' is not available: {}; trying again", deviceKindName(slot.request.kind),
              slot.request.name, error);
  }
  slot.lastError = std::move(error);
  ++slot.attempts;
  const Backoff backoff = slot.upkeep.backoff.value_or(Backoff{config_.firstBackoff, config_.maxBackoff});
  slot.backoff = slot.backoff.count() == 0 ? backoff.first : std::min(slot.backoff * 2, backoff.max);
  slot.nextAttempt = now + slot.backoff;
  transition(slot, wasLost ? DeviceState::kLost : DeviceState::kAbsent, now);
}

void DeviceManager::closeDevice(Slot& slot, SourceState streamState, Nanos now) {
  if (slot.dial) {
    slot.dial->close();
    slot.dial.reset();
  }
  if (slot.tracker) {
    slot.tracker->close();
    slot.tracker.reset();
  }
  if (slot.video) {
    slot.stream->detach(streamState, now);
    slot.video->close();
    slot.video.reset();
  }
  slot.foundBy = nullptr;
}

void DeviceManager::markLost(Slot& slot, Nanos now, std::string why) {
  if (!slot.upkeep.quiet) {
    log::warn(kLogDevices, "{} '{}' lost: {}: {}; reconnecting by itself", deviceKindName(slot.request.kind),
              slot.request.name, describeDevice(slot.device), why);
  }
  closeDevice(slot, SourceState::kLost, now);
  slot.lastError = std::move(why);
  const Backoff backoff = slot.upkeep.backoff.value_or(Backoff{config_.firstBackoff, config_.maxBackoff});
  slot.backoff = backoff.first;
  slot.nextAttempt = now + backoff.first;
  transition(slot, DeviceState::kLost, now);
}

DeviceManager::Slot* DeviceManager::slotNamed(std::string_view name) const {
  DeviceId id = 0;
  {
    std::lock_guard lock(mutex_);
    const auto it = held_.find(name);
    if (it == held_.end()) return nullptr;
    id = it->second.id;
  }
  for (const auto& s : slots_) {
    if (s->id == id) return s.get();
  }
  return nullptr;
}

void DeviceManager::step(Nanos now) {
  std::vector<HotplugEvent> hotplug;
  std::vector<std::unique_ptr<Slot>> incoming;
  std::vector<DeviceId> withdrawn;
  std::vector<DeviceId> restarts;
  bool tapsChanged = false;
  ReportTap* reportTap = nullptr;
  {
    std::lock_guard lock(mutex_);
    if (!hotplug_.empty()) hotplug.swap(hotplug_);
    if (!incoming_.empty()) incoming.swap(incoming_);
    if (!withdrawn_.empty()) withdrawn.swap(withdrawn_);
    if (!restarts_.empty()) restarts.swap(restarts_);
    tapsChanged = std::exchange(tapsChanged_, false);
    reportTap = reportTap_;
  }
  bool changed = false;
  // Withdrawn first: a request made again under the same name may want the same device.
  for (const DeviceId id : withdrawn) {
    const auto it = std::find_if(slots_.begin(), slots_.end(), [id](const auto& s) { return s->id == id; });
    if (it == slots_.end()) continue;
    closeDevice(**it, SourceState::kWaiting, now);
    slots_.erase(it);
    changed = true;
  }
  for (auto& s : incoming) slots_.push_back(std::move(s));
  changed = changed || !incoming.empty();
  for (const HotplugEvent& h : hotplug) {
    for (auto& s : slots_) {
      if (h.action == HotplugEvent::Action::kRemoved) {
        if (s->state == DeviceState::kLive && !h.devnode.empty() && s->device.path == h.devnode) {
          markLost(*s, now, fmt::format("{} was unplugged", h.devnode));
          changed = true;
        }
      } else if (s->state == DeviceState::kAbsent || s->state == DeviceState::kLost) {
        // Something appeared: look at once instead of waiting out the back-off, and start the
        // back-off over.
        s->nextAttempt = now;
        s->backoff = Nanos{0};
      }
    }
  }
  for (const DeviceId id : restarts) {
    const auto it = std::find_if(slots_.begin(), slots_.end(), [id](const auto& s) { return s->id == id; });
    if (it == slots_.end()) continue;
    Slot& s = **it;
    if (s.state == DeviceState::kLive) {
      // Its bindings let go, as for any loss; the open below may bring it back at once.
      closeDevice(s, SourceState::kLost, now);
      transition(s, DeviceState::kLost, now);
    }
    s.backoff = Nanos{0};
    tryOpen(s, now);
    ++s.restarts;
    changed = true;
  }
  for (auto& sp : slots_) {
    Slot& s = *sp;
    if (s.state == DeviceState::kLive) {
      if (tapsChanged && s.dial) s.dial->setReportTap(reportTap);
      if (s.dial) {
        s.dial->service(now);
        if (s.dial->state() != DeviceState::kLive) {
          // Lost (a read error, an unplug), or closed under the manager's feet: either way gone.
          const auto why = s.dial->lostReason();
          markLost(s, now, why ? why->describe() : "the device stopped answering");
          changed = true;
        }
      } else if (s.tracker) {
        if (tapsChanged) s.tracker->setReportTap(reportTap);
        s.tracker->service(now);
        if (s.tracker->state() != DeviceState::kLive) {
          const auto why = s.tracker->lostReason();
          markLost(s, now, why ? why->describe() : "the tracker stopped answering");
          changed = true;
        }
      } else if (s.video) {
        const DeviceState before = s.video->state();
        s.video->service(now);
        const DeviceState after = s.video->state();
        if (after == DeviceState::kLost && !s.video->recovering()) {
          const auto why = s.video->lostReason();
          markLost(s, now, why ? why->describe() : "the device stopped delivering frames");
          changed = true;
        } else if (after != before) {
          changed = true;
        }
      }
    } else if ((s.state == DeviceState::kAbsent || s.state == DeviceState::kLost) && now >= s.nextAttempt) {
      tryOpen(s, now);
      changed = true;
    }
  }
  if (changed) publish();
}

DeviceStatus DeviceManager::statusOf(const Slot& s) const {
  DeviceStatus st;
  st.name = s.request.name;
  st.kind = s.request.kind;
  st.state = s.state;
  st.since = s.since;
  st.id = s.id;
  st.device = s.device;
  st.match = s.request.match.describe();
  st.lastError = s.lastError;
  st.attempts = s.attempts;
  st.nextAttempt = s.nextAttempt;
  st.restarts = s.restarts;
  if (s.dial && s.state == DeviceState::kLive) st.reportDescriptor = s.dial->reportDescriptor();
  if (s.tracker && s.state == DeviceState::kLive) st.reportDescriptor = s.tracker->reportDescriptor();
  if (s.video && s.state == DeviceState::kLive) st.mode = s.video->mode();
  if (s.video && s.state == DeviceState::kLive && s.video->state() != DeviceState::kLive) {
    // The device itself is lost but recovering (an HDMI signal gone): show its state.
    st.state = s.video->state();
    st.since = s.video->stateSince();
    if (auto why = s.video->lostReason()) st.lastError = why->describe();
  }
  return st;
}

void DeviceManager::publish() {
  std::vector<DeviceStatus> out;
  out.reserve(slots_.size());
  for (const auto& sp : slots_) out.push_back(statusOf(*sp));
  {
    std::lock_guard lock(mutex_);
    // Requests withdrawn or made since this step began show as they are now.
    std::erase_if(out, [this](const DeviceStatus& st) {
      return std::find(withdrawn_.begin(), withdrawn_.end(), st.id) != withdrawn_.end();
    });
    for (const auto& s : incoming_) out.push_back(statusOf(*s));
    status_ = std::move(out);
  }
  statusVersion_.fetch_add(1, std::memory_order_acq_rel);
}

std::vector<DeviceStatus> DeviceManager::status() const {
  std::lock_guard lock(mutex_);
  return status_;
}

std::shared_ptr<ManagedVideoStream> DeviceManager::videoStream(std::string_view name) const {
  std::lock_guard lock(mutex_);
  const auto it = streams_.find(name);
  return it == streams_.end() ? nullptr : it->second;
}

std::shared_ptr<TrackerSamples> DeviceManager::trackerSamples(std::string_view name) const {
  std::lock_guard lock(mutex_);
  const auto it = samples_.find(name);
  return it == samples_.end() ? nullptr : it->second;
}

Tracker* DeviceManager::tracker(std::string_view name) const {
  const Slot* s = slotNamed(name);
  return s ? s->tracker.get() : nullptr;
}

DialBox* DeviceManager::dialBox(std::string_view name) const {
  const Slot* s = slotNamed(name);
  return s ? s->dial.get() : nullptr;
}

std::shared_ptr<VideoSource> DeviceManager::videoSource(std::string_view name) const {
  const Slot* s = slotNamed(name);
  return s ? s->video : nullptr;
}

void DeviceManager::start(Nanos period) {
  if (thread_.joinable()) return;
  {
    std::lock_guard lock(mutex_);
    stopping_ = false;
  }
  thread_ = std::thread([this, period] {
    for (;;) {
      step(clock_.now());
      std::unique_lock lock(mutex_);
      wake_.wait_for(lock, period, [this] {
        return stopping_ || !hotplug_.empty() || !incoming_.empty() || !withdrawn_.empty() || !restarts_.empty();
      });
      if (stopping_) break;
    }
  });
}

void DeviceManager::stop() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
  closeAll();
}

void DeviceManager::closeAll() {
  const Nanos now = clock_.now();
  for (auto& s : slots_) {
    closeDevice(*s, SourceState::kWaiting, now);
    if (s->state != DeviceState::kAbsent) {
      s->state = DeviceState::kAbsent;
      s->since = now;
    }
  }
  publish();
}

}  // namespace basalt::devices
