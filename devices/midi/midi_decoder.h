#pragma once

/// \file
/// \brief MIDI controllers as dial boxes, without ALSA: profiles (which control is which dial or
/// button, in which encoding), the decoder from MIDI messages to Events, the feedback messages
/// (LED rings, button lights, faders) and the descriptor that stands for a profile in traces.
/// Real backends (devices/midi, ALSA) and the replay of Standard MIDI Files (sim/) feed the same
/// bytes through the same decoder.

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/error.h"
#include "runtime/event.h"

namespace basalt::devices {

/// \brief How a control's value is sent.
enum class MidiEncoding : std::uint8_t {
  kAbsolute,        ///< a position: 0..127 (0..16383 for 14-bit controls)
  kTwosComplement,  ///< relative: 1..63 up, 127..65 down by 1..63 (127 = -1)
  kSignMagnitude,   ///< relative: 1..63 up, 65..127 down by 1..63 (bit 6 is the sign; Mackie V-Pots)
  kBinaryOffset,    ///< relative: 64 + steps: 65 = +1, 63 = -1
};

/// \brief "absolute", "twos_complement", "sign_magnitude", "binary_offset".
std::string_view midiEncodingName(MidiEncoding encoding);
[[nodiscard]] std::optional<MidiEncoding> parseMidiEncoding(std::string_view name);

/// \brief The message a control sends.
enum class MidiControlKind : std::uint8_t {
  kCc,         ///< control change `number`
  kCc14,       ///< 14-bit control change: MSB on `number` (0-31), LSB on `number + 32`
  kNrpn,       ///< non-registered parameter `number` (0-16383): CC 99/98 select, 6/38 data, 96/97 step
  kNote,       ///< note `number`: on with a velocity presses, off (or velocity 0) releases
  kPitchBend,  ///< the channel's pitch bend (14 bits): Mackie faders
};

/// \brief What Basalt sends back to show a control's state.
enum class MidiFeedback : std::uint8_t {
  kNone,
  kMackieRing,   ///< CC `feedbackNumber`: ring position 1..11 (Mackie V-Pot ring, single-dot mode)
  kXTouchRing,   ///< CC `feedbackNumber`: LED 1..13 (X-Touch Mini standard mode's ring remote control)
  kEchoValue,    ///< the control's own message with its value: motor faders, knobs with LED collars
  kNoteLight,    ///< buttons: note on `feedbackNumber`, velocity 127 lit, 0 dark (1 blinking where supported)
  kCcLight,      ///< buttons: CC `feedbackNumber`, 127 lit, 0 dark
  kXTouchLight,  ///< buttons: note `feedbackNumber` with velocity 1 lit, 2 blinking, 0 dark (standard mode)
};

/// \brief One control of a controller: a dial (relative or absolute) or a button.
struct MidiControl {
  MidiControlKind kind = MidiControlKind::kCc;
  std::uint8_t channel = 0;  ///< 0..15 (MIDI channel 1..16)
  std::uint16_t number = 0;  ///< CC, note or NRPN number
  MidiEncoding encoding = MidiEncoding::kAbsolute;
  bool button = false;      ///< a button (notes; CCs with 127 pressed, 0 released)
  std::uint16_t index = 0;  ///< the dial's or button's index
  /// Relative dials: turns per step (1/24: one detent of a 24-detent encoder). Absolute dials:
  /// turns for the whole travel (1: the same scale as an absolute HID dial).
  double turns = 0;
  MidiFeedback feedback = MidiFeedback::kNone;
  std::uint8_t feedbackChannel = 0;
  std::uint16_t feedbackNumber = 0;
};

/// \brief The generic profile's settings (manifest keys `channel`, `dials`, `buttons`,
/// `encoding`, `notes`, ...).
struct GenericMidiOptions {
  std::optional<std::uint8_t> channel;  ///< 0..15; unset: every channel (each channel's CCs are one bank)
  std::vector<std::uint16_t> dials;  ///< CC numbers that are dials, in dial order (default: every CC 0..119, dial = CC)
  std::vector<std::uint16_t> buttons;  ///< CC numbers that are buttons
  std::vector<std::uint16_t> notes;    ///< notes that are buttons (default: every note, button = note)
  std::vector<std::uint16_t> nrpn;     ///< NRPN parameters that are dials, after the CC dials
  bool highResolution = false;         ///< dials' CCs are 14-bit MSB/LSB pairs (MSB 0..31)
  MidiEncoding encoding = MidiEncoding::kAbsolute;
  bool echo = false;  ///< send absolute dials' values back (motor faders, LED collars)
};

/// \brief A controller's controls, and how to recognise it by its ALSA client or port name.
struct MidiProfile {
  std::string name;   ///< "xtouch-mini-mc", "nanokontrol2", "midimix", "generic"
  std::string title;  ///< "Behringer X-Touch Mini (MC mode)"
  /// Case-insensitive substrings of the client or port name ("X-TOUCH MINI"); empty for generic.
  std::vector<std::string> portNames;
  std::vector<MidiControl> controls;
  int dials = 0;    ///< one more than the highest dial index
  int buttons = 0;  ///< one more than the highest button index
  /// The generic profile's settings, which its descriptor holds instead of every control.
  std::optional<GenericMidiOptions> generic;

