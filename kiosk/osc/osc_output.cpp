// The OSC output on liblo's clients (lo_address over UDP or TCP, lo_send_message). Messages, with
// PREFIX from [[osc.send]] prefix (default /basalt):
//   PREFIX/item   ,sii  name, 1-based place in its list, items in the list   when an item starts
//   PREFIX/device ,ss   name, state ("live", "lost", "absent", ...)         when a state changes
//   PREFIX/lock   ,si   "leader"/"following"/"holding"/"waiting", followers  when it changes
//   PREFIX/NAME   ,f or ,i  one figure of kOscFigureNames                   every 1/rate s
// The news is sent once at the start too, so that a controller that starts first knows the node.

#include "kiosk/osc/osc_output.h"

#include <lo/lo.h>

#include <algorithm>
#include <chrono>
#include <limits>
#include <map>

#include <fmt/format.h>

#include "kiosk/osc/osc_message.h"
#include "runtime/clock.h"
#include "runtime/log.h"

namespace basalt::kiosk {

namespace {

constexpr std::chrono::milliseconds kPoll{50};

struct AddressFree {
  void operator()(lo_address a) const { lo_address_free(a); }
};
using AddressPtr = std::unique_ptr<std::remove_pointer_t<lo_address>, AddressFree>;
struct MessageFree {
  void operator()(lo_message m) const { lo_message_free(m); }
};
using MessagePtr = std::unique_ptr<std::remove_pointer_t<lo_message>, MessageFree>;

std::int32_t int32(std::int64_t v) {
  return static_cast<std::int32_t>(
      std::clamp<std::int64_t>(v, std::numeric_limits<std::int32_t>::min(), std::numeric_limits<std::int32_t>::max()));
}

}  // namespace

std::string_view oscLockState(const FrameLockFigures& l) {
  if (l.leader) return "leader";
  if (l.holding) return "holding";
  return l.leaderPresent ? "following" : "waiting";
}

struct OscOutput::Destination {
  OscSendSpec spec;
  AddressPtr address;
  Nanos nextFigures{0};
  std::uint64_t sent = 0;
  std::uint64_t failed = 0;
  bool failing = false;  // logged once per spell of failures

