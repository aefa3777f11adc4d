#pragma once

/// \file
/// \brief Turning a validated manifest into what plays: item players, devices with their
/// bindings, textures and their fallbacks, streams, the schedule. Loading reads files and opens
/// nothing on the screen, so it runs off the frame loop's thread (at start and on SIGHUP) while
/// the current show keeps playing; the director installs the result between two frames.
///
/// What it makes items, devices and texture streams with comes in a ShowFactories value, built
/// where the program starts (app/show_factories.cpp) and passed down to the loader and the
/// director. Without a factory, the item is unplayable, or the device or stream is reported
/// absent with the reason, its bindings stay quiet and its texture shows the fallback: the show
/// goes on. Loading opens no device: the director asks its devices::DeviceManager for them when
/// the show takes over.

#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "devices/device_manager.h"
#include "kiosk/manifest/manifest.h"
#include "kiosk/policy/kiosk_policy.h"
#include "kiosk/policy/schedule.h"
#include "kiosk/show/show_items.h"
#include "kiosk/status/status_board.h"
#include "render/texture_registry.h"
#include "runtime/bindings.h"
#include "runtime/clock.h"
#include "runtime/frame_queue.h"
#include "runtime/image.h"

namespace basalt::kiosk {

/// \brief A texture fed by a movie or a camera.
///
/// Threading: made on the loader's thread; update() on the frame loop's thread, never blocking.
class TextureStream {
 public:
  virtual ~TextureStream() = default;
  /// \brief Shows the frame due at `showTime` as texture `name`; false while the stream has
  /// nothing to show (not started, unplugged, broken), when the fallback is shown instead.
  virtual bool update(Nanos showTime, render::TextureRegistry& textures, const std::string& name) = 0;
  /// \brief One line for the status page: state and why.
  [[nodiscard]] virtual std::string describe() const = 0;
  /// \brief True while the stream's own content is broken (a movie file emptied, cut short,
  /// replaced by one that cannot play, or deleted): the fallback shows, the status says
  /// "degraded", and the stream waits for a good file. False for streams that are merely
  /// waiting (not started, a camera being opened).
  [[nodiscard]] virtual bool degraded() const { return false; }
  /// \brief A camera's own state as of the last update() (it can be lost while the texture
  /// still shows something: its on_loss picture); none for streams without a device.
  [[nodiscard]] virtual std::optional<SourceState> deviceState() const { return std::nullopt; }
  /// \brief Frame-locked nodes: play as if started at show time `origin` (frame 0 due then, the
  /// frame at `t - origin` due at `t`, looping where the media loops), so that every node shows
  /// the same frame whenever it started; wait up to `patience` each update for the frame due (a
  /// follower draws the leader's frame; a manual clock waits anyway). Streams that play no file
  /// (cameras) ignore it.
  virtual void alignTo(Nanos origin, std::chrono::milliseconds patience) {
    (void)origin;
    (void)patience;
  }
  /// \brief Frame-locked: one pass of the leader's loop of this stream (0: unknown yet), for
  /// placing a late joiner in the right loop (the leader's passes are its file's length, which
  /// can differ from frames x frame duration by the file's timestamp rounding).
  virtual void setLeaderPass(Nanos pass) { (void)pass; }
  /// \brief One pass of this stream's loop on its timeline, once it has looped (0 before, and
  /// for streams that are not movies).
  [[nodiscard]] virtual Nanos passDuration() const { return Nanos{0}; }
  /// \brief The number of the movie frame the last update() showed; -1 before the first, and
  /// for streams that are not movies.
  [[nodiscard]] virtual std::int64_t shownFrame() const { return -1; }
  /// \brief Frame-locked followers: the movie frame the leader's stream shows in the coming
  /// frame (its shownFrame()), which update() shows exactly; -1: none given (the stream's own
  /// timeline).
  virtual void setLeaderFrame(std::int64_t frame) { (void)frame; }
  /// \brief What the last update() did with the leader's frame.
  [[nodiscard]] virtual LeaderFrameResult leaderFrameResult() const { return LeaderFrameResult::kNone; }
  /// \brief Cameras: the manager that runs the show's devices, where the stream finds its
  /// camera by name (the director requested it there). Called by the director before the first
  /// update(); borrowed, it outlives the stream. Streams without a device ignore it.
  virtual void useDevices(devices::DeviceManager& devices) { (void)devices; }
};

/// \brief Makes the texture stream of a movie or camera. Called off the frame loop's thread.
using StreamFactory = std::function<Result<std::unique_ptr<TextureStream>>(const MediaSpec& media, const Manifest& show,
                                                                           const Clock& clock)>;

/// \brief How a show's device is found: the backend that lists and opens it (loaded with the
/// device's trace, port or script), what the DeviceManager is asked for, and how it keeps it.
struct DeviceSource {
  std::unique_ptr<devices::DeviceProvider> provider;
  devices::DeviceRequest request;
  devices::Upkeep upkeep;
};

/// \brief Makes the source of a device (dial box or camera; the spec says which) for a backend
/// other than the built-in synthetic dial box. Called off the frame loop's thread.
using DeviceFactory = std::function<Result<DeviceSource>(const DeviceSpec& device)>;

/// \brief What a show's items, texture streams and devices are made with, and what runs the
/// control server's script commands. A plain value: the program builds it where it starts
/// (app/show_factories.cpp) and hands it to loadShow() and the ShowDirector; tests build the one
/// they need. An empty member makes what it would make unplayable or absent, with a message that
/// says so. Threading: the loader's thread calls the factories; they keep no state of their own.
struct ShowFactories {
  ItemFactories items;
  StreamFactory movieStreams;   ///< textures fed by a movie file
  StreamFactory cameraStreams;  ///< textures fed by a camera
  DeviceFactory devices;        ///< hid, serial, replay, v4l2 and libcamera devices (synthetic dial boxes are built in)
  CommandRunner commands;       ///< the control server's "run a command"
};

/// \brief How long a show's dial box that cannot be opened waits before the next try: 1 s,
/// doubling to 30 s (cameras keep the DeviceManager's own).
inline constexpr devices::Backoff kDialBoxBackoff{std::chrono::seconds(1), std::chrono::seconds(30)};

/// \brief One device of a show, with what its inputs do.
struct DeviceSlot {
  DeviceSpec spec;
  /// What the director requests (the provider moves into its DeviceManager then).
  DeviceSource source;
  std::string unavailable;                ///< why it cannot be requested ("" when it can)
  runtime::Bindings dials;                ///< what its dials do to the show
  std::array<KioskAction, 32> buttons{};  ///< what its buttons do to the kiosk
  // What the director's DeviceManager says about it, mirrored by the director:
  DeviceId id = 0;  ///< the id its events carry; 0 while it is not requested
  devices::DeviceState state = devices::DeviceState::kAbsent;
  std::string message;     ///< why it is not live (the manager's last error)
  std::string deviceName;  ///< the device in use, or the last one used
  WallTime since{};
};

/// \brief One named texture of a show.
struct LoadedTexture {
  std::string name;
  std::string source;                      ///< the media it shows, "" for a plain image
  std::filesystem::path imageFile;         ///< the image to show, or the fallback for a stream
  std::optional<Image> image;              ///< imageFile, once read
  std::unique_ptr<TextureStream> stream;   ///< movies and cameras
  std::string streamState;                 ///< why there is no stream, when there is none
  bool live = false;                       ///< kept by the director
  std::optional<SourceState> deviceState;  ///< the stream's deviceState() at the last update
  bool degraded = false;                   ///< the stream's degraded() at the last update
  WallTime since{};  ///< when `live`, `deviceState` or `degraded` last changed (kept by the director)
};

/// \brief Everything a manifest needs to play.
struct LoadedShow {
  Manifest manifest;
  std::optional<Schedule> schedule;
  std::map<std::string, std::unique_ptr<ItemPlayer>, std::less<>> players;  ///< by entryKey()
  std::map<std::string, Error, std::less<>> unplayable;                     ///< by entryKey()
  std::vector<DeviceSlot> devices;
  std::vector<LoadedTexture> textures;
};

/// \brief The key of an entry in LoadedShow::players.
std::string entryKey(const EntrySpec& entry);

/// \brief Prepares a validated manifest. Errors only for what makes the show impossible (a time
/// zone that vanished); unplayable items, devices and streams are recorded and reported.
/// Items, streams and dial boxes are made with `factories`. Without `readImages` texture images
/// are left for the director to read in the background (start-up: the first frame does not wait
/// for image decoding).
[[nodiscard]] Result<std::unique_ptr<LoadedShow>> loadShow(Manifest manifest, const Clock& clock,
                                                           const ShowFactories& factories, bool readImages = true);

/// \brief Reads a texture's image, or says why not (a warning) and returns nothing.
std::optional<Image> readTextureImage(const std::string& texture, const std::filesystem::path& file);

/// \brief Reads, validates and loads `file`: what a reload does on its own thread.
[[nodiscard]] Result<std::unique_ptr<LoadedShow>> readAndLoadShow(const std::filesystem::path& file, const Clock& clock,
                                                                  const ShowFactories& factories,
                                                                  Diagnostics& diagnostics);

}  // namespace basalt::kiosk
