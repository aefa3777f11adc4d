// The deployment files in configs/: the systemd unit is what the issue asks of it (Type=notify,
// a watchdog, Restart=always, sandboxing, device access limited to the show's devices) and
// systemd itself accepts every line of it; the udev rule parses and covers the dial boxes and
// cameras Basalt supports.
// Example failures: a misspelt directive that systemd ignores with a warning (the sandbox
// silently weaker); a udev line with a typo that udev skips (the dial box unreadable on site).

#include <gtest/gtest.h>

#include <unistd.h>

#include <fstream>
#include <regex>
#include <sstream>

#include "support/process.h"
#include "support/test_paths.h"

namespace basalt {
namespace {

std::string read(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(SystemdUnit, HasWhatAKioskServiceNeeds) {
  const std::string unit = read(test::sourceDir() / "configs/systemd/basalt.service");
  for (const char* line : {"Type=notify",
                           "WatchdogSec=10",
                           "Restart=always",
                           "NoNewPrivileges=yes",
                           "ProtectSystem=strict",
                           "ProtectHome=yes",
                           "PrivateTmp=yes",
                           "DevicePolicy=closed",
                           "DeviceAllow=char-drm rw",
                           "DeviceAllow=char-video4linux rw",
                           "DeviceAllow=char-media rw",
                           "DeviceAllow=char-hidraw rw",
                           "DeviceAllow=char-ttyUSB rw",
                           "DeviceAllow=char-usb_device rw",
                           "StateDirectory=basalt",
                           "ExecReload=/bin/kill -HUP $MAINPID",
                           "StartLimitIntervalSec=0",
                           "CapabilityBoundingSet=",
                           "SupplementaryGroups=video render input dialout audio",
                           "DeviceAllow=char-ttyS rw",
                           "DeviceAllow=char-alsa rw",
                           "SystemCallFilter=@system-service",
                           "SystemCallErrorNumber=EPERM",
                           "ProtectProc=invisible"}) {
    EXPECT_NE(unit.find(std::string("\n") + line + "\n"), std::string::npos) << line;
  }
  EXPECT_EQ(unit.find("MemoryDenyWriteExecute=yes"), std::string::npos)
      << "Mesa's software renderer compiles shaders at run time";
}

// Makes sure the unit starts when the display and the network it needs are there, and no later:
// after Plymouth has let go of the display, without the deprecated systemd-udev-settle (devices
// are picked up as they appear), after network.target but not network-online.target, which the
// drop-in for a status server on the network adds. Example failure: a boot that waits for
// udev-settle's time-out, or for an online network a loopback status server does not need.
TEST(SystemdUnit, BootOrdering) {
  const std::string unit = read(test::sourceDir() / "configs/systemd/basalt.service");
  std::string after;
  std::istringstream lines(unit);
  for (std::string line; std::getline(lines, line);) {
    if (line.starts_with("After=")) after += line.substr(6) + " ";
  }
  for (const char* unitName : {"plymouth-quit.service", "plymouth-quit-wait.service", "network.target"}) {
    EXPECT_NE(after.find(std::string(unitName) + " "), std::string::npos) << unitName << " in After=" << after;
  }
  EXPECT_EQ(unit.find("systemd-udev-settle"), std::string::npos);
  EXPECT_EQ(unit.find("\nWants=network-online.target"), std::string::npos);
  EXPECT_EQ(after.find("network-online.target"), std::string::npos);
  const std::string dropIn = read(test::sourceDir() / "configs/systemd/network-online.conf");
  EXPECT_NE(dropIn.find("\n[Unit]\nWants=network-online.target\nAfter=network-online.target\n"), std::string::npos)
      << dropIn;
}

TEST(SystemdUnit, SystemdAcceptsEveryLine) {
  if (::access("/usr/bin/systemd-analyze", X_OK) != 0) GTEST_SKIP() << "systemd-analyze is not installed";
  // systemd-analyze checks that ExecStart's program exists: point it at the build.
  std::string unit = read(test::sourceDir() / "configs/systemd/basalt.service");
  unit = std::regex_replace(unit, std::regex("/usr/bin/basalt"), (test::binaryDir() / "basalt").string());
  const auto dir = test::scratchDir("configs-unit");
  std::ofstream(dir / "basalt.service") << unit;
  // ... and man, which it asks about Documentation=man:basalt(1), at the configured manual page.
  std::filesystem::create_directories(dir / "man/man1");
  std::filesystem::copy_file(test::binaryDir() / "basalt.1", dir / "man/man1/basalt.1");
  const auto verify = test::run({"/usr/bin/systemd-analyze", "verify", (dir / "basalt.service").string()},
                                {{"MANPATH", (dir / "man").string()}});
  EXPECT_EQ(verify.exitCode, 0) << verify.output;
  EXPECT_EQ(verify.output.find("basalt.service:"), std::string::npos) << "a line systemd ignores: " << verify.output;
  const auto security =
      test::run({"/usr/bin/systemd-analyze", "security", "--offline=true", (dir / "basalt.service").string()});
  std::smatch m;
  ASSERT_TRUE(
      std::regex_search(security.output, m, std::regex(R"(Overall exposure level for basalt\.service: ([0-9.]+))")))
      << security.output;
  // 3.5 before the system call filter and ProtectProc=, 1.9 with them (systemd 252).
  EXPECT_LE(std::stod(m[1]), 2.0) << "systemd rates the sandbox: " << m[0];
}

TEST(UdevRule, EveryLineParsesAndTheSupportedDevicesAreCovered) {
  const std::string rules = read(test::sourceDir() / "configs/udev/70-basalt.rules");
  // KEY or KEY{attr}, an operator, a quoted value; pairs separated by commas.
  const std::regex pair(
      R"re(\s*(ACTION|SUBSYSTEM|KERNEL|KERNELS|DRIVERS|ENV\{[A-Z_]+\}|ATTR\{[a-zA-Z_]+\}|ATTRS\{[a-zA-Z_]+\}|GROUP|MODE|TAG|GOTO|LABEL)(==|!=|\+=|=)"[^"]*"\s*)re");
  std::istringstream in(rules);
  std::string line;
  int number = 0;
  int rulesSeen = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty() || line.starts_with("#")) continue;
    std::istringstream parts(line);
    std::string part;
    while (std::getline(parts, part, ',')) {
      EXPECT_TRUE(std::regex_match(part, pair)) << "line " << number << ": '" << part << "'";
    }
    ++rulesSeen;
  }
  EXPECT_GE(rulesSeen, 8);
  for (const char* device :
       {"ATTR{idVendor}==\"077d\", ATTR{idProduct}==\"0410\"", "0003:256C:0060", "0005:256C:8251", "0005:045E:091B",
        "0003:0B33:0020", "SUBSYSTEM==\"video4linux\"",
        "SUBSYSTEM==\"tty\", KERNEL==\"ttyS[0-9]*|ttyUSB[0-9]*|ttyACM[0-9]*\", GROUP=\"dialout\""}) {
    EXPECT_NE(rules.find(device), std::string::npos) << device;
  }
  EXPECT_NE(rules.find("LABEL=\"basalt_end\""), std::string::npos) << "the GOTO's label";
}

}  // namespace
}  // namespace basalt
