#include "kiosk/status/rate_limiter.h"

#include <algorithm>

namespace basalt::kiosk {

RateLimiter::RateLimiter(double rate) : rate_(rate), burst_(std::max(2.0, rate * 2)) {}

bool RateLimiter::allow(const std::string& client, Nanos now) {
  std::lock_guard lock(mutex_);
  auto it = buckets_.find(client);
  if (it == buckets_.end()) {
    if (buckets_.size() >= kMaxClients) buckets_.clear();
    it = buckets_.emplace(client, Bucket{burst_, now}).first;
  }
  Bucket& b = it->second;
  b.tokens = std::min(burst_, b.tokens + std::max(0.0, toSeconds(now - b.last)) * rate_);
  b.last = std::max(b.last, now);
  if (b.tokens < 1) return false;
  b.tokens -= 1;
  return true;
}

}  // namespace basalt::kiosk
