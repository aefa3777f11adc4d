#include "support/kiosk_process.h"

#include <arpa/inet.h>
#include <httplib.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <system_error>

#include "support/test_paths.h"

namespace basalt::test {

std::filesystem::path writeShow(const std::string& name, const std::string& manifest) {
  const auto dir = scratchDir(name);
  std::ofstream(dir / "show.toml") << manifest;
  return dir;
}

std::unique_ptr<RunningShow> RunningShow::start(const std::vector<std::string>& args,
                                                const std::map<std::string, std::string>& env, std::string& why) {
  std::vector<std::string> argv{(binaryDir() / "basalt").string(), "run"};
  argv.insert(argv.end(), args.begin(), args.end());
  Process p = Process::start(argv, env);
  const std::string marker = "basalt: status server: http://127.0.0.1:";
  if (!p.started() || !p.waitForOutput(marker, std::chrono::seconds(30))) {
    why = p.outputSoFar();
    return nullptr;
  }
  p.waitForOutput("/\n", std::chrono::seconds(5));
  const std::string& out = p.outputSoFar();
  const auto at = out.find(marker) + marker.size();
  const int port = std::stoi(out.substr(at, out.find('/', at) - at));
  return std::unique_ptr<RunningShow>(new RunningShow(std::move(p), static_cast<std::uint16_t>(port)));
}

namespace {

HttpAnswer toAnswer(const httplib::Result& r) {
  HttpAnswer a;
  if (!r) return a;
  a.status = r->status;
  a.body = r->body;
  for (const auto& [k, v] : r->headers) a.headers[k] = v;
  return a;
}

}  // namespace

HttpAnswer RunningShow::get(const std::string& path) const {
  httplib::Client client("127.0.0.1", port_);
  client.set_read_timeout(10, 0);
  return toAnswer(client.Get(path));
}

HttpAnswer RunningShow::post(const std::string& path, const std::string& body, const std::string& token) const {
  httplib::Client client("127.0.0.1", port_);
  client.set_read_timeout(10, 0);
  httplib::Headers headers;
  if (!token.empty()) headers.emplace("Authorization", token);
  return toAnswer(client.Post(path, headers, body, "text/plain"));
}

std::string RunningShow::raw(const std::string& bytes) const {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(port_);
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  std::string answer;
  if (::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) == 0) {
    std::size_t sent = 0;
    while (sent < bytes.size()) {
      const ssize_t n = ::send(fd, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
      if (n <= 0) break;
      sent += static_cast<std::size_t>(n);
    }
    ::shutdown(fd, SHUT_WR);
    char buffer[4096];
    for (;;) {
      pollfd p{fd, POLLIN, 0};
      if (::poll(&p, 1, 10000) <= 0) break;
      const ssize_t n = ::recv(fd, buffer, sizeof buffer, 0);
      if (n <= 0) break;
      answer.append(buffer, static_cast<std::size_t>(n));
    }
  }
  ::close(fd);
  return answer;
}

bool headlessEglWorks(std::string& why) {
  // A folder of this process's own: test processes probe at once, and scratchDir() empties the
  // folder it is given (a shared one was emptied under another probe's snapshot).
  const auto folder = scratchDir("kiosk-egl-probe-" + std::to_string(::getpid()));
  const auto r = run({(binaryDir() / "basalt").string(), "run", "--frames", "1", "--headless", "--snapshot",
                      (folder / "probe.png").string()});
  std::error_code ec;
  std::filesystem::remove_all(folder, ec);
  if (r.exitCode == 0) return true;
  why = r.output;
  return false;
}

std::optional<double> metric(const std::string& text, const std::string& nameWithLabels) {
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(nameWithLabels + " ", 0) == 0) return std::stod(line.substr(nameWithLabels.size() + 1));
  }
  return std::nullopt;
}

}  // namespace basalt::test
