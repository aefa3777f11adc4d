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

// ManagedVideoStream

FrameRef ManagedVideoStream::frameAt(Nanos showTime) {
  std::shared_ptr<VideoSource> source;
  {
    std::lock_guard lock(mutex_);
    source = source_;
  }
  return source ? source->frameAt(showTime) : FrameRef{};
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
}

void ManagedVideoStream::detach(SourceState state, Nanos since) {
  std::shared_ptr<VideoSource> old;
  {
    std::lock_guard lock(mutex_);
    old = std::move(source_);
    idle_ = {state, since};
  }
}

// DeviceManager

DeviceManager::DeviceManager(const Clock& clock, BoundedQueue<Event>& events)
    : DeviceManager(clock, events, Config{}) {}

DeviceManager::DeviceManager(const Clock& clock, BoundedQueue<Event>& events, Config config)
    : clock_(clock), events_(events), config_(config) {}

DeviceManager::~DeviceManager() { stop(); }

void DeviceManager::addProvider(std::unique_ptr<DeviceProvider> provider) {
  provider->watchHotplug([this](HotplugEvent e) { notifyHotplug(std::move(e)); });
  providers_.push_back(std::move(provider));
}

Result<DeviceId> DeviceManager::request(DeviceRequest request) {
  for (const auto& s : slots_) {
    if (s->request.name == request.name) {
      return fail(Errc::kInvalidArgument,
                  fmt::format("two devices are named '{}'; give each device of the show its own name", request.name));
    }
  }
  auto slot = std::make_unique<Slot>();
  slot->id = nextId_++;
  slot->since = clock_.now();
  if (request.kind == DeviceKind::kVideoSource) {
    slot->stream = std::make_shared<ManagedVideoStream>();
    slot->stream->detach(SourceState::kWaiting, slot->since);
    std::lock_guard lock(mutex_);
    streams_[request.name] = slot->stream;
  }
  slot->request = std::move(request);
  const DeviceId id = slot->id;
  slots_.push_back(std::move(slot));
  publish();
  return id;
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
  std::lock_guard lock(mutex_);
  reportTap_ = reports;
  frameTap_ = frames;
  tapsChanged_ = true;
}

