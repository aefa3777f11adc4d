#include "sim/providers.h"

#include <charconv>

#include <fmt/format.h>

#include "devices/hid/dial_decoder.h"
#include "devices/hid/report_descriptor.h"
#include "devices/hid/tracker_decoder.h"
#include "devices/midi/midi_decoder.h"
#include "sim/midi_file.h"
#include "sim/raw_video.h"
#include "sim/replay.h"
#include "sim/replay_tracker.h"

namespace basalt::sim {

namespace {

std::string optionOr(const devices::DeviceRequest& request, const std::string& key, const std::string& fallback) {
  const auto it = request.options.find(key);
  return it == request.options.end() ? fallback : it->second;
}

std::string where(const devices::DeviceRequest& request) { return fmt::format("device '{}'", request.name); }

}  // namespace

Result<bool> boolOption(const devices::DeviceRequest& request, const std::string& key, bool fallback) {
  const auto it = request.options.find(key);
  if (it == request.options.end()) return fallback;
  if (it->second == "true") return true;
  if (it->second == "false") return false;
  return fail(Errc::kInvalidArgument, fmt::format("option {} must be true or false, not '{}'", key, it->second),
              where(request));
}

Result<void> applyCameraOptions(const devices::DeviceRequest& request, SyntheticCameraConfig& config) {
  const std::string format = optionOr(request, "format", "");
  if (!format.empty()) {
    PixelFormat f = PixelFormat::kUnknown;
    for (int i = 1; i <= static_cast<int>(PixelFormat::kMjpeg); ++i) {
      if (pixelFormatName(static_cast<PixelFormat>(i)) == format) f = static_cast<PixelFormat>(i);
    }
    if (f == PixelFormat::kUnknown) {
      return fail(
          Errc::kInvalidArgument,
          fmt::format("format '{}' is not one of RGBA, BGRA, RGB, GRAY8, I420, YV12, NV12, NV21, YUYV, UYVY, MJPEG",
                      format),
          where(request));
    }
    config.mode.format = f;
  }
  const std::string size = optionOr(request, "size", "");
  if (!size.empty()) {
    unsigned w = 0, h = 0;
    const auto x = size.find('x');
    if (x == std::string::npos || std::from_chars(size.data(), size.data() + x, w).ec != std::errc{} ||
        std::from_chars(size.data() + x + 1, size.data() + size.size(), h).ec != std::errc{} || w == 0 || h == 0 ||
        w > 8192 || h > 8192) {
      return fail(Errc::kInvalidArgument, fmt::format("size '{}' is not WIDTHxHEIGHT, e.g. 640x360", size),
                  where(request));
    }
    config.mode.width = w;
    config.mode.height = h;
  }
  const std::string fps = optionOr(request, "fps", "");
  if (!fps.empty()) {
    double v = 0;
    if (std::from_chars(fps.data(), fps.data() + fps.size(), v).ec != std::errc{} || !(v > 0 && v <= 1000)) {
      return fail(Errc::kInvalidArgument, fmt::format("fps '{}' is not a number from 1 to 1000", fps), where(request));
    }
    config.mode.fps = v;
  }
  const std::string pattern = optionOr(request, "pattern", "");
  if (pattern == "bars") {
    config.pattern = TestPattern::kColourBars;
  } else if (pattern == "gradient") {
    config.pattern = TestPattern::kGradient;
  } else if (pattern == "checker") {
    config.pattern = TestPattern::kChecker;
  } else if (pattern == "solid") {
    config.pattern = TestPattern::kSolid;
  } else if (!pattern.empty()) {
    return fail(Errc::kInvalidArgument, fmt::format("pattern '{}' is not bars, gradient, checker or solid", pattern),
                where(request));
  }
  auto moving = boolOption(request, "moving", config.moving);
  if (!moving) return std::unexpected(moving.error());
  config.moving = *moving;
  // "unplug@NS,signal_lost@NS+NS,stall@NS+NS,corrupt@NS": times in nanoseconds after opening.
  const std::string faults = optionOr(request, "faults", "");
  std::string_view rest = faults;
  while (!rest.empty()) {
    const auto comma = rest.find(',');
    const std::string_view item = rest.substr(0, comma);
    rest = comma == std::string_view::npos ? std::string_view{} : rest.substr(comma + 1);
    const auto at = item.find('@');
    const auto plus = item.find('+');
    CameraFault f;
    const std::string_view kind = item.substr(0, at);
    const auto number = [](std::string_view text, std::int64_t& out) {
      const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), out);
      return ec == std::errc{} && end == text.data() + text.size() && out >= 0;
    };
    std::int64_t time = 0;
    std::int64_t length = 0;
    bool ok = at != std::string_view::npos;
    if (kind == "unplug" || kind == "corrupt") {
      f.kind = kind == "corrupt" ? CameraFault::Kind::kCorrupt : CameraFault::Kind::kUnplug;
      ok = ok && plus == std::string_view::npos && number(item.substr(at + 1), time);
    } else if (kind == "signal_lost" || kind == "stall") {
      f.kind = kind == "stall" ? CameraFault::Kind::kStall : CameraFault::Kind::kSignalLost;
      ok = ok && plus != std::string_view::npos && plus > at && number(item.substr(at + 1, plus - at - 1), time) &&
           number(item.substr(plus + 1), length);
    } else {
      ok = false;
    }
    if (!ok) {
      return fail(Errc::kInvalidArgument,
                  fmt::format("fault '{}' is not unplug@NS, signal_lost@NS+NS, stall@NS+NS or corrupt@NS", item),
                  where(request));
    }
    if (f.kind == CameraFault::Kind::kCorrupt && config.mode.format != PixelFormat::kMjpeg) {
      return fail(Errc::kInvalidArgument,
                  fmt::format("fault '{}': only MJPEG frames can be corrupt (format = \"MJPEG\")", item),
                  where(request));
    }
    f.time = Nanos{time};
    f.duration = Nanos{length};
    config.faults.push_back(f);
  }
  return {};
}

