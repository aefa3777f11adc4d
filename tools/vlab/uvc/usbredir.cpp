// usbredir for the virtual lab's emulated devices (see usbredir.h). The "usb-host" side of the
// usbredir protocol 0.7, which qemu's usb-redir device (the "usb-guest" side) connects a guest's
// USB controller to.

#include "tools/vlab/uvc/usbredir.h"

#include <algorithm>
#include <array>

#include <fmt/format.h>

namespace basalt::sim::vlab {
namespace usbredir {

std::uint8_t statusCode(UsbStatus status) {
  switch (status) {
    case UsbStatus::kOk: return kSuccess;
    case UsbStatus::kStall: return kStall;
    case UsbStatus::kCancelled: return kCancelled;
    case UsbStatus::kError: return kIoError;
  }
  return kIoError;
}

void appendHeader(std::vector<std::uint8_t>& out, const Header& h, bool ids64) {
  appendLe32(out, h.type);
  appendLe32(out, h.length);
  appendLe32(out, static_cast<std::uint32_t>(h.id));
  if (ids64) appendLe32(out, static_cast<std::uint32_t>(h.id >> 32U));
}

}  // namespace usbredir

namespace {
constexpr std::uint32_t kMaxPacket = 64 * 1024 * 1024;
constexpr std::size_t kControlHeader = 10;
constexpr char kVersion[] = "basalt-vlab-uvc-camera";

std::size_t endpointIndex(std::uint8_t address) { return (address & 0x0fU) | ((address & 0x80U) ? 0x10U : 0U); }
}  // namespace

Result<void> UsbredirLink::start() {
  std::vector<std::uint8_t> hello(64, 0);
  std::copy(std::begin(kVersion), std::end(kVersion), hello.begin());
  appendLe32(hello, usbredir::kOurCaps);
  return sendPacket(usbredir::kHello, 0, hello);
}

Result<void> UsbredirLink::sendPacket(std::uint32_t type, std::uint64_t id, std::span<const std::uint8_t> body,
                                      std::span<const std::uint8_t> data) {
  out_.clear();
  usbredir::appendHeader(out_, {type, static_cast<std::uint32_t>(body.size() + data.size()), id},
                         helloReceived_ && both(usbredir::kCap64BitIds));
  out_.insert(out_.end(), body.begin(), body.end());
  return send(out_, data);
}

Result<std::size_t> UsbredirLink::handleMessage(std::span<const std::uint8_t> buffered) {
  // The hello always has 32-bit ids; later packets have 64-bit ones when both sides can.
  const std::size_t size = helloReceived_ ? headerSize() : 12;
  if (buffered.size() < size) return 0;
  usbredir::Header h;
  h.type = readLe32(buffered, 0);
  h.length = readLe32(buffered, 4);
  h.id = size == 16 ? readLe64(buffered, 8) : readLe32(buffered, 8);
  if (h.length > kMaxPacket)
    return failf(Errc::kParse, "usbredir: packet of type {} claims {} bytes", h.type, h.length);
  if (buffered.size() < size + h.length) return 0;
  if (!helloReceived_ && h.type != usbredir::kHello) {
    return failf(Errc::kParse, "usbredir: packet of type {} before qemu's hello", h.type);
  }
  auto handled = handle(h, buffered.subspan(size, h.length));
  if (!handled) return std::unexpected(handled.error());
  return size + h.length;
}

Result<void> UsbredirLink::handle(const usbredir::Header& h, std::span<const std::uint8_t> body) {
  using namespace usbredir;
  auto status = [](const ControlReply& r) { return statusCode(r.status); };
  switch (h.type) {
    case kHello: {
      if (body.size() < 64) return fail(Errc::kParse, "usbredir: short hello");
      const auto version = body.first(64);
      peerVersion_.assign(version.begin(), std::find(version.begin(), version.end(), std::uint8_t{0}));
      peerCaps_ = body.size() >= 68 ? readLe32(body, 64) : 0;
      helloReceived_ = true;
      return announceDevice();
    }
    case kReset:
      device_.reset();
      drainPending(
          [this](const PendingIn& p) { [[maybe_unused]] auto r = sendCompletion(p, UsbStatus::kCancelled, {}); });
      return {};
    case kSetConfiguration: {
      if (body.empty()) return fail(Errc::kParse, "usbredir: short set_configuration");
      const ControlReply r = device_.control({0x00, 0x09, body[0], 0, 0}, {}, now());
      if (r.status == UsbStatus::kOk) {
        if (auto sent = sendEndpointsAndInterfaces(); !sent) return sent;
      }
      const std::array<std::uint8_t, 2> reply = {status(r), body[0]};
      return sendPacket(kConfigurationStatus, h.id, reply);
    }
    case kGetConfiguration: {
      const ControlReply r = device_.control({0x80, 0x08, 0, 0, 1}, {}, now());
      const std::array<std::uint8_t, 2> reply = {status(r), r.data.empty() ? std::uint8_t{0} : r.data[0]};
      return sendPacket(kConfigurationStatus, h.id, reply);
    }
    case kSetAltSetting: {
      if (body.size() < 2) return fail(Errc::kParse, "usbredir: short set_alt_setting");
      const ControlReply r = device_.control({0x01, 0x0b, body[1], body[0], 0}, {}, now());
      if (r.status == UsbStatus::kOk) {
        if (auto sent = sendEndpointsAndInterfaces(); !sent) return sent;
      }
      const std::array<std::uint8_t, 3> reply = {status(r), body[0], body[1]};
      return sendPacket(kAltSettingStatus, h.id, reply);
    }
    case kGetAltSetting: {
      if (body.empty()) return fail(Errc::kParse, "usbredir: short get_alt_setting");
      const ControlReply r = device_.control({0x81, 0x0a, 0, body[0], 1}, {}, now());
      const std::array<std::uint8_t, 3> reply = {status(r), body[0], r.data.empty() ? std::uint8_t{0xff} : r.data[0]};
      return sendPacket(kAltSettingStatus, h.id, reply);
    }
    case kStartIsoStream:
    case kStopIsoStream: {
      const std::array<std::uint8_t, 2> reply = {kInval, body.empty() ? std::uint8_t{0} : body[0]};
      return sendPacket(kIsoStreamStatus, h.id, reply);
    }
    case kStartInterruptReceiving:
    case kStopInterruptReceiving: {
      const std::array<std::uint8_t, 2> reply = {kInval, body.empty() ? std::uint8_t{0} : body[0]};
      return sendPacket(kInterruptReceivingStatus, h.id, reply);
    }
    case kAllocBulkStreams:
    case kFreeBulkStreams: {
      std::vector<std::uint8_t> reply;
      appendLe32(reply, body.size() >= 4 ? readLe32(body, 0) : 0);
      appendLe32(reply, 0);
      reply.push_back(kInval);
      return sendPacket(kBulkStreamsStatus, h.id, reply);
    }
    case kStartBulkReceiving:
    case kStopBulkReceiving: {
      std::vector<std::uint8_t> reply;
      appendLe32(reply, body.size() >= 4 ? readLe32(body, 0) : 0);
      reply.push_back(body.size() >= 9 && h.type == kStartBulkReceiving ? body[8] : (body.size() >= 5 ? body[4] : 0));
      reply.push_back(kInval);
      return sendPacket(kBulkReceivingStatus, h.id, reply);
    }
    case kCancelDataPacket: {
      PendingIn p;
      if (cancelIn(h.id, &p)) return sendCompletion(p, UsbStatus::kCancelled, {});
      return {};  // already completed: qemu has (or will have) its answer
    }
    case kFilterReject: return fail(Errc::kUnavailable, "qemu's usb-redir rejected the device (its filter refused it)");
    case kControlPacket: return handleControl(h, body);
    case kBulkPacket: return handleBulk(h, body);
    case kInterruptPacket: {
      // An interrupt OUT transfer: the lab's devices have no such endpoint.
      if (body.size() < 4) return fail(Errc::kParse, "usbredir: short interrupt packet");
      const std::array<std::uint8_t, 4> reply = {body[0], kStall, 0, 0};
      return sendPacket(kInterruptPacket, h.id, reply);
    }
    default: return {};  // filter_filter, device_disconnect_ack, iso packets, newer packets: nothing to answer
  }
}

Result<void> UsbredirLink::handleControl(const usbredir::Header& h, std::span<const std::uint8_t> body) {
  if (body.size() < kControlHeader) return fail(Errc::kParse, "usbredir: short control packet");
  UsbSetup setup;
  setup.request = body[1];
  setup.requestType = body[2];
  setup.value = readLe16(body, 4);
  setup.index = readLe16(body, 6);
  setup.length = readLe16(body, 8);
  const auto data = body.subspan(kControlHeader);
  const ControlReply r = device_.control(setup, setup.isIn() ? std::span<const std::uint8_t>{} : data, now());
  std::array<std::uint8_t, kControlHeader> reply{};
  std::copy(body.begin(), body.begin() + kControlHeader, reply.begin());
  reply[3] = usbredir::statusCode(r.status);
  std::span<const std::uint8_t> in;
  std::uint16_t length = 0;
  if (setup.isIn()) {
    in = std::span<const std::uint8_t>(r.data).first(std::min<std::size_t>(r.data.size(), setup.length));
    length = static_cast<std::uint16_t>(in.size());
  } else if (r.status == UsbStatus::kOk) {
    length = setup.length;
  }
  reply[8] = static_cast<std::uint8_t>(length);
  reply[9] = static_cast<std::uint8_t>(length >> 8U);
  return sendPacket(usbredir::kControlPacket, h.id, reply, in);
}

Result<void> UsbredirLink::handleBulk(const usbredir::Header& h, std::span<const std::uint8_t> body) {
  const std::size_t headerBytes = both(usbredir::kCap32BitBulkLength) ? 10 : 8;
  if (body.size() < headerBytes) return fail(Errc::kParse, "usbredir: short bulk packet");
  const std::uint8_t endpoint = body[0];
  std::uint32_t length = readLe16(body, 2);
  if (headerBytes == 10) length |= std::uint32_t{readLe16(body, 8)} << 16U;
  if ((endpoint & 0x80U) == 0) {
    // Bulk OUT: the lab's devices have no such endpoint.
    const PendingIn p{h.id, endpoint, 0, 0};
    return sendCompletion(p, UsbStatus::kStall, {});
  }
  if (!queueIn({h.id, endpoint, length, 0})) return sendCompletion({h.id, endpoint, 0, 0}, UsbStatus::kError, {});
  return {};
}

Result<void> UsbredirLink::sendCompletion(const PendingIn& transfer, UsbStatus status,
                                          std::span<const std::uint8_t> data) {
  std::vector<std::uint8_t> header;
  header.push_back(transfer.endpoint);
  header.push_back(usbredir::statusCode(status));
  const auto length = static_cast<std::uint32_t>(data.size());
  appendLe16(header, length & 0xffffU);
  appendLe32(header, 0);  // stream id
  if (both(usbredir::kCap32BitBulkLength)) appendLe16(header, length >> 16U);
  return sendPacket(usbredir::kBulkPacket, transfer.id, header, data);
}

Result<void> UsbredirLink::sendEndpointsAndInterfaces() {
  const UsbIdentity& id = device_.identity();
  // ep_info: type, interval, interface and max packet size of endpoints 0-15 OUT, then 0-15 IN.
  std::array<std::uint8_t, 32> type{};
  std::array<std::uint8_t, 32> interval{};
  std::array<std::uint8_t, 32> interface{};
  std::array<std::uint16_t, 32> maxPacket{};
  type.fill(255);  // usb_redir_type_invalid
  type[0] = type[16] = 0;
  maxPacket[0] = maxPacket[16] = 64;
  for (const auto& ep : id.endpoints) {
    const std::size_t i = endpointIndex(ep.address);
    type[i] = static_cast<std::uint8_t>(ep.type);
    interval[i] = ep.interval;
    interface[i] = ep.interfaceNumber;
    maxPacket[i] = ep.maxPacketSize;
  }
  std::vector<std::uint8_t> epInfo(type.begin(), type.end());
  epInfo.insert(epInfo.end(), interval.begin(), interval.end());
  epInfo.insert(epInfo.end(), interface.begin(), interface.end());
  if (both(usbredir::kCapEpInfoMaxPacketSize)) {
    for (const auto m : maxPacket) appendLe16(epInfo, m);
  }
  if (auto sent = sendPacket(usbredir::kEpInfo, 0, epInfo); !sent) return sent;

  std::vector<std::uint8_t> info;
  appendLe32(info, static_cast<std::uint32_t>(id.interfaces.size()));
  std::array<std::array<std::uint8_t, 32>, 4> columns{};
  for (std::size_t i = 0; i < id.interfaces.size() && i < 32; ++i) {
    columns[0][i] = id.interfaces[i].number;
    columns[1][i] = id.interfaces[i].interfaceClass;
    columns[2][i] = id.interfaces[i].interfaceSubClass;
    columns[3][i] = id.interfaces[i].interfaceProtocol;
  }
  for (const auto& column : columns) info.insert(info.end(), column.begin(), column.end());
  return sendPacket(usbredir::kInterfaceInfo, 0, info);
}

Result<void> UsbredirLink::announceDevice() {
  if (auto sent = sendEndpointsAndInterfaces(); !sent) return sent;
  const UsbIdentity& id = device_.identity();
  std::vector<std::uint8_t> connect;
  switch (id.speed) {
    case UsbSpeed::kLow: connect.push_back(0); break;
    case UsbSpeed::kFull: connect.push_back(1); break;
    case UsbSpeed::kHigh: connect.push_back(2); break;
    case UsbSpeed::kSuper: connect.push_back(3); break;
  }
  connect.push_back(id.deviceClass);
  connect.push_back(id.deviceSubClass);
  connect.push_back(id.deviceProtocol);
  appendLe16(connect, id.vendor);
  appendLe16(connect, id.product);
  if (both(usbredir::kCapConnectDeviceVersion)) appendLe16(connect, id.bcdDevice);
  if (auto sent = sendPacket(usbredir::kDeviceConnect, 0, connect); !sent) return sent;
  connected_ = true;
  return {};
}

}  // namespace basalt::sim::vlab
