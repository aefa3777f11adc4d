#pragma once

/// \file
/// \brief The show manifest (`show.toml`, DESIGN.md §4): what one display node plays, as plain
/// data. `readManifest()` parses and validates it and reports every problem it finds as a
/// `Diagnostic` with the file and line; `basalt check show.toml` prints them.
///
/// Paths in a manifest are relative to its folder and may not leave it (DESIGN.md §8); the
/// reader resolves and confines them, so everything downstream receives absolute paths that
/// exist.

#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/bindings.h"
#include "runtime/clock.h"
#include "runtime/error.h"
#include "runtime/formats/cave.h"
#include "runtime/head_tracking.h"

namespace basalt::kiosk {

// ---------------------------------------------------------------------------------------------
// Problems found in a manifest

enum class Severity : std::uint8_t { kError, kWarning, kNote };

/// \brief One problem, at a place in a file. `line` is 1-based; 0 means the whole file.
struct Diagnostic {
  Severity severity = Severity::kError;
  std::filesystem::path file;
  int line = 0;
  std::string message;

  /// \brief "show.toml:12: devices.dials: ..." (errors), "...: warning: ..." and "...: note: ...".
  [[nodiscard]] std::string format() const;
};

/// \brief Collects diagnostics while a manifest is read.
class Diagnostics {
 public:
  void error(const std::filesystem::path& file, int line, std::string message);
  void warning(const std::filesystem::path& file, int line, std::string message);
  void note(const std::filesystem::path& file, int line, std::string message);
  void add(Diagnostic d) { items_.push_back(std::move(d)); }

  [[nodiscard]] const std::vector<Diagnostic>& items() const { return items_; }
  [[nodiscard]] std::size_t errorCount() const;
  [[nodiscard]] bool hasErrors() const { return errorCount() > 0; }
  /// \brief Every diagnostic, one per line, in file order.
  [[nodiscard]] std::string format() const;

