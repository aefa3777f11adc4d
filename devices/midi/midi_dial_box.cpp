// MIDI controllers as dial boxes, through ALSA's sequencer.
//
// Hardware: any port on the ALSA sequencer that other clients may read: USB class-compliant
// controllers (the kernel's snd-usb-audio makes a sequencer client per card), snd-virmidi ports
// written through rawmidi, and virtual ports of other programs. Controls are mapped by profile
// (devices/midi/midi_decoder.h; chosen by the client and port name or the request's `profile`).
// Feedback (LED rings, button lights, motor faders) is sent to the client's port of the same
// number when it is writable. Limits: system exclusive messages are ignored; a message is
// stamped when Basalt reads it (the sequencer's own timestamps are not used); reads poll every
// 100 ms for close().
//
// Configuration: DeviceRequest options (midi_backend.h); the port by `match.name` (a substring of
// "CLIENT: PORT") or `match.path` (`seq:CLIENT:PORT`).

#include <alsa/asoundlib.h>
#include <poll.h>
#include <unistd.h>

#include <atomic>
#include <charconv>
#include <mutex>
#include <thread>

#include <fmt/format.h>

#include "devices/midi/midi_backend.h"
#include "devices/midi/midi_decoder.h"

namespace basalt::devices {

namespace {

using namespace std::chrono_literals;

struct SeqCloser {
  void operator()(snd_seq_t* s) const { snd_seq_close(s); }
};
using SeqPtr = std::unique_ptr<snd_seq_t, SeqCloser>;
struct MidiEventCloser {
  void operator()(snd_midi_event_t* m) const { snd_midi_event_free(m); }
};
using MidiEventPtr = std::unique_ptr<snd_midi_event_t, MidiEventCloser>;

std::string alsaError(int err) { return snd_strerror(err); }

Result<SeqPtr> openSeq(const char* clientName, int mode) {
  // Without the kernel's sequencer, libasound would print its own error on stderr for every
  // enumeration; its error handler is the process's (GStreamer's alsasink shares it), so it is
  // not silenced: the node is looked for first.
  if (::access("/dev/snd/seq", F_OK) != 0) {
    return fail(Errc::kUnavailable, "cannot open the ALSA sequencer: no /dev/snd/seq (is snd-seq loaded?)");
  }
  snd_seq_t* raw = nullptr;
  const int err = snd_seq_open(&raw, "default", SND_SEQ_OPEN_DUPLEX, mode);
  if (err < 0) {
    return fail(Errc::kUnavailable,
                fmt::format("cannot open the ALSA sequencer: {} (is snd-seq loaded? /dev/snd/seq)", alsaError(err)));
  }
  SeqPtr seq(raw);
  snd_seq_set_client_name(seq.get(), clientName);
  return seq;
}

Result<MidiEventPtr> makeCodec() {
  snd_midi_event_t* raw = nullptr;
  if (const int err = snd_midi_event_new(64, &raw); err < 0) {
    return fail(Errc::kResourceExhausted, fmt::format("snd_midi_event_new: {}", alsaError(err)));
  }
  MidiEventPtr codec(raw);
  snd_midi_event_no_status(codec.get(), 1);  // every decoded message with its status byte
  return codec;
}

std::string seqAddress(int client, int port) { return fmt::format("seq:{}:{}", client, port); }

bool parseSeqAddress(std::string_view text, int& client, int& port) {
  if (!text.starts_with("seq:")) return false;
  const std::string s(text.substr(4));
  const auto colon = s.find(':');
  if (colon == std::string::npos) return false;
  const char* begin = s.c_str();
  const char* end = begin + s.size();
  const auto a = std::from_chars(begin, begin + colon, client);
  const auto b = std::from_chars(begin + colon + 1, end, port);
  return a.ec == std::errc{} && b.ec == std::errc{} && a.ptr == begin + colon && b.ptr == end;
}

struct PortEntry {
  DeviceInfo info;
  int client = 0;
  int port = 0;
};

/// Every readable, subscribable port but the system's and `self`'s.
std::vector<PortEntry> listPorts(snd_seq_t* seq) {
  std::vector<PortEntry> out;
  snd_seq_client_info_t* cinfo = nullptr;
  snd_seq_port_info_t* pinfo = nullptr;
  snd_seq_client_info_alloca(&cinfo);
  snd_seq_port_info_alloca(&pinfo);
  const int self = snd_seq_client_id(seq);
  snd_seq_client_info_set_client(cinfo, -1);
  while (snd_seq_query_next_client(seq, cinfo) >= 0) {
    const int client = snd_seq_client_info_get_client(cinfo);
    if (client == SND_SEQ_CLIENT_SYSTEM || client == self) continue;
    snd_seq_port_info_set_client(pinfo, client);
    snd_seq_port_info_set_port(pinfo, -1);
    while (snd_seq_query_next_port(seq, pinfo) >= 0) {
      const unsigned caps = snd_seq_port_info_get_capability(pinfo);
      if ((caps & (SND_SEQ_PORT_CAP_READ | SND_SEQ_PORT_CAP_SUBS_READ)) !=
              (SND_SEQ_PORT_CAP_READ | SND_SEQ_PORT_CAP_SUBS_READ) ||
          (caps & SND_SEQ_PORT_CAP_NO_EXPORT) != 0) {
        continue;
      }
      PortEntry e;
      e.client = client;
      e.port = snd_seq_port_info_get_port(pinfo);
      e.info.name = fmt::format("{}: {}", snd_seq_client_info_get_name(cinfo), snd_seq_port_info_get_name(pinfo));
      e.info.backend = "midi";
      e.info.bus = snd_seq_client_info_get_card(cinfo) >= 0 ? "usb" : "virtual";
      e.info.path = seqAddress(e.client, e.port);
      out.push_back(std::move(e));
    }
  }
  return out;
}

/// A MIDI controller on the sequencer: a client of Basalt's own subscribed to the controller's
/// port and to the announce port (so that the port's exit is a loss), read on a thread.
class MidiDialBox final : public DialBox {
 public:
  MidiDialBox(DeviceInfo info, const MidiProfile& profile, int client, int port, const Clock& clock)
      : DialBox(std::move(info), profile.dials, profile.buttons, true),
        decoder_(profile),
        client_(client),
        port_(port),
        clock_(clock) {
    setReportDescriptor(midiDescriptor(profile));
  }
  ~MidiDialBox() override { close(); }
  MidiDialBox(const MidiDialBox&) = delete;
  MidiDialBox& operator=(const MidiDialBox&) = delete;