bool DeviceManager::pathInUse(const Slot& except, const std::string& path) const {
  return std::any_of(slots_.begin(), slots_.end(), [&](const auto& s) {
    return s.get() != &except && (s->state == DeviceState::kLive) && s->device.path == path;
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
  FrameTap* frameTap = nullptr;
  {
    std::lock_guard lock(mutex_);
    reportTap = reportTap_;
    frameTap = frameTap_;
  }
  std::string error;
  bool matched = false;
  for (const auto& provider : providers_) {
    if (!slot.request.match.backend.empty() && provider->backend() != slot.request.match.backend) continue;
    for (const DeviceCandidate& c : provider->enumerate()) {
      if (c.kind != slot.request.kind || !slot.request.match.matches(c.info) || pathInUse(slot, c.info.path)) continue;
      matched = true;
      if (slot.request.kind == DeviceKind::kDialBox) {
        auto dial = provider->openDialBox(c, slot.request, clock_);
        if (dial) {
          (*dial)->setReportTap(reportTap);
          if (auto r = (*dial)->open(slot.id, events_); r) {
            slot.dial = std::move(*dial);
            slot.device = slot.dial->info();
          } else {
            error = r.error().describe();
          }
        } else {
          error = dial.error().describe();
        }
      } else {
        auto video = provider->openVideoSource(c, slot.request, clock_);
        if (video) {
          (*video)->setFrameTap(frameTap);
          auto r = (*video)->setControls(slot.request.controls);
          if (r) r = (*video)->open(slot.id);
          if (r) {
            slot.video = std::move(*video);
            slot.device = slot.video->info();
            slot.stream->attach(slot.video);
          } else {
            error = r.error().describe();
          }
        } else {
          error = video.error().describe();
        }
      }
      if (slot.dial || slot.video) break;
    }
    if (slot.dial || slot.video) break;
  }
  if (slot.dial || slot.video) {
    log::info(kLogDevices, "{} '{}': {} is live{}", deviceKindName(slot.request.kind), slot.request.name,
              describeDevice(slot.device), wasLost ? " again" : "");
    slot.attempts = 0;
    slot.backoff = Nanos{0};
    slot.lastError.clear();
    transition(slot, DeviceState::kLive, now);
    return;
  }
  if (!matched) {
    error = fmt::format("no device matches {}; is it plugged in? ('basalt devices' lists what is connected)",
                        slot.request.match.describe());
  }
  if (slot.attempts == 0 || error != slot.lastError) {
    log::warn(kLogDevices, "{} '{}' is not available: {}; trying again", deviceKindName(slot.request.kind),
              slot.request.name, error);
  }
  slot.lastError = std::move(error);
  ++slot.attempts;
  slot.backoff = slot.backoff.count() == 0 ? config_.firstBackoff : std::min(slot.backoff * 2, config_.maxBackoff);
  slot.nextAttempt = now + slot.backoff;
  transition(slot, wasLost ? DeviceState::kLost : DeviceState::kAbsent, now);
}

void DeviceManager::markLost(Slot& slot, Nanos now, std::string why) {
  log::warn(kLogDevices, "{} '{}' lost: {}: {}; reconnecting by itself", deviceKindName(slot.request.kind),
            slot.request.name, describeDevice(slot.device), why);
  if (slot.dial) {
    slot.dial->close();
    slot.dial.reset();
  }
  if (slot.video) {
    slot.stream->detach(SourceState::kLost, now);
    slot.video->close();
    slot.video.reset();
  }
  slot.lastError = std::move(why);
  slot.backoff = config_.firstBackoff;
  slot.nextAttempt = now + config_.firstBackoff;
  transition(slot, DeviceState::kLost, now);
}

void DeviceManager::step(Nanos now) {
  std::vector<HotplugEvent> hotplug;
  bool tapsChanged = false;
  ReportTap* reportTap = nullptr;
  FrameTap* frameTap = nullptr;
  {
    std::lock_guard lock(mutex_);
    if (!hotplug_.empty()) hotplug.swap(hotplug_);
    tapsChanged = std::exchange(tapsChanged_, false);
    reportTap = reportTap_;
    frameTap = frameTap_;
  }
  bool changed = false;
  for (const HotplugEvent& h : hotplug) {
    for (auto& s : slots_) {
      if (h.action == HotplugEvent::Action::kRemoved) {
        if (s->state == DeviceState::kLive && !h.devnode.empty() && s->device.path == h.devnode) {
          markLost(*s, now, fmt::format("{} was unplugged", h.devnode));
          changed = true;
        }
      } else if (s->state == DeviceState::kAbsent || s->state == DeviceState::kLost) {
        s->nextAttempt = now;  // something appeared: look at once instead of waiting out the back-off
      }
    }
  }
  for (auto& sp : slots_) {
    Slot& s = *sp;
    if (s.state == DeviceState::kLive) {
      if (tapsChanged) {
        if (s.dial) s.dial->setReportTap(reportTap);
        if (s.video) s.video->setFrameTap(frameTap);
      }
      if (s.dial) {
        s.dial->service(now);
        if (s.dial->state() == DeviceState::kLost) {
          const auto why = s.dial->lostReason();
          markLost(s, now, why ? why->describe() : "the device stopped answering");
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

void DeviceManager::publish() {
  std::vector<DeviceStatus> out;
  out.reserve(slots_.size());
  for (const auto& sp : slots_) {
    const Slot& s = *sp;
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
    if (s.dial && s.state == DeviceState::kLive) st.reportDescriptor = s.dial->reportDescriptor();
    if (s.video && s.state == DeviceState::kLive) st.mode = s.video->mode();
    if (s.video && s.state == DeviceState::kLive && s.video->state() != DeviceState::kLive) {
      // The device itself is lost but recovering (an HDMI signal gone): show its state.
      st.state = s.video->state();
      st.since = s.video->stateSince();
      if (auto why = s.video->lostReason()) st.lastError = why->describe();
    }
    out.push_back(std::move(st));
  }
  std::lock_guard lock(mutex_);
  status_ = std::move(out);
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

DialBox* DeviceManager::dialBox(std::string_view name) const {
  for (const auto& s : slots_) {
    if (s->request.name == name) return s->dial.get();
  }
  return nullptr;
}

std::shared_ptr<VideoSource> DeviceManager::videoSource(std::string_view name) const {
  for (const auto& s : slots_) {
    if (s->request.name == name) return s->video;
  }
  return nullptr;
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
      wake_.wait_for(lock, period, [this] { return stopping_ || !hotplug_.empty(); });
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
    if (s->dial) s->dial->close();
    if (s->video) {
      s->stream->detach(SourceState::kWaiting, now);
      s->video->close();
    }
    s->dial.reset();
    s->video.reset();
    if (s->state != DeviceState::kAbsent) {
      s->state = DeviceState::kAbsent;
      s->since = now;
    }
  }
  publish();
}

}  // namespace basalt::devices