 private:
  std::vector<Diagnostic> items_;
};

// ---------------------------------------------------------------------------------------------
// The manifest's sections

/// \brief Where frames go. `kAuto` detects in DESIGN.md §3's order: KMS when the process can be
/// DRM master, a window when a display server is present, headless otherwise.
enum class OutputKind : std::uint8_t { kAuto, kHeadless, kKms, kWindow };
std::string_view outputKindName(OutputKind kind);

/// \brief A display mode asked for by name: "1920x1080" or "1920x1080@60".
struct ModeRequest {
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  double refresh = 0;  ///< Hz; 0 = any
};

/// \brief `[output]`.
struct OutputSpec {
  OutputKind kind = OutputKind::kAuto;
  std::uint32_t width = 0;  ///< headless and window size; 0 = the default (500 x 500)
  std::uint32_t height = 0;
  std::string device;               ///< KMS: /dev/dri/cardN; empty = the first with a connected display
  std::string connector;            ///< KMS: "HDMI-A-1"; empty = the first connected
  std::optional<ModeRequest> mode;  ///< KMS: the mode; empty = the connector's preferred mode
  bool fullscreen = false;          ///< window: cover the screen
  int line = 0;
};

/// \brief How one view sees the show (DESIGN.md §3 "View").
/// \brief What a view shows: the show plainly, one facet of a polyhedral display, one stereo
/// eye, or the visual aids of a facet view (the display seen from outside, thesis §4.4.6).
enum class ViewKind : std::uint8_t { kPlain, kFacet, kStereo, kAids };
enum class Eye : std::uint8_t { kLeft, kRight };

/// \brief `[[views]]`: where a picture goes and from where it is seen.
struct ViewSpec {
  std::string name;
  ViewKind kind = ViewKind::kPlain;
  std::filesystem::path cave;                            ///< facet: the .cave file describing the display geometry
  std::uint32_t facet = 0;                               ///< facet: which facet of the cave
  Eye eye = Eye::kLeft;                                  ///< stereo
  std::optional<std::array<std::uint32_t, 4>> viewport;  ///< x, y, width, height in output pixels
  int line = 0;
  // Immersive displays (issue 10).
  bool facetGiven = false;  ///< facet: `facet` was given (else the cave file's facet[] is used)
  /// plain and facet: how the eyes are shown; "show" follows the show's stereo setting
  enum class Stereo : std::uint8_t { kShow, kOff, kAnaglyph, kSideBySide, kTopBottom } stereo = Stereo::kShow;
  std::optional<float> eyeSpacing;  ///< facet: distance between the eyes in cave units (default: the show's)
  bool rearProjection = true;       ///< facet: `projection = "rear"` (the thesis' default) or "front"
  /// facet: `winding = "inward"` (the thesis' default: the geometry's facets used as written),
  /// "outward" (every facet turned round) or "auto" (each facet the viewer sees from behind)
  formats::FacetWinding winding = formats::FacetWinding::kInward;
  std::string of;                            ///< aids: the facet view whose set-up is shown ("" = the first facet view)
  std::optional<std::array<float, 3>> from;  ///< aids: direction the display is seen from (cave axes)
  /// facet and aids: where the display geometry's origin stands, relative to the camera in the
  /// camera's axes (`display_at = [x, y, z]`, scene units; the thesis puts it at the camera)
  std::array<float, 3> displayAt{0, 0, 0};
  float displayScale = 1.0f;  ///< facet and aids: scene units per cave unit (`display_scale`)
};

/// \brief `[viewer]`: where an immersive display's viewer is (thesis §4.4.3: every facet's
/// frustum runs from the viewer's eye to the facet), in the display geometry's units with the
/// display centre (the cave's origin) as the origin.
struct ViewerSpec {
  std::array<float, 3> position{};  ///< the point between the eyes, when no tracker moves it
  /// A `[devices]` tracker that moves the viewer (empty: it stays at `position`).
  std::string tracker;
  runtime::HeadSmoothing smoothing;  ///< how its samples are smoothed
  /// Where the tracker's origin is (display units) and display units per tracker unit (metres
  /// for trackers that state their units).
  std::array<float, 3> trackerOffset{};
  float trackerScale = 1.0f;
  int line = 0;
};

/// \brief What a show entry, playlist item or standby item plays.
enum class EntryKind : std::uint8_t {
  kBuiltinDefault,  ///< "default": LAVA's start-up cube, built in
  kBuiltinBlack,    ///< "black": nothing on a black background
  kScript,          ///< a LAVA `.mdl` script
  kScene,           ///< a `.sce` scene
  kModel,           ///< a model file (.obj, .off) shown as LAVA shows a loaded object
  kMovie,           ///< a movie played full frame
};
std::string_view entryKindName(EntryKind kind);

/// \brief How an entry's world is framed (`view = "scene" | "fit"` beside the entry).
enum class EntryView : std::uint8_t {
  kDefault,  ///< the entry's own: a scene's camera for `.sce`, LAVA's fit for everything else
  kScene,    ///< drawn in its own units from the scene's camera (a model: the thesis' default camera)
  kFit,      ///< LAVA's view: fitted to the window
};

struct EntrySpec {
  EntryKind kind = EntryKind::kBuiltinDefault;
  std::string text;            ///< as written in the manifest
  std::filesystem::path path;  ///< resolved, inside the show folder; empty for built-ins
  int line = 0;
  EntryView view = EntryView::kDefault;  ///< scenes and models
  friend bool operator==(const EntrySpec&, const EntrySpec&) = default;
};

enum class MediaKind : std::uint8_t { kMovie, kImage, kCamera };
std::string_view mediaKindName(MediaKind kind);

/// \brief `[media.NAME]`: a movie, an image or a live camera that textures can show.
/// \brief What a camera's texture shows while the camera is lost or not there yet.
enum class CameraLoss : std::uint8_t {
  kFallbackImage,  ///< the texture's `fallback` image (black without one): the default
  kLastFrame,      ///< the last frame it showed (the fallback image until there was one)
  kTestPattern,    ///< colour bars
  kColour,         ///< one colour
};

struct MediaSpec {
  std::string name;
  MediaKind kind = MediaKind::kMovie;
  std::filesystem::path file;                      ///< movie and image
  std::string device;                              ///< camera: a name from [devices]
  bool loop = true;                                ///< movie
  bool audio = false;                              ///< movie: play its sound
  CameraLoss onLoss = CameraLoss::kFallbackImage;  ///< camera: what shows while it is lost
  std::array<std::uint8_t, 3> lossColour{};        ///< camera: RGB for CameraLoss::kColour
  int line = 0;
};

enum class DeviceKind : std::uint8_t { kDialBox, kCamera, kTracker };
enum class DeviceBackend : std::uint8_t { kHid, kV4l2, kLibcamera, kReplay, kSynthetic, kSerial, kMidi, kOsc };
std::string_view deviceKindName(DeviceKind kind);
std::string_view deviceBackendName(DeviceBackend backend);

/// \brief How a real device is recognised. Every field given must match.
struct DeviceMatch {
  std::optional<std::uint16_t> vendor;
  std::optional<std::uint16_t> product;
  std::string name;  ///< the product name as the device reports it
  std::string path;  ///< a /dev node or a USB path
  std::string serial;
  [[nodiscard]] bool empty() const { return !vendor && !product && name.empty() && path.empty() && serial.empty(); }
};

/// \brief One scripted turn or press of a synthetic dial box.
struct SyntheticInput {
  Nanos at{0};
  bool button = false;
  bool shuttle = false;  ///< a shuttle ring held at `value` (-1..1) until the next shuttle input
  std::uint16_t index = 0;
  double value = 0;  ///< turns for a dial; 1 pressed, 0 released for a button
};

/// \brief A scripted fault of a synthetic camera (tests and demos of the fallbacks).
struct SyntheticFault {
  /// corrupt: one damaged JPEG (MJPEG cameras only)
  enum class Kind : std::uint8_t { kUnplug, kSignalLost, kStall, kCorrupt };
  Nanos at{0};  ///< after the camera opens
  Kind kind = Kind::kUnplug;
  Nanos duration{0};  ///< signal_lost and stall
};

/// \brief Where a synthetic tracker moves (sim::TrackerPath): `motion`, `radius` (metres),
/// `period` (seconds a lap), `rate` (samples a second), `centre` ([x, y, z] metres).
struct TrackerMotion {
  enum class Shape : std::uint8_t { kCircle, kLine, kFigureEight };
  Shape shape = Shape::kCircle;
  float radius = 0.3f;
  double period = 4;
  std::uint32_t rate = 90;
  std::array<float, 3> centre{};
};

/// \brief `[devices.NAME]`.
struct DeviceSpec {
  std::string name;
  DeviceKind kind = DeviceKind::kDialBox;
  DeviceBackend backend = DeviceBackend::kSynthetic;
  DeviceMatch match;
  std::filesystem::path trace;         ///< replay: the NAME.trace folder, or a hid-recorder file (dial boxes)
  std::vector<SyntheticInput> script;  ///< synthetic dial box: what it does
  bool loop = true;                    ///< synthetic and replay: start again at the end
  bool required = false;               ///< the show does not start without it (default: it waits)
  std::optional<std::uint32_t> width;  ///< camera: requested size
  std::optional<std::uint32_t> height;
  bool mirror = false;                 ///< camera: flip left-right (in the device, else the renderer)
  std::string format;                  ///< camera: "MJPEG", "YUYV", ... asked of the device (empty: any)
  std::vector<SyntheticFault> faults;  ///< synthetic camera: what goes wrong, when
  double gain = 1;                     ///< dial box: multiplies every dial's gain
  double acceleration = 0;             ///< dial box: every dial's acceleration unless a binding says otherwise
  /// midi dial box: `midi = { profile, encoding, channel, dials, buttons, notes, nrpn,
  /// high_resolution, echo }` as the backend's options (devices/midi/midi_backend.h), checked
  std::map<std::string, std::string> midi;
  TrackerMotion motion;  ///< synthetic tracker: its path
  int line = 0;
};

/// \brief What a button binding does to the kiosk (dials act on the show, runtime::Action).
enum class KioskAction : std::uint8_t { kNone, kNextItem, kPreviousItem, kResetView };

/// \brief `[[bindings]]`: one dial or button of one device, and what it does.
struct BindingSpec {
  std::string device;
  bool button = false;
  std::uint16_t index = 0;
  runtime::Action action = runtime::Action::kNone;  ///< dials
  KioskAction kioskAction = KioskAction::kNone;     ///< buttons
  double gain = 0;
  bool actionGiven = true;             ///< dials: false keeps LAVA's action for the dial
  bool gainGiven = false;              ///< dials: `gain` was written (else the action's default)
  std::optional<double> acceleration;  ///< dials: overrides the device's acceleration
  bool invert = false;                 ///< dials: turns the other way
  int line = 0;
};

/// \brief `[textures.NAME]`: what a texture name shows, and what it shows when its source is
/// gone (an unplugged camera, a missing movie).
struct TextureSpec {
  std::string name;
  std::string source;              ///< a name from [media]; empty when `file` is the texture
  std::filesystem::path file;      ///< an image file shown as the texture
  std::filesystem::path fallback;  ///< an image shown while the source is not live
  int line = 0;
};

/// \brief A span of opening hours within one day, in minutes after midnight (end exclusive;
/// 24:00 is 1440).
struct TimeRange {
  int begin = 0;
  int end = 0;
  friend bool operator==(const TimeRange&, const TimeRange&) = default;
};

/// \brief A calendar date (proleptic Gregorian).
struct Date {
  int year = 1970;
  unsigned month = 1;
  unsigned day = 1;
  friend auto operator<=>(const Date&, const Date&) = default;
};

/// \brief Hours that replace a weekday's on one date; empty hours mean closed all day.
struct ExceptionDay {
  Date date;
  std::vector<TimeRange> hours;
  std::string note;
  int line = 0;
};

/// \brief What the node does outside opening hours.
enum class OutsideHours : std::uint8_t { kStandby, kBlack, kDisplayOff };
std::string_view outsideHoursName(OutsideHours outside);

/// \brief `[kiosk.schedule]`. Weekdays are indexed 0 = Monday ... 6 = Sunday.
struct ScheduleSpec {
  bool present = false;
  std::string timezone = "UTC";
  std::array<std::vector<TimeRange>, 7> week;
  std::vector<ExceptionDay> exceptions;
  OutsideHours outside = OutsideHours::kBlack;
  std::optional<EntrySpec> standby;
  int line = 0;
};

/// \brief One thing a playlist plays, for `duration` (0: until it ends by itself, or forever).
struct PlaylistItem {
  std::string name;
  EntrySpec entry;
  Nanos duration{0};
  int line = 0;
};

/// \brief `[kiosk.attract]`: the loop shown while nobody is using the exhibit.
struct AttractSpec {
  bool present = false;
  std::vector<PlaylistItem> items;
  Nanos idleTimeout{std::chrono::seconds(60)};  ///< after the last input, back to the attract loop
  int line = 0;
};

/// \brief `[kiosk]`.
struct KioskSpec {
  ScheduleSpec schedule;
  AttractSpec attract;
  std::vector<PlaylistItem> playlist;  ///< empty: the show's entry plays for ever
  bool resume = true;                  ///< save the current item and position and resume after a restart
  int line = 0;
};

/// \brief `[status]`: the status and control server.
struct StatusSpec {
  bool enabled = false;
  std::string host = "127.0.0.1";
  std::uint16_t port = 8180;
  std::string token;                ///< controls need "Authorization: Bearer TOKEN"
  std::filesystem::path tokenFile;  ///< or the token is read from this file (may be outside the show)
  std::size_t maxRequestBytes = std::size_t{16} * 1024;
  double requestsPerSecond = 20;  ///< per client address
  /// GETs from other machines need "Authorization: Bearer READ_TOKEN" (or HTTP Basic with it as
  /// the password; the control token serves too); empty: no token needed to read.
  std::string readToken;
  std::filesystem::path readTokenFile;  ///< or the read token is read from this file
  bool snapshot = true;                 ///< GET /snapshot.png serves the frame on screen
  int line = 0;
  /// \brief True when `host` is a loopback address (127.0.0.0/8, ::1, "localhost").
  [[nodiscard]] bool loopbackOnly() const;
};

/// \brief `[input]`: keyboards and mice read from the kernel (evdev) when no window delivers
/// them. "auto": with the KMS output only (a window has its own; headless has no visitor).
enum class EvdevMode : std::uint8_t { kAuto, kOn, kOff };

struct InputSpec {
  EvdevMode evdev = EvdevMode::kAuto;
  bool keyboards = true;           ///< read keyboards and numeric pads
  bool pointers = true;            ///< read mice, trackballs and touchpads
  std::vector<std::string> names;  ///< only devices whose name contains one of these; empty: all
  int line = 0;
};

/// \brief `[lock]`: frame-locked display nodes (thesis §4.5, kiosk/lock/frame_lock.h).
enum class LockRole : std::uint8_t { kOff, kLeader, kFollower };

/// The shortest frame-lock key (`lock.key_file`) accepted: 32 characters (`openssl rand -hex 32`
/// writes 64).
inline constexpr std::size_t kLockKeyMinChars = 32;

/// \brief The frame-lock key in `file`: its text less surrounding white space, at least
/// kLockKeyMinChars long; or why it is not there.
[[nodiscard]] Result<std::string> readLockKey(const std::filesystem::path& file);

/// \brief True for an IPv4 or IPv6 address literal.
[[nodiscard]] bool isAddress(std::string_view text);

struct LockSpec {
  LockRole role = LockRole::kOff;
  std::string node;    ///< this node's name (default: the host name); unique in the group
  std::string leader;  ///< follower: the leader's address (IP or host name)
  /// Leader: the address of this node its sockets (and the shared clock) listen on; loopback
  /// unless the manifest names another, so that a lock is never open to every network by default.
  std::string listen = "127.0.0.1";
  /// The group's shared secret (`lock.key_file`, a credential like status.token_file): every
  /// connection proves it with ZeroMQ's CURVE handshake. Empty: unauthenticated.
  std::filesystem::path keyFile;
  int maxFollowers = 16;       ///< leader: followers it admits; the extra are refused and counted
  int maxFrameJump = 600;      ///< follower: a frame more than this ahead of the last drawn is refused
  int port = 5560;             ///< frames on port, answers on port + 1, the network clock on port + 2
  int followers = 0;           ///< leader: followers to wait for before the first frame
  int joinTimeoutMs = 5000;    ///< leader: how long to wait for them
  int timeoutMs = 20;          ///< leader: how long each frame waits for the followers' answers
  int dropAfter = 3;           ///< leader: missed frames in a row before a follower leaves the barrier
  int leaderTimeoutMs = 1000;  ///< follower: silence before the leader is reported lost
  bool clock = true;           ///< share the leader's clock (GStreamer's network clock)
  int line = 0;
  /// \brief True when the lock's sockets reach only this machine: the leader listens on, or the
  /// follower connects to, a loopback address (127.0.0.0/8, ::1, "localhost").
  [[nodiscard]] bool loopbackOnly() const;
};

/// \brief What an `[[osc.bind]]` does: a dial's action (`action` of runtime::Action), a kiosk
/// control, or one LAVA script command made from `command` and the message's arguments.
enum class OscDo : std::uint8_t { kDial, kNext, kPrevious, kReload, kResetView, kCommand };

/// \brief The most arguments an OSC binding takes (`types`), and the longest address.
inline constexpr std::size_t kOscMaxArguments = 8;
inline constexpr std::size_t kOscMaxAddressBytes = 256;

/// \brief `[[osc.bind]]`: one OSC address and what a message to it does.
struct OscBindingSpec {
  std::string address;  ///< "/basalt/rotate_y": an OSC address without wildcards
  OscDo what = OscDo::kDial;
  runtime::Action action = runtime::Action::kNone;  ///< kDial
  std::string command;                              ///< kCommand: a LAVA command with $1..$8 for the arguments
  /// The argument types a message must carry: 'f' a number (OSC i, h, f, d), 's' a string (s, S).
  std::string types;
  /// Numbers in `input` (clamped to it) are scaled linearly into `range`; without `range` they
  /// pass unchanged (commands) or one `input` is a turn of the dial (dial actions).
  std::array<double, 2> input{0, 1};
  std::optional<std::array<double, 2>> range;
  /// Dial actions: a number moves by its value (false), or is a position and moves by its
  /// change since the previous message (true: a fader; the first message sets the start).
  bool absolute = false;
  int line = 0;
};

/// \brief `[[osc.send]]`: a destination that follows the node over OSC.
struct OscSendSpec {
  std::string host;
  std::uint16_t port = 0;
  bool tcp = false;
  std::string prefix = "/basalt";
  bool item = true;     ///< PREFIX/item ,sii name index count when an item starts
  bool devices = true;  ///< PREFIX/device ,ss name state when a device is lost or back
  bool lock = true;     ///< PREFIX/lock ,si state followers when the frame-lock state changes
  /// Figures sent every 1/rate s, each as PREFIX/NAME with one number (kOscFigureNames).
  std::vector<std::string> figures;
  double rate = 1;
  int line = 0;
};

/// \brief The figures `[[osc.send]] figures` may name.
inline constexpr std::array<std::string_view, 8> kOscFigureNames{
    "fps", "frames", "late_frames", "dropped_frames", "input_dropped", "work_ms", "frame_ms", "osc_refused"};

/// \brief `[osc]`: OSC input (bindings) and output (destinations).
struct OscSpec {
  bool enabled = false;
  std::string host = "127.0.0.1";
  std::uint16_t port = 9000;
  bool udp = true;
  bool tcp = true;
  std::vector<std::string> allow;  ///< senders' addresses; empty: any sender that reaches the port
  double messagesPerSecond = 20;   ///< per sender, bursts of twice that (as [status] requests)
  std::vector<OscBindingSpec> bindings;
  std::vector<OscSendSpec> send;
  int line = 0;
  /// \brief True when `host` is a loopback address.
  [[nodiscard]] bool loopbackOnly() const;
};

/// \brief A whole show manifest, validated.
struct Manifest {
  std::filesystem::path file;    ///< absolute path of show.toml
  std::filesystem::path folder;  ///< the show folder every path is confined to
  std::string name;              ///< [show] name; default: the folder's name
  double fps = 60;
  EntrySpec entry;
  OutputSpec output;
  std::vector<ViewSpec> views;
  ViewerSpec viewer;  ///< the viewer of the facet views
  std::vector<MediaSpec> media;
  std::vector<DeviceSpec> devices;
  std::vector<BindingSpec> bindings;
  std::vector<TextureSpec> textures;
  KioskSpec kiosk;
  StatusSpec status;
  InputSpec input;
  LockSpec lock;
  OscSpec osc;

