// The frame loop under a flood of status requests: `wrk` asks for /health and /snapshot.png as
// fast as it can for BASALT_STATUS_LOAD_SECONDS (default 60 s) while the default demo plays in
// real time at 60 fps, beside the same show played as long with nobody asking, in the same run.
// For each: late frames (basalt_frames_late_total), the present-to-present interval (p50, p99,
// max), the frame loop thread's CPU per frame (and the whole process's, which includes the
// server's threads), and the resident memory two seconds after the first frame and at the end.
// Targets, printed as target against measured and never asserted: no late frame, memory flat.
//
// The show allows 1 000 requests a second per client (the most `[status] requests_per_second`
// takes), so the server answers that many fully and refuses the rest with 429 as it would refuse
// any flood. The bench reads the figures from 127.0.0.2, a client address of its own, so that
// wrk's flood from 127.0.0.1 does not use up its share.
//
// The interval figures come from /health, read every 5 s: its percentiles cover the last 600
// frames (10 s at 60 fps), so consecutive readings overlap and every frame is in one. p50 is the
// median of the readings' medians, p99 the highest reading's p99 (an upper bound of the run's),
// max the highest reading's max (the run's).

#include <benchmark/benchmark.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "bench_main.h"
#include "support/process.h"

namespace {

using namespace std::chrono_literals;
namespace fs = std::filesystem;

std::string basalt() { return std::string(BASALT_BINARY_DIR) + "/basalt"; }

fs::path scratch() {
  const auto dir = fs::temp_directory_path() / "basalt-status-load-bench";
  fs::create_directories(dir);
  return dir;
}

/// Seconds each of the two runs lasts: BASALT_STATUS_LOAD_SECONDS, default 60.
int loadSeconds() {
  const char* value = std::getenv("BASALT_STATUS_LOAD_SECONDS");
  const int seconds = value ? std::atoi(value) : 60;
  return seconds >= 5 ? seconds : 60;
}

/// GET `path` from the status server on 127.0.0.1:`port`, sent from 127.0.0.2 (see the top).
/// The body of a 200 answer, or empty.
std::string probe(std::uint16_t port, const std::string& path) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return {};
  sockaddr_in from{};
  from.sin_family = AF_INET;
  from.sin_addr.s_addr = htonl(0x7f000002);
  // Without 127.0.0.2 the probe shares wrk's address, and may be refused under load.
  (void)::bind(fd, reinterpret_cast<sockaddr*>(&from), sizeof from);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(port);
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  std::string answer;
  if (::connect(fd, reinterpret_cast<sockaddr*>(&to), sizeof to) == 0) {
    const std::string request = "GET " + path + " HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n";
    if (::send(fd, request.data(), request.size(), MSG_NOSIGNAL) == static_cast<ssize_t>(request.size())) {
      char buffer[8192];
      for (;;) {
        pollfd p{fd, POLLIN, 0};
        if (::poll(&p, 1, 10000) <= 0) break;
        const ssize_t n = ::recv(fd, buffer, sizeof buffer, 0);
        if (n <= 0) break;
        answer.append(buffer, static_cast<std::size_t>(n));
      }
    }
  }
  ::close(fd);
  const auto body = answer.find("\r\n\r\n");
  if (!answer.starts_with("HTTP/1.1 200") || body == std::string::npos) return {};
  return answer.substr(body + 4);
}

double metric(const std::string& text, const std::string& name) {
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(name + " ", 0) == 0) return std::stod(line.substr(name.size() + 1));
  }
  return -1;
}

/// A line of /proc/PID/status, in kB ("VmRSS").
double procStatusKb(pid_t pid, const std::string& key) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(key + ":", 0) == 0) return std::stod(line.substr(key.size() + 1));
  }
  return -1;
}

