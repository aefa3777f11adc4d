#pragma once

/// \file
/// \brief What the status server says about the process and the machine it runs on, read from
/// /proc, /sys and the C library when a report is asked for (on the server's threads, never the
/// frame loop's).

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace basalt::kiosk {

/// \brief The process's own figures, as Prometheus' client libraries name them (process_*).
struct ProcessFigures {
  double cpuSeconds = 0;               ///< user and system CPU time since the start
  std::uint64_t residentBytes = 0;     ///< resident set size
  std::uint64_t virtualBytes = 0;      ///< virtual memory size
  std::uint64_t openFds = 0;           ///< open file descriptors
  std::uint64_t maxFds = 0;            ///< the soft limit on them
  std::optional<double> startSeconds;  ///< when the process started, seconds since 1970
};

/// \brief This process's figures.
[[nodiscard]] ProcessFigures readProcessFigures();

/// \brief A folder whose file system's free space the status page shows.
struct FolderToWatch {
  std::string name;  ///< "show", "state"
  std::filesystem::path path;
};

/// \brief The file system a watched folder is on.
struct DiskFacts {
  std::string name;
  std::string path;
  std::uint64_t totalBytes = 0;
  std::uint64_t freeBytes = 0;  ///< what an unprivileged process may still write
  std::string error;            ///< why the figures are missing ("" when they are there)
};

/// \brief One address other machines may reach this one at.
struct NetworkAddress {
  std::string interface;  ///< "eth0"
  std::string address;    ///< "192.168.1.20", "2001:db8::5"
};

/// \brief A temperature sensor's reading.
struct Temperature {
  double celsius = 0;
  std::string sensor;  ///< where it was read: "thermal_zone0 (x86_pkg_temp)", "hwmon1 (coretemp: Package id 0)"
};

/// \brief What a signage technician asks of the machine first.
struct MachineFacts {
  std::string hostname;
  std::vector<NetworkAddress> addresses;  ///< up, not loopback, not IPv6 link-local; IPv4 first
  double uptimeSeconds = 0;               ///< since the machine booted
  std::uint64_t memoryTotalBytes = 0;
  std::uint64_t memoryAvailableBytes = 0;  ///< MemAvailable: what programs may still take
  std::vector<DiskFacts> disks;
  std::optional<Temperature> cpuTemperature;  ///< none where the machine has no sensor
};

/// \brief The CPU's temperature from the kernel's thermal zones (a zone typed like the CPU's or
/// the package's first, then any zone) or, without those, from a hwmon chip known to measure the
/// CPU (coretemp, k10temp, zenpower, cpu_thermal ...). `sys` is where sysfs is mounted (tests
/// give a tree of their own). None when there is no sensor.
[[nodiscard]] std::optional<Temperature> readCpuTemperature(const std::filesystem::path& sys = "/sys");

/// \brief The machine's facts, with the file systems of `folders`.
[[nodiscard]] MachineFacts readMachineFacts(const std::vector<FolderToWatch>& folders,
                                            const std::filesystem::path& sys = "/sys");

}  // namespace basalt::kiosk
