#pragma once

/// \file
/// \brief The one owner of a file descriptor.

#include <utility>

namespace basalt {

/// \brief Owns a file descriptor and closes it once. Move-only; -1 means empty.
class UniqueFd {
 public:
  UniqueFd() = default;
  explicit UniqueFd(int fd) : fd_(fd) {}
  UniqueFd(UniqueFd&& other) noexcept : fd_(std::exchange(other.fd_, -1)) {}
  UniqueFd& operator=(UniqueFd&& other) noexcept {
    if (this != &other) reset(std::exchange(other.fd_, -1));
    return *this;
  }
  UniqueFd(const UniqueFd&) = delete;
  UniqueFd& operator=(const UniqueFd&) = delete;
  ~UniqueFd() { reset(); }

  [[nodiscard]] int get() const { return fd_; }
  [[nodiscard]] bool isValid() const { return fd_ >= 0; }
  explicit operator bool() const { return isValid(); }
  /// \brief Gives up ownership without closing.
  [[nodiscard]] int release() { return std::exchange(fd_, -1); }
  /// \brief Closes the current descriptor (if any) and owns `fd`.
  void reset(int fd = -1);
  /// \brief A new descriptor for the same open file (F_DUPFD_CLOEXEC); empty on failure.
  [[nodiscard]] UniqueFd duplicate() const;

 private:
  int fd_ = -1;
};

}  // namespace basalt