  /// \brief "9 dials, 26 buttons".
  [[nodiscard]] std::string shape() const;
};

/// \brief The profiles Basalt knows (X-Touch Mini in MC mode and in standard mode, layer A and
/// B; nanoKONTROL2 in CC mode; MIDImix), by name.
const std::vector<MidiProfile>& builtinMidiProfiles();
/// \brief The built-in profile called `name`, or nothing.
[[nodiscard]] std::optional<MidiProfile> midiProfileByName(std::string_view name);
/// \brief The built-in profile whose port names match `portName` (client and port name), or the
/// generic one.
[[nodiscard]] MidiProfile midiProfileForPort(std::string_view portName);

/// \brief The generic profile: `options` made into controls.
[[nodiscard]] Result<MidiProfile> makeGenericMidiProfile(const GenericMidiOptions& options);

/// \brief Applies backend options (`profile`, `encoding`, `channel`, `dials`, `buttons`, `notes`,
/// `nrpn`, `high_resolution`, `echo`, as text) to the profile chosen for `portName`. Errors name
/// the option.
[[nodiscard]] Result<MidiProfile> midiProfileFromOptions(std::string_view portName,
                                                         const std::map<std::string, std::string>& options);

/// \brief The descriptor of a MIDI dial box's raw reports (each report one MIDI message): the
/// profile as text behind a magic line, so that a trace replays with the controls it was recorded
/// with.
[[nodiscard]] std::vector<std::uint8_t> midiDescriptor(const MidiProfile& profile);
/// \brief True when `descriptor` was made by midiDescriptor() (not a HID report descriptor).
[[nodiscard]] bool isMidiDescriptor(std::span<const std::uint8_t> descriptor);
/// \brief The profile in a descriptor made by midiDescriptor(). Errors name the line.
[[nodiscard]] Result<MidiProfile> parseMidiDescriptor(std::span<const std::uint8_t> descriptor);

/// \brief The length of a channel or system common message whose status is `status` (1..3), 0
/// for system exclusive and undefined statuses.
[[nodiscard]] int midiMessageLength(std::uint8_t status);

/// \brief Turns MIDI messages into dial and button events by a profile, keeping the state that
/// 14-bit controllers and NRPNs need; and makes the feedback messages.
///
/// Threading: one thread at a time (the reader's).
class MidiDecoder {
 public:
  static constexpr std::size_t kMaxEventsPerMessage = 4;
  /// A feedback message: up to 3 bytes.
  struct Message {
    std::array<std::uint8_t, 3> bytes{};
    std::uint8_t size = 0;
    [[nodiscard]] std::span<const std::uint8_t> span() const { return {bytes.data(), size}; }
  };

  explicit MidiDecoder(MidiProfile profile);

  /// \brief Decodes one complete message (status byte first, no running status) into `out`
  /// (time and device left 0). Returns how many events were written. Messages of no control are
  /// ignored.
  std::size_t decode(std::span<const std::uint8_t> message, std::span<Event> out);
  /// \brief Forgets the 14-bit, NRPN and position state (on open).
  void reset();

  /// \brief The feedback the events of the last decode() call ask for (a relative dial's LED ring
  /// following its position), appended to `out`.
  void feedbackFor(std::span<const Event> events, std::vector<Message>& out) const;
  /// \brief The message that lights button `index` (level 0..1, pulse: blinking), if it has a light.
  [[nodiscard]] std::optional<Message> lightMessage(int index, double level, bool pulse) const;

  [[nodiscard]] const MidiProfile& profile() const { return profile_; }

 private:
  struct ChannelState {
    std::int32_t nrpn = -1;  // selected parameter; -1 none (or an RPN)
    std::uint8_t nrpnMsb = 0x7f;
    std::uint8_t dataMsb = 0;
    std::uint8_t dataLsb = 0;
    std::array<std::uint8_t, 32> ccMsb{};
    std::array<std::uint8_t, 32> ccLsb{};
  };
  std::size_t controlEvent(const MidiControl& c, int value, bool relativeStep, std::span<Event> out, std::size_t n);
  const MidiControl* find(MidiControlKind kind, std::uint8_t channel, std::uint16_t number) const;

  MidiProfile profile_;
  std::array<ChannelState, 16> channels_{};
  std::vector<double> position_;  // each dial's position in turns since open (LED rings)
};

}  // namespace basalt::devices
