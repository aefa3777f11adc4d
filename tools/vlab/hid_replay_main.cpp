// basalt-vlab-hid-replay: plays a HID recording (hid-tools' hid-recorder format) as kernel HID
// devices through /dev/uhid, as hid-tools' hid-replay does, for the virtual lab's tests: the
// real hidraw backend then reads the recorded reports from a real kernel device.
//
//   basalt-vlab-hid-replay [--wait-open S | --wait-signal S] [--speed X] [--max-gap S] [--hold S] FILE
//
// Creates one device per recorded device and prints "device INDEX /dev/hidrawN NAME" for each.
// Then, so that no report is sent before its reader listens: with --wait-open it waits (up to
// S seconds) until every device that has reports is opened (by anyone: the kernel's own
// keyboard handler opens keyboards at once), with --wait-signal until it gets SIGUSR1 (what a
// test sends once it has opened the nodes). Then it sends the reports at their recorded times
// (divided by --speed; gaps longer than --max-gap shortened to it), prints "replayed N
// reports", keeps the devices for --hold seconds (default 0; -1: until SIGUSR1, SIGTERM or
// SIGINT, at most an hour) and removes them. SIGTERM and SIGINT end it cleanly at any time.
// Exit status: 0 done or stopped by a signal, 1 a failure (said on stderr), 2 usage.

#include <signal.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "sim/hid_recording.h"
#include "tools/vlab/uhid_device.h"