 private:
  Result<void> doOpen() override {
    auto seq = openSeq("Basalt", SND_SEQ_NONBLOCK);
    if (!seq) return std::unexpected(seq.error());
    const int port = snd_seq_create_simple_port(
        seq->get(), "Basalt dial box",
        SND_SEQ_PORT_CAP_WRITE | SND_SEQ_PORT_CAP_SUBS_WRITE | SND_SEQ_PORT_CAP_READ | SND_SEQ_PORT_CAP_NO_EXPORT,
        SND_SEQ_PORT_TYPE_MIDI_GENERIC | SND_SEQ_PORT_TYPE_APPLICATION);
    if (port < 0) return fail(Errc::kUnavailable, fmt::format("cannot create a sequencer port: {}", alsaError(port)));
    snd_seq_port_info_t* pinfo = nullptr;
    snd_seq_port_info_alloca(&pinfo);
    if (snd_seq_get_any_port_info(seq->get(), client_, port_, pinfo) < 0) {
      return fail(Errc::kNotFound, fmt::format("MIDI port {} is gone", seqAddress(client_, port_)), info().path);
    }
    if (const int err = snd_seq_connect_from(seq->get(), port, client_, port_); err < 0) {
      return fail(err == -EPERM ? Errc::kPermissionDenied : Errc::kUnavailable,
                  fmt::format("cannot subscribe to MIDI port {}: {}", seqAddress(client_, port_), alsaError(err)),
                  info().path);
    }
    // The port's exit, announced by the system client, is the unplug.
    (void)snd_seq_connect_from(seq->get(), port, SND_SEQ_CLIENT_SYSTEM, SND_SEQ_PORT_SYSTEM_ANNOUNCE);
    // Feedback goes to the controller's port of the same number, when it takes input.
    const unsigned caps = snd_seq_port_info_get_capability(pinfo);
    feedback_ = (caps & (SND_SEQ_PORT_CAP_WRITE | SND_SEQ_PORT_CAP_SUBS_WRITE)) ==
                    (SND_SEQ_PORT_CAP_WRITE | SND_SEQ_PORT_CAP_SUBS_WRITE) &&
                snd_seq_connect_to(seq->get(), port, client_, port_) >= 0;
    auto in = makeCodec();
    auto out = makeCodec();
    if (!in || !out) return std::unexpected(in ? out.error() : in.error());
    seq_ = std::move(*seq);
    ownPort_ = port;
    in_ = std::move(*in);
    out_ = std::move(*out);
    decoder_.reset();
    stop_.store(false);
    reader_ = std::thread([this] { readLoop(); });
    return {};
  }