  /// \brief A manifest for the built-in default show: no file, every default.
  static Manifest builtinDefault();
  [[nodiscard]] const DeviceSpec* findDevice(std::string_view name) const;
  [[nodiscard]] const MediaSpec* findMedia(std::string_view name) const;
};

// ---------------------------------------------------------------------------------------------
// Reading

/// \brief Checks the contents of a file a manifest refers to (a script, scene, model, image).
/// Returns the problems found; an empty list means it parsed.
using ContentChecker = std::vector<Diagnostic> (*)(const std::filesystem::path& file);

/// \brief How a manifest is read.
struct ReadOptions {
  /// \brief Checks referenced files by extension (".mdl" -> the script checker). A file whose
  /// extension has no checker is only checked to exist, and a note says so.
  const std::map<std::string, ContentChecker, std::less<>>* fileCheckers = nullptr;
};

/// \brief Reads and validates `file`. Every problem goes into `diagnostics`; the result is
/// empty when there was an error (warnings and notes do not stop it).
std::optional<Manifest> readManifest(const std::filesystem::path& file, Diagnostics& diagnostics,
                                     const ReadOptions& options = {});

/// \brief Validates manifest `text` as if read from `file` (paths resolve against its folder).
/// For fuzzing and for tools that hold the text already.
std::optional<Manifest> readManifestText(std::string_view text, const std::filesystem::path& file,
                                         Diagnostics& diagnostics, const ReadOptions& options = {});

/// \brief Parses "90s", "5m", "1h30m", "250ms" or a plain number of seconds.
[[nodiscard]] Result<Nanos> parseDuration(std::string_view text);
/// \brief Parses "09:00-17:30" (24:00 allowed as an end).
[[nodiscard]] Result<TimeRange> parseTimeRange(std::string_view text);
/// \brief Parses "2026-12-24".
[[nodiscard]] Result<Date> parseDate(std::string_view text);
/// \brief Parses "1920x1080" or "1920x1080@60".
[[nodiscard]] Result<ModeRequest> parseMode(std::string_view text);

/// \brief Resolves `text` against `folder` and makes sure the result stays inside it (after
/// following symbolic links). Absolute paths are allowed only when they lie inside.
[[nodiscard]] Result<std::filesystem::path> confinePath(const std::filesystem::path& folder, std::string_view text);

}  // namespace basalt::kiosk