// SyntheticProvider

std::vector<ScriptedInput> SyntheticProvider::demoScript() {
  std::vector<ScriptedInput> script;
  script.reserve(7);
  for (int i = 0; i < 7; ++i) {
    script.push_back({std::chrono::seconds(i + 1), EventKind::kDialDelta, static_cast<std::uint16_t>(i), 0.05});
  }
  return script;
}

SyntheticProvider::SyntheticProvider() {
  Device dial;
  dial.candidate = {SyntheticDial::defaultInfo(), devices::DeviceKind::kDialBox, "",
                    "scripted turns: 8 dials, 32 buttons"};
  dial.script = demoScript();
  Device camera;
  camera.candidate = {SyntheticCamera::defaultInfo(), devices::DeviceKind::kVideoSource, "",
                      "test pattern: YUYV 640x360 @ 30 fps"};
  plug(std::move(dial));
  plug(std::move(camera));
}

SyntheticProvider::SyntheticProvider(std::vector<Device> devices) {
  for (auto& d : devices) plug(std::move(d));
}

void SyntheticProvider::plug(Device device) {
  std::lock_guard lock(mutex_);
  for (auto& e : entries_) {
    if (e.device.candidate.info.path == device.candidate.info.path) {
      e.present->store(false);  // whatever was open there is gone
      e = Entry{std::move(device), std::make_shared<std::atomic<bool>>(true)};
      return;
    }
  }
  entries_.push_back(Entry{std::move(device), std::make_shared<std::atomic<bool>>(true)});
}

void SyntheticProvider::unplug(const std::string& path) {
  std::lock_guard lock(mutex_);
  std::erase_if(entries_, [&](const Entry& e) {
    if (e.device.candidate.info.path != path) return false;
    e.present->store(false);
    return true;
  });
}

std::vector<devices::DeviceCandidate> SyntheticProvider::enumerate() {
  std::lock_guard lock(mutex_);
  std::vector<devices::DeviceCandidate> out;
  out.reserve(entries_.size());
  for (const auto& e : entries_) out.push_back(e.device.candidate);
  return out;
}

Result<std::unique_ptr<devices::DialBox>> SyntheticProvider::openDialBox(const devices::DeviceCandidate& candidate,
                                                                         const devices::DeviceRequest& request,
                                                                         const Clock& clock) {
  std::lock_guard lock(mutex_);
  for (const auto& e : entries_) {
    if (e.device.candidate.info.path != candidate.info.path) continue;
    auto loop = boolOption(request, "loop", e.device.loop);
    if (!loop) return std::unexpected(loop.error());
    return std::unique_ptr<devices::DialBox>(
        std::make_unique<SyntheticDial>(e.device.candidate.info, e.device.script, clock, *loop, e.present));
  }
  return fail(Errc::kNotFound, "the synthetic device was unplugged", candidate.info.path);
}

