// MIDI controllers as dial boxes: profiles and decoding, shared by the ALSA backend and the replay
// of Standard MIDI Files. No ALSA here.
//
// Profiles, from the vendors' documentation (factory settings; every one can be changed in the
// vendor's editor, which the generic profile and the manifest's overrides are for):
// - Behringer X-Touch Mini, standard mode (Behringer's X-Touch Mini MIDI tables): controls on
//   channel 11; layer A: encoders CC 1-8, fader CC 9, encoder pushes notes 0-7, buttons notes
//   8-23; layer B: encoders CC 11-18, fader CC 10, pushes notes 24-31, buttons notes 32-47. The
//   encoders are absolute and light their own rings; button lights by note 0-15 on the global
//   channel (1): velocity 1 lit, 2 blinking, 0 dark.
// - Behringer X-Touch Mini, MC mode (Mackie Control): V-Pots CC 16-23 on channel 1, relative in
//   sign-magnitude; their rings CC 48-55 (position 1..11 in the low bits); pushes notes 32-39;
//   buttons notes 89 90 40-45 (top row) and 87 88 91 92 86 93 94 95 (bottom row), layer A/B 84/85,
//   lit by the same note (127 lit, 1 blinking, 0 dark); the fader sends pitch bend on channel 9.
// - Korg nanoKONTROL2, CC mode (Korg's parameter list): channel 1, faders CC 0-7, knobs CC 16-23,
//   S/M/R buttons CC 32-39/48-55/64-71, transport CC 41-46 and 58-62 (127 pressed, 0 released);
//   lights by the same CC when its LED mode is "external".
// - Akai MIDImix (factory map): channel 1, knob rows CC 16 20 24 28 46 50 54 58 (+1, +2 for rows
//   2 and 3), faders CC 19 23 27 31 49 53 57 61, master CC 62; mute notes 1 4 ... 22, rec arm
//   notes 3 6 ... 24, solo (shift + mute) notes 2 5 ... 23, bank left/right 25/26, solo 27; the
//   mute, rec arm and bank buttons light by note on with velocity 127.

#include "devices/midi/midi_decoder.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <sstream>
#include <tuple>

