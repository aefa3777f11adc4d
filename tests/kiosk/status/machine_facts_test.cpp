// What the status page says about the machine: the CPU's temperature from the kernel's thermal
// zones or hwmon chips (made up here as sysfs trees of files, as the kernel lays them out), and
// the host name, addresses, memory and disk space, checked against what other programs say
// (hostname, df, free, ip).
// Example failures: a GPU's or a Wi-Fi card's sensor reported as the CPU's; millidegrees shown as
// degrees; a machine without a sensor shown as 0 °C; free space counted with the blocks only root
// may use.

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "kiosk/status/machine_facts.h"
#include "support/process.h"
#include "support/test_paths.h"

namespace basalt::kiosk {
namespace {

namespace fs = std::filesystem;

void write(const fs::path& file, const std::string& text) {
  fs::create_directories(file.parent_path());
  std::ofstream(file) << text << "\n";
}

TEST(CpuTemperature, AThermalZoneTypedLikeTheCpuComesFirst) {
  const fs::path sys = test::scratchDir("machine-sys-zones");
  write(sys / "class/thermal/thermal_zone0/type", "acpitz");
  write(sys / "class/thermal/thermal_zone0/temp", "27800");
  write(sys / "class/thermal/thermal_zone1/type", "iwlwifi_1");
  write(sys / "class/thermal/thermal_zone1/temp", "41000");
  write(sys / "class/thermal/thermal_zone2/type", "x86_pkg_temp");
  write(sys / "class/thermal/thermal_zone2/temp", "47500");
  const auto t = readCpuTemperature(sys);
  ASSERT_TRUE(t);
  EXPECT_DOUBLE_EQ(t->celsius, 47.5);
  EXPECT_EQ(t->sensor, "thermal_zone2 (x86_pkg_temp)");
}

TEST(CpuTemperature, ARaspberryPisZone) {
  const fs::path sys = test::scratchDir("machine-sys-pi");
  write(sys / "class/thermal/thermal_zone0/type", "cpu-thermal");
  write(sys / "class/thermal/thermal_zone0/temp", "51121");
  const auto t = readCpuTemperature(sys);
  ASSERT_TRUE(t);
  EXPECT_DOUBLE_EQ(t->celsius, 51.121);
  EXPECT_EQ(t->sensor, "thermal_zone0 (cpu-thermal)");
}

TEST(CpuTemperature, AnyZoneBeforeNone) {
  const fs::path sys = test::scratchDir("machine-sys-acpi");
  write(sys / "class/thermal/thermal_zone0/type", "acpitz");
  write(sys / "class/thermal/thermal_zone0/temp", "-273150");  // not wired: skipped
  write(sys / "class/thermal/thermal_zone1/type", "acpitz");
  write(sys / "class/thermal/thermal_zone1/temp", "33000");
  const auto t = readCpuTemperature(sys);
  ASSERT_TRUE(t);
  EXPECT_DOUBLE_EQ(t->celsius, 33.0);
  EXPECT_EQ(t->sensor, "thermal_zone1 (acpitz)");
}

TEST(CpuTemperature, HwmonPackageWhenThereIsNoZone) {
  const fs::path sys = test::scratchDir("machine-sys-hwmon");
  fs::create_directories(sys / "class/thermal");  // present, empty: as on many PCs and VMs
  write(sys / "class/hwmon/hwmon0/name", "nvme");
  write(sys / "class/hwmon/hwmon0/temp1_input", "38850");
  write(sys / "class/hwmon/hwmon1/name", "coretemp");
  write(sys / "class/hwmon/hwmon1/temp1_input", "52000");
  write(sys / "class/hwmon/hwmon1/temp1_label", "Core 0");
  write(sys / "class/hwmon/hwmon1/temp2_input", "55000");
  write(sys / "class/hwmon/hwmon1/temp2_label", "Package id 0");
  const auto t = readCpuTemperature(sys);
  ASSERT_TRUE(t);
  EXPECT_DOUBLE_EQ(t->celsius, 55.0);
  EXPECT_EQ(t->sensor, "hwmon1 (coretemp: Package id 0)") << "the package, not the first core";
}

TEST(CpuTemperature, AnAmdChipsTctl) {
  const fs::path sys = test::scratchDir("machine-sys-k10");
  write(sys / "class/hwmon/hwmon3/name", "k10temp");
  write(sys / "class/hwmon/hwmon3/temp1_input", "61250");
  write(sys / "class/hwmon/hwmon3/temp1_label", "Tctl");
  const auto t = readCpuTemperature(sys);
  ASSERT_TRUE(t);
  EXPECT_DOUBLE_EQ(t->celsius, 61.25);
  EXPECT_EQ(t->sensor, "hwmon3 (k10temp: Tctl)");
}

TEST(CpuTemperature, NoSensorIsNone) {
  const fs::path sys = test::scratchDir("machine-sys-none");
  fs::create_directories(sys / "class/thermal");
  write(sys / "class/hwmon/hwmon0/name", "nvme");  // a disk's sensor is not the CPU's
  write(sys / "class/hwmon/hwmon0/temp1_input", "38850");
  EXPECT_FALSE(readCpuTemperature(sys));
  EXPECT_FALSE(readCpuTemperature(sys / "nowhere"));
}

/// The output of a command, or "" when it cannot run.
std::string output(const std::vector<std::string>& argv) {
  const auto r = test::run(argv);
  return r.exitCode == 0 ? r.output : std::string();
}

TEST(MachineFacts, AgreeWithOtherPrograms) {
  const fs::path folder = test::scratchDir("machine-disk");
  const MachineFacts m = readMachineFacts({{"show", folder}, {"gone", folder / "missing"}});
  std::string hostname = output({"/usr/bin/hostname"});
  while (!hostname.empty() && hostname.back() == '\n') hostname.pop_back();
  if (!hostname.empty()) {
    EXPECT_EQ(m.hostname, hostname);
  }

  // `ip -o addr` lists every address; each one the facts give is among them, none is loopback.
  const std::string ip = output({"/usr/sbin/ip", "-o", "addr", "show", "up"});
  for (const NetworkAddress& a : m.addresses) {
    EXPECT_NE(a.address, "127.0.0.1");
    EXPECT_NE(a.address, "::1");
    if (!ip.empty()) {
      EXPECT_NE(ip.find(a.interface), std::string::npos) << a.interface << "\n" << ip;
      EXPECT_NE(ip.find(" " + a.address + "/"), std::string::npos) << a.address << "\n" << ip;
    }
  }
  for (std::size_t i = 1; i < m.addresses.size(); ++i) {
    const bool v6 = m.addresses[i - 1].address.find(':') != std::string::npos;
    if (v6) {
      EXPECT_NE(m.addresses[i].address.find(':'), std::string::npos) << "IPv4 first";
    }
  }

  // `df -B1 --output=size,avail`: the same file system, bytes; free space as an unprivileged
  // program sees it ("avail"), within what other programs write meanwhile.
  ASSERT_EQ(m.disks.size(), 2u);
  EXPECT_EQ(m.disks[0].name, "show");
  EXPECT_EQ(m.disks[0].error, "");
  std::istringstream df(output({"/usr/bin/df", "-B1", "--output=size,avail", folder.string()}));
  std::string header;
  std::getline(df, header);
  double size = 0;
  double avail = 0;
  if (df >> size >> avail) {
    EXPECT_DOUBLE_EQ(static_cast<double>(m.disks[0].totalBytes), size);
    EXPECT_NEAR(static_cast<double>(m.disks[0].freeBytes), avail, 64.0 * 1024 * 1024);
  }
  EXPECT_EQ(m.disks[1].name, "gone");
  EXPECT_EQ(m.disks[1].totalBytes, 0u);
  EXPECT_NE(m.disks[1].error.find("No such file"), std::string::npos) << m.disks[1].error;

  // `free -b`: total memory exactly, available within what moves meanwhile.
  std::istringstream free(output({"/usr/bin/free", "-b"}));
  std::string line;
  std::getline(free, line);
  std::string label;
  double total = 0;
  double used = 0;
  double freeBytes = 0;
  double shared = 0;
  double cache = 0;
  double available = 0;
  if (free >> label >> total >> used >> freeBytes >> shared >> cache >> available) {
    EXPECT_DOUBLE_EQ(static_cast<double>(m.memoryTotalBytes), total);
    EXPECT_NEAR(static_cast<double>(m.memoryAvailableBytes), available, 256.0 * 1024 * 1024);
  }
  EXPECT_GT(m.uptimeSeconds, 0);
}

}  // namespace
}  // namespace basalt::kiosk