Result<std::shared_ptr<devices::VideoSource>> SyntheticProvider::openVideoSource(
    const devices::DeviceCandidate& candidate, const devices::DeviceRequest& request, const Clock& clock) {
  std::lock_guard lock(mutex_);
  for (const auto& e : entries_) {
    if (e.device.candidate.info.path != candidate.info.path) continue;
    SyntheticCameraConfig config = e.device.camera;
    if (auto r = applyCameraOptions(request, config); !r) return std::unexpected(r.error());
    return std::shared_ptr<devices::VideoSource>(
        std::make_shared<SyntheticCamera>(e.device.candidate.info, std::move(config), clock, e.present));
  }
  return fail(Errc::kNotFound, "the synthetic device was unplugged", candidate.info.path);
}

Result<std::unique_ptr<devices::Tracker>> SyntheticProvider::openTracker(const devices::DeviceCandidate& candidate,
                                                                         const devices::DeviceRequest& request,
                                                                         const Clock& clock) {
  (void)request;
  std::lock_guard lock(mutex_);
  for (const auto& e : entries_) {
    if (e.device.candidate.info.path != candidate.info.path) continue;
    return std::unique_ptr<devices::Tracker>(
        std::make_unique<SyntheticTracker>(e.device.candidate.info, e.device.tracker, clock, e.present));
  }
  return fail(Errc::kNotFound, "the synthetic device was unplugged", candidate.info.path);
}

// ReplayProvider

ReplayProvider::ReplayProvider(TraceVideoReaderFactory videoReader)
    : videoReader_(videoReaderFactory(std::move(videoReader))) {}

Result<void> ReplayProvider::addMidiFile(const std::filesystem::path& file) {
  auto rec = readMidiFile(file);
  if (!rec) return std::unexpected(rec.error());
  Entry e;
  e.candidate.kind = devices::DeviceKind::kDialBox;
  e.candidate.info.name = rec->name;
  e.candidate.info.backend = "replay";
  e.candidate.info.bus = "virtual";
  e.candidate.info.path = file.string();
  auto profile = devices::parseMidiDescriptor(rec->descriptor);
  if (profile) {
    e.candidate.usage = fmt::format("{} (MIDI, profile {}): {}, {} messages", profile->title, profile->name,
                                    profile->shape(), rec->reports.size());
  } else {
    e.candidate.problem = profile.error().describe();
  }
  e.requestName = file.stem().string();
  e.hid = std::move(*rec);
  entries_.push_back(std::move(e));
  return {};
}

Result<void> ReplayProvider::addHidRecording(const std::filesystem::path& file) {
  if (isMidiFilePath(file)) return addMidiFile(file);
  auto rec = readHidRecording(file);
  if (!rec) return std::unexpected(rec.error());
  const bool multi = rec->devices.size() > 1;
  for (HidRecordedDevice& d : rec->devices) {
    Entry e;
    e.candidate.kind = devices::DeviceKind::kDialBox;
    e.candidate.info.name = d.name;
    e.candidate.info.backend = "replay";
    e.candidate.info.bus = busName(d.bus);
    e.candidate.info.vendor = d.vendor;
    e.candidate.info.product = d.product;
    e.candidate.info.path = multi ? fmt::format("{}#{}", file.string(), d.index) : file.string();
    auto decoder = devices::DialDecoder::create(d.vendor, d.product, d.descriptor, e.candidate.info.path);
    auto parsed = devices::hid::parseReportDescriptor(d.descriptor, e.candidate.info.path);
    auto tracker = parsed ? devices::TrackerDecoder::create(*parsed, e.candidate.info.path)
                          : Result<devices::TrackerDecoder>(std::unexpected(parsed.error()));
    if (tracker) {
      e.candidate.kind = devices::DeviceKind::kTracker;
      e.candidate.usage =
          fmt::format("tracker: X/Y/Z{}, {} reports", tracker->hasRotation() ? ", Rx/Ry/Rz" : "", d.reports.size());
    } else if (decoder) {
      e.candidate.usage = fmt::format("{}: {} dial(s), {} button(s), {} reports", dialProfileName(decoder->profile()),
                                      decoder->dialCount(), decoder->buttonCount(), d.reports.size());
    } else {
      e.candidate.problem = decoder.error().describe();
    }
    e.requestName = multi ? fmt::format("{}#{}", file.stem().string(), d.index) : file.stem().string();
    e.hid = std::move(d);
    entries_.push_back(std::move(e));
  }
  return {};
}

