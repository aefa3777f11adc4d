#include "kiosk/status/machine_facts.h"

#include <arpa/inet.h>
#include <ifaddrs.h>
#include <net/if.h>
#include <netinet/in.h>
#include <sys/resource.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <fstream>
#include <sstream>
#include <string_view>
#include <system_error>

namespace basalt::kiosk {

namespace {

double seconds(const timeval& t) { return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_usec) / 1e6; }

/// When the process started: /proc/self/stat's field 22 (clock ticks after boot) plus the boot
/// time in /proc/stat.
std::optional<double> startSeconds() {
  std::ifstream statFile("/proc/self/stat");
  std::string stat;
  std::getline(statFile, stat);
  // Field 2, the command, is in parentheses and may hold spaces: count fields after its end.
  const auto close = stat.rfind(')');
  if (close == std::string::npos) return std::nullopt;
  std::istringstream fields(stat.substr(close + 1));
  std::string field;
  unsigned long long ticks = 0;
  for (int i = 3; i <= 22 && fields >> field; ++i) {
    if (i == 22) std::from_chars(field.data(), field.data() + field.size(), ticks);
  }
  if (ticks == 0) return std::nullopt;
  std::ifstream machine("/proc/stat");
  std::string key;
  while (machine >> key) {
    if (key == "btime") {
      unsigned long long boot = 0;
      machine >> boot;
      const long hz = ::sysconf(_SC_CLK_TCK);
      if (boot == 0 || hz <= 0) return std::nullopt;
      return static_cast<double>(boot) + static_cast<double>(ticks) / static_cast<double>(hz);
    }
    std::string rest;
    std::getline(machine, rest);
  }
  return std::nullopt;
}

/// The first line of a small sysfs or procfs file, without its line end; "" when unreadable.
std::string firstLine(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  while (!line.empty() && std::isspace(static_cast<unsigned char>(line.back()))) line.pop_back();
  return line;
}

/// A sysfs temperature in millidegrees Celsius, as degrees; none when unreadable or implausible.
std::optional<double> millidegrees(const std::filesystem::path& file) {
  const std::string text = firstLine(file);
  long long value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || ec != std::errc{} || end != text.data() + text.size()) return std::nullopt;
  const double celsius = static_cast<double>(value) / 1000.0;
  if (celsius < -40 || celsius > 150) return std::nullopt;  // a sensor not wired, or not a temperature
  return celsius;
}

bool containsAny(std::string_view text, std::initializer_list<std::string_view> words) {
  std::string lower(text);
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
  return std::any_of(words.begin(), words.end(),
                     [&](std::string_view w) { return lower.find(w) != std::string::npos; });
}

