#include "kiosk/show/show_loader.h"

#include <fmt/format.h>
#include <fmt/std.h>

#include "kiosk/manifest/content_check.h"
#include "media/image_io.h"
#include "runtime/log.h"
#include "sim/providers.h"

namespace basalt::kiosk {

BASALT_LOG_CATEGORY(Loader, "kiosk");

namespace {

/// A synthetic dial box playing the manifest's script, in a backend of its own.
DeviceSource syntheticDialBox(const DeviceSpec& spec) {
  sim::SyntheticProvider::Device device;
  device.candidate = {sim::SyntheticDial::defaultInfo(), devices::DeviceKind::kDialBox, "", "the manifest's script"};
  device.script.reserve(spec.script.size());
  for (const SyntheticInput& in : spec.script) {
    const EventKind kind = in.button ? EventKind::kButton : (in.shuttle ? EventKind::kShuttle : EventKind::kDialDelta);
    device.script.push_back({in.at, kind, in.index, in.value});
  }
  device.loop = spec.loop;
  DeviceSource source;
  source.provider = std::make_unique<sim::SyntheticProvider>(std::vector{std::move(device)});
  source.request.kind = devices::DeviceKind::kDialBox;
  source.request.match.backend = "synthetic";
  source.request.options["loop"] = spec.loop ? "true" : "false";
  return source;
}

/// A synthetic tracker moving along the manifest's path, in a backend of its own.
DeviceSource syntheticTracker(const DeviceSpec& spec) {
  sim::SyntheticProvider::Device device;
  device.candidate = {sim::SyntheticTracker::defaultInfo(), devices::DeviceKind::kTracker, "", "the manifest's path"};
  const TrackerMotion& m = spec.motion;
  sim::TrackerPath& path = device.tracker;
  path.shape = m.shape == TrackerMotion::Shape::kLine          ? sim::TrackerPath::Shape::kLine
               : m.shape == TrackerMotion::Shape::kFigureEight ? sim::TrackerPath::Shape::kFigureEight
                                                               : sim::TrackerPath::Shape::kCircle;
  path.radius = m.radius;
  path.period = Nanos{static_cast<std::int64_t>(m.period * 1e9)};
  path.rate = m.rate;
  path.centre = {m.centre[0], m.centre[1], m.centre[2]};
  DeviceSource source;
  source.provider = std::make_unique<sim::SyntheticProvider>(std::vector{std::move(device)});
  source.request.kind = devices::DeviceKind::kTracker;
  source.request.match.backend = "synthetic";
  return source;
}

Result<DeviceSource> makeDeviceSource(const DeviceSpec& spec, const ShowFactories& factories) {
  const bool dialBox = spec.kind == DeviceKind::kDialBox;
  if (dialBox && spec.backend == DeviceBackend::kSynthetic) return syntheticDialBox(spec);
  if (spec.kind == DeviceKind::kTracker && spec.backend == DeviceBackend::kSynthetic) return syntheticTracker(spec);
  if (factories.devices) return factories.devices(spec);
  return fail(Errc::kUnsupported, fmt::format("this build has no {} {} backend", deviceBackendName(spec.backend),
                                              deviceKindName(spec.kind)));
}

/// The factory for the texture stream of `kind` (movies and cameras); null for images.
const StreamFactory* streamFactory(MediaKind kind, const ShowFactories& factories) {
  switch (kind) {
    case MediaKind::kMovie: return &factories.movieStreams;
    case MediaKind::kCamera: return &factories.cameraStreams;
    case MediaKind::kImage: break;
  }
  return nullptr;
}

}  // namespace

std::string entryKey(const EntrySpec& entry) { return entry.path.empty() ? entry.text : entry.path.string(); }

std::optional<Image> readTextureImage(const std::string& texture, const std::filesystem::path& file) {
  auto image = media::readImage(file);
  if (!image) {
    log::warn(kLogLoader, "texture '{}': cannot read {}: {}", texture, file, image.error().message());
    return std::nullopt;
  }
  return std::move(*image);
}

Result<std::unique_ptr<LoadedShow>> loadShow(Manifest manifest, const Clock& clock, const ShowFactories& factories,
                                             bool readImages) {
  auto show = std::make_unique<LoadedShow>();
  show->manifest = std::move(manifest);
  const Manifest& m = show->manifest;
  if (m.kiosk.schedule.present) {
    auto schedule = Schedule::create(m.kiosk.schedule);
    if (!schedule) return std::unexpected(schedule.error().withContext("the schedule's time zone"));
    show->schedule = std::move(*schedule);
  }

  // Every item the show may play, prepared once.
  std::vector<const EntrySpec*> entries{&m.entry};
  for (const PlaylistItem& item : m.kiosk.playlist) entries.push_back(&item.entry);
  for (const PlaylistItem& item : m.kiosk.attract.items) entries.push_back(&item.entry);
  if (m.kiosk.schedule.standby) entries.push_back(&*m.kiosk.schedule.standby);
  for (const EntrySpec* entry : entries) {
    const std::string key = entryKey(*entry);
    if (show->players.contains(key) || show->unplayable.contains(key)) continue;
    auto player = prepareItem(*entry, m, factories.items);
    if (player) {
      show->players.emplace(key, std::move(*player));
    } else {
      log::warn(kLogLoader, "{}", player.error().describe());
      show->unplayable.emplace(key, player.error());
    }
  }

  // Devices and their bindings: LAVA's dial table for a dial box no binding mentions. Nothing
  // is opened here: the director asks its DeviceManager for them.
  for (const DeviceSpec& spec : m.devices) {
    DeviceSlot slot;
    slot.spec = spec;
    auto source = makeDeviceSource(spec, factories);
    if (source) {
      slot.source = std::move(*source);
      slot.source.request.name = spec.name;
      if (spec.kind == DeviceKind::kDialBox) {
        // The director says what happens to a show's dial box (its status line, its log), and
        // retries it less eagerly than a camera.
        slot.source.upkeep.backoff = kDialBoxBackoff;
        slot.source.upkeep.quiet = true;
      }
    } else {
      slot.unavailable = source.error().message();
    }
    if (spec.kind == DeviceKind::kDialBox) {
      // LAVA's dial table with the device's gain and acceleration, then each binding's
      // override of one dial (the others keep LAVA's action).
      slot.dials = runtime::Bindings::lavaDefaults();
      slot.dials.setGain(spec.gain);
      slot.dials.setAcceleration(spec.acceleration);
      for (const BindingSpec& b : m.bindings) {
        if (b.device != spec.name) continue;
        if (b.button) {
          slot.buttons[b.index] = b.kioskAction;
          continue;
        }
        runtime::DialBinding dial = slot.dials.dial(b.index);
        if (b.actionGiven || b.gainGiven) {
          dial.action = b.action;
          dial.gain = b.gain;
        }
        dial.acceleration = b.acceleration.value_or(spec.acceleration);
        dial.invert = b.invert;
        slot.dials.setDial(b.index, dial);
      }
    }
    slot.message = slot.unavailable;
    show->devices.push_back(std::move(slot));
  }

  // Textures: images read now; streams made now and started by their first update.
  for (const TextureSpec& spec : m.textures) {
    LoadedTexture t;
    t.name = spec.name;
    t.source = spec.source;
    if (!spec.file.empty()) t.imageFile = spec.file;
    if (const MediaSpec* media = m.findMedia(spec.source)) {
      if (media->kind == MediaKind::kImage) {
        t.imageFile = media->file;
      } else {
        const StreamFactory* factory = streamFactory(media->kind, factories);
        if (factory && *factory) {
          auto stream = (*factory)(*media, m, clock);
          if (stream) {
            t.stream = std::move(*stream);
          } else {
            t.streamState = stream.error().message();
          }
        } else {
          t.streamState =
              media->kind == MediaKind::kMovie ? "this build has no movie player" : "this build has no camera stream";
        }
        t.imageFile = spec.fallback;
      }
    }
    if (readImages && !t.imageFile.empty()) t.image = readTextureImage(t.name, t.imageFile);
    show->textures.push_back(std::move(t));
  }
  return show;
}

Result<std::unique_ptr<LoadedShow>> readAndLoadShow(const std::filesystem::path& file, const Clock& clock,
                                                    const ShowFactories& factories, Diagnostics& diagnostics) {
  ReadOptions options;
  options.fileCheckers = &contentCheckers();
  auto manifest = readManifest(file, diagnostics, options);
  if (!manifest) {
    return fail(Errc::kParse, fmt::format("{} has {} problem{}", file.string(), diagnostics.errorCount(),
                                          diagnostics.errorCount() == 1 ? "" : "s"));
  }
  return loadShow(std::move(*manifest), clock, factories, true);
}

}  // namespace basalt::kiosk
