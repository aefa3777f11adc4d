// `basalt record` as a technician runs it on site: on a terminal one line shows the time, reports,
// frames, size and free space every second (and nothing of it reaches a log or a pipe); the
// recording stops, keeping a valid trace, before the disk is full; a folder left by a crashed
// recording does not make the retry fail; a trace that cannot be finished is removed.
// Runs the real binary with the synthetic devices and raw video (no GPU, no GStreamer).
// Example failures: a silent recording that fills the disk; a retry refused because of the
// crashed attempt's files; an empty trace folder left behind by a failed recording.

#include <gtest/gtest.h>

#include <poll.h>
#include <pty.h>
#include <signal.h>
#include <sys/statvfs.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

#include "sim/trace.h"
#include "support/process.h"
#include "support/test_paths.h"

namespace basalt {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

std::vector<std::string> basaltArgs(const std::vector<std::string>& arguments) {
  std::vector<std::string> argv{(test::binaryDir() / "basalt").string(), "record"};
  argv.insert(argv.end(), arguments.begin(), arguments.end());
  return argv;
}

test::ProcessResult record(const std::vector<std::string>& arguments) {
  return test::run(basaltArgs(arguments), {}, std::chrono::seconds(120));
}

/// Runs `basalt record` with a terminal as stdout and stderr (a pseudo-terminal), and returns all
/// it wrote there and its exit status.
test::ProcessResult recordOnATerminal(const std::vector<std::string>& arguments) {
  test::ProcessResult result;
  const std::vector<std::string> args = basaltArgs(arguments);
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  int master = -1;
  const pid_t pid = ::forkpty(&master, nullptr, nullptr, nullptr);
  if (pid < 0) {
    result.output = "forkpty failed";
    return result;
  }
  if (pid == 0) {
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  const auto deadline = std::chrono::steady_clock::now() + 60s;
  char buf[4096];
  for (;;) {
    pollfd p{master, POLLIN, 0};
    if (std::chrono::steady_clock::now() > deadline) {
      ::kill(pid, SIGKILL);
      result.timedOut = true;
      break;
    }
    if (::poll(&p, 1, 200) <= 0) continue;
    const ssize_t n = ::read(master, buf, sizeof buf);
    if (n <= 0) break;  // EIO once the child has exited and the terminal is closed
    result.output.append(buf, static_cast<std::size_t>(n));
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  ::close(master);
  result.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return result;
}

std::uint64_t freeBytes(const fs::path& path) {
  struct statvfs s{};
  if (::statvfs(path.c_str(), &s) != 0) return 0;
  return static_cast<std::uint64_t>(s.f_bavail) * s.f_frsize;
}

std::uint64_t folderBytes(const fs::path& folder) {
  std::uint64_t bytes = 0;
  for (const auto& e : fs::directory_iterator(folder)) bytes += e.is_regular_file() ? e.file_size() : 0;
  return bytes;
}

TEST(RecordCli, OnATerminalALineShowsProgressEverySecond) {
  const fs::path trace = test::scratchDir("record-cli-progress") / "live.trace";
  const auto r = recordOnATerminal({"--synthetic", "--raw-video", "--seconds", "2.6", "--output", trace.string()});
  ASSERT_FALSE(r.timedOut) << r.output;
  EXPECT_EQ(r.exitCode, 0) << r.output;
  // Each second the line is rewritten in place: carriage return, the figures, erase to the end.
  const std::regex line(
      "\rbasalt: recording 00:00:0([12])  [0-9]+ reports  [0-9]+ frames  [0-9.]+ (bytes|KiB|MiB|GiB)  "
      "[0-9.]+ (bytes|KiB|MiB|GiB|TiB) free\x1b\\[K");
  std::vector<std::string> seconds;
  for (auto it = std::sregex_iterator(r.output.begin(), r.output.end(), line); it != std::sregex_iterator(); ++it) {
    seconds.push_back((*it)[1]);
  }
  EXPECT_EQ(seconds, (std::vector<std::string>{"1", "2"})) << r.output;
  EXPECT_NE(r.output.find("\r\x1b[Kbasalt: recorded 2 device(s)"), std::string::npos)
      << "the line is cleared before the summary: " << r.output;

  // Into a pipe (a log, systemd): no progress line at all.
  fs::remove_all(trace);
  const auto piped = record({"--synthetic", "--raw-video", "--seconds", "2.2", "--output", trace.string()});
  EXPECT_EQ(piped.exitCode, 0) << piped.output;
  EXPECT_EQ(piped.output.find('\r'), std::string::npos) << piped.output;
  EXPECT_EQ(piped.output.find("basalt: recording 00:"), std::string::npos) << piped.output;
}

TEST(RecordCli, StopsBeforeTheDiskFillsAndKeepsTheTrace) {
  const fs::path dir = test::scratchDir("record-cli-disk");
  const fs::path trace = dir / "big.trace";
  // Keep all but 40 MiB of what is free now: raw video (about 13 MiB per second of show time,
  // far faster under --fast) reaches that long before the 60 seconds asked for.
  const std::uint64_t free = freeBytes(dir);
  ASSERT_GT(free, 200u << 20) << "this test needs 200 MiB free on " << dir;
  const std::uint64_t keep = free - (40u << 20);
  const auto r = record({"--synthetic", "--raw-video", "--fast", "--seconds", "60", "--keep-free", std::to_string(keep),
                         "--output", trace.string()});
  EXPECT_EQ(r.exitCode, 1) << "a recording shorter than asked fails: " << r.output;
  EXPECT_NE(r.output.find("stopped after "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("before the disk is full"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("--keep-free"), std::string::npos) << r.output;
  auto info = sim::readTrace(trace);
  ASSERT_TRUE(info) << "the trace is kept, finished: " << info.error().describe();
  EXPECT_LT(info->seconds, 60.0);
  EXPECT_EQ(info->devices.size(), 2u);
  EXPECT_FALSE(fs::exists(trace / ".recording"));
  EXPECT_LT(folderBytes(trace), 200u << 20) << "stopped near the 40 MiB, not at the end";

  // A disk already short of the reserve: refused before anything is made.
  fs::remove_all(trace);
  const auto short_ =
      record({"--synthetic", "--raw-video", "--seconds", "1", "--keep-free", "1000000T", "--output", trace.string()});
  EXPECT_EQ(short_.exitCode, 1) << short_.output;
  EXPECT_NE(short_.output.find("cannot record into " + trace.string() + ": only "), std::string::npos) << short_.output;
  EXPECT_NE(short_.output.find("free (--keep-free); free some space or record onto another disk"), std::string::npos)
      << short_.output;
  EXPECT_FALSE(fs::exists(trace));

  const auto bad = record({"--synthetic", "--keep-free", "lots", "--output", trace.string()});
  EXPECT_EQ(bad.exitCode, 2) << bad.output;
  EXPECT_NE(bad.output.find("--keep-free needs a size such as 256M"), std::string::npos) << bad.output;
}

TEST(RecordCli, ARetryAfterACrashRecordsOverTheUnfinishedTrace) {
  const fs::path trace = test::scratchDir("record-cli-crash") / "site.trace";
  // A recording killed the hard way (power cut, SIGKILL): its files stay, without trace.toml.
  test::Process crashed = test::Process::start(basaltArgs({"--synthetic", "--raw-video", "--output", trace.string()}));
  ASSERT_TRUE(crashed.started());
  ASSERT_TRUE(crashed.waitForOutput("recording camera", 20s)) << crashed.outputSoFar();
  // While it runs, a second recording into the same folder is refused.
  const auto second = record({"--synthetic", "--raw-video", "--seconds", "1", "--output", trace.string()});
  EXPECT_EQ(second.exitCode, 1) << second.output;
  EXPECT_NE(second.output.find(trace.string() + ": another 'basalt record' is writing this trace now (pid " +
                               std::to_string(crashed.pid())),
            std::string::npos)
      << second.output;
  crashed.signal(SIGKILL);
  (void)crashed.wait(10s);
  ASSERT_TRUE(fs::exists(trace / "camera.bvraw"));
  ASSERT_FALSE(fs::exists(trace / "trace.toml"));

  const auto retry = record({"--synthetic", "--raw-video", "--seconds", "1", "--output", trace.string()});
  EXPECT_EQ(retry.exitCode, 0) << retry.output;
  EXPECT_NE(retry.output.find(trace.string() + " held an unfinished trace"), std::string::npos) << retry.output;
  EXPECT_NE(retry.output.find("(removed camera.bvraw, dials.hid)"), std::string::npos) << retry.output;
  auto info = sim::readTrace(trace);
  ASSERT_TRUE(info) << info.error().describe();
  EXPECT_NEAR(info->seconds, 1.0, 0.5);

  // A finished trace is not recorded over: the message names the folder and what to do.
  const auto again = record({"--synthetic", "--raw-video", "--seconds", "1", "--output", trace.string()});
  EXPECT_EQ(again.exitCode, 1) << again.output;
  EXPECT_NE(again.output.find(trace.string() + ": this folder holds a finished trace (it has trace.toml); record "
                                               "into another folder, or remove this one to record it again"),
            std::string::npos)
      << again.output;
}

TEST(RecordCli, ATraceThatCannotBeFinishedIsRemoved) {
  const fs::path trace = test::scratchDir("record-cli-nothing") / "empty.trace";
  const auto r = record({"--dial", "hid:/dev/basalt-no-such-hidraw", "--seconds", "1", "--output", trace.string()});
  EXPECT_EQ(r.exitCode, 1) << r.output;
  EXPECT_NE(r.output.find("dials was never live"), std::string::npos) << r.output;
  EXPECT_NE(
      r.output.find("no device was live, so nothing was recorded; removed the unfinished trace " + trace.string()),
      std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(trace)) << "nothing is left to block the next try";
}

// Makes sure a tracker is recorded as dial boxes and cameras are: `basalt record --tracker
// synthetic` writes the simulated head's samples into the trace as a tracker, in the
// hid-recorder format a replay reads back. At 60 fps of a manual clock for 2 s the synthetic
// tracker gives one sample a frame.
// Example failure: --tracker refused, or the tracker opened but never registered with the
// recorder (no file in the trace, "tracker was never live").
TEST(RecordCli, RecordsATracker) {
  const fs::path trace = test::scratchDir("record-cli-tracker") / "head.trace";
  const auto r = record({"--tracker", "synthetic", "--fast", "--seconds", "2", "--output", trace.string()});
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("recording tracker from"), std::string::npos) << r.output;
  auto info = sim::readTrace(trace);
  ASSERT_TRUE(info) << info.error().describe();
  ASSERT_EQ(info->devices.size(), 1u);
  EXPECT_EQ(info->devices[0].kind, devices::DeviceKind::kTracker);
  std::ifstream file(trace / info->devices[0].file);
  std::size_t events = 0;
  for (std::string line; std::getline(file, line);) events += line.starts_with("E: ");
  EXPECT_GE(events, 100u) << "about one sample a frame over 2 s at 60 fps";
  const auto bad = record({"--tracker", "v4l2:/dev/video0", "--seconds", "1", "--output", trace.string()});
  EXPECT_EQ(bad.exitCode, 2) << bad.output;
  EXPECT_NE(bad.output.find("a tracker is recorded from hid or synthetic"), std::string::npos) << bad.output;
}

}  // namespace
}  // namespace basalt
