#pragma once

/// \file
/// \brief The `midi` backend: MIDI controllers (X-Touch Mini, nanoKONTROL2, MIDImix, any
/// controller with knobs, encoders, faders or pads) as dial boxes through ALSA's sequencer, so
/// USB class-compliant devices, virtual ports of other programs and snd-virmidi all work.
/// Includes no ALSA header: those stay in devices/midi/*.cpp.

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "devices/device_manager.h"

namespace basalt::devices {

/// \brief The `midi` backend. Enumerates the sequencer's readable ports (not the system ports,
/// not Basalt's own), each with the profile its client and port name match
/// (devices/midi/midi_decoder.h). Device path: `seq:CLIENT:PORT`; name: `CLIENT NAME: PORT NAME`.
///
/// Request options it reads: `profile` (a built-in profile's name or `generic`), `encoding`,
/// `channel`, `dials`, `buttons`, `notes`, `nrpn`, `high_resolution`, `echo`
/// (midiProfileFromOptions()).
///
/// Hotplug: watchHotplug() listens to the sequencer's announce port on a thread of its own and
/// reports every port that starts (`kAdded`, subsystem "midi") or exits (`kRemoved`).
class MidiProvider final : public DeviceProvider {
 public:
  MidiProvider();
  ~MidiProvider() override;
  MidiProvider(const MidiProvider&) = delete;
  MidiProvider& operator=(const MidiProvider&) = delete;

  [[nodiscard]] std::string_view backend() const override { return "midi"; }
  std::vector<DeviceCandidate> enumerate() override;
  Result<std::unique_ptr<DialBox>> openDialBox(const DeviceCandidate& candidate, const DeviceRequest& request,
                                               const Clock& clock) override;
  void watchHotplug(const std::function<void(HotplugEvent)>& notify) override;

 private:
  struct Watcher;
  std::unique_ptr<Watcher> watcher_;
};

/// \brief Opens the sequencer port `seq:CLIENT:PORT` (or the first port whose name contains
/// `address`) as a dial box with `options` (tests, `basalt record --dial midi:NAME`).
[[nodiscard]] Result<std::unique_ptr<DialBox>> openMidiDialBox(const std::string& address,
                                                               const std::map<std::string, std::string>& options,
                                                               const Clock& clock);

/// \brief A port of Basalt's own on the sequencer that other clients can subscribe to and that
/// sends raw MIDI messages: a virtual controller for tests and benchmarks, and the other end of
/// a real path through the kernel's sequencer.
///
/// Threading: send() from one thread at a time.
class VirtualMidiPort {
 public:
  /// \brief Creates client `name` with one readable port `name`. Fails where the sequencer is
  /// not available (no /dev/snd/seq).
  [[nodiscard]] static Result<std::unique_ptr<VirtualMidiPort>> create(const std::string& name);
  ~VirtualMidiPort();
  VirtualMidiPort(const VirtualMidiPort&) = delete;
  VirtualMidiPort& operator=(const VirtualMidiPort&) = delete;

  /// \brief `seq:CLIENT:PORT`.
  [[nodiscard]] const std::string& address() const { return address_; }
  /// \brief Sends one MIDI message (status byte first) to every subscriber, at once.
  [[nodiscard]] Result<void> send(std::span<const std::uint8_t> message);
  /// \brief Messages sent to this port by subscribers it is connected to (feedback), as read so
  /// far (non-blocking).
  std::vector<std::vector<std::uint8_t>> received();
  /// \brief Connects this port's input from `address` (so that feedback sent there arrives).
  [[nodiscard]] Result<void> listenTo(const std::string& address);

 private:
  struct Impl;
  explicit VirtualMidiPort(std::unique_ptr<Impl> impl, std::string address);
  std::unique_ptr<Impl> impl_;
  std::string address_;
};

}  // namespace basalt::devices