Result<void> ReplayProvider::addTrace(const std::filesystem::path& folder) {
  auto trace = readTrace(folder);
  if (!trace) return std::unexpected(trace.error());
  for (const TraceDevice& d : trace->devices) {
    Entry e;
    e.requestName = d.name;
    e.candidate.kind = d.kind;
    e.candidate.info = d.info;
    e.candidate.info.backend = "replay";
    e.candidate.info.path = (folder / d.file).string();
    if (d.kind == devices::DeviceKind::kDialBox && isMidiFilePath(d.file)) {
      auto rec = readMidiFile(folder / d.file);
      if (!rec) return std::unexpected(rec.error());
      e.hid = std::move(*rec);
      e.candidate.usage = fmt::format("recorded {} with {} MIDI messages", d.info.name, e.hid.reports.size());
    } else if (d.kind != devices::DeviceKind::kVideoSource) {
      auto rec = readHidRecording(folder / d.file);
      if (!rec) return std::unexpected(rec.error());
      if (rec->devices.empty()) return fail(Errc::kParse, "the recording has no device", (folder / d.file).string());
      e.hid = std::move(rec->devices.front());
      e.candidate.usage = fmt::format("recorded {} with {} reports", d.info.name, e.hid.reports.size());
    } else {
      e.video = folder / d.file;
      e.candidate.usage = fmt::format("recorded {}: {}", d.info.name, devices::describeMode(d.mode));
    }
    entries_.push_back(std::move(e));
  }
  return {};
}

std::vector<devices::DeviceRequest> ReplayProvider::requests() const {
  std::vector<devices::DeviceRequest> out;
  for (const Entry& e : entries_) {
    devices::DeviceRequest r;
    r.name = e.requestName;
    r.kind = e.candidate.kind;
    r.match.backend = "replay";
    r.match.path = e.candidate.info.path;
    out.push_back(std::move(r));
  }
  return out;
}

std::vector<devices::DeviceCandidate> ReplayProvider::enumerate() {
  std::vector<devices::DeviceCandidate> out;
  out.reserve(entries_.size());
  for (const Entry& e : entries_) out.push_back(e.candidate);
  return out;
}

Result<std::unique_ptr<devices::DialBox>> ReplayProvider::openDialBox(const devices::DeviceCandidate& candidate,
                                                                      const devices::DeviceRequest& request,
                                                                      const Clock& clock) {
  auto loop = boolOption(request, "loop", true);
  if (!loop) return std::unexpected(loop.error());
  for (const Entry& e : entries_) {
    if (e.candidate.info.path != candidate.info.path) continue;
    auto dial = ReplayDialBox::create(e.candidate.info, e.hid, clock, *loop);
    if (!dial) return std::unexpected(dial.error());
    return std::unique_ptr<devices::DialBox>(std::move(*dial));
  }
  return fail(Errc::kNotFound, "no such recorded device", candidate.info.path);
}

Result<std::unique_ptr<devices::Tracker>> ReplayProvider::openTracker(const devices::DeviceCandidate& candidate,
                                                                      const devices::DeviceRequest& request,
                                                                      const Clock& clock) {
  auto loop = boolOption(request, "loop", true);
  if (!loop) return std::unexpected(loop.error());
  for (const Entry& e : entries_) {
    if (e.candidate.info.path != candidate.info.path) continue;
    auto tracker = ReplayTracker::create(e.candidate.info, e.hid, clock, *loop);
    if (!tracker) return std::unexpected(tracker.error());
    return std::unique_ptr<devices::Tracker>(std::move(*tracker));
  }
  return fail(Errc::kNotFound, "no such recorded device", candidate.info.path);
}

Result<std::shared_ptr<devices::VideoSource>> ReplayProvider::openVideoSource(const devices::DeviceCandidate& candidate,
                                                                              const devices::DeviceRequest& request,
                                                                              const Clock& clock) {
  auto loop = boolOption(request, "loop", true);
  if (!loop) return std::unexpected(loop.error());
  for (const Entry& e : entries_) {
    if (e.candidate.info.path != candidate.info.path) continue;
    auto reader = videoReader_(e.video);
    if (!reader) return std::unexpected(reader.error());
    return std::shared_ptr<devices::VideoSource>(
        std::make_shared<ReplayCamera>(e.candidate.info, std::move(*reader), clock, *loop));
  }
  return fail(Errc::kNotFound, "no such recorded device", candidate.info.path);
}

}  // namespace basalt::sim