namespace {

using basalt::sim::vlab::UhidDevice;
using Clock = std::chrono::steady_clock;

struct Options {
  double waitOpen = -1;
  double waitSignal = -1;
  double speed = 1;
  double maxGap = -1;
  double hold = 0;
  std::string file;
};

int usage() {
  std::fputs(
      "usage: basalt-vlab-hid-replay [--wait-open S | --wait-signal S] [--speed X] [--max-gap S] [--hold S] FILE\n",
      stderr);
  return 2;
}

bool parseDouble(const char* text, double& out) {
  char* end = nullptr;
  out = std::strtod(text, &end);
  return end != text && *end == '\0';
}

/// Services the devices for up to `limit` or until one of the blocked signals arrives; returns
/// the signal, or 0 on time-out.
int serviceUntilSignal(std::vector<UhidDevice>& devices, const sigset_t& signals, std::chrono::milliseconds limit) {
  const auto end = Clock::now() + limit;
  while (Clock::now() < end) {
    for (auto& d : devices) d.service();
    const timespec slice{0, 10'000'000};
    const int sig = ::sigtimedwait(&signals, nullptr, &slice);
    if (sig > 0) return sig;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options opt;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    double* target = nullptr;
    if (arg == "--wait-open") target = &opt.waitOpen;
    if (arg == "--wait-signal") target = &opt.waitSignal;
    if (arg == "--speed") target = &opt.speed;
    if (arg == "--max-gap") target = &opt.maxGap;
    if (arg == "--hold") target = &opt.hold;
    if (target) {
      if (i + 1 >= argc || !parseDouble(argv[i + 1], *target)) return usage();
      ++i;
      continue;
    }
    const bool isOption = !arg.empty() && arg[0] == '-';
    if (isOption || !opt.file.empty()) return usage();
    opt.file = arg;
  }
  if (opt.file.empty() || opt.speed <= 0 || (opt.waitOpen >= 0 && opt.waitSignal >= 0)) return usage();

  // SIGUSR1 (go on), SIGTERM and SIGINT (stop) are taken with sigtimedwait, never asynchronously.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGUSR1);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  ::sigprocmask(SIG_BLOCK, &signals, nullptr);
  auto stopRequested = [&signals]() {
    const timespec now{0, 0};
    sigset_t stop;
    sigemptyset(&stop);
    sigaddset(&stop, SIGTERM);
    sigaddset(&stop, SIGINT);
    (void)signals;
    return ::sigtimedwait(&stop, nullptr, &now) > 0;
  };

  auto recording = basalt::sim::readHidRecording(opt.file);
  if (!recording) {
    std::fprintf(stderr, "basalt-vlab-hid-replay: error: %s\n", recording.error().describe().c_str());
    return 1;
  }
  std::vector<UhidDevice> devices;
  const std::vector<basalt::sim::HidRecordedDevice>& recorded = recording->devices;
  for (std::size_t i = 0; i < recorded.size(); ++i) {
    const auto& rec = recorded[i];
    basalt::sim::vlab::UhidIdentity id;
    id.name = rec.name.empty() ? "Basalt replay " + std::to_string(i) : rec.name;
    id.phys = rec.phys.empty() ? "basalt-vlab-replay/input" + std::to_string(i) : rec.phys;
    id.bus = rec.bus ? rec.bus : 3;
    id.vendor = rec.vendor;
    id.product = rec.product;
    id.descriptor = rec.descriptor;
    auto dev = UhidDevice::create(std::move(id));
    if (!dev) {
      std::fprintf(stderr, "basalt-vlab-hid-replay: error: %s: device %zu: %s\n", opt.file.c_str(), i,
                   dev.error().describe().c_str());
      return 1;
    }
    devices.push_back(std::move(*dev));
  }
  for (std::size_t i = 0; i < devices.size(); ++i) {
    auto node = devices[i].hidrawNode(std::chrono::seconds(10));
    if (!node) {
      std::fprintf(stderr, "basalt-vlab-hid-replay: error: %s: device %zu: %s\n", opt.file.c_str(), i,
                   node.error().describe().c_str());
      return 1;
    }
    std::printf("device %zu %s %s\n", i, node->c_str(), devices[i].identity().name.c_str());
  }
  std::fflush(stdout);

  if (opt.waitSignal >= 0) {
    const auto limit = std::chrono::milliseconds(static_cast<long long>(opt.waitSignal * 1000));
    const int sig = serviceUntilSignal(devices, signals, limit);
    if (sig == SIGTERM || sig == SIGINT) return 0;
    if (sig != SIGUSR1) {
      std::fprintf(stderr, "basalt-vlab-hid-replay: error: no SIGUSR1 within %.0f s\n", opt.waitSignal);
      return 1;
    }
  }
  if (opt.waitOpen >= 0) {
    for (std::size_t i = 0; i < devices.size(); ++i) {
      if (recorded[i].reports.empty()) continue;
      const auto limit = std::chrono::milliseconds(static_cast<long long>(opt.waitOpen * 1000));
      if (auto ok = devices[i].waitOpened(limit); !ok) {
        std::fprintf(stderr, "basalt-vlab-hid-replay: error: %s\n", ok.error().describe().c_str());
        return 1;
      }
    }
  }

  // All devices' reports in recorded order; times scaled and long gaps shortened.
  struct Item {
    std::chrono::nanoseconds time;
    std::size_t device;
    const std::vector<std::uint8_t>* bytes;
  };
  std::vector<Item> items;
  for (std::size_t i = 0; i < recorded.size(); ++i) {
    for (const auto& r : recorded[i].reports) items.push_back({r.time, i, &r.bytes});
  }
  // By time; reports at the same time keep their recorded order (the vector's).
  std::vector<std::size_t> order(items.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&items](std::size_t a, std::size_t b) {
    return items[a].time != items[b].time ? items[a].time < items[b].time : a < b;
  });
  std::vector<Item> sorted;
  sorted.reserve(items.size());
  for (const std::size_t i : order) sorted.push_back(items[i]);
  items = std::move(sorted);
  const auto start = Clock::now();
  std::chrono::nanoseconds previous{0};
  std::chrono::nanoseconds due{0};
  std::size_t sent = 0;
  for (const auto& item : items) {
    auto gap = std::chrono::duration_cast<std::chrono::nanoseconds>((item.time - previous) / opt.speed);
    if (sent == 0) gap = std::chrono::nanoseconds{0};
    if (opt.maxGap >= 0) gap = std::min(gap, std::chrono::nanoseconds(static_cast<long long>(opt.maxGap * 1e9)));
    previous = item.time;
    due += gap;
    while (Clock::now() - start < due) {
      for (auto& d : devices) d.service();
      if (stopRequested()) return 0;
      std::this_thread::sleep_for(
          std::min<std::chrono::nanoseconds>(due - (Clock::now() - start), std::chrono::milliseconds(5)));
    }
    if (auto ok = devices[item.device].sendInput(*item.bytes); !ok) {
      std::fprintf(stderr, "basalt-vlab-hid-replay: error: device %zu: %s\n", item.device,
                   ok.error().describe().c_str());
      return 1;
    }
    ++sent;
  }
  std::printf("replayed %zu reports\n", sent);
  std::fflush(stdout);
  const auto hold = opt.hold < 0 ? std::chrono::milliseconds(3600 * 1000)
                                 : std::chrono::milliseconds(static_cast<long long>(opt.hold * 1000));
  (void)serviceUntilSignal(devices, signals, hold);
  return 0;
}
