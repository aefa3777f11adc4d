#include "kiosk/status/machine_facts.h"

#include <sys/resource.h>
#include <unistd.h>

#include <charconv>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
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

}  // namespace

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
  p.startSeconds = startSeconds();
  return p;
}

}  // namespace basalt::kiosk
