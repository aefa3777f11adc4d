// The shared HID recordings (../shared/testdata/hid), each played twice: by the replay backend
// under a manual clock, and as kernel devices through /dev/uhid (the lab's hid-replay tool, as
// hid-tools' hid-replay does) read back by the real hidraw backend. Both must make the same dial
// boxes (the same devices open or are refused, with the same dials and buttons) and the same
// event stream, in order. Runs in the virtual lab; elsewhere it skips with the reason.
// Example failures: the hidraw backend reading a different descriptor from sysfs than the one
// recorded (a device with other dials); a report split or merged on its way through the kernel;
// the replay backend decoding a report differently from the real one.

#include <gtest/gtest.h>

#include <signal.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "devices/dial_box.h"
#include "devices/hid/hid_backend.h"
#include "runtime/bounded_queue.h"
#include "runtime/clock.h"
#include "sim/hid_recording.h"
#include "sim/providers.h"
#include "support/process.h"
#include "support/test_paths.h"
#include "vlab.h"

namespace basalt::devices {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

/// One device as a backend made it: refused (why), or its shape and what it sent.
struct Seen {
  bool opened = false;
  std::string refused;
  int dials = 0;
  int buttons = 0;
  std::vector<Event> events;
};

std::string describe(const Event& e) {
  std::ostringstream s;
  s << (e.kind == EventKind::kDialDelta      ? "delta"
        : e.kind == EventKind::kDialAbsolute ? "absolute"
        : e.kind == EventKind::kButton       ? "button"
                                             : "other")
    << "[" << e.index << "]=" << e.value;
  return s.str();
}

std::string describe(const Seen& s) {
  if (!s.opened) return "refused: " + s.refused;
  std::string out = std::to_string(s.dials) + " dials, " + std::to_string(s.buttons) + " buttons:";
  for (const Event& e : s.events) out += " " + describe(e);
  return out;
}

void drain(BoundedQueue<Event>& queue, std::vector<Event>& into) {
  Event e;
  while (queue.pop(e)) {
    if (e.kind == EventKind::kDialDelta || e.kind == EventKind::kDialAbsolute || e.kind == EventKind::kButton) {
      into.push_back(e);
    }
  }
}

/// The replay backend's view of every device of `file`, played to its end.
std::vector<Seen> replayed(const fs::path& file, const std::vector<sim::HidRecordedDevice>& recording) {
  std::vector<Seen> out;
  sim::ReplayProvider provider;
  if (auto r = provider.addHidRecording(file); !r) {
    ADD_FAILURE() << r.error().describe();
    return out;
  }
  Nanos end{0};
  for (const auto& d : recording) {
    for (const auto& report : d.reports) end = std::max(end, report.time);
  }
  const auto candidates = provider.enumerate();
  EXPECT_EQ(candidates.size(), recording.size());
  for (const DeviceCandidate& c : candidates) {
    Seen seen;
    ManualClock clock;
    DeviceRequest request{c.info.name, DeviceKind::kDialBox, {}, {{"loop", "false"}}, {}};
    auto box = provider.openDialBox(c, request, clock);
    if (!box) {
      seen.refused = box.error().describe();
      out.push_back(seen);
      continue;
    }
    BoundedQueue<Event> queue(4096);
    if (auto r = (*box)->open(1, queue); !r) {
      seen.refused = r.error().describe();
      out.push_back(seen);
      continue;
    }
    seen.opened = true;
    seen.dials = (*box)->dialCount();
    seen.buttons = (*box)->buttonCount();
    for (Nanos t{0}; t <= end + 1s; t += 10ms) {
      clock.set(t);
      (*box)->service(t);
      drain(queue, seen.events);
    }
    (*box)->close();
    out.push_back(std::move(seen));
  }
  return out;
}

class HidRecordingsHardware : public testing::TestWithParam<const char*> {};

TEST_P(HidRecordingsHardware, TheRealBackendSeesWhatTheReplayBackendGives) {
  if (!test::vlabEnv("BASALT_VLAB_UHID")) GTEST_SKIP() << test::needsVlab("BASALT_VLAB_UHID=1 (/dev/uhid usable)");
  const fs::path data = test::testdataDir();
  if (data.empty()) GTEST_SKIP() << "../shared/testdata is missing (BASALT_TESTDATA)";
  const fs::path file = data / "hid" / GetParam();
  auto read = sim::readHidRecording(file);
  ASSERT_TRUE(read) << read.error().describe();
  const std::vector<sim::HidRecordedDevice>& recording = read->devices;
  const std::vector<Seen> expected = replayed(file, recording);
  ASSERT_EQ(expected.size(), recording.size());

  std::string tool = test::vlabEnv("BASALT_VLAB_HID_REPLAY").value_or("");
  if (tool.empty()) tool = (test::binaryDir() / "tools" / "vlab" / "basalt-vlab-hid-replay").string();
  auto replay = test::Process::start({tool, "--wait-signal", "30", "--max-gap", "0.05", "--hold", "-1", file.string()});
  ASSERT_TRUE(replay.started()) << tool;
  const std::string last = "device " + std::to_string(recording.size() - 1) + " ";
  ASSERT_TRUE(replay.waitForOutput(last, 30s)) << replay.outputSoFar();
  ASSERT_TRUE(replay.waitForOutput("\n", 1s));

  // Every kernel device through the real hidraw backend, opened before the reports come.
  const SystemClock clock;
  std::vector<std::unique_ptr<DialBox>> boxes(recording.size());
  std::vector<std::unique_ptr<BoundedQueue<Event>>> queues(recording.size());
  std::vector<Seen> seen(recording.size());
  std::istringstream lines(replay.outputSoFar());
  for (std::size_t i = 0; i < recording.size(); ++i) {
    std::string word;
    std::size_t index = 0;
    std::string node;
    ASSERT_TRUE(lines >> word >> index >> node) << replay.outputSoFar();
    std::string name;
    std::getline(lines, name);
    auto box = openHidrawDialBox(node, clock);
    if (!box) {
      seen[i].refused = box.error().describe();
      continue;
    }
    queues[i] = std::make_unique<BoundedQueue<Event>>(4096);
    if (auto r = (*box)->open(1, *queues[i]); !r) {
      seen[i].refused = r.error().describe();
      continue;
    }
    seen[i].opened = true;
    seen[i].dials = (*box)->dialCount();
    seen[i].buttons = (*box)->buttonCount();
    boxes[i] = std::move(*box);
  }
  replay.signal(SIGUSR1);  // every device is open: play
  ASSERT_TRUE(replay.waitForOutput("replayed", 60s)) << replay.outputSoFar();
  // The last reports reach the reader threads a moment after the tool wrote them.
  for (int settle = 0; settle < 50; ++settle) {
    std::this_thread::sleep_for(20ms);
    for (std::size_t i = 0; i < boxes.size(); ++i) {
      if (!boxes[i]) continue;
      boxes[i]->service(clock.now());
      drain(*queues[i], seen[i].events);
    }
  }
  for (auto& box : boxes) {
    if (box) box->close();
  }
  replay.signal(SIGTERM);
  const auto done = replay.wait(30s);
  EXPECT_EQ(done.exitCode, 0) << done.output;

  for (std::size_t i = 0; i < recording.size(); ++i) {
    SCOPED_TRACE("device " + std::to_string(i) + " (" + recording[i].name + ")");
    std::printf("device %zu (%s): %s\n", i, recording[i].name.c_str(), describe(seen[i]).c_str());
    EXPECT_EQ(seen[i].opened, expected[i].opened)
        << "real: " << describe(seen[i]) << "\nreplay: " << describe(expected[i]);
    if (!seen[i].opened || !expected[i].opened) continue;
    EXPECT_EQ(seen[i].dials, expected[i].dials);
    EXPECT_EQ(seen[i].buttons, expected[i].buttons);
    ASSERT_EQ(seen[i].events.size(), expected[i].events.size())
        << "real: " << describe(seen[i]) << "\nreplay: " << describe(expected[i]);
    for (std::size_t k = 0; k < seen[i].events.size(); ++k) {
      const Event& a = seen[i].events[k];
      const Event& b = expected[i].events[k];
      EXPECT_TRUE(a.kind == b.kind && a.index == b.index && std::abs(a.value - b.value) < 1e-9)
          << "event " << k << ": real " << describe(a) << ", replay " << describe(b);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(SharedRecordings, HidRecordingsHardware,
                         testing::Values("udev-hid-bpf/huion_dial2_q630m_rdescs.hid",
                                         "udev-hid-bpf/huion_keydial_mini050_bluetooth.hid",
                                         "udev-hid-bpf/microsoft_surface_dial_rdesc.hid"),
                         [](const testing::TestParamInfo<const char*>& param) {
                           std::string name = fs::path(param.param).stem().string();
                           for (char& c : name) {
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           }
                           return name;
                         });

}  // namespace
}  // namespace basalt::devices