/// The process's user and system CPU time in seconds, from /proc/PID/stat.
double processCpuSeconds(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string text;
  std::getline(in, text);  // one line
  const auto close = text.rfind(')');
  if (close == std::string::npos) return -1;
  std::istringstream fields(text.substr(close + 2));
  std::vector<std::string> f;
  for (std::string s; fields >> s;) f.push_back(s);
  // After the name: state is field 3 of the line, utime 14 and stime 15 (proc(5)).
  if (f.size() < 13) return -1;
  return (std::stod(f[11]) + std::stod(f[12])) / static_cast<double>(::sysconf(_SC_CLK_TCK));
}

/// The frame loop's counters since the start, from /metrics.
struct Totals {
  double frames = -1;
  double late = 0;
  double dropped = 0;
  double loopCpu = 0;
  double processCpu = 0;
};
Totals totals(std::uint16_t port, pid_t pid) {
  const std::string m = probe(port, "/metrics");
  if (m.empty()) return {};
  return {metric(m, "basalt_frame_work_seconds_count"), metric(m, "basalt_frames_late_total"),
          metric(m, "basalt_frames_dropped_total"), metric(m, "basalt_frame_work_cpu_seconds_sum"),
          processCpuSeconds(pid)};
}

struct Figures {
  std::string why;  ///< why there are none; empty when measured
  double frames = 0;
  double late = 0;
  double dropped = 0;
  double p50Ms = 0;
  double p99Ms = 0;
  double maxMs = 0;
  double loopCpuMs = 0;     ///< per frame
  double processCpuMs = 0;  ///< per frame
  double rssStartKb = 0;
  double rssMidKb = 0;  ///< half-way: growth that stops early is a warm-up, growth that goes on a leak
  double rssEndKb = 0;
  std::string wrk;  ///< wrk's own summary (load only)
  double requestsPerSecond = 0;
  double refused = 0;  ///< answers that were not 2xx (mostly 429)
};
Figures quiet;
Figures loaded;

/// The default demo with its status server allowing the most requests a second.
fs::path writeShow() {
  const fs::path dir = scratch() / "show";
  fs::create_directories(dir);
  std::ifstream in(std::string(BASALT_SOURCE_DIR) + "/configs/shows/default/show.toml");
  std::stringstream text;
  text << in.rdbuf();
  std::string manifest = text.str();
  const std::string status = "[status]\n";
  const auto at = manifest.find(status);
  if (at == std::string::npos) return {};
  manifest.insert(at + status.size(), "requests_per_second = 1000\n");
  std::ofstream(dir / "show.toml", std::ios::trunc) << manifest;
  return dir / "show.toml";
}

/// wrk's script: /health and /snapshot.png in turn on every connection.
fs::path writeWrkScript() {
  const fs::path file = scratch() / "health-and-snapshot.lua";
  std::ofstream(file, std::ios::trunc) << "local paths = { \"/health\", \"/snapshot.png\" }\n"
                                          "local n = 0\n"
                                          "request = function()\n"
                                          "  n = n + 1\n"
                                          "  return wrk.format(\"GET\", paths[n % 2 + 1])\n"
                                          "end\n";
  return file;
}

