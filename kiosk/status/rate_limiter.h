#pragma once

/// \file
/// \brief The rate limit of every control that reaches the show from outside: token buckets per
/// client address. The status server's HTTP requests and the OSC input's messages use it alike.

#include <map>
#include <mutex>
#include <string>

#include "runtime/clock.h"

namespace basalt::kiosk {

/// \brief `rate` requests a second per client, in bursts of at most twice that (and at least 2).
/// Remembers at most 256 clients: past that it forgets them all and starts again (bounded memory
/// whatever the clients), which lets a client in rather than keep one out.
///
/// Threading: any thread; a mutex guards the buckets.
class RateLimiter {
 public:
  explicit RateLimiter(double rate);
  /// \brief Takes a token from `client`'s bucket, filled up to `now`; false when it is empty.
  [[nodiscard]] bool allow(const std::string& client, Nanos now);
  [[nodiscard]] double rate() const { return rate_; }
  [[nodiscard]] double burst() const { return burst_; }

  static constexpr std::size_t kMaxClients = 256;

 private:
  struct Bucket {
    double tokens;
    Nanos last;
  };
  double rate_;
  double burst_;
  std::mutex mutex_;
  std::map<std::string, Bucket> buckets_;  // guarded by mutex_
};

}  // namespace basalt::kiosk
