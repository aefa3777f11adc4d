#include "kiosk/show/osc_trackers.h"

#include <array>
#include <optional>
#include <string_view>

#include <fmt/format.h>

namespace basalt::kiosk {

/// One tracker's feed: its last sample and the device open on it, if any.
struct OscTrackerFeeds::Feed {
  std::string name;
  const Clock* clock = nullptr;
  std::mutex mutex;                  // guards everything below
  devices::Tracker* live = nullptr;  // an OscTracker, open
  Nanos lastMessage{-1};
  runtime::TrackerSample sample;  // the pose as the messages so far set it
};

namespace {

/// A fed tracker as the DeviceManager sees it. It registers itself with its feed while open,
/// and takes itself off before it goes, so that the OSC thread never reaches a closed device.
class OscTracker final : public devices::Tracker {
 public:
  OscTracker(devices::DeviceInfo info, std::shared_ptr<OscTrackerFeeds::Feed> feed)
      : Tracker(std::move(info)), feed_(std::move(feed)) {}
  ~OscTracker() override { detach(); }
  OscTracker(const OscTracker&) = delete;
  OscTracker& operator=(const OscTracker&) = delete;

  /// Called with the feed's mutex held.
  void deliver(const runtime::TrackerSample& sample) { (void)emit(sample); }

 private:
  Result<void> doOpen() override {
    std::lock_guard lock(feed_->mutex);
    const Nanos now = feed_->clock->now();
    if (feed_->lastMessage < Nanos{0} || now - feed_->lastMessage > kOscTrackerSilence) {
      return fail(Errc::kUnavailable,
                  fmt::format("no /tracker/{} message within {} s; the sender is not sending", feed_->name,
                              toSeconds(kOscTrackerSilence)),
                  info().path);
    }
    feed_->live = this;
    return {};
  }
  void doClose() override { detach(); }
  void doService(Nanos now) override {
    std::lock_guard lock(feed_->mutex);
    if (feed_->live == this && now - feed_->lastMessage > kOscTrackerSilence) {
      reportLost(Error(Errc::kDeviceLost,
                       fmt::format("no /tracker/{} message for {} s", feed_->name, toSeconds(kOscTrackerSilence))));
    }
  }
  void detach() {
    std::lock_guard lock(feed_->mutex);
    if (feed_->live == this) feed_->live = nullptr;
  }

  std::shared_ptr<OscTrackerFeeds::Feed> feed_;
};

devices::DeviceInfo infoFor(const std::string& name) {
  devices::DeviceInfo info;
  info.name = name;
  info.backend = "osc";
  info.bus = "network";
  info.path = OscTrackerFeeds::pathFor(name);
  return info;
}

class OscTrackerProvider final : public devices::DeviceProvider {
 public:
  explicit OscTrackerProvider(std::vector<std::shared_ptr<OscTrackerFeeds::Feed>> feeds) : feeds_(std::move(feeds)) {}
  [[nodiscard]] std::string_view backend() const override { return "osc"; }
  std::vector<devices::DeviceCandidate> enumerate() override {
    std::vector<devices::DeviceCandidate> out;
    for (const auto& feed : feeds_) {
      devices::DeviceCandidate c;
      c.info = infoFor(feed->name);
      c.kind = devices::DeviceKind::kTracker;
      c.usage = fmt::format("a tracker fed by OSC messages to /tracker/{}", feed->name);
      out.push_back(std::move(c));
    }
    return out;
  }
  Result<std::unique_ptr<devices::Tracker>> openTracker(const devices::DeviceCandidate& candidate,
                                                        const devices::DeviceRequest& request,
                                                        const Clock& clock) override {
    (void)request;
    (void)clock;
    for (const auto& feed : feeds_) {
      if (OscTrackerFeeds::pathFor(feed->name) == candidate.info.path) {
        return std::unique_ptr<devices::Tracker>(std::make_unique<OscTracker>(candidate.info, feed));
      }
    }
    return fail(Errc::kNotFound, "no such OSC tracker", candidate.info.path);
  }

