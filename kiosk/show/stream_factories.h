#pragma once

/// \file
/// \brief The loader's factories (ShowFactories in kiosk/show/show_loader.h) for devices and
/// media: dial boxes of the hid, replay and serial backends, and texture streams for movies
/// (media::MoviePlayer) and cameras (devices' VideoSources: v4l2, libcamera, synthetic, replay;
/// MJPEG decoded by media::MjpegDecoder off the frame loop's thread). The program puts them into
/// its ShowFactories where it starts (app/show_factories.cpp); tests pick the ones they need.
///
/// Who keeps a device open (kiosk/show/README.md): a dial box of a show is
/// retried by the director's DeviceSlot (its back-off, its status line); the factory's dial box
/// only finds and opens the device once per attempt. A camera is kept by a DeviceManager of its
/// own inside its texture stream (absent -> live -> lost -> reopening, with its back-off); the
/// director sees it only through TextureStream::update() and describe(). One state machine per
/// device, never two.

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
/// names, kept open by a DeviceManager of the stream's own.
[[nodiscard]] Result<std::unique_ptr<TextureStream>> makeCameraStream(const MediaSpec& media, const Manifest& show,
                                                                      const Clock& clock);

/// \brief The dial box factory for the hid, replay and serial backends: a dial box found by the
/// device's rule through its backend (makeMatchedDialBox) each time it is opened.
[[nodiscard]] Result<std::unique_ptr<devices::DialBox>> makeDialBoxFromSpec(const DeviceSpec& spec, const Clock& clock);

/// \brief For tests: the thread a camera stream's MJPEG frames are decoded on (never the frame
/// loop's); none for other streams, cameras that deliver raw frames, and before the first JPEG.
[[nodiscard]] std::optional<std::thread::id> mjpegDecodeThread(const TextureStream& stream);

/// \brief The device rule for a manifest's device: its backend and match fields.
[[nodiscard]] devices::DeviceMatch deviceMatchFor(const DeviceSpec& spec);

/// \brief The backend (provider) a manifest's device is found with: hid, v4l2, libcamera,
/// synthetic, or replay with the trace folder or hid-recorder file of the spec loaded.
[[nodiscard]] Result<std::unique_ptr<devices::DeviceProvider>> providerFor(const DeviceSpec& spec);

/// \brief A dial box found by a rule each time it is opened: the device that matches now, opened
/// through its backend. Its events are passed on from the device in service(); a lost device is
/// reported lost, and the next open() looks for it again (it may be on another node).
[[nodiscard]] std::unique_ptr<devices::DialBox> makeMatchedDialBox(std::unique_ptr<devices::DeviceProvider> provider,
                                                                   devices::DeviceRequest request, const Clock& clock);

/// \brief The name of the texture the scripts' VCR shows (LAVA's texture.switch = video): while
/// it exists, parts of a show whose texture source is video show it (render/renderer.cpp).
inline constexpr std::string_view kScriptVideoTexture = render::kVideoTexture;

/// \brief Sets what a script's VCR needs from the run: the show's first camera for
/// `tv.camera = on` (none when the manifest names none) and whether to wait for frames (a
/// ManualClock run).
void setScriptVcrOptions(ScriptPlayerOptions& options, const Manifest& show, const Clock& clock);

}  // namespace basalt::kiosk
