#pragma once

/// \file
/// \brief systemd's side of a service for tests: a datagram socket the way its notify and journal
/// sockets are, in a folder of its own under /tmp (a socket's path must fit sun_path's 107 bytes,
/// which a build folder deep in a checkout does not always leave room for).

#include <gtest/gtest.h>

#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace basalt::test {

/// \brief A folder of its own under /tmp for sockets; removed with everything in it.
class SocketDir {
 public:
  SocketDir() {
    char name[] = "/tmp/basalt-sock-XXXXXX";
    if (::mkdtemp(name)) path_ = name;
  }
  ~SocketDir() {
    std::error_code ec;
    if (!path_.empty()) std::filesystem::remove_all(path_, ec);
  }
  SocketDir(const SocketDir&) = delete;
  SocketDir& operator=(const SocketDir&) = delete;
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

/// \brief A bound datagram socket the test reads; a path too long for sun_path is a failure.
class DatagramSocket {
 public:
  explicit DatagramSocket(std::filesystem::path path) : path_(std::move(path)) {
    sockaddr_un address{};
    if (path_.native().size() >= sizeof address.sun_path) {
      ADD_FAILURE() << "the socket path " << path_ << " is longer than " << sizeof address.sun_path - 1 << " bytes";
      return;
    }
    fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    address.sun_family = AF_UNIX;
    std::memcpy(address.sun_path, path_.c_str(), path_.native().size() + 1);
    ::unlink(path_.c_str());
    bound_ = ::bind(fd_, reinterpret_cast<sockaddr*>(&address), sizeof address) == 0;
  }
  ~DatagramSocket() {
    if (fd_ >= 0) ::close(fd_);
    if (bound_) ::unlink(path_.c_str());
  }
  DatagramSocket(const DatagramSocket&) = delete;
  DatagramSocket& operator=(const DatagramSocket&) = delete;
  [[nodiscard]] bool bound() const { return bound_; }
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

  /// \brief The next datagram within `limit`, or nothing.
  std::optional<std::string> receive(std::chrono::milliseconds limit) {
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(limit.count())) <= 0) return std::nullopt;
    std::vector<char> buffer(65536);
    const ssize_t n = ::recv(fd_, buffer.data(), buffer.size(), 0);
    if (n < 0) return std::nullopt;
    return std::string(buffer.data(), static_cast<std::size_t>(n));
  }
  /// \brief Waits for a datagram containing `needle`; every datagram seen goes to `seen`.
  bool waitFor(const std::string& needle, std::chrono::milliseconds limit, std::vector<std::string>* seen = nullptr) {
    const auto end = std::chrono::steady_clock::now() + limit;
    while (std::chrono::steady_clock::now() < end) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(end - std::chrono::steady_clock::now());
      auto d = receive(left);
      if (!d) continue;
      if (seen) seen->push_back(*d);
      if (d->find(needle) != std::string::npos) return true;
    }
    return false;
  }

 private:
  std::filesystem::path path_;
  int fd_ = -1;
  bool bound_ = false;
};

}  // namespace basalt::test
