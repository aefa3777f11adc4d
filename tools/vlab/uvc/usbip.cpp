// USB/IP for the virtual lab's emulated devices (see usbip.h): the URB protocol of
// Documentation/usb/usbip_protocol.rst as vhci_hcd speaks it after an attach through sysfs, and
// the attach and detach themselves (what `usbip attach` does once it has a connection).

#include "tools/vlab/uvc/usbip.h"

#include <fcntl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <fstream>
#include <sstream>
#include <vector>

#include <fmt/format.h>

namespace basalt::sim::vlab {
namespace usbip {

Command Command::parse(std::span<const std::uint8_t, kHeaderSize> b) {
  Command c;
  c.command = readBe32(b, 0);
  c.seqnum = readBe32(b, 4);
  c.devid = readBe32(b, 8);
  c.direction = readBe32(b, 12);
  c.ep = readBe32(b, 16);
  c.transferFlags = readBe32(b, 20);
  c.unlinkSeqnum = c.transferFlags;  // CMD_UNLINK puts unlink_seqnum where CMD_SUBMIT has the flags
  c.transferBufferLength = static_cast<std::int32_t>(readBe32(b, 24));
  c.startFrame = static_cast<std::int32_t>(readBe32(b, 28));
  c.numberOfPackets = static_cast<std::int32_t>(readBe32(b, 32));
  c.interval = static_cast<std::int32_t>(readBe32(b, 36));
  for (std::size_t i = 0; i < 8; ++i) c.setup[i] = b[40 + i];
  return c;
}

std::array<std::uint8_t, kHeaderSize> Command::bytes() const {
  std::array<std::uint8_t, kHeaderSize> b{};
  writeBe32(b, 0, command);
  writeBe32(b, 4, seqnum);
  writeBe32(b, 8, devid);
  writeBe32(b, 12, direction);
  writeBe32(b, 16, ep);
  if (command == kCmdUnlink) {
    writeBe32(b, 20, unlinkSeqnum);
    return b;
  }
  writeBe32(b, 20, transferFlags);
  writeBe32(b, 24, static_cast<std::uint32_t>(transferBufferLength));
  writeBe32(b, 28, static_cast<std::uint32_t>(startFrame));
  writeBe32(b, 32, static_cast<std::uint32_t>(numberOfPackets));
  writeBe32(b, 36, static_cast<std::uint32_t>(interval));
  for (std::size_t i = 0; i < 8; ++i) b[40 + i] = setup[i];
  return b;
}

std::array<std::uint8_t, kHeaderSize> retSubmit(std::uint32_t seqnum, std::int32_t status, std::uint32_t actualLength,
                                                std::int32_t numberOfPackets) {
  std::array<std::uint8_t, kHeaderSize> b{};
  writeBe32(b, 0, kRetSubmit);
  writeBe32(b, 4, seqnum);
  writeBe32(b, 20, static_cast<std::uint32_t>(status));
  writeBe32(b, 24, actualLength);
  writeBe32(b, 32, static_cast<std::uint32_t>(numberOfPackets));
  return b;
}

std::array<std::uint8_t, kHeaderSize> retUnlink(std::uint32_t seqnum, std::int32_t status) {
  std::array<std::uint8_t, kHeaderSize> b{};
  writeBe32(b, 0, kRetUnlink);
  writeBe32(b, 4, seqnum);
  writeBe32(b, 20, static_cast<std::uint32_t>(status));
  return b;
}

std::int32_t statusErrno(UsbStatus status) {
  switch (status) {
    case UsbStatus::kOk: return 0;
    case UsbStatus::kStall: return -EPIPE;
    case UsbStatus::kCancelled: return -ECONNRESET;
    case UsbStatus::kError: return -EPROTO;
  }
  return -EPROTO;
}

}  // namespace usbip

namespace {
constexpr std::int32_t kMaxTransfer = 16 * 1024 * 1024;
}

Result<std::size_t> UsbipLink::handleMessage(std::span<const std::uint8_t> buffered) {
  using namespace usbip;
  if (buffered.size() < kHeaderSize) return 0;
  const Command cmd = Command::parse(buffered.first<kHeaderSize>());
  if (cmd.command == kCmdUnlink) {
    const bool cancelled = cancelIn(cmd.unlinkSeqnum);
    auto sent = send(retUnlink(cmd.seqnum, cancelled ? -ECONNRESET : 0));
    if (!sent) return std::unexpected(sent.error());
    return kHeaderSize;
  }
  if (cmd.command != kCmdSubmit) return failf(Errc::kParse, "USB/IP: unknown command {:#x} from vhci_hcd", cmd.command);
  if (cmd.transferBufferLength < 0 || cmd.transferBufferLength > kMaxTransfer) {
    return failf(Errc::kParse, "USB/IP: transfer of {} bytes (seqnum {})", cmd.transferBufferLength, cmd.seqnum);
  }
  if (cmd.numberOfPackets > 0) {
    return failf(Errc::kParse, "USB/IP: isochronous transfer on endpoint {} (this device has none)", cmd.ep);
  }
  const auto length = static_cast<std::size_t>(cmd.transferBufferLength);
  const std::size_t outBytes = cmd.direction == kDirOut ? length : 0;
  if (buffered.size() < kHeaderSize + outBytes) return 0;
  const auto outData = buffered.subspan(kHeaderSize, outBytes);

  if (cmd.ep == 0) {
    const UsbSetup setup = UsbSetup::fromBytes(cmd.setup);
    const ControlReply reply = device_.control(setup, outData, now());
    const std::int32_t status = statusErrno(reply.status);
    std::span<const std::uint8_t> data;
    std::uint32_t actual = 0;
    if (setup.isIn()) {
      data = std::span<const std::uint8_t>(reply.data).first(std::min(reply.data.size(), length));
      actual = static_cast<std::uint32_t>(data.size());
    } else if (reply.status == UsbStatus::kOk) {
      actual = static_cast<std::uint32_t>(outBytes);
    }
    auto sent = send(retSubmit(cmd.seqnum, status, actual, cmd.numberOfPackets), data);
    if (!sent) return std::unexpected(sent.error());
  } else if (cmd.direction == kDirIn) {
    const PendingIn transfer{cmd.seqnum, static_cast<std::uint8_t>(0x80U | (cmd.ep & 0x0fU)),
                             static_cast<std::uint32_t>(length), static_cast<std::uint32_t>(cmd.numberOfPackets)};
    if (!queueIn(transfer)) {
      auto sent = send(retSubmit(cmd.seqnum, -ENOMEM, 0, cmd.numberOfPackets));
      if (!sent) return std::unexpected(sent.error());
    }
  } else {
    // No OUT endpoint but 0 on the lab's devices: the endpoint stalls.
    auto sent = send(retSubmit(cmd.seqnum, -EPIPE, 0, cmd.numberOfPackets));
    if (!sent) return std::unexpected(sent.error());
  }
  return kHeaderSize + outBytes;
}

Result<void> UsbipLink::sendCompletion(const PendingIn& transfer, UsbStatus status,
                                       std::span<const std::uint8_t> data) {
  return send(usbip::retSubmit(static_cast<std::uint32_t>(transfer.id), usbip::statusErrno(status),
                               static_cast<std::uint32_t>(data.size()), static_cast<std::int32_t>(transfer.extra)),
              data);
}

std::optional<int> freeVhciPort(const std::string& statusText, UsbSpeed speed) {
  const std::string wantedHub = speed == UsbSpeed::kSuper ? "ss" : "hs";
  std::istringstream lines(statusText);
  std::string line;
  std::getline(lines, line);  // the column names
  while (std::getline(lines, line)) {
    std::istringstream words(line);
    std::vector<std::string> w;
    for (std::string s; words >> s;) w.push_back(s);
    if (w.size() < 2) continue;
    std::size_t at = 0;
    if (w[0] == "hs" || w[0] == "ss") {
      if (w[0] != wantedHub || w.size() < 3) continue;
      at = 1;
    }
    // VDEV_ST_NULL (4): nothing attached.
    if (w[at + 1] != "004") continue;
    try {
      return std::stoi(w[at]);
    } catch (...) {
      continue;
    }
  }
  return std::nullopt;
}

Result<VhciAttachment> VhciAttachment::attach(UsbDevice& device, const Clock& clock,
                                              const std::filesystem::path& controller) {
  std::error_code ec;
  if (!std::filesystem::exists(controller / "attach", ec)) {
    return failf(Errc::kNotFound, "{} does not exist: vhci_hcd is not loaded (modprobe vhci-hcd)",
                 (controller / "attach").string());
  }
  std::ifstream statusFile(controller / "status");
  std::stringstream status;
  status << statusFile.rdbuf();
  const auto port = freeVhciPort(status.str(), device.identity().speed);
  if (!port) return failf(Errc::kResourceExhausted, "every port of {} is in use", controller.string());

  int sv[2] = {-1, -1};
  if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, sv) != 0) {
    return fail(Errc::kIo, systemErrorText("socketpair for USB/IP", errno));
  }
  UniqueFd ours(sv[0]);
  UniqueFd theirs(sv[1]);
  unsigned speed = 3;  // enum usb_device_speed: USB_SPEED_HIGH
  switch (device.identity().speed) {
    case UsbSpeed::kLow: speed = 1; break;
    case UsbSpeed::kFull: speed = 2; break;
    case UsbSpeed::kHigh: speed = 3; break;
    case UsbSpeed::kSuper: speed = 5; break;
  }
  // devid names the device in the requests; ours is "bus 1, device port + 2".
  const std::uint32_t devid = (1U << 16U) | static_cast<std::uint32_t>(*port + 2);
  const std::string line = fmt::format("{} {} {} {}", *port, theirs.get(), devid, speed);
  UniqueFd attachFile(::open((controller / "attach").c_str(), O_WRONLY | O_CLOEXEC));
  if (!attachFile) {
    const int e = errno;
    return fail(e == EACCES ? Errc::kPermissionDenied : Errc::kIo,
                systemErrorText("opening " + (controller / "attach").string(), e));
  }
  if (::write(attachFile.get(), line.data(), line.size()) != static_cast<ssize_t>(line.size())) {
    return failf(Errc::kUnavailable, "vhci_hcd refused to attach port {} (\"{}\"): {}", *port, line,
                 systemErrorText("write", errno));
  }
  // The kernel holds its own reference to its end of the pair now.
  auto link = std::make_unique<UsbipLink>(std::move(ours), device, clock);
  return VhciAttachment(std::move(link), *port, controller);
}

VhciAttachment::VhciAttachment(VhciAttachment&& other) noexcept
    : link_(std::move(other.link_)), port_(std::exchange(other.port_, -1)), controller_(std::move(other.controller_)) {}

VhciAttachment& VhciAttachment::operator=(VhciAttachment&& other) noexcept {
  if (this != &other) {
    detach();
    link_ = std::move(other.link_);
    port_ = std::exchange(other.port_, -1);
    controller_ = std::move(other.controller_);
  }
  return *this;
}

VhciAttachment::~VhciAttachment() { detach(); }

void VhciAttachment::detach() {
  if (port_ < 0) return;
  UniqueFd detachFile(::open((controller_ / "detach").c_str(), O_WRONLY | O_CLOEXEC));
  if (detachFile) {
    const std::string text = std::to_string(port_);
    // EINVAL: the kernel already let the port go (the link broke); nothing to do.
    [[maybe_unused]] const ssize_t n = ::write(detachFile.get(), text.data(), text.size());
  }
  port_ = -1;
}

}  // namespace basalt::sim::vlab
