// SGI dial and button box over a serial line.
//
// Hardware: the SGI dials box and button box, daisy-chained on one RS-232 port at 9600 baud, 8
// data bits, no parity, 1 stop bit; today usually through a USB serial adapter. Protocol (as
// VRPN's raw SGI box driver documents it): 0x20 resets both boxes, which answer 0x20; 0x50 xx FF
// enables the dials; 0x71 and 0x73 with FF FF FF FF enable and activate the buttons; 0x75 with
// four bytes sets the 32 button lights. Limits: the dials have no absolute position (only counts
// since the reset); lights are on/off.

#include "devices/serial/sgi_dial_box.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <filesystem>

#include <fmt/format.h>

namespace basalt::devices {

namespace {

/// Button index for a press or release byte, or -1.
int buttonOf(std::uint8_t b, bool& pressed) {
  static constexpr struct {
    std::uint8_t base;
    int first;
  } kBanks[] = {{0xd8, 0}, {0xd0, 8}, {0xc8, 16}, {0xc0, 24}};
  for (const auto& bank : kBanks) {
    if (b >= bank.base && b < bank.base + 8) {
      pressed = true;
      return bank.first + (b - bank.base);
    }
    const auto release = static_cast<std::uint8_t>(bank.base + 0x20);
    if (b >= release && b < release + 8) {
      pressed = false;
      return bank.first + (b - release);
    }
  }
  return -1;
}

bool writeAll(int fd, std::span<const std::uint8_t> bytes) {
  std::size_t done = 0;
  for (int tries = 0; done < bytes.size() && tries < 100; ++tries) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
    } else if (n < 0 && errno != EAGAIN && errno != EINTR) {
      return false;
    } else {
      pollfd p{fd, POLLOUT, 0};
      ::poll(&p, 1, 10);
    }
  }
  return done == bytes.size();
}

}  // namespace

std::size_t SgiBoxDecoder::feed(std::span<const std::uint8_t> bytes, std::span<Event> out) {
  std::size_t n = 0;
  for (std::uint8_t b : bytes) {
    if (have_ > 0) {
      pending_[have_++] = b;
      if (have_ == 3) {
        have_ = 0;
        const int dial = pending_[0] - 0x30;
        const auto value = static_cast<std::uint16_t>(pending_[1] << 8 | pending_[2]);
        const auto delta =
            static_cast<std::int16_t>(static_cast<std::uint16_t>(value - counts_[static_cast<std::size_t>(dial)]));
        counts_[static_cast<std::size_t>(dial)] = value;
        if (delta != 0 && n < out.size()) {
          out[n++] =
              Event{Nanos{0}, 0, EventKind::kDialDelta, static_cast<std::uint16_t>(dial), delta / kSgiCountsPerTurn};
        }
      }
      continue;
    }
    if (b >= 0x30 && b <= 0x37) {
      pending_[0] = b;
      have_ = 1;
      continue;
    }
    if (b == 0x20) {
      counts_.fill(0);  // the box answered a reset
      continue;
    }
    bool pressed = false;
    const int button = buttonOf(b, pressed);
    if (button < 0) {
      ++unknown_;
      continue;
    }
    if (n < out.size())
      out[n++] = Event{Nanos{0}, 0, EventKind::kButton, static_cast<std::uint16_t>(button), pressed ? 1.0 : 0.0};
  }
  return n;
}

void SgiBoxDecoder::reset() {
  counts_.fill(0);
  have_ = 0;
}

SgiDialBox::SgiDialBox(std::string path, const Clock& clock, Nanos resetTimeout)
    : DialBox(DeviceInfo{"SGI dial and button box", "serial", "rs232", 0, 0, path, ""}, 8, 32),
      path_(std::move(path)),
      clock_(clock),
      resetTimeout_(resetTimeout) {}

SgiDialBox::~SgiDialBox() { close(); }

