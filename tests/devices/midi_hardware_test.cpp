// MIDI controllers through the kernel's sequencer (snd-seq; the virtual lab loads it): feedback
// to the controller, a port that leaves and comes back under the DeviceManager, Basalt's
// Standard MIDI Files played by aplaymidi into the backend, and arecordmidi's files read back.
// Outside the lab (no /dev/snd/seq) every case skips with the reason.
// Example failures: the LED ring message sent to Basalt's own port instead of the controller's;
// a port's exit not noticed (the dial box stays "live" with nothing behind it); a file Basalt
// writes that aplaymidi refuses or plays at the wrong times.

#include <gtest/gtest.h>

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <thread>

#include "devices/device_manager.h"
#include "devices/midi/midi_backend.h"
#include "devices/midi/midi_decoder.h"
#include "sim/midi_file.h"

extern char** environ;

namespace basalt::devices {
namespace {

using namespace std::chrono_literals;

bool haveSequencer() { return ::access("/dev/snd/seq", F_OK) == 0; }
#define NEEDS_SEQUENCER()                                                            \
  if (!haveSequencer())                                                              \
  GTEST_SKIP() << "needs ALSA's sequencer (/dev/snd/seq, snd-seq): the virtual lab " \
                  "(make vlab) loads it"

bool haveTool(const char* tool) { return std::system((std::string(tool) + " --version >/dev/null 2>&1").c_str()) == 0; }

template <typename Pred>
bool waitFor(Pred pred, std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < end) {
    if (pred()) return true;
    std::this_thread::sleep_for(5ms);
  }
  return pred();
}

std::vector<Event> drain(BoundedQueue<Event>& q) {
  std::vector<Event> out;
  Event e;
  while (q.pop(e)) {
    if (e.kind == EventKind::kDialDelta || e.kind == EventKind::kButton || e.kind == EventKind::kDialAbsolute) {
      out.push_back(e);
    }
  }
  return out;
}

TEST(MidiHardware, LedRingAndButtonLightsReachTheController) {
  NEEDS_SEQUENCER();
  auto port = VirtualMidiPort::create("X-TOUCH MINI");
  ASSERT_TRUE(port) << port.error().describe();
  SystemClock clock;
  auto box = openMidiDialBox((*port)->address(), {{"profile", "xtouch-mini-mc"}}, clock);
  ASSERT_TRUE(box) << box.error().describe();
  BoundedQueue<Event> events(64);
  ASSERT_TRUE((*box)->open(1, events));
  // Half a turn (12 detents) on V-Pot 1: the ring's dot goes to its middle LED (CC 48 = 6).
  const std::uint8_t turn[] = {0xB0, 0x10, 0x0C};
  ASSERT_TRUE((*port)->send(turn));
  std::vector<std::vector<std::uint8_t>> got;
  const auto saw = [&](std::vector<std::uint8_t> m) {
    for (auto& r : (*port)->received()) got.push_back(r);
    return std::find(got.begin(), got.end(), m) != got.end();
  };
  EXPECT_TRUE(waitFor([&] { return saw({0xB0, 0x30, 0x06}); }, 2s)) << "no ring message came back";
  ASSERT_TRUE((*box)->setLight(8, 1.0));  // the top row's first button, note 89
  EXPECT_TRUE(waitFor([&] { return saw({0x90, 0x59, 0x7F}); }, 2s)) << "no light message came back";
  const auto e = drain(events);
  ASSERT_FALSE(e.empty());
  EXPECT_EQ(e[0].kind, EventKind::kDialDelta);
  EXPECT_DOUBLE_EQ(e[0].value, 0.5);
  (*box)->close();
}

TEST(MidiHardware, PortLeavesAndComesBackUnderTheManager) {
  NEEDS_SEQUENCER();
  SystemClock clock;
  BoundedQueue<Event> events(4096);
  DeviceManager manager(clock, events);
  manager.addProvider(std::make_unique<MidiProvider>());
  DeviceRequest r;
  r.name = "mini";
  r.match.backend = "midi";
  r.match.name = "Basalt hotplug mini";
  ASSERT_TRUE(manager.request(r));
  manager.start(10ms);
  auto state = [&] { return manager.status()[0].state; };
  auto port = VirtualMidiPort::create("Basalt hotplug mini");
  ASSERT_TRUE(port) << port.error().describe();
  ASSERT_TRUE(waitFor([&] { return state() == DeviceState::kLive; }, 10s)) << manager.status()[0].lastError;
  port->reset();  // the client leaves the sequencer, as a controller unplugged
  EXPECT_TRUE(waitFor([&] { return state() == DeviceState::kLost || state() == DeviceState::kReopening; }, 5s))
      << "the port's exit was not noticed";
  auto again = VirtualMidiPort::create("Basalt hotplug mini");
  ASSERT_TRUE(again) << again.error().describe();
  EXPECT_TRUE(waitFor([&] { return state() == DeviceState::kLive; }, 10s))
      << "not live again: " << manager.status()[0].lastError;
  const std::uint8_t turn[] = {0xB0, 0x10, 0x01};
  EXPECT_TRUE(waitFor(
      [&] {
        (void)(*again)->send(turn);
        return !drain(events).empty();
      },
      5s))
      << "no events from the port that came back";
  manager.stop();
}

TEST(MidiHardware, AplaymidiPlaysBasaltsRecordingIntoTheBackend) {
  NEEDS_SEQUENCER();
  if (!haveTool("aplaymidi")) GTEST_SKIP() << "needs aplaymidi (alsa-utils, scripts/packages-test.txt)";
  // Basalt's recording of an X-Touch Mini in MC mode, played by aplaymidi to a port of ours that
  // the backend reads from.
  sim::HidRecordedDevice rec;
  rec.name = "X-TOUCH MINI";
  rec.descriptor = midiDescriptor(*midiProfileByName("xtouch-mini-mc"));
  rec.reports = {{Nanos{0}, {0xB0, 0x10, 0x02}}, {50ms, {0xB0, 0x10, 0x41}}, {100ms, {0x90, 0x20, 0x7F}}};
  const auto file = std::filesystem::temp_directory_path() / "basalt_midi_aplay.mid";
  {
    const auto bytes = sim::formatMidiFile(rec);
    std::ofstream out(file, std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  }
  // aplaymidi writes to a port; a port of ours that takes input passes nothing on, so the
  // backend reads the sequencer's "Midi Through" (snd-seq-dummy), which echoes what it is sent.
  MidiProvider provider;
  std::string through;
  for (const DeviceCandidate& c : provider.enumerate()) {
    if (c.info.name.find("Midi Through") != std::string::npos) through = c.info.path;
  }
  if (through.empty()) GTEST_SKIP() << "no Midi Through port (snd-seq-dummy is not loaded)";
  SystemClock clock;
  auto box = openMidiDialBox(through, {{"profile", "xtouch-mini-mc"}}, clock);
  ASSERT_TRUE(box) << box.error().describe();
  BoundedQueue<Event> events(64);
  ASSERT_TRUE((*box)->open(1, events));
  const std::string target = through.substr(4);  // "14:0"
  ASSERT_EQ(std::system(("aplaymidi -p " + target + " " + file.string()).c_str()), 0);
  std::vector<Event> got;
  EXPECT_TRUE(waitFor(
      [&] {
        for (const Event& e : drain(events)) got.push_back(e);
        return got.size() >= 3;
      },
      3s));
  (*box)->close();
  std::filesystem::remove(file);
  ASSERT_EQ(got.size(), 3u);
  EXPECT_DOUBLE_EQ(got[0].value, 2.0 / 24);
  EXPECT_DOUBLE_EQ(got[1].value, -1.0 / 24);
  EXPECT_EQ(got[2].kind, EventKind::kButton);
  // aplaymidi keeps the file's times: 50 ms between the turns (give the lab's emulator 20 ms).
  EXPECT_NEAR(toSeconds(got[1].time - got[0].time), 0.050, 0.020);
  EXPECT_NEAR(toSeconds(got[2].time - got[0].time), 0.100, 0.020);
}

TEST(MidiHardware, ArecordmidiFilesReadBack) {
  NEEDS_SEQUENCER();
  if (!haveTool("arecordmidi")) GTEST_SKIP() << "needs arecordmidi (alsa-utils, scripts/packages-test.txt)";
  auto port = VirtualMidiPort::create("Basalt arecordmidi source");
  ASSERT_TRUE(port) << port.error().describe();
  const auto file = std::filesystem::temp_directory_path() / "basalt_midi_arecord.mid";
  std::filesystem::remove(file);
  const std::string source = (*port)->address().substr(4);
  const std::string path = file.string();
  const char* argv[] = {"arecordmidi", "-p", source.c_str(), path.c_str(), nullptr};
  pid_t pid = 0;
  ASSERT_EQ(::posix_spawnp(&pid, "arecordmidi", nullptr, nullptr, const_cast<char**>(argv), environ), 0);
  std::this_thread::sleep_for(500ms);  // arecordmidi subscribes
  const std::vector<std::vector<std::uint8_t>> sent = {{0xB0, 0x10, 0x03}, {0xB0, 0x10, 0x43}, {0x90, 0x20, 0x7F}};
  for (const auto& m : sent) {
    ASSERT_TRUE((*port)->send(m));
    std::this_thread::sleep_for(100ms);
  }
  ::kill(pid, SIGINT);  // arecordmidi writes the file when interrupted
  int status = 0;
  ::waitpid(pid, &status, 0);
  auto rec = sim::readMidiFile(file);
  std::filesystem::remove(file);
  ASSERT_TRUE(rec) << rec.error().describe();
  ASSERT_EQ(rec->reports.size(), sent.size());
  for (std::size_t i = 0; i < sent.size(); ++i) EXPECT_EQ(rec->reports[i].bytes, sent[i]);
  EXPECT_NEAR(toSeconds(rec->reports[2].time - rec->reports[0].time), 0.200, 0.050);
}

}  // namespace
}  // namespace basalt::devices