/// The entries of `folder` whose names start with `prefix`, in name order, so that the same
/// sensor is chosen at every call.
std::vector<std::filesystem::path> entries(const std::filesystem::path& folder, std::string_view prefix) {
  std::vector<std::filesystem::path> out;
  std::error_code ec;
  for (std::filesystem::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    if (it->path().filename().string().starts_with(prefix)) out.push_back(it->path());
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

std::optional<Temperature> readCpuTemperature(const std::filesystem::path& sys) {
  // Thermal zones: the one typed like the CPU or its package, else the first that reads.
  std::optional<Temperature> anyZone;
  for (const auto& zone : entries(sys / "class" / "thermal", "thermal_zone")) {
    const auto celsius = millidegrees(zone / "temp");
    if (!celsius) continue;
    const std::string type = firstLine(zone / "type");
    Temperature t{*celsius, zone.filename().string() + (type.empty() ? "" : " (" + type + ")")};
    if (containsAny(type, {"cpu", "x86_pkg", "pkg", "package", "soc", "core", "tctl"})) return t;
    if (!anyZone) anyZone = t;
  }
  if (anyZone) return anyZone;
  // hwmon chips that measure the CPU: the input labelled as the package or Tctl, else the first.
  for (const auto& chip : entries(sys / "class" / "hwmon", "hwmon")) {
    const std::string name = firstLine(chip / "name");
    if (!containsAny(name, {"coretemp", "k10temp", "k8temp", "zenpower", "cpu", "soc"})) continue;
    std::optional<Temperature> first;
    for (const auto& input : entries(chip, "temp")) {
      const std::string file = input.filename().string();
      if (!file.ends_with("_input")) continue;
      const auto celsius = millidegrees(input);
      if (!celsius) continue;
      const std::string label = firstLine(chip / (file.substr(0, file.size() - 6) + "_label"));
      Temperature t{*celsius, chip.filename().string() + " (" + name + (label.empty() ? "" : ": " + label) + ")"};
      if (containsAny(label, {"package", "tctl", "tdie"})) return t;
      if (!first) first = t;
    }
    if (first) return first;
  }
  return std::nullopt;
}

MachineFacts readMachineFacts(const std::vector<FolderToWatch>& folders, const std::filesystem::path& sys) {
  MachineFacts m;
  std::array<char, 256> host{};
  if (::gethostname(host.data(), host.size() - 1) == 0) m.hostname = host.data();
  ifaddrs* list = nullptr;
  std::vector<NetworkAddress> ipv6;  // after the IPv4 addresses, which people type more easily
  if (::getifaddrs(&list) == 0) {
    for (const ifaddrs* a = list; a; a = a->ifa_next) {
      if (!a->ifa_addr || (a->ifa_flags & IFF_LOOPBACK) || !(a->ifa_flags & IFF_UP)) continue;
      std::array<char, INET6_ADDRSTRLEN> text{};
      if (a->ifa_addr->sa_family == AF_INET) {
        ::inet_ntop(AF_INET, &reinterpret_cast<const sockaddr_in*>(a->ifa_addr)->sin_addr, text.data(), text.size());
      } else if (a->ifa_addr->sa_family == AF_INET6) {
        const auto& v6 = reinterpret_cast<const sockaddr_in6*>(a->ifa_addr)->sin6_addr;
        if (IN6_IS_ADDR_LINKLOCAL(&v6)) continue;  // reachable only with the interface named
        ::inet_ntop(AF_INET6, &v6, text.data(), text.size());
      } else {
        continue;
      }
      (a->ifa_addr->sa_family == AF_INET ? m.addresses : ipv6).push_back({a->ifa_name ? a->ifa_name : "", text.data()});
    }
    ::freeifaddrs(list);
  }
  m.addresses.insert(m.addresses.end(), ipv6.begin(), ipv6.end());
  std::ifstream uptime("/proc/uptime");
  uptime >> m.uptimeSeconds;
  std::ifstream meminfo("/proc/meminfo");
  std::string key;
  std::uint64_t kilobytes = 0;
  std::string unit;
  while (meminfo >> key >> kilobytes) {
    std::getline(meminfo, unit);
    if (key == "MemTotal:") m.memoryTotalBytes = kilobytes * 1024;
    if (key == "MemAvailable:") m.memoryAvailableBytes = kilobytes * 1024;
  }
  for (const FolderToWatch& folder : folders) {
    DiskFacts d{folder.name, folder.path.string(), 0, 0, {}};
    struct statvfs fs{};
    if (::statvfs(folder.path.c_str(), &fs) == 0) {
      d.totalBytes = static_cast<std::uint64_t>(fs.f_blocks) * fs.f_frsize;
      d.freeBytes = static_cast<std::uint64_t>(fs.f_bavail) * fs.f_frsize;
    } else {
      d.error = std::error_code(errno, std::generic_category()).message();
    }
    m.disks.push_back(std::move(d));
  }
  m.cpuTemperature = readCpuTemperature(sys);
  return m;
}

ProcessFigures readProcessFigures() {
  ProcessFigures p;
  rusage usage{};
  if (::getrusage(RUSAGE_SELF, &usage) == 0) p.cpuSeconds = seconds(usage.ru_utime) + seconds(usage.ru_stime);
  std::ifstream statm("/proc/self/statm");
  std::uint64_t pages = 0;
  std::uint64_t resident = 0;
  if (statm >> pages >> resident) {
    const auto pageSize = static_cast<std::uint64_t>(::sysconf(_SC_PAGESIZE));
    p.virtualBytes = pages * pageSize;
    p.residentBytes = resident * pageSize;
  }
  std::error_code ec;
  std::uint64_t fds = 0;
  for (std::filesystem::directory_iterator it("/proc/self/fd", ec), end; !ec && it != end; it.increment(ec)) ++fds;
  // The listing's own descriptor is in the listing.
  p.openFds = fds > 0 ? fds - 1 : 0;
  rlimit limit{};
  if (::getrlimit(RLIMIT_NOFILE, &limit) == 0) p.maxFds = limit.rlim_cur;
  static const std::optional<double> started = startSeconds();  // read once: it never changes
  p.startSeconds = started;
  return p;
}

}  // namespace basalt::kiosk
