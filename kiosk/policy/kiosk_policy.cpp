#include "kiosk/policy/kiosk_policy.h"

#include <fmt/format.h>

namespace basalt::kiosk {

std::string_view kioskModeName(KioskMode mode) {
  switch (mode) {
    case KioskMode::kClosed: return "closed";
    case KioskMode::kAttract: return "attract";
    case KioskMode::kActive: return "active";
  }
  return "?";
}

std::string_view displayStateName(DisplayState state) {
  switch (state) {
    case DisplayState::kOn: return "on";
    case DisplayState::kBlack: return "black";
    case DisplayState::kOff: return "off";
  }
  return "?";
}

KioskPolicy::KioskPolicy(const Manifest& manifest, std::optional<Schedule> schedule)
    : schedule_(std::move(schedule)),
      programme_(manifest.kiosk.playlist),
      attract_(manifest.kiosk.attract.items),
      hasAttract_(manifest.kiosk.attract.present && !manifest.kiosk.attract.items.empty()),
      idleTimeout_(manifest.kiosk.attract.idleTimeout),
      outside_(manifest.kiosk.schedule.outside) {
  if (programme_.empty()) {
    const std::string name = manifest.entry.path.empty() ? manifest.name : manifest.entry.path.filename().string();
    programme_.push_back({name, manifest.entry, Nanos{0}, manifest.entry.line});
  }
  if (manifest.kiosk.schedule.standby) {
    standby_.push_back({"standby", *manifest.kiosk.schedule.standby, Nanos{0}, manifest.kiosk.schedule.standby->line});
  }
}

const std::vector<PlaylistItem>& KioskPolicy::listFor(KioskMode mode) const {
  switch (mode) {
    case KioskMode::kClosed: return standby_;
    case KioskMode::kAttract: return attract_;
    case KioskMode::kActive: return programme_;
  }
  return programme_;
}

void KioskPolicy::play(std::size_t index, Nanos now) {
  const auto& list = listFor(current_.mode);
  current_.count = list.size();
  current_.index = list.empty() ? 0 : index % list.size();
  current_.itemStart = now;
  current_.item = list.empty() ? nullptr : &list[current_.index];
  current_.display = DisplayState::kOn;
  if (current_.mode == KioskMode::kClosed) {
    if (outside_ == OutsideHours::kBlack || !current_.item) current_.display = DisplayState::kBlack;
    if (outside_ == OutsideHours::kDisplayOff) current_.display = DisplayState::kOff;
    if (current_.display != DisplayState::kOn) current_.item = nullptr;
  }
  ++current_.generation;
}

void KioskPolicy::enter(KioskMode mode, std::size_t index, Nanos now) {
  current_.mode = mode;
  failuresInARow_ = 0;
  play(index, now);
}

void KioskPolicy::start(Nanos now, WallTime wall, const std::optional<ResumePoint>& resume) {
  lastInput_ = now;
  const bool open = openAt(wall);
  KioskMode mode = open ? (hasAttract_ ? KioskMode::kAttract : KioskMode::kActive) : KioskMode::kClosed;
  std::size_t index = 0;
  Nanos position{0};
  if (resume && open == (resume->mode != KioskMode::kClosed)) {
    const KioskMode resumed = resume->mode == KioskMode::kAttract && !hasAttract_ ? KioskMode::kActive : resume->mode;
    const auto& list = listFor(resumed);
    if (resume->index < list.size() && list[resume->index].name == resume->item) {
      mode = resumed;
      index = resume->index;
      const Nanos duration = list[index].duration;
      position = duration > Nanos{0} && resume->position >= duration ? Nanos{0} : resume->position;
    }
  }
  enter(mode, index, now);
  current_.itemStart = now - position;
}

bool KioskPolicy::update(Nanos now, WallTime wall) {
  const bool open = openAt(wall);
  if (!open && current_.mode != KioskMode::kClosed) {
    enter(KioskMode::kClosed, 0, now);
    return true;
  }
  if (open && current_.mode == KioskMode::kClosed) {
    lastInput_ = now;
    enter(hasAttract_ ? KioskMode::kAttract : KioskMode::kActive, 0, now);
    return true;
  }
  if (current_.mode == KioskMode::kActive && hasAttract_ && now - lastInput_ >= idleTimeout_) {
    enter(KioskMode::kAttract, 0, now);
    return true;
  }
  if (current_.item && current_.item->duration > Nanos{0} && now - current_.itemStart >= current_.item->duration) {
    failuresInARow_ = 0;
    play(current_.index + 1, now);
    return true;
  }
  return false;
}

bool KioskPolicy::noteInput(Nanos now) {
  if (current_.mode == KioskMode::kClosed) return false;
  lastInput_ = now;
  if (current_.mode == KioskMode::kAttract) {
    enter(KioskMode::kActive, 0, now);
    return true;
  }
  return false;
}

bool KioskPolicy::itemEnded(Nanos now) {
  if (!current_.item) return false;
  failuresInARow_ = 0;
  play(current_.index + 1, now);
  return true;
}

bool KioskPolicy::itemFailed(Nanos now) {
  if (!current_.item) return false;
  ++failuresInARow_;
  if (failuresInARow_ >= current_.count) {
    // Nothing in this list plays: black until the mode changes, never a tight retry loop.
    current_.item = nullptr;
    current_.display = current_.display == DisplayState::kOff ? DisplayState::kOff : DisplayState::kBlack;
    ++current_.generation;
    return true;
  }
  play(current_.index + 1, now);
  return true;
}

bool KioskPolicy::step(int direction, Nanos now) {
  if (current_.mode == KioskMode::kClosed || current_.count < 2) return false;
  if (current_.mode == KioskMode::kActive) lastInput_ = now;
  failuresInARow_ = 0;
  play(direction > 0 ? current_.index + 1 : current_.index + current_.count - 1, now);
  return true;
}

bool KioskPolicy::next(Nanos now) { return step(1, now); }
bool KioskPolicy::previous(Nanos now) { return step(-1, now); }

bool KioskPolicy::follow(KioskMode mode, DisplayState display, bool hasItem, std::size_t index, std::string_view item,
                         Nanos itemStart) {
  const auto& list = listFor(mode);
  std::size_t at = index;
  for (std::size_t i = 0; i < list.size(); ++i) {
    if (list[i].name == item) {
      at = i;
      break;
    }
  }
  const PlaylistItem* playing = hasItem && at < list.size() ? &list[at] : nullptr;
  const std::size_t place = playing ? at : 0;
  if (current_.mode == mode && current_.display == display && current_.item == playing && current_.index == place &&
      current_.itemStart == itemStart) {
    return false;
  }
  current_.mode = mode;
  current_.display = display;
  current_.count = list.size();
  current_.index = place;
  current_.item = playing;
  current_.itemStart = itemStart;
  failuresInARow_ = 0;
  ++current_.generation;
  return true;
}

ResumePoint KioskPolicy::resumePoint(Nanos now) const {
  ResumePoint p;
  p.mode = current_.mode;
  p.index = current_.index;
  p.item = current_.item ? current_.item->name : std::string{};
  p.position = current_.item ? position(now) : Nanos{0};
  return p;
}

std::string KioskPolicy::describe() const {
  const char* state = current_.mode == KioskMode::kClosed ? "closed" : "open";
  if (!current_.item) {
    return fmt::format("{}, {}: display {}", state, kioskModeName(current_.mode), displayStateName(current_.display));
  }
  return fmt::format("{}, {}: '{}' ({}/{})", state,
                     current_.mode == KioskMode::kClosed    ? "standby"
                     : current_.mode == KioskMode::kAttract ? "attract loop"
                                                            : "playing",
                     current_.item->name, current_.index + 1, current_.count);
}

}  // namespace basalt::kiosk