  void doClose() override {
    stop_.store(true);
    if (reader_.joinable()) reader_.join();
    std::lock_guard lock(sendMutex_);
    seq_.reset();  // deletes the port and its subscriptions
    in_.reset();
    out_.reset();
  }

  Result<void> doSetLight(int index, double level, bool pulse) override {
    const auto message = decoder_.lightMessage(index, level, pulse);
    if (!message) return fail(Errc::kUnsupported, fmt::format("{} has no light {}", info().name, index));
    send(message->span());
    return {};
  }

  void send(std::span<const std::uint8_t> bytes) {
    std::lock_guard lock(sendMutex_);
    if (!seq_ || !feedback_) return;
    snd_seq_event_t ev;
    snd_seq_ev_clear(&ev);
    snd_midi_event_reset_encode(out_.get());
    if (snd_midi_event_encode(out_.get(), bytes.data(), static_cast<long>(bytes.size()), &ev) <= 0 ||
        ev.type == SND_SEQ_EVENT_NONE) {
      return;
    }
    snd_seq_ev_set_source(&ev, static_cast<unsigned char>(ownPort_));
    snd_seq_ev_set_subs(&ev);
    snd_seq_ev_set_direct(&ev);
    (void)snd_seq_event_output_direct(seq_.get(), &ev);
  }

  void readLoop() {
    const int count = snd_seq_poll_descriptors_count(seq_.get(), POLLIN);
    std::vector<pollfd> fds(static_cast<std::size_t>(std::max(count, 1)));
    snd_seq_poll_descriptors(seq_.get(), fds.data(), static_cast<unsigned>(fds.size()), POLLIN);
    std::array<Event, MidiDecoder::kMaxEventsPerMessage> events{};
    std::vector<MidiDecoder::Message> feedback;
    std::array<unsigned char, 16> bytes{};
    while (!stop_.load()) {
      if (::poll(fds.data(), fds.size(), 100) <= 0) continue;
      snd_seq_event_t* ev = nullptr;
      int err = 0;
      while ((err = snd_seq_event_input(seq_.get(), &ev)) >= 0 && ev) {
        if (ev->type == SND_SEQ_EVENT_PORT_EXIT || ev->type == SND_SEQ_EVENT_CLIENT_EXIT) {
          const bool ours =
              ev->data.addr.client == client_ && (ev->type == SND_SEQ_EVENT_CLIENT_EXIT || ev->data.addr.port == port_);
          if (ours) {
            reportLost(Error{Errc::kDeviceLost, "the MIDI port went away (unplugged?)", info().path});
            return;
          }
          continue;
        }
        if (ev->source.client != client_ || ev->source.port != port_) continue;
        snd_midi_event_reset_decode(in_.get());
        const long n = snd_midi_event_decode(in_.get(), bytes.data(), static_cast<long>(bytes.size()), ev);
        if (n <= 0 || bytes[0] == 0xf0) continue;
        const std::span<const std::uint8_t> message(bytes.data(), static_cast<std::size_t>(n));
        const Nanos now = clock_.now();
        tapReport(now, message);
        const std::size_t made = decoder_.decode(message, events);
        for (std::size_t i = 0; i < made; ++i) {
          events[i].time = now;
          emit(events[i]);
        }
        feedback.clear();
        decoder_.feedbackFor(std::span<const Event>(events.data(), made), feedback);
        for (const MidiDecoder::Message& m : feedback) send(m.span());
      }
      if (err == -ENOSPC) continue;  // the input buffer overran: events were lost, go on reading
    }
  }

