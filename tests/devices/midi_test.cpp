// MIDI controllers as dial boxes: each encoding, 14-bit controllers, NRPNs, notes, the built-in
// profiles and their feedback. Every byte sequence below is written from the MIDI 1.0
// specification (status 0xBn control change, 0x9n/0x8n notes, 0xEn pitch bend, CC 99/98 NRPN
// select, 6/38 data entry) and the vendors' published maps, never produced by the code under test.
// Example failures: a sign-magnitude encoder read as two's complement turns the wrong way at
// speed; a MIDImix fader mapped to a knob's dial; an NRPN's data LSB dropped; a note off read as
// a press.

#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "devices/midi/midi_decoder.h"

namespace basalt::devices {
namespace {

std::vector<Event> decode(MidiDecoder& d, std::vector<std::uint8_t> bytes) {
  std::array<Event, MidiDecoder::kMaxEventsPerMessage> out{};
  const std::size_t n = d.decode(bytes, out);
  return {out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n)};
}

MidiProfile generic(std::map<std::string, std::string> options) {
  auto p = midiProfileFromOptions("Some Controller: Port 1", options);
  EXPECT_TRUE(p) << (p ? "" : p.error().describe());
  return p ? *p : MidiProfile{};
}

void expectDelta(const std::vector<Event>& e, std::uint16_t index, double turns) {
  ASSERT_EQ(e.size(), 1u);
  EXPECT_EQ(e[0].kind, EventKind::kDialDelta);
  EXPECT_EQ(e[0].index, index);
  EXPECT_DOUBLE_EQ(e[0].value, turns);
}

void expectAbsolute(const std::vector<Event>& e, std::uint16_t index, double position) {
  ASSERT_EQ(e.size(), 1u);
  EXPECT_EQ(e[0].kind, EventKind::kDialAbsolute);
  EXPECT_EQ(e[0].index, index);
  EXPECT_DOUBLE_EQ(e[0].value, position);
}

void expectButton(const std::vector<Event>& e, std::uint16_t index, double value) {
  ASSERT_EQ(e.size(), 1u);
  EXPECT_EQ(e[0].kind, EventKind::kButton);
  EXPECT_EQ(e[0].index, index);
  EXPECT_EQ(e[0].value, value);
}

constexpr double kDetent = 1.0 / 24;

TEST(MidiEncodings, TwosComplement) {
  MidiDecoder d(generic({{"dials", "16"}, {"encoding", "twos_complement"}}));
  expectDelta(decode(d, {0xB0, 16, 0x01}), 0, kDetent);
  expectDelta(decode(d, {0xB0, 16, 0x7F}), 0, -kDetent);      // 127 = -1
  expectDelta(decode(d, {0xB0, 16, 0x7D}), 0, -3 * kDetent);  // 125 = -3
  expectDelta(decode(d, {0xB0, 16, 0x05}), 0, 5 * kDetent);
}

TEST(MidiEncodings, SignMagnitude) {
  MidiDecoder d(generic({{"dials", "16"}, {"encoding", "sign_magnitude"}}));
  expectDelta(decode(d, {0xB0, 16, 0x01}), 0, kDetent);
  expectDelta(decode(d, {0xB0, 16, 0x41}), 0, -kDetent);      // bit 6 set: down 1
  expectDelta(decode(d, {0xB0, 16, 0x45}), 0, -5 * kDetent);  // down 5
  expectDelta(decode(d, {0xB0, 16, 0x0F}), 0, 15 * kDetent);
}

TEST(MidiEncodings, BinaryOffset) {
  MidiDecoder d(generic({{"dials", "16"}, {"encoding", "binary_offset"}}));
  expectDelta(decode(d, {0xB0, 16, 0x41}), 0, kDetent);   // 65 = +1
  expectDelta(decode(d, {0xB0, 16, 0x3F}), 0, -kDetent);  // 63 = -1
  expectDelta(decode(d, {0xB0, 16, 0x44}), 0, 4 * kDetent);
  EXPECT_TRUE(decode(d, {0xB0, 16, 0x40}).empty()) << "64 is no motion";
}

TEST(MidiEncodings, AbsoluteSevenBitAndChannelFilter) {
  MidiDecoder d(generic({{"dials", "7,10"}, {"channel", "3"}}));
  expectAbsolute(decode(d, {0xB2, 7, 127}), 0, 1.0);
  expectAbsolute(decode(d, {0xB2, 10, 0}), 1, 0.0);
  expectAbsolute(decode(d, {0xB2, 10, 64}), 1, 64.0 / 127);
  EXPECT_TRUE(decode(d, {0xB0, 7, 64}).empty()) << "channel 1 is not channel 3";
}

TEST(MidiEncodings, FourteenBitControlChangePair) {
  MidiDecoder d(generic({{"dials", "1"}, {"high_resolution", "true"}}));
  // MSB on CC 1, then LSB on CC 33: 0x40 << 7 | 0x00 = 8192, then 0x40 << 7 | 0x11 = 8209.
  expectAbsolute(decode(d, {0xB0, 1, 0x40}), 0, 8192.0 / 16383);
  expectAbsolute(decode(d, {0xB0, 33, 0x11}), 0, 8209.0 / 16383);
  expectAbsolute(decode(d, {0xB0, 1, 0x7F}), 0, 16256.0 / 16383);  // a new MSB clears the LSB
  expectAbsolute(decode(d, {0xB0, 33, 0x7F}), 0, 1.0);
}

TEST(MidiEncodings, Nrpn) {
  MidiDecoder d(generic({{"nrpn", "5"}}));
  // Parameter 5 (MSB 0, LSB 5), data 0x10/0x20: 0x10 << 7 | 0x20 = 2080.
  EXPECT_TRUE(decode(d, {0xB0, 99, 0}).empty());
  EXPECT_TRUE(decode(d, {0xB0, 98, 5}).empty());
  expectAbsolute(decode(d, {0xB0, 6, 0x10}), 0, 2048.0 / 16383);
  expectAbsolute(decode(d, {0xB0, 38, 0x20}), 0, 2080.0 / 16383);
  expectAbsolute(decode(d, {0xB0, 96, 0}), 0, 2081.0 / 16383);  // data increment
  expectAbsolute(decode(d, {0xB0, 97, 0}), 0, 2080.0 / 16383);  // data decrement
  // Another parameter (6) is not ours; nor is data entry after an RPN select.
  EXPECT_TRUE(decode(d, {0xB0, 98, 6}).empty());
  EXPECT_TRUE(decode(d, {0xB0, 6, 0x10}).empty());
  EXPECT_TRUE(decode(d, {0xB0, 101, 0}).empty());
  EXPECT_TRUE(decode(d, {0xB0, 100, 5}).empty());
  EXPECT_TRUE(decode(d, {0xB0, 6, 0x10}).empty());
}

TEST(MidiEncodings, RelativeNrpnSteps) {
  MidiDecoder d(generic({{"nrpn", "300"}, {"encoding", "binary_offset"}}));
  // Parameter 300 = MSB 2, LSB 44; increments and decrements are one step each.
  (void)decode(d, {0xB0, 99, 2});
  (void)decode(d, {0xB0, 98, 44});
  expectDelta(decode(d, {0xB0, 96, 1}), 0, kDetent);
  expectDelta(decode(d, {0xB0, 97, 1}), 0, -kDetent);
}

TEST(MidiEncodings, NotesAreButtons) {
  MidiDecoder d(generic({{"dials", "1"}, {"notes", "36-39"}}));
  expectButton(decode(d, {0x90, 37, 100}), 1, 1);
  expectButton(decode(d, {0x80, 37, 64}), 1, 0);
  expectButton(decode(d, {0x90, 36, 127}), 0, 1);
  expectButton(decode(d, {0x90, 36, 0}), 0, 0);  // note on with velocity 0 is a release
  EXPECT_TRUE(decode(d, {0x90, 40, 127}).empty());
  EXPECT_TRUE(decode(d, {0xB0, 1}).empty()) << "a truncated message decodes to nothing";
}

TEST(MidiProfiles, MatchedByPortName) {
  EXPECT_EQ(midiProfileForPort("X-TOUCH MINI: X-TOUCH MINI MIDI 1").name, "xtouch-mini");
  EXPECT_EQ(midiProfileForPort("nanoKONTROL2: nanoKONTROL2 MIDI 1").name, "nanokontrol2");
  EXPECT_EQ(midiProfileForPort("MIDI Mix: MIDI Mix MIDI 1").name, "midimix");
  EXPECT_EQ(midiProfileForPort("Arturia BeatStep: Arturia BeatStep MIDI 1").name, "generic");
}

TEST(MidiProfiles, XTouchMiniMcMode) {
  auto p = midiProfileByName("xtouch-mini-mc");
  ASSERT_TRUE(p);
  EXPECT_EQ(p->dials, 9);
  EXPECT_EQ(p->buttons, 26);
  MidiDecoder d(*p);
  expectDelta(decode(d, {0xB0, 0x10, 0x01}), 0, kDetent);            // V-Pot 1 clockwise
  expectDelta(decode(d, {0xB0, 0x17, 0x43}), 7, -3 * kDetent);       // V-Pot 8 counter-clockwise 3
  expectButton(decode(d, {0x90, 0x20, 0x7F}), 0, 1);                 // V-Pot 1 push
  expectButton(decode(d, {0x90, 0x59, 0x7F}), 8, 1);                 // top row, first button (note 89)
  expectButton(decode(d, {0x90, 0x5F, 0x7F}), 23, 1);                // bottom row, last button (note 95)
  expectButton(decode(d, {0x90, 0x55, 0x7F}), 25, 1);                // layer B (note 85)
  expectAbsolute(decode(d, {0xE8, 0x00, 0x40}), 8, 8192.0 / 16383);  // fader: pitch bend on channel 9
  // Half a turn (12 detents) puts the ring's dot on the middle LED of 11: Mackie ring CC 48, value 6.
  std::vector<MidiDecoder::Message> fb;
  const auto e = decode(d, {0xB0, 0x10, 0x0C});
  d.feedbackFor(e, fb);
  ASSERT_EQ(fb.size(), 1u);
  EXPECT_EQ(std::vector<std::uint8_t>(fb[0].span().begin(), fb[0].span().end()),
            (std::vector<std::uint8_t>{0xB0, 0x30, 0x06}));
  auto light = d.lightMessage(8, 1, true);
  ASSERT_TRUE(light);
  EXPECT_EQ(std::vector<std::uint8_t>(light->span().begin(), light->span().end()),
            (std::vector<std::uint8_t>{0x90, 0x59, 0x01}))
      << "Mackie button lights blink at velocity 1";
}

TEST(MidiProfiles, XTouchMiniStandardMode) {
  auto p = midiProfileByName("xtouch-mini");
  ASSERT_TRUE(p);
  MidiDecoder d(*p);
  expectAbsolute(decode(d, {0xBA, 1, 127}), 0, 1.0);   // layer A encoder 1, channel 11
  expectAbsolute(decode(d, {0xBA, 9, 0}), 8, 0.0);     // layer A fader
  expectAbsolute(decode(d, {0xBA, 11, 127}), 9, 1.0);  // layer B encoder 1
  expectAbsolute(decode(d, {0xBA, 10, 127}), 17, 1.0);
  expectButton(decode(d, {0x9A, 8, 127}), 8, 1);  // upper row, first button
  EXPECT_TRUE(decode(d, {0xB0, 1, 127}).empty()) << "channel 1 is not the X-Touch Mini's";
  auto light = d.lightMessage(8, 1, false);
  ASSERT_TRUE(light);
  EXPECT_EQ(std::vector<std::uint8_t>(light->span().begin(), light->span().end()),
            (std::vector<std::uint8_t>{0x90, 0x00, 0x01}))
      << "standard mode's button LED remote control: note 0, velocity 1 lit";
}

TEST(MidiProfiles, NanoKontrol2) {
  auto p = midiProfileByName("nanokontrol2");
  ASSERT_TRUE(p);
  EXPECT_EQ(p->dials, 16);
  EXPECT_EQ(p->buttons, 35);
  MidiDecoder d(*p);
  expectAbsolute(decode(d, {0xB0, 0x00, 0x7F}), 0, 1.0);          // fader 1
  expectAbsolute(decode(d, {0xB0, 0x12, 0x40}), 10, 64.0 / 127);  // knob 3
  expectButton(decode(d, {0xB0, 0x20, 0x7F}), 0, 1);              // S1
  expectButton(decode(d, {0xB0, 0x47, 0x00}), 23, 0);             // R8 released
  expectButton(decode(d, {0xB0, 0x29, 0x7F}), 33, 1);             // play (CC 41)
  auto light = d.lightMessage(33, 1, false);
  ASSERT_TRUE(light);
  EXPECT_EQ(std::vector<std::uint8_t>(light->span().begin(), light->span().end()),
            (std::vector<std::uint8_t>{0xB0, 0x29, 0x7F}));
}

TEST(MidiProfiles, Midimix) {
  auto p = midiProfileByName("midimix");
  ASSERT_TRUE(p);
  EXPECT_EQ(p->dials, 33);
  EXPECT_EQ(p->buttons, 27);
  MidiDecoder d(*p);
  expectAbsolute(decode(d, {0xB0, 16, 127}), 0, 1.0);   // column 1, top knob
  expectAbsolute(decode(d, {0xB0, 18, 127}), 16, 1.0);  // column 1, bottom knob
  expectAbsolute(decode(d, {0xB0, 46, 127}), 4, 1.0);   // column 5, top knob
  expectAbsolute(decode(d, {0xB0, 61, 127}), 31, 1.0);  // fader 8
  expectAbsolute(decode(d, {0xB0, 62, 127}), 32, 1.0);  // master
  expectButton(decode(d, {0x90, 22, 127}), 7, 1);       // mute 8
  expectButton(decode(d, {0x90, 3, 127}), 8, 1);        // rec arm 1
  expectButton(decode(d, {0x90, 27, 127}), 26, 1);      // solo
  auto light = d.lightMessage(8, 1, false);
  ASSERT_TRUE(light);
  EXPECT_EQ(std::vector<std::uint8_t>(light->span().begin(), light->span().end()),
            (std::vector<std::uint8_t>{0x90, 0x03, 0x7F}));
  EXPECT_FALSE(d.lightMessage(26, 1, false)) << "the solo button has no light";
}

TEST(MidiProfiles, EncodingOverrideAndOptionErrors) {
  // An X-Touch Mini in standard mode whose encoders were set relative in Behringer's editor.
  auto p = midiProfileFromOptions("X-TOUCH MINI: X-TOUCH MINI MIDI 1", {{"encoding", "binary_offset"}});
  ASSERT_TRUE(p);
  MidiDecoder d(*p);
  expectDelta(decode(d, {0xBA, 1, 0x41}), 0, kDetent);
  EXPECT_FALSE(midiProfileFromOptions("x", {{"profile", "launchpad"}}));
  EXPECT_FALSE(midiProfileFromOptions("x", {{"encoding", "gray"}}));
  EXPECT_FALSE(midiProfileFromOptions("x", {{"channel", "17"}}));
  EXPECT_FALSE(midiProfileFromOptions("x", {{"dials", "40"}, {"high_resolution", "true"}}));
  EXPECT_FALSE(midiProfileFromOptions("x", {{"dials", "16-"}}));
}

TEST(MidiProfiles, DescriptorRoundTrip) {
  for (const MidiProfile& p : {*midiProfileByName("xtouch-mini-mc"), *midiProfileByName("midimix"),
                               generic({{"nrpn", "5"}, {"dials", "1"}})}) {
    const auto desc = midiDescriptor(p);
    EXPECT_TRUE(isMidiDescriptor(desc));
    auto back = parseMidiDescriptor(desc);
    ASSERT_TRUE(back) << back.error().describe();
    EXPECT_EQ(back->name, p.name);
    EXPECT_EQ(back->dials, p.dials);
    EXPECT_EQ(back->buttons, p.buttons);
    ASSERT_EQ(back->controls.size(), p.controls.size());
    for (std::size_t i = 0; i < p.controls.size(); ++i) {
      EXPECT_EQ(back->controls[i].number, p.controls[i].number);
      EXPECT_EQ(back->controls[i].channel, p.controls[i].channel);
      EXPECT_EQ(back->controls[i].turns, p.controls[i].turns) << "turns must survive exactly";
      EXPECT_EQ(back->controls[i].feedback, p.controls[i].feedback);
    }
  }
  // The generic map is held as its settings, not its 248 controls (traces keep it twice).
  EXPECT_LT(midiDescriptor(generic({})).size(), 200u);
  auto g = parseMidiDescriptor(midiDescriptor(generic({{"channel", "4"}, {"notes", "36-39"}, {"echo", "true"}})));
  ASSERT_TRUE(g) << g.error().describe();
  MidiDecoder d(*g);
  expectButton(decode(d, {0x93, 37, 100}), 1, 1);
  EXPECT_TRUE(decode(d, {0x90, 37, 100}).empty()) << "the channel survives the descriptor";
  const std::uint8_t hid[] = {0x05, 0x01, 0x09, 0x37};
  EXPECT_FALSE(isMidiDescriptor(hid));
}

}  // namespace
}  // namespace basalt::devices