 private:
  std::vector<std::shared_ptr<OscTrackerFeeds::Feed>> feeds_;
};

/// The numbers of `m`, when it has exactly `count` and all are numbers.
std::optional<std::array<float, 6>> numbers(const OscMessage& m, std::size_t count) {
  if (m.arguments.size() != count) return std::nullopt;
  std::array<float, 6> out{};
  for (std::size_t i = 0; i < count; ++i) {
    if (!m.arguments[i].isNumber()) return std::nullopt;
    out.at(i) = static_cast<float>(m.arguments[i].number);
  }
  return out;
}

}  // namespace

OscTrackerFeeds::OscTrackerFeeds(const std::vector<std::string>& names, const Clock& clock) : clock_(clock) {
  for (const std::string& name : names) {
    auto feed = std::make_shared<Feed>();
    feed->name = name;
    feed->clock = &clock_;
    feeds_.emplace(name, std::move(feed));
  }
}

std::string OscTrackerFeeds::pathFor(const std::string& name) { return "osc:/tracker/" + name; }

std::string OscTrackerFeeds::nameOf(const DeviceSpec& spec) {
  return spec.match.name.empty() ? spec.name : spec.match.name;
}

std::vector<std::string> OscTrackerFeeds::namesIn(const Manifest& show) {
  std::vector<std::string> names;
  for (const DeviceSpec& d : show.devices) {
    if (d.kind == DeviceKind::kTracker && d.backend == DeviceBackend::kOsc) names.push_back(nameOf(d));
  }
  return names;
}

DeviceSource OscTrackerFeeds::sourceFor(const DeviceSpec& spec) const {
  DeviceSource source;
  source.provider = provider();
  source.request.name = spec.name;
  source.request.kind = devices::DeviceKind::kTracker;
  source.request.match.backend = "osc";
  source.request.match.path = pathFor(nameOf(spec));
  return source;
}

std::unique_ptr<devices::DeviceProvider> OscTrackerFeeds::provider() const {
  std::vector<std::shared_ptr<Feed>> feeds;
  feeds.reserve(feeds_.size());
  for (const auto& [name, feed] : feeds_) feeds.push_back(feed);
  return std::make_unique<OscTrackerProvider>(std::move(feeds));
}

bool OscTrackerFeeds::take(const OscMessage& message) {
  std::string_view rest = message.address;
  if (!rest.starts_with(kOscTrackerPrefix)) return false;
  rest.remove_prefix(kOscTrackerPrefix.size());
  std::string_view part;
  if (const std::size_t slash = rest.find('/'); slash != std::string_view::npos) {
    part = rest.substr(slash + 1);
    rest = rest.substr(0, slash);
  }
  const auto it = feeds_.find(rest);
  if (it == feeds_.end()) return false;
  std::optional<std::array<float, 6>> position;
  std::optional<std::array<float, 6>> rotation;
  if (part.empty()) {
    if (auto six = numbers(message, 6)) {
      position = six;
      rotation = std::array<float, 6>{(*six)[3], (*six)[4], (*six)[5]};
    } else {
      position = numbers(message, 3);
    }
    if (!position) return false;
  } else if (part == "position") {
    position = numbers(message, 3);
    if (!position) return false;
  } else if (part == "rotation") {
    rotation = numbers(message, 3);
    if (!rotation) return false;
  } else {
    return false;
  }
  Feed& feed = *it->second;
  std::lock_guard lock(feed.mutex);
  feed.lastMessage = clock_.now();
  if (position) feed.sample.position = {(*position)[0], (*position)[1], (*position)[2]};
  if (rotation) feed.sample.rotation = {(*rotation)[0], (*rotation)[1], (*rotation)[2]};
  feed.sample.time = feed.lastMessage;
  if (feed.live) static_cast<OscTracker*>(feed.live)->deliver(feed.sample);
  return true;
}

}  // namespace basalt::kiosk