Result<void> SgiDialBox::doOpen() {
  UniqueFd fd(::open(path_.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC));
  if (!fd) {
    const int e = errno;
    if (e == EACCES || e == EPERM) {
      return fail(Errc::kPermissionDenied,
                  systemErrorText("cannot open the serial port", e) +
                      "; add the user to the 'dialout' group or install configs/udev/70-basalt.rules",
                  path_);
    }
    return fail(e == ENOENT ? Errc::kNotFound : Errc::kIo, systemErrorText("cannot open the serial port", e), path_);
  }
  termios tio{};
  if (::tcgetattr(fd.get(), &tio) != 0) {
    return fail(Errc::kUnsupported, systemErrorText("not a serial port", errno), path_);
  }
  ::cfmakeraw(&tio);
  tio.c_cflag &= ~static_cast<tcflag_t>(CSTOPB | PARENB | CRTSCTS);
  tio.c_cflag |= CS8 | CLOCAL | CREAD;
  ::cfsetispeed(&tio, B9600);
  ::cfsetospeed(&tio, B9600);
  if (::tcsetattr(fd.get(), TCSANOW, &tio) != 0) {
    return fail(Errc::kIo, systemErrorText("cannot set 9600 8N1", errno), path_);
  }
  ::tcflush(fd.get(), TCIOFLUSH);
  const std::uint8_t reset[] = {0x20};
  if (!writeAll(fd.get(), reset)) return fail(Errc::kIo, systemErrorText("cannot write the reset", errno), path_);
  // Wait for the box to answer the reset: a port with nothing on it fails here, clearly.
  const Nanos deadline = clock_.now() + resetTimeout_;
  bool answered = false;
  while (!answered) {
    const Nanos left = deadline - clock_.now();
    if (left <= Nanos{0}) break;
    pollfd p{fd.get(), POLLIN, 0};
    const int ms = static_cast<int>(
        std::min<std::int64_t>(std::chrono::duration_cast<std::chrono::milliseconds>(left).count() + 1, 100));
    if (::poll(&p, 1, ms) < 0 && errno != EINTR) break;
    if (!(p.revents & POLLIN)) {
      if (p.revents & (POLLHUP | POLLERR)) break;
      if (clock_.isManual()) break;  // a manual clock never moves here: one poll period only
      continue;
    }
    std::uint8_t buf[64];
    const ssize_t n = ::read(fd.get(), buf, sizeof buf);
    for (ssize_t i = 0; i < n; ++i) answered = answered || buf[i] == 0x20;
    if (n <= 0 && errno != EAGAIN) break;
  }
  if (!answered) {
    return fail(Errc::kTimeout,
                fmt::format("no answer to the reset within {} ms; is the dial box connected and powered, and is "
                            "this its port?",
                            std::chrono::duration_cast<std::chrono::milliseconds>(resetTimeout_).count()),
                path_);
  }
  // Dials first: enabling the dials disables the buttons on some boxes.
  const std::uint8_t enableDials[] = {0x50, 0xff, 0xff};
  const std::uint8_t enableButtons[] = {0x71, 0xff, 0xff, 0xff, 0xff};
  const std::uint8_t activateButtons[] = {0x73, 0xff, 0xff, 0xff, 0xff};
  if (!writeAll(fd.get(), enableDials) || !writeAll(fd.get(), enableButtons) || !writeAll(fd.get(), activateButtons)) {
    return fail(Errc::kIo, systemErrorText("cannot enable the dials and buttons", errno), path_);
  }
  stopFd_.reset(::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK));
  if (!stopFd_) return fail(Errc::kResourceExhausted, systemErrorText("eventfd", errno), path_);
  fd_ = std::move(fd);
  reader_ = std::thread([this] { readLoop(); });
  return {};
}

