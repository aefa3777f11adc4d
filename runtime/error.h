#pragma once

/// \file
/// \brief Errors as values: every fallible call across a module boundary returns
/// `basalt::Result<T>`, a `std::expected<T, basalt::Error>`.

#include <expected>
#include <string>
#include <string_view>
#include <utility>

#include <fmt/format.h>

namespace basalt {

/// \brief What kind of failure an Error reports. Callers branch on the code; people read the message.
enum class Errc {
  kInvalidArgument,    ///< a value given by the caller or a user is out of range or malformed
  kParse,              ///< a file or text did not parse; `where` holds file:line:column
  kNotFound,           ///< a file, device, part or name does not exist
  kPermissionDenied,   ///< the OS refused access (permissions, udev rule missing)
  kIo,                 ///< reading or writing failed (disk full, EIO)
  kUnsupported,        ///< valid, but this build, driver or platform cannot do it
  kUnavailable,        ///< a resource that exists cannot be used now (no EGL, device busy)
  kDeviceLost,         ///< a device vanished while in use
  kTimeout,            ///< something did not answer in time
  kResourceExhausted,  ///< a limit was reached (queue full, file too large, count capped)
  kInternal,           ///< a bug in Basalt; the message says what invariant broke
};

/// \brief Short lower-case name of an error code ("parse", "not found", ...).
std::string_view errcName(Errc code);

/// \brief A failure with a code, a message for people and where it happened.
///
/// `where` names the file:line:column, the device or the stream; `message` says what failed
/// and, where possible, what to do next. Low layers fill both; the caller with the context
/// logs the error once.
class Error {
 public:
  Error(Errc code, std::string message, std::string where = {})
      : code_(code), message_(std::move(message)), where_(std::move(where)) {}

  [[nodiscard]] Errc code() const { return code_; }
  [[nodiscard]] const std::string& message() const { return message_; }
  [[nodiscard]] const std::string& where() const { return where_; }

  /// \brief "where: message", or just the message when there is no location.
  [[nodiscard]] std::string describe() const;

  /// \brief Returns a copy with `context` put in front of the message ("loading x: " + msg).
  [[nodiscard]] Error withContext(std::string_view context) const;
  /// \brief Returns a copy whose location is `where` unless one is already set.
  [[nodiscard]] Error at(std::string where) const;

 private:
  Errc code_;
  std::string message_;
  std::string where_;
};

template <typename T>
using Result = std::expected<T, Error>;

/// \brief Builds the unexpected value for a Result: `return fail(Errc::kParse, "...", where);`
inline std::unexpected<Error> fail(Errc code, std::string message, std::string where = {}) {
  return std::unexpected<Error>(std::in_place, code, std::move(message), std::move(where));
}

/// \brief Formats the message with fmt: `return failf(Errc::kIo, "cannot write {}", path);`
template <typename... Args>
std::unexpected<Error> failf(Errc code, fmt::format_string<Args...> format, Args&&... args) {
  return fail(code, fmt::format(format, std::forward<Args>(args)...));
}

/// \brief "what: strerror(errno)" for a failed system call.
std::string systemErrorText(std::string_view what, int errnum);

}  // namespace basalt
