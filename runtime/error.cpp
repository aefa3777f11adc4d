#include "runtime/error.h"

#include <cstring>

namespace basalt {

std::string_view errcName(Errc code) {
  switch (code) {
    case Errc::kInvalidArgument: return "invalid argument";
    case Errc::kParse: return "parse error";
    case Errc::kNotFound: return "not found";
    case Errc::kPermissionDenied: return "permission denied";
    case Errc::kIo: return "i/o error";
    case Errc::kUnsupported: return "unsupported";
    case Errc::kUnavailable: return "unavailable";
    case Errc::kDeviceLost: return "device lost";
    case Errc::kTimeout: return "timeout";
    case Errc::kResourceExhausted: return "limit reached";
    case Errc::kInternal: return "internal error";
  }
  return "unknown error";
}

std::string Error::describe() const {
  if (where_.empty()) return message_;
  return where_ + ": " + message_;
}

Error Error::withContext(std::string_view context) const {
  return Error(code_, std::string(context) + ": " + message_, where_);
}

Error Error::at(std::string where) const {
  if (!where_.empty()) return *this;
  return Error(code_, message_, std::move(where));
}

std::string systemErrorText(std::string_view what, int errnum) {
  char buffer[256];
  // GNU strerror_r returns the message pointer, which may or may not be `buffer`.
  const char* text = strerror_r(errnum, buffer, sizeof buffer);
  return std::string(what) + ": " + text;
}

}  // namespace basalt
