// Standard MIDI Files as recordings of MIDI dial boxes. Expected bytes and times are worked out
// by hand from the SMF 1.0 specification (MThd/MTrk chunks, variable-length deltas, running
// status, tempo meta events FF 51, SMPTE divisions), not produced by the writer under test.
// Example failures: ticks converted with the wrong tempo after a tempo change; running status
// lost after a system exclusive event; a replay whose events drift from the recorded times.

#include <gtest/gtest.h>

#include <array>
#include <filesystem>
#include <fstream>

#include "devices/midi/midi_decoder.h"
#include "sim/midi_file.h"
#include "sim/providers.h"
#include "sim/replay.h"

namespace basalt::sim {
namespace {

using namespace std::chrono_literals;

TEST(MidiFile, WritesFormatZeroWithMicrosecondTicks) {
  HidRecordedDevice d;
  d.name = "X";
  d.descriptor = {0x05, 0x01};                                  // not a MIDI profile: no text event
  d.reports.push_back({Nanos{1'500'999}, {0xB0, 0x10, 0x01}});  // 1500 µs (truncated)
  const std::vector<std::uint8_t> expected = {
      'M',  'T',  'h',  'd',  0,    0,    0,    6,
      0,    0,    0,    1,    0x03, 0xE8,              // format 0, 1 track, 1000 ticks a quarter
      'M',  'T',  'r',  'k',  0,    0,    0,    0x15,  // 21 bytes
      0x00, 0xFF, 0x51, 0x03, 0x00, 0x03, 0xE8,        // tempo: 1000 µs a quarter
      0x00, 0xFF, 0x03, 0x01, 'X',                     // track name
      0x8B, 0x5C, 0xB0, 0x10, 0x01,                    // delta 1500 = 11 * 128 + 92
      0x00, 0xFF, 0x2F, 0x00};                         // end of track
  EXPECT_EQ(formatMidiFile(d), expected);
}

TEST(MidiFile, ReadsArecordmidiStyleFormatOne) {
  // Format 1, two tracks, 384 ticks a quarter; tempo 500000 µs in the first track; the second
  // uses running status and a system exclusive event.
  const std::vector<std::uint8_t> file = {
      'M',  'T',  'h',  'd',  0,    0,    0,   6,  0,    1,    0,    2,    0x01, 0x80,  // 384
      'M',  'T',  'r',  'k',  0,    0,    0,   11, 0x00, 0xFF, 0x51, 0x03, 0x07, 0xA1, 0x20, 0x00,
      0xFF, 0x2F, 0x00, 'M',  'T',  'r',  'k', 0,  0,    0,    23,   0x00, 0x90, 0x3C, 0x64,  // note on at tick 0
      0x81, 0x40, 0x3C, 0x00,              // tick 192: running status, velocity 0
      0x00, 0xF0, 0x03, 0x7E, 0x7F, 0xF7,  // system exclusive: skipped
      0x83, 0x00, 0xB0, 0x07, 0x7F,        // tick 576
      0x00, 0xFF, 0x2F, 0x00};
  auto d = parseMidiFile(file, "take.mid");
  ASSERT_TRUE(d) << d.error().describe();
  ASSERT_EQ(d->reports.size(), 3u);
  EXPECT_EQ(d->reports[0].bytes, (std::vector<std::uint8_t>{0x90, 0x3C, 0x64}));
  EXPECT_EQ(d->reports[1].bytes, (std::vector<std::uint8_t>{0x90, 0x3C, 0x00}));
  EXPECT_EQ(d->reports[2].bytes, (std::vector<std::uint8_t>{0xB0, 0x07, 0x7F}));
  EXPECT_EQ(d->reports[0].time, Nanos{0});
  EXPECT_EQ(d->reports[1].time, 250ms);  // 192 / 384 quarters of 0.5 s
  EXPECT_EQ(d->reports[2].time, 750ms);
  EXPECT_TRUE(devices::isMidiDescriptor(d->descriptor)) << "a foreign file gets the generic profile";
}

TEST(MidiFile, TempoChangesAndSmpteDivisions) {
  // 100 ticks a quarter; 1 s a quarter, then 0.5 s from tick 100: tick 200 is at 1.5 s.
  const std::vector<std::uint8_t> tempo = {'M',  'T',  'h',  'd',  0,    0,    0,    6,    0,    0,
                                           0,    1,    0,    100,  'M',  'T',  'r',  'k',  0,    0,
                                           0,    22,   0x00, 0xFF, 0x51, 0x03, 0x0F, 0x42, 0x40,  // 1000000
                                           0x64, 0xFF, 0x51, 0x03, 0x07, 0xA1, 0x20,              // tick 100: 500000
                                           0x64, 0xB0, 0x01, 0x02,                                // tick 200
                                           0x00, 0xFF, 0x2F, 0x00};
  auto a = parseMidiFile(tempo, "tempo.mid");
  ASSERT_TRUE(a) << a.error().describe();
  ASSERT_EQ(a->reports.size(), 1u);
  EXPECT_EQ(a->reports[0].time, 1500ms);
  // SMPTE: 25 frames a second, 40 ticks a frame: one tick a millisecond.
  const std::vector<std::uint8_t> smpte = {'M', 'T', 'h', 'd', 0, 0, 0, 6,    0,    0,    0,    1,    0xE7, 0x28, 'M',
                                           'T', 'r', 'k', 0,   0, 0, 8, 0x64, 0xB0, 0x01, 0x02, 0x00, 0xFF, 0x2F, 0x00};
  auto b = parseMidiFile(smpte, "smpte.mid");
  ASSERT_TRUE(b) << b.error().describe();
  ASSERT_EQ(b->reports.size(), 1u);
  EXPECT_EQ(b->reports[0].time, 100ms);
}

TEST(MidiFile, BrokenFilesNameTheByte) {
  EXPECT_FALSE(parseMidiFile(std::vector<std::uint8_t>{'R', 'I', 'F', 'F'}, "x.mid"));
  const std::vector<std::uint8_t> cut = {'M', 'T', 'h', 'd', 0,   0, 0, 6, 0, 0,    0,    1,   0,
                                         96,  'M', 'T', 'r', 'k', 0, 0, 0, 3, 0x00, 0xB0, 0x01};
  auto r = parseMidiFile(cut, "cut.mid");
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message().find("byte"), std::string::npos) << r.error().message();
  const std::vector<std::uint8_t> orphan = {'M', 'T', 'h', 'd', 0,   0, 0, 6, 0, 0,    0,    1,   0,
                                            96,  'M', 'T', 'r', 'k', 0, 0, 0, 3, 0x00, 0x01, 0x02};
  EXPECT_FALSE(parseMidiFile(orphan, "orphan.mid")) << "running status with no status before it";
}

TEST(MidiFile, ReplaysBitExactUnderTheManualClock) {
  // An X-Touch Mini in MC mode, recorded: V-Pot 1 up 2 at 10.000123 s... written, read back and
  // replayed twice; both replays give the same events at the recorded microseconds.
  HidRecordedDevice d;
  d.name = "X-TOUCH MINI";
  d.descriptor = devices::midiDescriptor(*devices::midiProfileByName("xtouch-mini-mc"));
  d.reports = {{Nanos{10'000'123'000}, {0xB0, 0x10, 0x02}},
               {Nanos{10'016'789'000}, {0xB0, 0x10, 0x41}},
               {Nanos{10'033'000'000}, {0x90, 0x20, 0x7F}}};
  const auto bytes = formatMidiFile(d);
  auto back = parseMidiFile(bytes, "x.mid");
  ASSERT_TRUE(back) << back.error().describe();
  ASSERT_EQ(back->reports.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(back->reports[i].time, d.reports[i].time);
    EXPECT_EQ(back->reports[i].bytes, d.reports[i].bytes);
  }
  EXPECT_EQ(back->descriptor, d.descriptor) << "the profile travels with the file";
  std::vector<std::vector<Event>> runs;
  for (int run = 0; run < 2; ++run) {
    ManualClock clock;
    clock.set(Nanos{5'000'000'000});
    auto box = ReplayDialBox::create({"X", "replay", "virtual", 0, 0, "x.mid", ""}, *back, clock, false);
    ASSERT_TRUE(box) << box.error().describe();
    BoundedQueue<Event> events(64);
    ASSERT_TRUE((*box)->open(1, events));
    EXPECT_EQ((*box)->dialCount(), 9);
    std::vector<Event> got;
    for (int frame = 0; frame < 700; ++frame) {
      clock.advance(Nanos{16'666'667});
      (*box)->service(clock.now());
      Event e;
      while (events.pop(e)) {
        if (e.kind != EventKind::kDeviceState) got.push_back(e);
      }
    }
    runs.push_back(got);
  }
  ASSERT_EQ(runs[0].size(), 3u);
  EXPECT_EQ(runs[0][0].time, Nanos{15'000'123'000});
  EXPECT_EQ(runs[0][0].kind, EventKind::kDialDelta);
  EXPECT_DOUBLE_EQ(runs[0][0].value, 2.0 / 24);
  EXPECT_DOUBLE_EQ(runs[0][1].value, -1.0 / 24);
  EXPECT_EQ(runs[0][2].kind, EventKind::kButton);
  ASSERT_EQ(runs[1].size(), runs[0].size());
  for (std::size_t i = 0; i < runs[0].size(); ++i) {
    EXPECT_EQ(runs[1][i].time, runs[0][i].time);
    EXPECT_EQ(runs[1][i].index, runs[0][i].index);
    EXPECT_EQ(runs[1][i].value, runs[0][i].value);
  }
}

TEST(MidiFile, ReplayProviderOffersMidiFiles) {
  const auto dir = std::filesystem::temp_directory_path() / "basalt_midi_file_test";
  std::filesystem::create_directories(dir);
  HidRecordedDevice d;
  d.name = "MIDI Mix";
  d.descriptor = devices::midiDescriptor(*devices::midiProfileByName("midimix"));
  d.reports = {{Nanos{1'000'000}, {0xB0, 16, 64}}};
  const auto bytes = formatMidiFile(d);
  {
    std::ofstream out(dir / "mix.mid", std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  }
  ReplayProvider provider;
  ASSERT_TRUE(provider.addHidRecording(dir / "mix.mid"));
  const auto candidates = provider.enumerate();
  ASSERT_EQ(candidates.size(), 1u);
  EXPECT_NE(candidates[0].usage.find("33 dials, 27 buttons"), std::string::npos) << candidates[0].usage;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace basalt::sim