  void send(const std::string& name, const MessagePtr& m) {
    const std::string path = spec.prefix + "/" + name;
    if (lo_send_message(address.get(), path.c_str(), m.get()) >= 0) {
      ++sent;
      if (failing) {
        log::info(kLogOsc, "OSC to {}:{} is sent again", spec.host, spec.port);
        failing = false;
      }
      return;
    }
    ++failed;
    if (!failing) {
      failing = true;
      log::warn(kLogOsc, "OSC to {}:{} ({}) cannot be sent: {}; counted, and said again when it can", spec.host,
                spec.port, spec.tcp ? "tcp" : "udp", lo_address_errstr(address.get()));
    }
  }
};

OscOutput::OscOutput(StatusBoard& board) : board_(board) {}

Result<std::unique_ptr<OscOutput>> OscOutput::start(const std::vector<OscSendSpec>& destinations, StatusBoard& board) {
  std::unique_ptr<OscOutput> out(new OscOutput(board));
  for (const OscSendSpec& spec : destinations) {
    auto d = std::make_unique<Destination>();
    d->spec = spec;
    const std::string port = std::to_string(spec.port);
    d->address.reset(lo_address_new_with_proto(spec.tcp ? LO_TCP : LO_UDP, spec.host.c_str(), port.c_str()));
    if (!d->address) {
      return fail(Errc::kInvalidArgument, fmt::format("OSC: cannot send to {}:{}", spec.host, spec.port));
    }
    out->destinations_.push_back(std::move(d));
  }
  out->thread_ = std::thread([self = out.get()] { self->run(); });
  return out;
}

OscOutput::~OscOutput() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void OscOutput::run() {
  SystemClock clock;
  std::string item;
  std::size_t index = 0;
  bool first = true;
  std::map<std::string, std::string> devices;
  std::string lock;
  std::int64_t followers = -1;
  for (;;) {
    {
      std::unique_lock l(mutex_);
      if (!first && wake_.wait_for(l, kPoll, [this] { return stopping_; })) return;
      if (stopping_) return;
    }
    const ShowStatus show = board_.showStatus();
    if (first || show.item != item || show.index != index) {
      item = show.item;
      index = show.index;
      if (!item.empty()) {
        for (auto& d : destinations_) {
          if (!d->spec.item) continue;
          MessagePtr m(lo_message_new());
          lo_message_add_string(m.get(), item.c_str());
          lo_message_add_int32(m.get(), int32(static_cast<std::int64_t>(show.index)));
          lo_message_add_int32(m.get(), int32(static_cast<std::int64_t>(show.count)));
          d->send("item", m);
        }
      }
    }
    for (const DeviceStatus& device : board_.deviceStatus()) {
      auto [it, added] = devices.try_emplace(device.name, device.state);
      if (!added && it->second == device.state) continue;
      it->second = device.state;
      for (auto& d : destinations_) {
        if (!d->spec.devices) continue;
        MessagePtr m(lo_message_new());
        lo_message_add_string(m.get(), device.name.c_str());
        lo_message_add_string(m.get(), device.state.c_str());
        d->send("device", m);
      }
    }
    if (const auto figures = board_.lockFigures()) {
      const std::string_view state = oscLockState(*figures);
      const std::int64_t n = figures->leader ? figures->followers : 0;
      if (state != lock || n != followers) {
        lock = std::string(state);
        followers = n;
        for (auto& d : destinations_) {
          if (!d->spec.lock) continue;
          MessagePtr m(lo_message_new());
          lo_message_add_string(m.get(), lock.c_str());
          lo_message_add_int32(m.get(), int32(n));
          d->send("lock", m);
        }
      }
    }
    const Nanos now = clock.now();
    std::optional<FrameFigures> frames;
    for (auto& d : destinations_) {
      if (d->spec.figures.empty() || now < d->nextFigures) continue;
      // The next time from the last, so that the rate holds on average whatever the poll's jitter.
      const Nanos period = fromSeconds(1.0 / d->spec.rate);
      d->nextFigures =
          d->nextFigures.count() == 0 || now - d->nextFigures > period ? now + period : d->nextFigures + period;
      if (!frames) frames = board_.frameFigures();
      for (const std::string& name : d->spec.figures) {
        MessagePtr m(lo_message_new());
        if (name == "fps") {
          lo_message_add_float(m.get(), static_cast<float>(frames->framesPerSecond));
        } else if (name == "frames") {
          lo_message_add_int32(m.get(), int32(frames->frames));
        } else if (name == "late_frames") {
          lo_message_add_int32(m.get(), int32(frames->lateFrames));
        } else if (name == "dropped_frames") {
          lo_message_add_int32(m.get(), int32(frames->droppedFrames));
        } else if (name == "input_dropped") {
          lo_message_add_int32(m.get(), int32(static_cast<std::int64_t>(frames->inputDropped)));
        } else if (name == "work_ms") {
          lo_message_add_float(m.get(), static_cast<float>(frames->workMean * 1e3));
        } else if (name == "frame_ms") {
          lo_message_add_float(m.get(), static_cast<float>(frames->intervalP50 * 1e3));
        } else if (name == "osc_refused") {
          const auto osc = board_.oscFigures();
          lo_message_add_int32(m.get(), int32(osc ? static_cast<std::int64_t>(osc->refused()) : 0));
        } else {
          continue;  // the manifest allows only the names above
        }
        d->send(name, m);
      }
    }
    first = false;
    std::uint64_t sent = 0;
    std::uint64_t failed = 0;
    for (const auto& d : destinations_) {
      sent += d->sent;
      failed += d->failed;
    }
    board_.publishOscSent(sent, failed);
  }
}

}  // namespace basalt::kiosk