/// Plays the show for `seconds` in real time, with wrk flooding its server when `flood`.
Figures play(int seconds, bool flood) {
  Figures out;
  const std::string wrk = basalt::test::onPath("wrk");
  if (flood && wrk.empty()) {
    out.why = "wrk is not installed (scripts/packages-test.txt)";
    return out;
  }
  const fs::path manifest = writeShow();
  basalt::test::Process show = basalt::test::Process::start(
      {basalt(), "run", manifest.string(), "--output", "headless", "--realtime", "--fps", "60", "--no-resume",
       "--status", "127.0.0.1:0", "--state-dir", (scratch() / "state").string(), "--output-dir", scratch().string()});
  const std::string marker = "status server: http://127.0.0.1:";
  if (!show.started() || !show.waitForOutput(marker, 30s) || !show.waitForOutput("first frame on", 30s)) {
    out.why = "the show did not start (is EGL available?): " + show.outputSoFar();
    return out;
  }
  const std::string& text = show.outputSoFar();
  const auto port = static_cast<std::uint16_t>(std::stoi(text.substr(text.find(marker) + marker.size())));
  (void)show.outputWithin(2s);  // past the start's allocations
  const Totals first = totals(port, show.pid());
  out.rssStartKb = procStatusKb(show.pid(), "VmRSS");
  std::optional<basalt::test::Process> load;
  if (flood) {
    // The flood's client stands for a machine elsewhere on the network; here it shares the show's
    // cores, so it runs at the lowest priority: what the show then loses is what answering costs
    // it, not what wrk's own work does.
    load.emplace(basalt::test::Process::start(
        {"/usr/bin/nice", "-n", "19", wrk, "-t2", "-c16", "-d" + std::to_string(seconds) + "s", "--timeout", "5s", "-s",
         writeWrkScript().string(), "http://127.0.0.1:" + std::to_string(port) + "/"}));
  }
  // Readings every 5 s; waiting on the show's output keeps its pipe drained meanwhile.
  std::vector<double> p50, p99, max;
  const std::regex interval(
      R"re("frame_time_ms": \{\s*"p50": ([0-9.]+),\s*"p90": [0-9.]+,\s*"p99": ([0-9.]+),\s*"max": ([0-9.]+)\s*\})re");
  const auto begin = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - begin < std::chrono::seconds(seconds)) {
    (void)show.outputWithin(std::min<std::chrono::milliseconds>(
        5s, std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::seconds(seconds) -
                                                                  (std::chrono::steady_clock::now() - begin))));
    if (out.rssMidKb == 0 && std::chrono::steady_clock::now() - begin >= std::chrono::seconds(seconds) / 2) {
      out.rssMidKb = procStatusKb(show.pid(), "VmRSS");
    }
    std::smatch m;
    const std::string health = probe(port, "/health");
    if (std::regex_search(health, m, interval)) {
      p50.push_back(std::stod(m[1].str()));
      p99.push_back(std::stod(m[2].str()));
      max.push_back(std::stod(m[3].str()));
    }
  }
  if (load) {
    basalt::test::ProcessResult r = load->wait(30s);
    out.wrk = r.output;
    std::smatch m;
    if (std::regex_search(r.output, m, std::regex(R"(Requests/sec:\s+([0-9.]+))"))) {
      out.requestsPerSecond = std::stod(m[1].str());
    }
    if (std::regex_search(r.output, m, std::regex(R"(Non-2xx or 3xx responses:\s+([0-9]+))"))) {
      out.refused = std::stod(m[1].str());
    }
  }
  // wrk has stopped: the totals are the run's.
  const Totals last = totals(port, show.pid());
  out.rssEndKb = procStatusKb(show.pid(), "VmRSS");
  show.signal(SIGTERM);
  (void)show.wait(20s);
  out.frames = last.frames - first.frames;
  if (first.frames < 0 || last.frames < 0 || out.frames <= 0 || p50.empty()) {
    out.why = "no figures from the status server (frames " + std::to_string(first.frames) + " then " +
              std::to_string(last.frames) + ", " + std::to_string(p50.size()) + " readings of /health)";
    return out;
  }
  out.late = last.late - first.late;
  out.dropped = last.dropped - first.dropped;
  out.loopCpuMs = (last.loopCpu - first.loopCpu) / out.frames * 1e3;
  out.processCpuMs = (last.processCpu - first.processCpu) / out.frames * 1e3;
  std::ranges::sort(p50);
  out.p50Ms = p50[p50.size() / 2];
  out.p99Ms = *std::ranges::max_element(p99);
  out.maxMs = *std::ranges::max_element(max);
  return out;
}

void statusServerFlood(benchmark::State& state, bool flood) {
  for (auto _ : state) {
    Figures& f = flood ? loaded : quiet;
    f = play(loadSeconds(), flood);
    if (!f.why.empty()) {
      state.SkipWithError(f.why.c_str());
      return;
    }
    state.counters["late"] = f.late;
    state.counters["p99_ms"] = f.p99Ms;
    state.counters["loop_cpu_ms"] = f.loopCpuMs;
    state.counters["rss_growth_kb"] = f.rssEndKb - f.rssStartKb;
    state.SetIterationTime(1);
  }
}

