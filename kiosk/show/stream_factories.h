#pragma once

/// \file
/// \brief What fills the loader's seams (kiosk/show/show_loader.h): dial boxes of the hid and replay
/// backends, and texture streams for movies (media::MoviePlayer) and cameras (devices'
/// VideoSources: v4l2, libcamera, synthetic, replay; MJPEG decoded by media::MjpegDecoder off the
/// frame loop's thread). `registerShowFactories()` installs them;
/// runShow calls it before the first show loads, and so do tests.
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

/// \brief Registers the hid and replay dial box factories and the movie and camera stream
/// factories. Idempotent; call before the first show loads.
void registerShowFactories();

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
