#pragma once

/// \file
/// \brief Standard MIDI Files (SMF, format 0 and 1) as recordings of MIDI dial boxes: Basalt
/// writes format 0 with one tick per microsecond (division 1000, tempo 1000 µs per quarter) so
/// that a recording replays exactly and `aplaymidi` plays it; it reads any tempo map, SMPTE
/// divisions, running status and several tracks (merged in time order), so files recorded with
/// `arecordmidi` replay too. A recording is held as an HidRecordedDevice whose reports are MIDI
/// messages and whose descriptor is the profile's (devices/midi/midi_decoder.h).

#include <cstdint>
#include <filesystem>
#include <span>
#include <string_view>
#include <vector>

#include "runtime/error.h"
#include "sim/hid_recording.h"

namespace basalt::sim {

/// \brief The file for `device`: its name as the track name, its descriptor as a text event,
/// each report (one MIDI message) at its time, truncated to the microsecond.
[[nodiscard]] std::vector<std::uint8_t> formatMidiFile(const HidRecordedDevice& device);

/// \brief Reads a file's channel messages (system exclusive and meta events skipped) as reports.
/// The descriptor is the one Basalt wrote, else the profile the track name (else `name`)
/// matches. Errors name the byte offset.
[[nodiscard]] Result<HidRecordedDevice> parseMidiFile(std::span<const std::uint8_t> bytes, std::string_view name);
[[nodiscard]] Result<HidRecordedDevice> readMidiFile(const std::filesystem::path& path);

/// \brief True when `path` names a Standard MIDI File by its extension (.mid, .midi, .smf).
[[nodiscard]] bool isMidiFilePath(const std::filesystem::path& path);

}  // namespace basalt::sim
