// GStreamer's network clock (libgstnet): GstNetTimeProvider answers time requests on a UDP port
// with the provided clock's time; GstNetClientClock polls it and keeps a calibrated estimate,
// filtering out round trips that took long. Both are used as GStreamer documents them; the
// only Basalt part is that the served clock is the one SystemClock reads.

#include "media/net_clock.h"

#include <gst/gst.h>
#include <gst/net/net.h>

#include <fmt/format.h>

#include "media/gst_support.h"

namespace basalt::media {

namespace {
GstClock* asClock(void* p) { return static_cast<GstClock*>(p); }
}  // namespace

Result<std::unique_ptr<NetClockServer>> NetClockServer::start(const std::string& address, int port) {
  if (auto r = ensureGstreamer(); !r) return std::unexpected(r.error());
  GstPtr<GstClock> system(gst_system_clock_obtain());
  GstNetTimeProvider* provider = gst_net_time_provider_new(system.get(), address.c_str(), port);
  if (!provider) {
    return failf(Errc::kUnavailable,
                 "cannot serve the network clock on {}:{} (is the port taken, or the address not this node's?)",
                 address, port);
  }
  std::unique_ptr<NetClockServer> server(new NetClockServer());
  server->provider_ = provider;
  gint bound = 0;
  g_object_get(provider, "port", &bound, nullptr);
  server->port_ = bound;
  return server;
}

NetClockServer::~NetClockServer() {
  if (provider_) gst_object_unref(provider_);
}

Result<std::unique_ptr<NetClock>> NetClock::connect(const std::string& address, int port) {
  if (auto r = ensureGstreamer(); !r) return std::unexpected(r.error());
  GstClock* clock = gst_net_client_clock_new("basalt-lock", address.c_str(), port, 0);
  if (!clock) return failf(Errc::kUnavailable, "cannot follow the network clock at {}:{}", address, port);
  gst_object_ref_sink(clock);
  std::unique_ptr<NetClock> made(new NetClock());
  made->clock_ = clock;
  return made;
}

NetClock::~NetClock() {
  if (clock_) gst_object_unref(clock_);
}

Nanos NetClock::now() const { return fromGstTime(gst_clock_get_time(asClock(clock_))); }

WallTime NetClock::wallNow() const { return std::chrono::system_clock::now(); }

bool NetClock::waitForSync(Nanos timeout) const {
  return gst_clock_wait_for_sync(asClock(clock_), toGstTime(timeout)) != 0;
}

bool NetClock::synced() const { return gst_clock_is_synced(asClock(clock_)) != 0; }

Nanos NetClock::offset() const {
  const SystemClock own;
  const Nanos before = own.now();
  const Nanos shared = now();
  const Nanos after = own.now();
  return shared - (before + (after - before) / 2);
}

}  // namespace basalt::media