// The quiet run first: the baseline the loaded run is set beside.
BENCHMARK_CAPTURE(statusServerFlood, quiet, false)->UseManualTime()->Iterations(1)->Repetitions(1);
BENCHMARK_CAPTURE(statusServerFlood, wrk, true)->UseManualTime()->Iterations(1)->Repetitions(1);

void printRun(const char* name, const Figures& f) {
  std::printf(
      "status flood, %s: %.0f frames at 60 fps; late %.0f, dropped %.0f; frame interval p50 %.2f ms, p99 %.2f ms, "
      "max %.2f ms; frame loop CPU %.3f ms per frame (whole process %.3f ms); resident %.1f MB at the start, %.1f MB "
      "half-way, %.1f MB at the end (%+.0f kB, %+.0f kB in the second half)\n",
      name, f.frames, f.late, f.dropped, f.p50Ms, f.p99Ms, f.maxMs, f.loopCpuMs, f.processCpuMs, f.rssStartKb / 1024,
      f.rssMidKb / 1024, f.rssEndKb / 1024, f.rssEndKb - f.rssStartKb, f.rssEndKb - f.rssMidKb);
}

}  // namespace

int main(int argc, char** argv) {
  return basalt::bench::runBenchmarks(argc, argv, [](const basalt::bench::Medians&) {
    if (!quiet.why.empty() || !loaded.why.empty() || quiet.frames <= 0 || loaded.frames <= 0) {
      std::printf("status flood: no figure (a run failed: %s)\n", (quiet.why + " " + loaded.why).c_str());
      return;
    }
    std::printf("status flood: %d s each, the default demo at 60 fps; wrk -t2 -c16 on /health and /snapshot.png\n",
                loadSeconds());
    printRun("no requests (baseline)", quiet);
    printRun("under wrk", loaded);
    std::printf("status flood: wrk %.0f requests/s, %.0f of them refused (429 past 1000/s, or other non-2xx)\n",
                loaded.requestsPerSecond, loaded.refused);
    // wrk's own lines: its latency and throughput, as wrk printed them.
    std::istringstream wrkLines(loaded.wrk);
    for (std::string line; std::getline(wrkLines, line);) {
      if (line.find("Latency") != std::string::npos || line.find("requests in") != std::string::npos ||
          line.find("Socket errors") != std::string::npos) {
        std::printf("status flood: wrk: %s\n", line.c_str());
      }
    }
    std::printf("status flood: late frames under load: target 0, measured %.0f (baseline %.0f): %s\n", loaded.late,
                quiet.late, loaded.late == 0 ? "met" : "NOT MET");
    const double growth = loaded.rssEndKb - loaded.rssStartKb;
    const double baseGrowth = quiet.rssEndKb - quiet.rssStartKb;
    // Flat: in the second half, once the server's workers, buffers and snapshot copy exist, it
    // grew no more than the quiet run did, give or take 1 MB of allocator noise. A leak goes on
    // growing there; a working set taken on at the start of the flood does not.
    const double lateGrowth = loaded.rssEndKb - loaded.rssMidKb;
    const double baseLateGrowth = quiet.rssEndKb - quiet.rssMidKb;
    std::printf(
        "status flood: resident memory under load: target flat, measured %+.0f kB in the second half (baseline "
        "%+.0f kB): %s; over all %d s %+.0f kB (%+.2f%%; baseline %+.0f kB), the server's working set under the "
        "flood included\n",
        lateGrowth, baseLateGrowth, lateGrowth <= std::max(baseLateGrowth, 0.0) + 1024 ? "met" : "NOT MET",
        loadSeconds(), growth, growth / loaded.rssStartKb * 100, baseGrowth);
    std::printf("status flood: frame loop CPU per frame under load %.3f ms vs %.3f ms without (%+.1f%%)\n",
                loaded.loopCpuMs, quiet.loopCpuMs, (loaded.loopCpuMs / quiet.loopCpuMs - 1) * 100);
  });
}
