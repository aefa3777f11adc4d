// Start-up: process start to the first frame written, for the default show headless
// (issue 2's figure, target under 300 ms here). The baseline in the same run is the cost of
// starting the same binary and exiting (`basalt --version`), so the difference is Basalt's own
// work: EGL, shaders, the first frame and the PNG.

#include <benchmark/benchmark.h>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "bench_main.h"

extern char** environ;

namespace {

std::string basaltPath() { return std::string(BASALT_BINARY_DIR) + "/basalt"; }

/// Spawns the command and waits; returns the wall time in seconds, or -1 on failure.
double timeProcess(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  argv.reserve(args.size() + 1);
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  const auto start = std::chrono::steady_clock::now();
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) return -1;
  int status = 0;
  waitpid(pid, &status, 0);
  const auto end = std::chrono::steady_clock::now();
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return -1;
  return std::chrono::duration<double>(end - start).count();
}

void runTimed(benchmark::State& state, const std::vector<std::string>& args) {
  for (auto _ : state) {
    const double seconds = timeProcess(args);
    if (seconds < 0) {
      state.SkipWithError("the process failed (is EGL available?)");
      return;
    }
    state.SetIterationTime(seconds);
  }
}

void processStartFloor(benchmark::State& state) { runTimed(state, {basaltPath(), "--version"}); }

void firstFrameWritten(benchmark::State& state) {
  const std::string snapshot = std::filesystem::temp_directory_path() / "basalt-bench-first-frame.png";
  runTimed(state, {basaltPath(), "run", "--frames", "1", "--headless", "--snapshot", snapshot});
}

BENCHMARK(processStartFloor)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(5)->Repetitions(5);
BENCHMARK(firstFrameWritten)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(3)->Repetitions(7);

}  // namespace

int main(int argc, char** argv) {
  return basalt::bench::runBenchmarks(argc, argv, [](const basalt::bench::Medians& m) {
    const auto floor = m.find("processStartFloor");
    const auto first = m.find("firstFrameWritten");
    if (floor == m.end() || first == m.end()) {
      std::printf("startup: no figures (a benchmark failed)\n");
      return;
    }
    std::printf(
        "startup: first frame written %.1f ms after process start (median); process start floor %.1f ms; "
        "Basalt's own start-up %.1f ms; target < 300 ms: %s\n",
        first->second * 1e3, floor->second * 1e3, (first->second - floor->second) * 1e3,
        first->second < 0.300 ? "met" : "NOT MET");
  });
}