void SgiDialBox::readLoop() {
  SgiBoxDecoder decoder;
  std::array<Event, 256> events;
  std::uint8_t buf[256];
  for (;;) {
    pollfd fds[2] = {{fd_.get(), POLLIN, 0}, {stopFd_.get(), POLLIN, 0}};
    if (::poll(fds, 2, -1) < 0) {
      if (errno == EINTR) continue;
      reportLost(Error(Errc::kIo, systemErrorText("poll", errno), path_));
      return;
    }
    if (fds[1].revents) return;
    if (fds[0].revents & (POLLHUP | POLLERR | POLLNVAL) && !(fds[0].revents & POLLIN)) {
      reportLost(Error(Errc::kDeviceLost, "the serial line hung up (adapter unplugged?)", path_));
      return;
    }
    const ssize_t n = ::read(fd_.get(), buf, sizeof buf);
    if (n < 0 && (errno == EAGAIN || errno == EINTR)) continue;
    if (n <= 0) {
      reportLost(Error(Errc::kDeviceLost,
                       n == 0 ? std::string("the serial line closed") : systemErrorText("read failed", errno), path_));
      return;
    }
    const Nanos now = clock_.now();
    const std::size_t count = decoder.feed(std::span(buf, static_cast<std::size_t>(n)), events);
    for (std::size_t i = 0; i < count; ++i) {
      events[i].time = now;
      emit(events[i]);
    }
  }
}

void SgiDialBox::doClose() {
  if (reader_.joinable()) {
    const std::uint64_t one = 1;
    (void)!::write(stopFd_.get(), &one, sizeof one);
    reader_.join();
  }
  fd_.reset();
  stopFd_.reset();
}

Result<void> SgiDialBox::doSetLight(int index, double level, bool) {
  if (index < 0 || index >= 32) return fail(Errc::kInvalidArgument, "the SGI box has lights 0-31", path_);
  std::uint32_t bits = lights_.load();
  bits = level > 0.5 ? (bits | (1u << index)) : (bits & ~(1u << index));
  lights_.store(bits);
  const std::uint8_t msg[] = {0x75, static_cast<std::uint8_t>(bits), static_cast<std::uint8_t>(bits >> 8),
                              static_cast<std::uint8_t>(bits >> 16), static_cast<std::uint8_t>(bits >> 24)};
  if (!writeAll(fd_.get(), msg)) return fail(Errc::kIo, systemErrorText("cannot set the lights", errno), path_);
  return {};
}

SerialProvider::SerialProvider(std::vector<std::string> ports) : ports_(std::move(ports)) {}

std::vector<DeviceCandidate> SerialProvider::enumerate() {
  std::vector<std::string> paths = ports_;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator("/dev", ec)) {
    const std::string name = entry.path().filename().string();
    if (name.starts_with("ttyUSB") || name.starts_with("ttyACM")) paths.push_back(entry.path().string());
  }
  std::vector<DeviceCandidate> out;
  for (const std::string& p : paths) {
    DeviceCandidate c;
    c.info = DeviceInfo{"SGI dial and button box", "serial", "rs232", 0, 0, p, ""};
    c.kind = DeviceKind::kDialBox;
    c.usage = "SGI dial and button box, if one answers: 8 dials, 32 buttons";
    if (::access(p.c_str(), R_OK | W_OK) != 0) {
      c.problem = systemErrorText("cannot open", errno) + "; add the user to 'dialout' (configs/udev/70-basalt.rules)";
    }
    out.push_back(std::move(c));
  }
  return out;
}

Result<std::unique_ptr<DialBox>> SerialProvider::openDialBox(const DeviceCandidate& candidate,
                                                             const DeviceRequest& request, const Clock& clock) {
  Nanos timeout = std::chrono::milliseconds(1000);
  if (auto it = request.options.find("reset_timeout_ms"); it != request.options.end()) {
    int ms = 0;
    const auto& s = it->second;
    if (std::from_chars(s.data(), s.data() + s.size(), ms).ec != std::errc{} || ms < 1 || ms > 60000) {
      return fail(Errc::kInvalidArgument, "reset_timeout_ms must be 1..60000", request.name);
    }
    timeout = std::chrono::milliseconds(ms);
  }
  return std::unique_ptr<DialBox>(std::make_unique<SgiDialBox>(candidate.info.path, clock, timeout));
}

}  // namespace basalt::devices
