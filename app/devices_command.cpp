#include "app/devices_command.h"

#include <cstdio>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "app/commands.h"
#include "app/options.h"
#include "devices/hid/hid_backend.h"
#include "kiosk/show/device_wiring.h"
#include "kiosk/show/trace_video_glue.h"
#include "runtime/log.h"
#include "sim/providers.h"

namespace basalt::kiosk {

std::string_view devicesUsage() {
  return R"(Usage: basalt devices [options]

Lists the dial boxes, cameras and capture cards connected to this machine, what Basalt would
use each one as, and why a device cannot be opened, with what to do about it.

Options:
  --replay PATH     also list the devices recorded in a trace folder, hid-recorder file or
                    Standard MIDI File
  --serial PORT     also offer PORT to an SGI dial box (repeatable; USB serial adapters are
                    listed anyway)
  --synthetic       also list the simulated twins (a synthetic dial box and camera)
  -h, --help        this text

Exit status: 0 (also when nothing is connected), 2 for usage errors.
)";
}

namespace {

std::string ids(const devices::DeviceInfo& info) {
  return info.vendor || info.product ? fmt::format("{:04x}:{:04x}", info.vendor, info.product) : std::string("-");
}

}  // namespace

int devicesMain(std::span<const std::string_view> args) {
  auto parsed = parseOptions("devices", args, {{"--help|-h"}, {"--replay", true}, {"--serial", true}, {"--synthetic"}});
  if (!parsed) return usageError(parsed.error().describe());
  std::vector<std::string> ports;
  std::vector<std::string> replays;
  bool synthetic = false;
  for (const ParsedOption& o : *parsed) {
    if (o.name.empty())
      return usageError(fmt::format("unexpected argument '{}'; see 'basalt devices --help'", o.value));
    if (o.name == "--help") {
      fmt::print("{}", devicesUsage());
      return 0;
    }
    if (o.name == "--serial") ports.emplace_back(o.value);
    if (o.name == "--replay") replays.emplace_back(o.value);
    if (o.name == "--synthetic") synthetic = true;
  }
  log::configure("warning");  // backends' info lines would drown the list

  std::vector<std::unique_ptr<devices::DeviceProvider>> providers = allProviders(ports);
  if (!synthetic) std::erase_if(providers, [](const auto& p) { return p->backend() == "synthetic"; });
  for (const std::string& path : replays) {
    auto replay = std::make_unique<sim::ReplayProvider>(matroskaTraceReaderFactory());
    std::error_code ec;
    auto r = std::filesystem::is_directory(path, ec) ? replay->addTrace(path) : replay->addHidRecording(path);
    if (!r) {
      fmt::print(stderr, "basalt: error: cannot read {}: {}\n", path, r.error().describe());
      return 1;
    }
    providers.push_back(std::move(replay));
  }

  struct Row {
    std::string backend, path, ids, name, text;
  };
  std::vector<Row> dials, video, trackers, problems, others;
  for (const auto& p : providers) {
    for (const devices::DeviceCandidate& c : p->enumerate()) {
      Row row{c.info.backend, c.info.path, ids(c.info), c.info.name, c.usage};
      const bool notADial = c.problem.starts_with("not a dial box");
      if (notADial) {
        row.text = c.problem;
        others.push_back(std::move(row));
      } else if (!c.problem.empty()) {
        row.text = c.problem;
        problems.push_back(std::move(row));
      } else {
        (c.kind == devices::DeviceKind::kDialBox   ? dials
         : c.kind == devices::DeviceKind::kTracker ? trackers
                                                   : video)
            .push_back(std::move(row));
      }
    }
  }
  auto print = [](const char* title, const std::vector<Row>& rows) {
    if (rows.empty()) return;
    fmt::print("{}\n", title);
    for (const Row& r : rows) {
      fmt::print("  {:<9} {:<24} {:<9} {}\n", r.backend, r.path, r.ids, r.name);
      if (!r.text.empty()) fmt::print("  {:<9} {}\n", "", r.text);
    }
    fmt::print("\n");
  };
  print("Dial boxes:", dials);
  print("Video sources:", video);
  print("Trackers:", trackers);
  print("Found but cannot be opened:", problems);
  print("Other HID devices (not used: no dials):", others);
  if (dials.empty() && video.empty() && problems.empty()) {
    fmt::print(
        "No dial box, camera or capture card found. Plug one in, or use the simulated twins\n"
        "('basalt devices --synthetic') or a recording ('basalt devices --replay NAME.trace').\n");
  }
  for (const Row& r : problems) {
    if (r.text.find("ermission") != std::string::npos) {
      fmt::print("Permission problems: {}.\n", devices::kUdevRuleHint);
      break;
    }
  }
  std::fflush(stdout);
  return 0;
}

}  // namespace basalt::kiosk
