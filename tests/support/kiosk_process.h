#pragma once

/// \file
/// \brief Running `basalt run` on a show in a child process for the kiosk's tests: a scratch
/// show folder, the status server's address read from its output, HTTP requests to it.

#include <chrono>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "support/process.h"

namespace basalt::test {

/// \brief A show folder under the build tree with a manifest (and whatever else a test writes).
std::filesystem::path writeShow(const std::string& name, const std::string& manifest);

/// \brief One HTTP answer.
struct HttpAnswer {
  int status = 0;  ///< 0 when the request failed at the transport
  std::string body;
  std::map<std::string, std::string> headers;
};

/// \brief A running `basalt run` with its status server.
class RunningShow {
 public:
  /// \brief Starts `basalt run ARGS...` and waits (up to 30 s) for the status server's line.
  /// Empty when it did not come up; `why` then holds the output.
  static std::unique_ptr<RunningShow> start(const std::vector<std::string>& args,
                                            const std::map<std::string, std::string>& env, std::string& why);

  [[nodiscard]] std::uint16_t port() const { return port_; }
  [[nodiscard]] Process& process() { return process_; }
  HttpAnswer get(const std::string& path) const;
  HttpAnswer post(const std::string& path, const std::string& body = {}, const std::string& token = {}) const;
  /// \brief Sends raw bytes and returns the raw answer (for malformed requests).
  [[nodiscard]] std::string raw(const std::string& bytes) const;

 private:
  RunningShow(Process process, std::uint16_t port) : process_(std::move(process)), port_(port) {}
  Process process_;
  std::uint16_t port_;
};

/// \brief Whether headless EGL works here (otherwise the show tests skip, saying why).
bool headlessEglWorks(std::string& why);

/// \brief The value of a Prometheus sample line `name{labels} value`, or empty.
std::optional<double> metric(const std::string& text, const std::string& nameWithLabels);

}  // namespace basalt::test