  MidiDecoder decoder_;  // the reader's; lightMessage() reads only the profile
  int client_;
  int port_;
  const Clock& clock_;
  SeqPtr seq_;  // opened in doOpen(), closed in doClose() after the reader is joined
  int ownPort_ = -1;
  bool feedback_ = false;
  MidiEventPtr in_;       // the reader's
  MidiEventPtr out_;      // guarded by sendMutex_
  std::mutex sendMutex_;  // guards output on seq_ (reader's feedback and setLight())
  std::atomic<bool> stop_{false};
  std::thread reader_;
};

}  // namespace

struct MidiProvider::Watcher {
  SeqPtr seq;
  std::atomic<bool> stop{false};
  std::thread thread;
  ~Watcher() {
    stop.store(true);
    if (thread.joinable()) thread.join();
  }
};

MidiProvider::MidiProvider() = default;
MidiProvider::~MidiProvider() = default;

std::vector<DeviceCandidate> MidiProvider::enumerate() {
  std::vector<DeviceCandidate> out;
  auto seq = openSeq("Basalt enumerate", SND_SEQ_NONBLOCK);
  if (!seq) return out;  // no sequencer: no MIDI devices
  for (PortEntry& e : listPorts(seq->get())) {
    DeviceCandidate c;
    c.info = std::move(e.info);
    c.kind = DeviceKind::kDialBox;
    const MidiProfile profile = midiProfileForPort(c.info.name);
    c.usage = fmt::format("{} (profile {}): {}", profile.title, profile.name, profile.shape());
    out.push_back(std::move(c));
  }
  return out;
}

Result<std::unique_ptr<DialBox>> MidiProvider::openDialBox(const DeviceCandidate& candidate,
                                                           const DeviceRequest& request, const Clock& clock) {
  int client = 0;
  int port = 0;
  if (!parseSeqAddress(candidate.info.path, client, port)) {
    return fail(Errc::kInvalidArgument,
                fmt::format("'{}' is not a sequencer port (seq:CLIENT:PORT)", candidate.info.path));
  }
  auto profile = midiProfileFromOptions(candidate.info.name, request.options);
  if (!profile) return std::unexpected(profile.error());
  DeviceInfo info = candidate.info;
  return std::unique_ptr<DialBox>(
      std::make_unique<MidiDialBox>(std::move(info), std::move(*profile), client, port, clock));
}

void MidiProvider::watchHotplug(const std::function<void(HotplugEvent)>& notify) {
  auto seq = openSeq("Basalt hotplug", SND_SEQ_NONBLOCK);
  if (!seq) return;  // no sequencer: nothing to watch
  const int port = snd_seq_create_simple_port(
      seq->get(), "announce", SND_SEQ_PORT_CAP_WRITE | SND_SEQ_PORT_CAP_NO_EXPORT, SND_SEQ_PORT_TYPE_APPLICATION);
  if (port < 0 || snd_seq_connect_from(seq->get(), port, SND_SEQ_CLIENT_SYSTEM, SND_SEQ_PORT_SYSTEM_ANNOUNCE) < 0)
    return;
  watcher_ = std::make_unique<Watcher>();
  watcher_->seq = std::move(*seq);
  Watcher* w = watcher_.get();
  w->thread = std::thread([w, notify] {
    std::vector<pollfd> fds(
        static_cast<std::size_t>(std::max(snd_seq_poll_descriptors_count(w->seq.get(), POLLIN), 1)));
    snd_seq_poll_descriptors(w->seq.get(), fds.data(), static_cast<unsigned>(fds.size()), POLLIN);
    while (!w->stop.load()) {
      if (::poll(fds.data(), fds.size(), 100) <= 0) continue;
      snd_seq_event_t* ev = nullptr;
      while (snd_seq_event_input(w->seq.get(), &ev) >= 0 && ev) {
        if (ev->type == SND_SEQ_EVENT_PORT_START || ev->type == SND_SEQ_EVENT_PORT_EXIT) {
          notify(HotplugEvent{
              ev->type == SND_SEQ_EVENT_PORT_START ? HotplugEvent::Action::kAdded : HotplugEvent::Action::kRemoved,
              "midi", seqAddress(ev->data.addr.client, ev->data.addr.port)});
        }
      }
    }
  });
}

Result<std::unique_ptr<DialBox>> openMidiDialBox(const std::string& address,
                                                 const std::map<std::string, std::string>& options,
                                                 const Clock& clock) {
  MidiProvider provider;
  for (const DeviceCandidate& c : provider.enumerate()) {
    if (c.info.path == address || (!address.starts_with("seq:") && c.info.name.find(address) != std::string::npos)) {
      DeviceRequest request;
      request.options = options;
      return provider.openDialBox(c, request, clock);
    }
  }
  return fail(Errc::kNotFound, fmt::format("no MIDI port '{}' on the sequencer (aconnect -l lists them)", address));
}

struct VirtualMidiPort::Impl {
  SeqPtr seq;
  MidiEventPtr codec;
  MidiEventPtr decoder;
  int port = -1;
};

VirtualMidiPort::VirtualMidiPort(std::unique_ptr<Impl> impl, std::string address)
    : impl_(std::move(impl)), address_(std::move(address)) {}
VirtualMidiPort::~VirtualMidiPort() = default;

Result<std::unique_ptr<VirtualMidiPort>> VirtualMidiPort::create(const std::string& name) {
  auto seq = openSeq(name.c_str(), SND_SEQ_NONBLOCK);
  if (!seq) return std::unexpected(seq.error());
  const int port = snd_seq_create_simple_port(
      seq->get(), name.c_str(),
      SND_SEQ_PORT_CAP_READ | SND_SEQ_PORT_CAP_SUBS_READ | SND_SEQ_PORT_CAP_WRITE | SND_SEQ_PORT_CAP_SUBS_WRITE,
      SND_SEQ_PORT_TYPE_MIDI_GENERIC | SND_SEQ_PORT_TYPE_APPLICATION);
  if (port < 0) return fail(Errc::kUnavailable, fmt::format("cannot create a sequencer port: {}", alsaError(port)));
  auto codec = makeCodec();
  auto decoder = makeCodec();
  if (!codec || !decoder) return std::unexpected(codec ? decoder.error() : codec.error());
  auto impl = std::make_unique<Impl>();
  const std::string address = seqAddress(snd_seq_client_id(seq->get()), port);
  impl->seq = std::move(*seq);
  impl->codec = std::move(*codec);
  impl->decoder = std::move(*decoder);
  impl->port = port;
  return std::unique_ptr<VirtualMidiPort>(new VirtualMidiPort(std::move(impl), address));
}

Result<void> VirtualMidiPort::send(std::span<const std::uint8_t> message) {
  snd_seq_event_t ev;
  snd_seq_ev_clear(&ev);
  snd_midi_event_reset_encode(impl_->codec.get());
  if (snd_midi_event_encode(impl_->codec.get(), message.data(), static_cast<long>(message.size()), &ev) <= 0 ||
      ev.type == SND_SEQ_EVENT_NONE) {
    return fail(Errc::kInvalidArgument, "not a complete MIDI message");
  }
  snd_seq_ev_set_source(&ev, static_cast<unsigned char>(impl_->port));
  snd_seq_ev_set_subs(&ev);
  snd_seq_ev_set_direct(&ev);
  if (const int err = snd_seq_event_output_direct(impl_->seq.get(), &ev); err < 0) {
    return fail(Errc::kIo, fmt::format("sending to the sequencer: {}", alsaError(err)));
  }
  return {};
}

std::vector<std::vector<std::uint8_t>> VirtualMidiPort::received() {
  std::vector<std::vector<std::uint8_t>> out;
  snd_seq_event_t* ev = nullptr;
  std::array<unsigned char, 16> bytes{};
  while (snd_seq_event_input(impl_->seq.get(), &ev) >= 0 && ev) {
    snd_midi_event_reset_decode(impl_->decoder.get());
    const long n = snd_midi_event_decode(impl_->decoder.get(), bytes.data(), static_cast<long>(bytes.size()), ev);
    if (n > 0) out.emplace_back(bytes.begin(), bytes.begin() + n);
  }
  return out;
}

Result<void> VirtualMidiPort::listenTo(const std::string& address) {
  int client = 0;
  int port = 0;
  if (!parseSeqAddress(address, client, port)) return fail(Errc::kInvalidArgument, "not seq:CLIENT:PORT: " + address);
  if (const int err = snd_seq_connect_from(impl_->seq.get(), impl_->port, client, port); err < 0) {
    return fail(Errc::kUnavailable, fmt::format("cannot subscribe to {}: {}", address, alsaError(err)));
  }
  return {};
}

}  // namespace basalt::devices
