#pragma once

/// \file
/// rief The loader's factories (ShowFactories in kiosk/show/show_loader.h) for devices and
/// media: the backends of a manifest's devices (hid, serial, replay, v4l2, libcamera, synthetic
/// cameras), and texture streams for movies (media::MoviePlayer) and cameras (devices'
/// VideoSources; MJPEG decoded by media::MjpegDecoder off the frame loop's thread). The program
/// puts them into its ShowFactories where it starts (app/show_factories.cpp); tests pick the ones
/// they need.
///
/// Who keeps a device open (kiosk/show/README.md): the director's
/// devices::DeviceManager, for dial boxes and cameras alike (absent -> live -> lost ->
/// reopening, with its back-off, off the frame loop on the system clock). A factory only says
/// where a device is looked for (its provider) and what is asked for (its request); a camera's
/// texture stream finds the camera in that manager by name. One state machine per device.

#include <memory>
#include <optional>
#include <string>
#include <thread>

#include "devices/device_manager.h"
#include "kiosk/show/show_loader.h"
#include "render/texture_registry.h"

namespace basalt::kiosk {

struct ScriptPlayerOptions;

/// \brief The stream factory for movies (MediaKind::kMovie): a media::MoviePlayer on the file,
/// started by the stream's first update(). A missing file is an error here.
[[nodiscard]] Result<std::unique_ptr<TextureStream>> makeMovieStream(const MediaSpec& media, const Manifest& show,
                                                                     const Clock& clock);

/// \brief The stream factory for cameras (MediaKind::kCamera): the manifest's device the media
/// names, found by name in the director's devices::DeviceManager (TextureStream::useDevices).
[[nodiscard]] Result<std::unique_ptr<TextureStream>> makeCameraStream(const MediaSpec& media, const Manifest& show,
                                                                      const Clock& clock);

/// \brief The device factory for every backend a manifest names (dial boxes and cameras): the
/// backend the device is looked for in, and what the director's DeviceManager is asked for.
[[nodiscard]] Result<DeviceSource> makeDeviceSource(const DeviceSpec& spec);

/// \brief For tests: the thread a camera stream's MJPEG frames are decoded on (never the frame
/// loop's); none for other streams, cameras that deliver raw frames, and before the first JPEG.
[[nodiscard]] std::optional<std::thread::id> mjpegDecodeThread(const TextureStream& stream);

/// \brief The device rule for a manifest's device: its backend and match fields.
[[nodiscard]] devices::DeviceMatch deviceMatchFor(const DeviceSpec& spec);

/// \brief The backend (provider) a manifest's device is found with: hid, v4l2, libcamera,
/// synthetic, or replay with the trace folder or hid-recorder file of the spec loaded.
[[nodiscard]] Result<std::unique_ptr<devices::DeviceProvider>> providerFor(const DeviceSpec& spec);

/// \brief The name of the texture the scripts' VCR shows (LAVA's texture.switch = video): while
/// it exists, parts of a show whose texture source is video show it (render/renderer.cpp).
inline constexpr std::string_view kScriptVideoTexture = render::kVideoTexture;

/// \brief Sets what a script's VCR needs from the run: the show's first camera for
/// `tv.camera = on` (none when the manifest names none), found in `devices` (the director's:
/// shared with a texture that shows it, requested there otherwise), and whether to wait for
/// frames (a ManualClock run). `show`, `clock` and `devices` outlive the options.
void setScriptVcrOptions(ScriptPlayerOptions& options, const Manifest& show, const Clock& clock,
                         devices::DeviceManager& devices);

}  // namespace basalt::kiosk
