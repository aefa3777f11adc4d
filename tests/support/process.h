#pragma once

/// \file
/// \brief Runs a program as a child process for tests: captures its output, signals it, and
/// never waits forever.

#include <sys/types.h>

#include <chrono>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace basalt::test {

struct ProcessResult {
  int exitCode = -1;      ///< exit status, or 128 + signal when killed
  bool timedOut = false;  ///< killed by the time limit
  std::string output;     ///< stdout and stderr, interleaved as written
};

/// \brief A running child with stdout and stderr on one pipe.
class Process {
 public:
  /// \brief Starts `argv[0]` (a path) with `argv`, the current environment plus `env`.
  static Process start(const std::vector<std::string>& argv, const std::map<std::string, std::string>& env = {});
  Process(Process&& other) noexcept;
  Process& operator=(Process&&) = delete;
  Process(const Process&) = delete;
  ~Process();

  [[nodiscard]] pid_t pid() const { return pid_; }
  [[nodiscard]] bool started() const { return pid_ > 0; }
  void signal(int sig) const;
  /// \brief Reads output until the child exits or `limit` passes (then SIGKILL).
  ProcessResult wait(std::chrono::milliseconds limit = std::chrono::seconds(60));
  /// \brief Reads what output is available within `limit`; for waiting on a line.
  bool waitForOutput(const std::string& needle, std::chrono::milliseconds limit);
  [[nodiscard]] const std::string& outputSoFar() const { return output_; }
  /// \brief Reads for `limit` (or until the output ends) and returns all output so far: for
  /// failure messages of tests that waited on something else.
  const std::string& outputWithin(std::chrono::milliseconds limit);

 private:
  Process(pid_t pid, int fd) : pid_(pid), fd_(fd) {}
  bool readSome(int timeoutMs);
  pid_t pid_ = -1;
  int fd_ = -1;
  std::string output_;
};

/// \brief The full path of `program` on $PATH (Process::start does not search it), or empty.
std::string onPath(std::string_view program);

/// \brief Starts, waits and returns the result.
ProcessResult run(const std::vector<std::string>& argv, const std::map<std::string, std::string>& env = {},
                  std::chrono::milliseconds limit = std::chrono::seconds(60));

/// \brief True once process `pid` blocks signal `sig` (its SigBlk mask in /proc), i.e. reads it
/// as an event: from then on the signal stops it cleanly instead of killing it mid-start.
bool signalBlocked(pid_t pid, int sig);
/// \brief Waits up to `limit` for signalBlocked(pid, sig); false when it never came.
bool waitUntilSignalBlocked(pid_t pid, int sig, std::chrono::milliseconds limit = std::chrono::seconds(20));

}  // namespace basalt::test
