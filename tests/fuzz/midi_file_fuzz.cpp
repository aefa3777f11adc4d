// Fuzzes the Standard MIDI File reader that replays MIDI controllers' traces (and files written by
// arecordmidi): any bytes give a recording whose reports are in time order, or an error, never a
// crash.

#include <cstddef>
#include <cstdint>
#include <span>

#include "sim/midi_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  auto recording = basalt::sim::parseMidiFile(std::span<const std::uint8_t>(data, size), "fuzz.mid");
  if (recording) {
    for (std::size_t i = 1; i < recording->reports.size(); ++i) {
      if (recording->reports[i].time < recording->reports[i - 1].time) __builtin_trap();
    }
  }
  return 0;
}