namespace basalt::devices {

namespace {

constexpr std::string_view kMagic = "basalt-midi 1\n";
constexpr double kDetent = 1.0 / 24;  // one detent of a 24-detent encoder

MidiControl dial(MidiControlKind kind, int channel, int number, int index, MidiEncoding encoding, double turns) {
  MidiControl c;
  c.kind = kind;
  c.channel = static_cast<std::uint8_t>(channel);
  c.number = static_cast<std::uint16_t>(number);
  c.index = static_cast<std::uint16_t>(index);
  c.encoding = encoding;
  c.turns = turns;
  return c;
}

MidiControl button(MidiControlKind kind, int channel, int number, int index) {
  MidiControl c;
  c.kind = kind;
  c.channel = static_cast<std::uint8_t>(channel);
  c.number = static_cast<std::uint16_t>(number);
  c.index = static_cast<std::uint16_t>(index);
  c.button = true;
  return c;
}

MidiControl lit(MidiControl c, MidiFeedback feedback, int channel, int number) {
  c.feedback = feedback;
  c.feedbackChannel = static_cast<std::uint8_t>(channel == 0xff ? 0 : channel);  // any channel: answer on 1
  c.feedbackNumber = static_cast<std::uint16_t>(number);
  return c;
}

void finishShape(MidiProfile& p) {
  p.dials = 0;
  p.buttons = 0;
  for (const MidiControl& c : p.controls) {
    if (c.button) {
      p.buttons = std::max(p.buttons, c.index + 1);
    } else {
      p.dials = std::max(p.dials, c.index + 1);
    }
  }
}

MidiProfile xtouchMiniStandard() {
  MidiProfile p;
  p.name = "xtouch-mini";
  p.title = "Behringer X-Touch Mini (standard mode)";
  p.portNames = {"X-TOUCH MINI"};
  constexpr std::uint8_t ch = 10;  // channel 11
  for (int i = 0; i < 8; ++i) {
    p.controls.push_back(dial(MidiControlKind::kCc, ch, 1 + i, i, MidiEncoding::kAbsolute, 1));       // layer A
    p.controls.push_back(dial(MidiControlKind::kCc, ch, 11 + i, 9 + i, MidiEncoding::kAbsolute, 1));  // layer B
  }
  p.controls.push_back(dial(MidiControlKind::kCc, ch, 9, 8, MidiEncoding::kAbsolute, 1));
  p.controls.push_back(dial(MidiControlKind::kCc, ch, 10, 17, MidiEncoding::kAbsolute, 1));
  // Buttons are numbered as their notes: pushes 0-7, buttons 8-23 (layer A); 24-47 (layer B).
  for (int note = 0; note < 48; ++note) {
    MidiControl b = button(MidiControlKind::kNote, ch, note, note);
    if (note >= 8 && note < 24) b = lit(b, MidiFeedback::kXTouchLight, 0, note - 8);
    if (note >= 32) b = lit(b, MidiFeedback::kXTouchLight, 0, note - 32);
    p.controls.push_back(b);
  }
  finishShape(p);
  return p;
}

MidiProfile xtouchMiniMc() {
  MidiProfile p;
  p.name = "xtouch-mini-mc";
  p.title = "Behringer X-Touch Mini (MC mode)";
  p.portNames = {"X-TOUCH MINI"};
  for (int i = 0; i < 8; ++i) {
    p.controls.push_back(lit(dial(MidiControlKind::kCc, 0, 16 + i, i, MidiEncoding::kSignMagnitude, kDetent),
                             MidiFeedback::kMackieRing, 0, 48 + i));
    p.controls.push_back(button(MidiControlKind::kNote, 0, 32 + i, i));  // V-Pot pushes
  }
  p.controls.push_back(dial(MidiControlKind::kPitchBend, 8, 0, 8, MidiEncoding::kAbsolute, 1));
  constexpr std::array<std::uint16_t, 18> kButtons = {89, 90, 40, 41, 42, 43, 44, 45, 87,
                                                      88, 91, 92, 86, 93, 94, 95, 84, 85};
  for (int i = 0; i < static_cast<int>(kButtons.size()); ++i) {
    p.controls.push_back(lit(button(MidiControlKind::kNote, 0, kButtons[static_cast<std::size_t>(i)], 8 + i),
                             MidiFeedback::kNoteLight, 0, kButtons[static_cast<std::size_t>(i)]));
  }
  finishShape(p);
  return p;
}

MidiProfile nanoKontrol2() {
  MidiProfile p;
  p.name = "nanokontrol2";
  p.title = "Korg nanoKONTROL2 (CC mode)";
  p.portNames = {"nanoKONTROL2"};
  for (int i = 0; i < 8; ++i) {
    p.controls.push_back(dial(MidiControlKind::kCc, 0, i, i, MidiEncoding::kAbsolute, 1));           // faders
    p.controls.push_back(dial(MidiControlKind::kCc, 0, 16 + i, 8 + i, MidiEncoding::kAbsolute, 1));  // knobs
  }
  std::vector<std::uint16_t> ccs;
  for (int row : {32, 48, 64}) {
    for (std::uint16_t i = 0; i < 8; ++i) ccs.push_back(static_cast<std::uint16_t>(row + i));  // S, M, R
  }
  // track <, >, cycle, marker set, <, >, rewind, fast forward, stop, play, record
  for (int cc : {58, 59, 46, 60, 61, 62, 43, 44, 42, 41, 45}) ccs.push_back(static_cast<std::uint16_t>(cc));
  for (std::size_t i = 0; i < ccs.size(); ++i) {
    const auto b = static_cast<int>(i);
    p.controls.push_back(lit(button(MidiControlKind::kCc, 0, ccs[i], b), MidiFeedback::kCcLight, 0, ccs[i]));
  }
  finishShape(p);
  return p;
}

MidiProfile midimix() {
  MidiProfile p;
  p.name = "midimix";
  p.title = "Akai MIDImix";
  p.portNames = {"MIDI Mix", "MIDImix"};
  constexpr std::array<std::uint16_t, 8> kColumns = {16, 20, 24, 28, 46, 50, 54, 58};
  for (int col = 0; col < 8; ++col) {
    const std::uint16_t top = kColumns[static_cast<std::size_t>(col)];
    for (int row = 0; row < 3; ++row) {
      p.controls.push_back(dial(MidiControlKind::kCc, 0, top + row, row * 8 + col, MidiEncoding::kAbsolute, 1));
    }
    p.controls.push_back(dial(MidiControlKind::kCc, 0, top + 3, 24 + col, MidiEncoding::kAbsolute, 1));
  }
  p.controls.push_back(dial(MidiControlKind::kCc, 0, 62, 32, MidiEncoding::kAbsolute, 1));
  for (int col = 0; col < 8; ++col) {
    const int mute = 1 + 3 * col;
    const int arm = 3 + 3 * col;
    p.controls.push_back(lit(button(MidiControlKind::kNote, 0, mute, col), MidiFeedback::kNoteLight, 0, mute));
    p.controls.push_back(lit(button(MidiControlKind::kNote, 0, arm, 8 + col), MidiFeedback::kNoteLight, 0, arm));
    p.controls.push_back(button(MidiControlKind::kNote, 0, 2 + 3 * col, 16 + col));  // solo: shift + mute
  }
  p.controls.push_back(lit(button(MidiControlKind::kNote, 0, 25, 24), MidiFeedback::kNoteLight, 0, 25));
  p.controls.push_back(lit(button(MidiControlKind::kNote, 0, 26, 25), MidiFeedback::kNoteLight, 0, 26));
  p.controls.push_back(button(MidiControlKind::kNote, 0, 27, 26));
  finishShape(p);
  return p;
}

bool containsIgnoringCase(std::string_view haystack, std::string_view needle) {
  if (needle.empty()) return false;
  const auto lower = [](char c) { return static_cast<char>(std::tolower(static_cast<unsigned char>(c))); };
  return std::search(haystack.begin(), haystack.end(), needle.begin(), needle.end(),
                     [&](char a, char b) { return lower(a) == lower(b); }) != haystack.end();
}

Result<std::vector<std::uint16_t>> numberList(std::string_view key, std::string_view text, std::uint16_t max) {
  // "16-23,30,32": numbers and ranges.
  std::vector<std::uint16_t> out;
  std::size_t pos = 0;
  while (pos <= text.size()) {
    const std::size_t comma = std::min(text.find(',', pos), text.size());
    std::string_view item = text.substr(pos, comma - pos);
    while (!item.empty() && item.front() == ' ') item.remove_prefix(1);
    while (!item.empty() && item.back() == ' ') item.remove_suffix(1);
    const std::size_t dash = item.find('-');
    unsigned first = 0;
    unsigned last = 0;
    const auto num = [](std::string_view s, unsigned& v) {
      const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
      return !s.empty() && ec == std::errc{} && end == s.data() + s.size();
    };
    const bool ok = dash == std::string_view::npos
                        ? (num(item, first) && (last = first, true))
                        : (num(item.substr(0, dash), first) && num(item.substr(dash + 1), last));
    if (!ok || first > last || last > max) {
      return fail(Errc::kInvalidArgument,
                  fmt::format("MIDI option {}: '{}' is not a list of numbers 0..{} (\"16-23,30\")", key, item, max));
    }
    for (unsigned v = first; v <= last; ++v) out.push_back(static_cast<std::uint16_t>(v));
    pos = comma + 1;
  }
  return out;
}

std::string_view kindName(MidiControlKind kind) {
  switch (kind) {
    case MidiControlKind::kCc: return "cc";
    case MidiControlKind::kCc14: return "cc14";
    case MidiControlKind::kNrpn: return "nrpn";
    case MidiControlKind::kNote: return "note";
    case MidiControlKind::kPitchBend: return "pitchbend";
  }
  return "cc";
}

std::string_view feedbackName(MidiFeedback f) {
  switch (f) {
    case MidiFeedback::kNone: return "none";
    case MidiFeedback::kMackieRing: return "mackie_ring";
    case MidiFeedback::kXTouchRing: return "xtouch_ring";
    case MidiFeedback::kEchoValue: return "echo";
    case MidiFeedback::kNoteLight: return "note_light";
    case MidiFeedback::kCcLight: return "cc_light";
    case MidiFeedback::kXTouchLight: return "xtouch_light";
  }
  return "none";
}

MidiDecoder::Message message3(std::uint8_t a, std::uint8_t b, std::uint8_t c) {
  MidiDecoder::Message m;
  m.bytes = {a, b, c};
  m.size = 3;
  return m;
}

}  // namespace

std::string_view midiEncodingName(MidiEncoding encoding) {
  switch (encoding) {
    case MidiEncoding::kAbsolute: return "absolute";
    case MidiEncoding::kTwosComplement: return "twos_complement";
    case MidiEncoding::kSignMagnitude: return "sign_magnitude";
    case MidiEncoding::kBinaryOffset: return "binary_offset";
  }
  return "absolute";
}

std::optional<MidiEncoding> parseMidiEncoding(std::string_view name) {
  for (MidiEncoding e : {MidiEncoding::kAbsolute, MidiEncoding::kTwosComplement, MidiEncoding::kSignMagnitude,
                         MidiEncoding::kBinaryOffset}) {
    if (midiEncodingName(e) == name) return e;
  }
  return std::nullopt;
}

std::string MidiProfile::shape() const {
  return fmt::format("{} dial{}, {} button{}", dials, dials == 1 ? "" : "s", buttons, buttons == 1 ? "" : "s");
}

const std::vector<MidiProfile>& builtinMidiProfiles() {
  static const std::vector<MidiProfile> profiles = {xtouchMiniStandard(), xtouchMiniMc(), nanoKontrol2(), midimix()};
  return profiles;
}

std::optional<MidiProfile> midiProfileByName(std::string_view name) {
  for (const MidiProfile& p : builtinMidiProfiles()) {
    if (p.name == name) return p;
  }
  if (name == "generic") {
    if (auto g = makeGenericMidiProfile({})) return *g;
  }
  return std::nullopt;
}

MidiProfile midiProfileForPort(std::string_view portName) {
  for (const MidiProfile& p : builtinMidiProfiles()) {
    for (const std::string& n : p.portNames) {
      if (containsIgnoringCase(portName, n)) return p;
    }
  }
  return *makeGenericMidiProfile({});
}

Result<MidiProfile> makeGenericMidiProfile(const GenericMidiOptions& o) {
  MidiProfile p;
  p.name = "generic";
  p.title = "MIDI controller";
  p.generic = o;
  // Unset channel: the profile lists channel 0 and the decoder matches any channel (see find()).
  const std::uint8_t ch = o.channel.value_or(0xff);
  std::vector<std::uint16_t> dials = o.dials;
  if (dials.empty() && o.nrpn.empty()) {
    for (int cc = 0; cc < (o.highResolution ? 32 : 120); ++cc) dials.push_back(static_cast<std::uint16_t>(cc));
  }
  const double turns = o.encoding == MidiEncoding::kAbsolute ? 1.0 : kDetent;
  std::uint16_t index = 0;
  for (std::uint16_t cc : dials) {
    if (o.highResolution && cc >= 32) {
      return fail(Errc::kInvalidArgument,
                  fmt::format("MIDI option dials: CC {} cannot be a 14-bit MSB (0..31; its LSB is CC + 32)", cc));
    }
    if (cc > 119) {
      return fail(Errc::kInvalidArgument,
                  fmt::format("MIDI option dials: CC {} is a channel mode message (120..127), not a control", cc));
    }
    MidiControl c =
        dial(o.highResolution ? MidiControlKind::kCc14 : MidiControlKind::kCc, ch, cc, index++, o.encoding, turns);
    if (o.echo && o.encoding == MidiEncoding::kAbsolute) c = lit(c, MidiFeedback::kEchoValue, ch, cc);
    p.controls.push_back(c);
  }
  for (std::uint16_t n : o.nrpn) {
    MidiControl c = dial(MidiControlKind::kNrpn, ch, n, index++, o.encoding, turns);
    if (o.echo && o.encoding == MidiEncoding::kAbsolute) c = lit(c, MidiFeedback::kEchoValue, ch, n);
    p.controls.push_back(c);
  }
  std::uint16_t b = 0;
  for (std::uint16_t cc : o.buttons) {
    p.controls.push_back(lit(button(MidiControlKind::kCc, ch, cc, b++), MidiFeedback::kCcLight, ch, cc));
  }
  std::vector<std::uint16_t> notes = o.notes;
  if (notes.empty()) {
    for (std::uint16_t n = 0; n < 128; ++n) notes.push_back(n);
  }
  for (std::uint16_t n : notes) {
    p.controls.push_back(lit(button(MidiControlKind::kNote, ch, n, b++), MidiFeedback::kNoteLight, ch, n));
  }
  finishShape(p);
  return p;
}

Result<MidiProfile> midiProfileFromOptions(std::string_view portName,
                                           const std::map<std::string, std::string>& options) {
  static constexpr std::array<std::string_view, 9> kKnown = {
      "profile", "encoding", "channel", "dials", "buttons", "notes", "nrpn", "high_resolution", "echo"};
  bool generic = false;
  for (const auto& [key, value] : options) {
    if (std::find(kKnown.begin(), kKnown.end(), key) == kKnown.end()) continue;  // other backends' options
    generic = generic || (key != "profile" && key != "encoding");
  }
  MidiProfile profile = midiProfileForPort(portName);
  if (auto it = options.find("profile"); it != options.end() && !it->second.empty()) {
    auto named = midiProfileByName(it->second);
    if (!named) {
      std::string names;
      for (const MidiProfile& p : builtinMidiProfiles()) names += p.name + ", ";
      return fail(Errc::kInvalidArgument,
                  fmt::format("MIDI option profile: '{}' is not one of {}generic", it->second, names));
    }
    profile = *named;
  }
  std::optional<MidiEncoding> encoding;
  if (auto it = options.find("encoding"); it != options.end()) {
    encoding = parseMidiEncoding(it->second);
    if (!encoding) {
      return fail(Errc::kInvalidArgument,
                  fmt::format("MIDI option encoding: '{}' is not absolute, twos_complement, sign_magnitude or "
                              "binary_offset",
                              it->second));
    }
  }
  if (generic || profile.name == "generic") {
    GenericMidiOptions g;
    if (auto it = options.find("channel"); it != options.end()) {
      auto ch = numberList("channel", it->second, 16);
      if (!ch) return std::unexpected(ch.error());
      if (ch->size() != 1 || ch->front() < 1) {
        return fail(Errc::kInvalidArgument,
                    fmt::format("MIDI option channel: '{}' is not one channel 1..16", it->second));
      }
      g.channel = static_cast<std::uint8_t>(ch->front() - 1);
    }
    for (auto [key, out, max] : {std::tuple{"dials", &g.dials, 127}, std::tuple{"buttons", &g.buttons, 127},
                                 std::tuple{"notes", &g.notes, 127}, std::tuple{"nrpn", &g.nrpn, 16383}}) {
      if (auto it = options.find(key); it != options.end()) {
        auto list = numberList(key, it->second, static_cast<std::uint16_t>(max));
        if (!list) return std::unexpected(list.error());
        *out = std::move(*list);
      }
    }
    for (auto [key, out] : {std::pair{"high_resolution", &g.highResolution}, std::pair{"echo", &g.echo}}) {
      if (auto it = options.find(key); it != options.end()) {
        if (it->second != "true" && it->second != "false") {
          return fail(Errc::kInvalidArgument,
                      fmt::format("MIDI option {}: '{}' is not true or false", key, it->second));
        }
        *out = it->second == "true";
      }
    }
    if (encoding) g.encoding = *encoding;
    auto made = makeGenericMidiProfile(g);
    if (!made) return made;
    if (profile.name != "generic") made->title = profile.title + " (generic map)";
    return made;
  }
  if (encoding) {
    // The controller's encoders were set to another encoding in its editor: every relative dial
    // (or every dial of a profile without relative ones) reads it.
    const bool hasRelative = std::any_of(profile.controls.begin(), profile.controls.end(), [](const MidiControl& c) {
      return !c.button && c.encoding != MidiEncoding::kAbsolute;
    });
    for (MidiControl& c : profile.controls) {
      if (c.button || c.kind == MidiControlKind::kPitchBend) continue;
      if (hasRelative && c.encoding == MidiEncoding::kAbsolute) continue;
      if ((c.encoding == MidiEncoding::kAbsolute) != (*encoding == MidiEncoding::kAbsolute)) {
        c.turns = *encoding == MidiEncoding::kAbsolute ? 1.0 : kDetent;
        if (c.feedback == MidiFeedback::kMackieRing && *encoding == MidiEncoding::kAbsolute) {
          c.feedback = MidiFeedback::kNone;
        }
      }
      c.encoding = *encoding;
    }
  }
  return profile;
}

std::vector<std::uint8_t> midiDescriptor(const MidiProfile& profile) {
  std::string text(kMagic);
  text += fmt::format("name {}\ntitle {}\n", profile.name, profile.title);
  if (profile.generic) {
    // The generic map's settings, not its (up to 248) controls: the parser makes them again.
    const GenericMidiOptions& g = *profile.generic;
    const auto list = [](const std::vector<std::uint16_t>& v) {
      return v.empty() ? std::string("-") : fmt::format("{}", fmt::join(v, ","));
    };
    text += fmt::format("generic {} {} {} {} {} {} {} {}\n", g.channel ? std::to_string(*g.channel) : "any",
                        midiEncodingName(g.encoding), g.highResolution ? 1 : 0, g.echo ? 1 : 0, list(g.dials),
                        list(g.buttons), list(g.notes), list(g.nrpn));
    return {text.begin(), text.end()};
  }
  for (const MidiControl& c : profile.controls) {
    char turns[32];
    const auto [end, ec] = std::to_chars(turns, turns + sizeof turns, c.turns);
    text += fmt::format("control {} {} {} {} {} {} {} {} {} {}\n", kindName(c.kind), c.channel, c.number,
                        midiEncodingName(c.encoding), c.button ? "button" : "dial", c.index,
                        std::string_view(turns, static_cast<std::size_t>(end - turns)), feedbackName(c.feedback),
                        c.feedbackChannel, c.feedbackNumber);
  }
  return {text.begin(), text.end()};
}

bool isMidiDescriptor(std::span<const std::uint8_t> descriptor) {
  return descriptor.size() >= kMagic.size() && std::equal(kMagic.begin(), kMagic.end(), descriptor.begin());
}

Result<MidiProfile> parseMidiDescriptor(std::span<const std::uint8_t> descriptor) {
  if (!isMidiDescriptor(descriptor)) {
    return fail(Errc::kInvalidArgument, "not a MIDI dial box descriptor (no 'basalt-midi 1' line)");
  }
  std::istringstream in(std::string(descriptor.begin() + static_cast<std::ptrdiff_t>(kMagic.size()), descriptor.end()));
  MidiProfile p;
  std::string line;
  int lineNo = 1;
  while (std::getline(in, line)) {
    ++lineNo;
    if (line.starts_with("name ")) {
      p.name = line.substr(5);
      continue;
    }
    if (line.starts_with("title ")) {
      p.title = line.substr(6);
      continue;
    }
    if (line.starts_with("generic ")) {
      std::istringstream fields(line.substr(8));
      std::string channel, encoding, dials, buttons, notes, nrpn;
      int high = 0;
      int echo = 0;
      fields >> channel >> encoding >> high >> echo >> dials >> buttons >> notes >> nrpn;
      GenericMidiOptions g;
      const auto e = parseMidiEncoding(encoding);
      bool ok = static_cast<bool>(fields) && e.has_value();
      if (ok && channel != "any") {
        unsigned ch = 16;
        const auto [end, ec] = std::from_chars(channel.data(), channel.data() + channel.size(), ch);
        ok = ec == std::errc{} && end == channel.data() + channel.size() && ch < 16;
        g.channel = static_cast<std::uint8_t>(ch);
      }
      for (auto [text, out, max] : {std::tuple{&dials, &g.dials, 127}, std::tuple{&buttons, &g.buttons, 127},
                                    std::tuple{&notes, &g.notes, 127}, std::tuple{&nrpn, &g.nrpn, 16383}}) {
        if (!ok || *text == "-") continue;
        auto l = numberList("descriptor", *text, static_cast<std::uint16_t>(max));
        ok = l.has_value();
        if (ok) *out = std::move(*l);
      }
      if (!ok) {
        return fail(Errc::kParse,
                    fmt::format("MIDI dial box descriptor line {}: '{}' is not a generic map", lineNo, line));
      }
      g.encoding = *e;
      g.highResolution = high != 0;
      g.echo = echo != 0;
      auto made = makeGenericMidiProfile(g);
      if (!made) return made;
      made->title = p.title;
      return made;
    }
    std::istringstream fields(line);
    std::string word, kind, encoding, role, turns, feedback;
    unsigned channel = 0, number = 0, index = 0, fbChannel = 0, fbNumber = 0;
    fields >> word >> kind >> channel >> number >> encoding >> role >> index >> turns >> feedback >> fbChannel >>
        fbNumber;
    MidiControl c;
    bool ok = fields && word == "control" && (channel < 16 || channel == 0xff) && number <= 16383 && index <= 0xffff;
    ok = ok && (role == "dial" || role == "button");
    bool kindOk = false;
    for (MidiControlKind x : {MidiControlKind::kCc, MidiControlKind::kCc14, MidiControlKind::kNrpn,
                              MidiControlKind::kNote, MidiControlKind::kPitchBend}) {
      if (kindName(x) == kind) {
        c.kind = x;
        kindOk = true;
      }
    }
    bool feedbackOk = false;
    for (MidiFeedback f :
         {MidiFeedback::kNone, MidiFeedback::kMackieRing, MidiFeedback::kXTouchRing, MidiFeedback::kEchoValue,
          MidiFeedback::kNoteLight, MidiFeedback::kCcLight, MidiFeedback::kXTouchLight}) {
      if (feedbackName(f) == feedback) {
        c.feedback = f;
        feedbackOk = true;
      }
    }
    const auto e = parseMidiEncoding(encoding);
    const auto [end, ec] = std::from_chars(turns.data(), turns.data() + turns.size(), c.turns);
    if (!ok || !kindOk || !feedbackOk || !e || ec != std::errc{} || end != turns.data() + turns.size()) {
      return fail(Errc::kParse, fmt::format("MIDI dial box descriptor line {}: '{}' is not a control", lineNo, line));
    }
    c.channel = static_cast<std::uint8_t>(channel);
    c.number = static_cast<std::uint16_t>(number);
    c.encoding = *e;
    c.button = role == "button";
    c.index = static_cast<std::uint16_t>(index);
    c.feedbackChannel = static_cast<std::uint8_t>(fbChannel & 0x0f);
    c.feedbackNumber = static_cast<std::uint16_t>(fbNumber);
    p.controls.push_back(c);
  }
  finishShape(p);
  return p;
}

int midiMessageLength(std::uint8_t status) {
  if (status < 0x80) return 0;
  if (status < 0xf0) return (status & 0xf0) == 0xc0 || (status & 0xf0) == 0xd0 ? 2 : 3;
  switch (status) {
    case 0xf1:
    case 0xf3: return 2;
    case 0xf2: return 3;
    case 0xf6:
    case 0xf8:
    case 0xfa:
    case 0xfb:
    case 0xfc:
    case 0xfe:
    case 0xff: return 1;
    default: return 0;
  }
}

MidiDecoder::MidiDecoder(MidiProfile profile)
    : profile_(std::move(profile)), position_(static_cast<std::size_t>(profile_.dials), 0.0) {}

void MidiDecoder::reset() {
  channels_ = {};
  std::fill(position_.begin(), position_.end(), 0.0);
}

const MidiControl* MidiDecoder::find(MidiControlKind kind, std::uint8_t channel, std::uint16_t number) const {
  for (const MidiControl& c : profile_.controls) {
    if (c.kind == kind && c.number == number && (c.channel == channel || c.channel == 0xff)) return &c;
  }
  return nullptr;
}

std::size_t MidiDecoder::controlEvent(const MidiControl& c, int value, bool relativeStep, std::span<Event> out,
                                      std::size_t n) {
  if (n >= out.size()) return n;
  const bool wide =
      c.kind == MidiControlKind::kCc14 || c.kind == MidiControlKind::kNrpn || c.kind == MidiControlKind::kPitchBend;
  if (c.button) {
    out[n] = Event{Nanos{0}, 0, EventKind::kButton, c.index, value >= (wide ? 8192 : 64) ? 1.0 : 0.0};
    return n + 1;
  }
  int steps = 0;
  if (relativeStep) {
    steps = value;  // data increment/decrement: one step each
  } else {
    const int half = wide ? 8192 : 64;
    switch (c.encoding) {
      case MidiEncoding::kAbsolute: {
        const double full = wide ? 16383.0 : 127.0;
        out[n] = Event{Nanos{0}, 0, EventKind::kDialAbsolute, c.index, value / full * c.turns};
        return n + 1;
      }
      case MidiEncoding::kTwosComplement: steps = value < half ? value : value - 2 * half; break;
      case MidiEncoding::kSignMagnitude: steps = (value & half) != 0 ? -(value & (half - 1)) : value; break;
      case MidiEncoding::kBinaryOffset: steps = value - half; break;
    }
  }
  if (steps == 0) return n;
  const double turns = steps * c.turns;
  if (c.index < position_.size()) position_[c.index] += turns;
  out[n] = Event{Nanos{0}, 0, EventKind::kDialDelta, c.index, turns};
  return n + 1;
}

std::size_t MidiDecoder::decode(std::span<const std::uint8_t> m, std::span<Event> out) {
  if (m.empty()) return 0;
  const std::uint8_t status = m[0];
  if (status < 0x80 || status >= 0xf0 || static_cast<int>(m.size()) < midiMessageLength(status)) return 0;
  const auto ch = static_cast<std::uint8_t>(status & 0x0f);
  const std::uint8_t d1 = m.size() > 1 ? (m[1] & 0x7f) : 0;
  const std::uint8_t d2 = m.size() > 2 ? (m[2] & 0x7f) : 0;
  std::size_t n = 0;
  switch (status & 0xf0) {
    case 0x80:
      if (const MidiControl* c = find(MidiControlKind::kNote, ch, d1); c && c->button)
        n = controlEvent(*c, 0, false, out, n);
      break;
    case 0x90:
      if (const MidiControl* c = find(MidiControlKind::kNote, ch, d1); c && c->button) {
        n = controlEvent(*c, d2 > 0 ? 127 : 0, false, out, n);
      }
      break;
    case 0xe0:
      if (const MidiControl* c = find(MidiControlKind::kPitchBend, ch, 0))
        n = controlEvent(*c, d1 | (d2 << 7), false, out, n);
      break;
    case 0xb0: {
      ChannelState& s = channels_[ch];
      // 14-bit and NRPN controllers first: their CCs may also be listed as plain ones elsewhere.
      switch (d1) {
        case 99:
          s.nrpnMsb = d2;
          s.nrpn = -1;
          return 0;
        case 98: s.nrpn = s.nrpnMsb == 0x7f ? -1 : (s.nrpnMsb << 7) | d2; return 0;
        case 101:
        case 100:
          s.nrpn = -1;  // an RPN: not ours
          s.nrpnMsb = 0x7f;
          return 0;
        case 6:
        case 38:
        case 96:
        case 97:
          if (s.nrpn >= 0) {
            const MidiControl* c = find(MidiControlKind::kNrpn, ch, static_cast<std::uint16_t>(s.nrpn));
            if (!c) return 0;
            if (d1 == 6) {
              s.dataMsb = d2;
              s.dataLsb = 0;  // a new MSB starts a new value (the LSB, if any, follows)
              return controlEvent(*c, s.dataMsb << 7, false, out, n);
            }
            if (d1 == 38) {
              s.dataLsb = d2;
              return controlEvent(*c, (s.dataMsb << 7) | s.dataLsb, false, out, n);
            }
            if (c->encoding == MidiEncoding::kAbsolute) {
              int v = ((s.dataMsb << 7) | s.dataLsb) + (d1 == 96 ? 1 : -1);
              v = std::clamp(v, 0, 16383);
              s.dataMsb = static_cast<std::uint8_t>(v >> 7);
              s.dataLsb = static_cast<std::uint8_t>(v & 0x7f);
              return controlEvent(*c, v, false, out, n);
            }
            return controlEvent(*c, d1 == 96 ? 1 : -1, true, out, n);
          }
          break;
        default: break;
      }
      if (d1 < 32) {
        if (const MidiControl* c = find(MidiControlKind::kCc14, ch, d1)) {
          s.ccMsb[d1] = d2;
          s.ccLsb[d1] = 0;
          return controlEvent(*c, d2 << 7, false, out, n);
        }
      } else if (d1 < 64) {
        if (const MidiControl* c = find(MidiControlKind::kCc14, ch, d1 - 32)) {
          s.ccLsb[d1 - 32] = d2;
          return controlEvent(*c, (s.ccMsb[d1 - 32] << 7) | d2, false, out, n);
        }
      }
      if (const MidiControl* c = find(MidiControlKind::kCc, ch, d1)) n = controlEvent(*c, d2, false, out, n);
      break;
    }
    default: break;
  }
  return n;
}

void MidiDecoder::feedbackFor(std::span<const Event> events, std::vector<Message>& out) const {
  for (const Event& e : events) {
    if (e.kind != EventKind::kDialDelta && e.kind != EventKind::kDialAbsolute) continue;
    for (const MidiControl& c : profile_.controls) {
      if (c.button || c.index != e.index || c.feedback == MidiFeedback::kNone) continue;
      if (c.index >= position_.size()) continue;
      const double pos = e.kind == EventKind::kDialDelta ? position_[c.index] : e.value / (c.turns == 0 ? 1 : c.turns);
      const double frac = pos - std::floor(pos);  // within one turn, 0..1
      const auto status = static_cast<std::uint8_t>(0xb0 | c.feedbackChannel);
      const auto number = static_cast<std::uint8_t>(c.feedbackNumber & 0x7f);
      switch (c.feedback) {
        case MidiFeedback::kMackieRing:
          // Single-dot mode (bits 4-5 zero), LEDs 1..11 round the ring.
          out.push_back(message3(status, number, static_cast<std::uint8_t>(1 + std::lround(frac * 10))));
          break;
        case MidiFeedback::kXTouchRing:
          out.push_back(message3(status, number, static_cast<std::uint8_t>(1 + std::lround(frac * 12))));
          break;
        case MidiFeedback::kEchoValue: {
          if (e.kind != EventKind::kDialAbsolute) break;
          const double v = std::clamp(e.value / (c.turns == 0 ? 1 : c.turns), 0.0, 1.0);
          if (c.kind == MidiControlKind::kPitchBend) {
            const auto w = static_cast<int>(std::lround(v * 16383));
            out.push_back(message3(static_cast<std::uint8_t>(0xe0 | c.feedbackChannel),
                                   static_cast<std::uint8_t>(w & 0x7f), static_cast<std::uint8_t>(w >> 7)));
          } else if (c.kind == MidiControlKind::kCc14) {
            const auto w = static_cast<int>(std::lround(v * 16383));
            out.push_back(message3(status, number, static_cast<std::uint8_t>(w >> 7)));
            out.push_back(
                message3(status, static_cast<std::uint8_t>(number + 32), static_cast<std::uint8_t>(w & 0x7f)));
          } else if (c.kind == MidiControlKind::kCc) {
            out.push_back(message3(status, number, static_cast<std::uint8_t>(std::lround(v * 127))));
          }
          break;
        }
        default: break;
      }
    }
  }
}

std::optional<MidiDecoder::Message> MidiDecoder::lightMessage(int index, double level, bool pulse) const {
  for (const MidiControl& c : profile_.controls) {
    if (!c.button || c.index != index) continue;
    const bool on = level >= 0.5;
    const auto number = static_cast<std::uint8_t>(c.feedbackNumber & 0x7f);
    switch (c.feedback) {
      case MidiFeedback::kNoteLight:
        return message3(static_cast<std::uint8_t>(0x90 | c.feedbackChannel), number,
                        static_cast<std::uint8_t>(pulse ? 1 : (on ? 127 : 0)));
      case MidiFeedback::kXTouchLight:
        return message3(static_cast<std::uint8_t>(0x90 | c.feedbackChannel), number,
                        static_cast<std::uint8_t>(pulse ? 2 : (on ? 1 : 0)));
      case MidiFeedback::kCcLight:
        return message3(static_cast<std::uint8_t>(0xb0 | c.feedbackChannel), number,
                        static_cast<std::uint8_t>(on || pulse ? 127 : 0));
      default: return std::nullopt;
    }
  }
  return std::nullopt;
}

}  // namespace basalt::devices
