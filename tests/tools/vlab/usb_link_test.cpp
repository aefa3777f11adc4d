// The transports of the virtual lab's emulated USB devices (tools/vlab/uvc): USB/IP as vhci_hcd
// speaks it and usbredir as qemu's usb-redir speaks it. Each test plays the host side over a
// socket pair, byte for byte as the protocol documents describe it, against the lab's UVC camera.
// The same code runs against the real kernel and the real qemu in the virtual lab
// (tests/tools/vlab/lab_selftest.cpp); here each message and each failure is pinned down quickly.

#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <cerrno>
#include <cstring>
#include <optional>

#include "runtime/clock.h"
#include "runtime/unique_fd.h"
#include "tools/vlab/uvc/usbip.h"
#include "tools/vlab/uvc/usbredir.h"
#include "tools/vlab/uvc/uvc_camera.h"

namespace basalt::sim::vlab {
namespace {

using Bytes = std::vector<std::uint8_t>;

// The host's end of the socket pair.
class Host {
 public:
  explicit Host(UniqueFd fd) : fd_(std::move(fd)) {}
  void write(std::span<const std::uint8_t> bytes) const {
    ASSERT_EQ(::send(fd_.get(), bytes.data(), bytes.size(), MSG_NOSIGNAL), static_cast<ssize_t>(bytes.size()));
  }
  /// Reads exactly n bytes, or fewer when none come for 2 s.
  Bytes read(std::size_t n) const {
    Bytes out(n);
    std::size_t got = 0;
    while (got < n) {
      pollfd p{fd_.get(), POLLIN, 0};
      if (::poll(&p, 1, 2000) <= 0) break;
      const ssize_t r = ::recv(fd_.get(), out.data() + got, n - got, 0);
      if (r <= 0) break;
      got += static_cast<std::size_t>(r);
    }
    out.resize(got);
    return out;
  }
  [[nodiscard]] bool quiet() const {
    pollfd p{fd_.get(), POLLIN, 0};
    return ::poll(&p, 1, 50) == 0;
  }
  void close() { fd_.reset(); }

 private:
  UniqueFd fd_;
};

std::pair<UniqueFd, UniqueFd> socketPair() {
  int sv[2] = {-1, -1};
  EXPECT_EQ(::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, sv), 0);
  return {UniqueFd(sv[0]), UniqueFd(sv[1])};
}

UvcCamera makeCamera() {
  auto cam = UvcCamera::create(UvcCameraConfig::labDefault());
  EXPECT_TRUE(cam);
  return std::move(*cam);
}

std::array<std::uint8_t, 8> setupBytes(std::uint8_t type, std::uint8_t request, std::uint16_t value,
                                       std::uint16_t index, std::uint16_t length) {
  return UsbSetup{type, request, value, index, length}.bytes();
}

// A 320x240 YUYV probe at 30 fps, as uvcvideo sends it.
Bytes probe320() {
  UvcStreamingControl c;
  c.formatIndex = 1;
  c.frameIndex = 2;
  c.frameInterval = 333333;
  return c.bytes();
}

// ---- USB/IP ---------------------------------------------------------------------------------

class UsbipTest : public testing::Test {
 protected:
  UsbipTest() : camera_(makeCamera()) {
    auto [ours, theirs] = socketPair();
    link_.emplace(std::move(ours), camera_, clock_);
    host_.emplace(std::move(theirs));
  }

  Bytes submit(std::uint32_t seqnum, std::uint32_t direction, std::uint32_t ep, std::int32_t length,
               std::array<std::uint8_t, 8> setup = {}, std::span<const std::uint8_t> out = {}) {
    usbip::Command c;
    c.command = usbip::kCmdSubmit;
    c.seqnum = seqnum;
    c.devid = 0x00010002;
    c.direction = direction;
    c.ep = ep;
    c.transferBufferLength = length;
    c.numberOfPackets = -1;  // not isochronous
    c.setup = setup;
    const auto header = c.bytes();
    Bytes msg(header.size() + out.size());
    std::copy(header.begin(), header.end(), msg.begin());
    for (std::size_t i = 0; i < out.size(); ++i) msg[header.size() + i] = out[i];
    return msg;
  }
  /// Sends a message, lets the link handle it, returns the RET header and data that came back.
  std::pair<usbip::Command, Bytes> exchange(const Bytes& msg, std::size_t dataBytes) {
    host_->write(msg);
    EXPECT_TRUE(link_->onReadable());
    return readReply(dataBytes);
  }
  std::pair<usbip::Command, Bytes> readReply(std::size_t dataBytes) {
    const Bytes header = host_->read(usbip::kHeaderSize);
    EXPECT_EQ(header.size(), usbip::kHeaderSize);
    usbip::Command ret;
    if (header.size() == usbip::kHeaderSize) {
      ret = usbip::Command::parse(std::span<const std::uint8_t, usbip::kHeaderSize>(header.data(), usbip::kHeaderSize));
    }
    return {ret, host_->read(dataBytes)};
  }
  void configureAndCommit() {
    exchange(submit(1, usbip::kDirOut, 0, 0, setupBytes(0x00, 0x09, 1, 0, 0)), 0);
    const Bytes probe = probe320();
    exchange(submit(2, usbip::kDirOut, 0, 34, setupBytes(0x21, 0x01, 0x0200, 1, 34), probe), 0);  // commit
  }

  ManualClock clock_{Nanos{1'000'000'000}};
  UvcCamera camera_;
  std::optional<UsbipLink> link_;
  std::optional<Host> host_;
};

// Makes sure a control transfer comes back as RET_SUBMIT with the request's seqnum, status 0,
// the data, and zeros where the protocol says the server puts zeros. Example failure: the reply
// echoes the devid, and vhci_hcd (which matches on seqnum) is fine but a stricter client is not.
TEST_F(UsbipTest, ControlTransferGetsRetSubmitWithData) {
  auto [ret, data] = exchange(submit(7, usbip::kDirIn, 0, 64, setupBytes(0x80, 0x06, 0x0100, 0, 64)), 18);
  EXPECT_EQ(ret.command, usbip::kRetSubmit);
  EXPECT_EQ(ret.seqnum, 7U);
  EXPECT_EQ(ret.devid, 0U);
  EXPECT_EQ(ret.direction, 0U);
  EXPECT_EQ(ret.ep, 0U);
  EXPECT_EQ(ret.transferFlags, 0U) << "status";
  EXPECT_EQ(ret.transferBufferLength, 18) << "actual_length";
  EXPECT_EQ(ret.numberOfPackets, -1) << "number_of_packets is echoed";
  ASSERT_EQ(data.size(), 18U);
  EXPECT_EQ(data, camera_.deviceDescriptor());
  EXPECT_TRUE(host_->quiet());
}

// Makes sure a request the device refuses comes back as -EPIPE (a stall), the way vhci_hcd
// passes it to usbcore. Example failure: a stall reported as status 1, which usbcore reads as
// success with garbage.
TEST_F(UsbipTest, RefusedRequestIsAStall) {
  auto [ret, data] = exchange(submit(3, usbip::kDirIn, 0, 10, setupBytes(0x80, 0x06, 0x0600, 0, 10)), 0);
  EXPECT_EQ(static_cast<std::int32_t>(ret.transferFlags), -EPIPE);
  EXPECT_EQ(ret.transferBufferLength, 0);
}

// Makes sure bulk IN transfers wait while the camera has nothing, complete with payloads once
// it streams, and that an unlinked waiting transfer is answered with RET_UNLINK -ECONNRESET (and
// one already completed with 0). Example failure: an unlink of a waiting URB gets no answer, and
// uvcvideo's stream-off hangs in usb_kill_urb.
TEST_F(UsbipTest, BulkTransfersWaitCompleteAndUnlink) {
  exchange(submit(1, usbip::kDirOut, 0, 0, setupBytes(0x00, 0x09, 1, 0, 0)), 0);
  host_->write(submit(10, usbip::kDirIn, 1, 16384));
  ASSERT_TRUE(link_->onReadable());
  EXPECT_TRUE(host_->quiet()) << "no stream yet: the transfer must wait";
  EXPECT_EQ(link_->pendingTransfers(), 1U);

  usbip::Command unlink;
  unlink.command = usbip::kCmdUnlink;
  unlink.seqnum = 11;
  unlink.unlinkSeqnum = 10;
  const auto u = unlink.bytes();
  auto [ret, none] = exchange(Bytes(u.begin(), u.end()), 0);
  EXPECT_EQ(ret.command, usbip::kRetUnlink);
  EXPECT_EQ(ret.seqnum, 11U);
  EXPECT_EQ(static_cast<std::int32_t>(ret.transferFlags), -ECONNRESET);
  EXPECT_EQ(link_->pendingTransfers(), 0U);
  unlink.seqnum = 12;
  const auto again = unlink.bytes();
  auto [ret2, none2] = exchange(Bytes(again.begin(), again.end()), 0);
  EXPECT_EQ(static_cast<std::int32_t>(ret2.transferFlags), 0) << "unlinking what is no longer queued";

  const Bytes probe = probe320();
  exchange(submit(2, usbip::kDirOut, 0, 34, setupBytes(0x21, 0x01, 0x0200, 1, 34), probe), 0);  // commit
  host_->write(submit(20, usbip::kDirIn, 1, 16384));
  ASSERT_TRUE(link_->onReadable());
  auto [bulk, payload] = readReply(16384);
  EXPECT_EQ(bulk.seqnum, 20U);
  EXPECT_EQ(bulk.transferBufferLength, 16384);
  ASSERT_EQ(payload.size(), 16384U);
  EXPECT_EQ(payload[0], UvcPayloadWriter::kHeaderSize);
  EXPECT_EQ(payload[1] & UvcPayloadWriter::kEoh, UvcPayloadWriter::kEoh);
}

// Makes sure a message that arrives in pieces is handled once it is whole, with its OUT data.
// Example failure: the link parses the header alone and reads the probe data as the next header.
TEST_F(UsbipTest, MessageInPiecesIsHandledWhenWhole) {
  exchange(submit(1, usbip::kDirOut, 0, 0, setupBytes(0x00, 0x09, 1, 0, 0)), 0);
  const Bytes probe = probe320();
  const Bytes msg = submit(5, usbip::kDirOut, 0, 34, setupBytes(0x21, 0x01, 0x0100, 1, 34), probe);  // SET_CUR probe
  host_->write(std::span<const std::uint8_t>(msg).first(60));
  ASSERT_TRUE(link_->onReadable());
  EXPECT_TRUE(host_->quiet());
  host_->write(std::span<const std::uint8_t>(msg).subspan(60));
  ASSERT_TRUE(link_->onReadable());
  auto [ret, none] = readReply(0);
  EXPECT_EQ(ret.seqnum, 5U);
  EXPECT_EQ(ret.transferFlags, 0U);
  EXPECT_EQ(ret.transferBufferLength, 34);
  EXPECT_EQ(camera_.probe().frameIndex, 2);
}

// Makes sure what the link cannot serve is an error that ends the link, not a crash or a hang:
// an isochronous transfer, an unknown command, an absurd length, a host that hangs up.
// Example failure: a length of -1 is taken as 4 GiB and the link waits forever for the data.
TEST_F(UsbipTest, GarbageEndsTheLink) {
  Bytes iso = submit(1, usbip::kDirIn, 1, 512);
  iso[35] = 8;  // number_of_packets 8
  iso[32] = iso[33] = iso[34] = 0;
  host_->write(iso);
  auto r = link_->onReadable();
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code(), Errc::kParse);
  EXPECT_NE(r.error().message().find("isochronous"), std::string::npos);

  auto [ours, theirs] = socketPair();
  link_.emplace(std::move(ours), camera_, clock_);
  host_.emplace(std::move(theirs));
  host_->write(submit(1, usbip::kDirIn, 0, -1));
  r = link_->onReadable();
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code(), Errc::kParse);

  auto [ours2, theirs2] = socketPair();
  link_.emplace(std::move(ours2), camera_, clock_);
  host_.emplace(std::move(theirs2));
  Bytes unknown = submit(1, usbip::kDirIn, 0, 0);
  unknown[3] = 9;
  host_->write(unknown);
  EXPECT_FALSE(link_->onReadable());

  auto [ours3, theirs3] = socketPair();
  link_.emplace(std::move(ours3), camera_, clock_);
  host_.emplace(std::move(theirs3));
  host_->close();
  r = link_->onReadable();
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code(), Errc::kDeviceLost);
}

// Makes sure the free port is found in vhci_hcd's status file, in both layouts the kernel has
// used, for high-speed and SuperSpeed devices. Example failure: the hub column is read as the
// port number, and the attach writes port "hs".
TEST(VhciStatus, FreePortIsFoundInBothLayouts) {
  const std::string withHub =
      "hub port sta spd dev      sockfd local_busid\n"
      "hs  0000 006 003 00010002 000005 1-1\n"
      "hs  0001 004 000 00000000 000000 0-0\n"
      "ss  0002 004 000 00000000 000000 0-0\n";
  EXPECT_EQ(freeVhciPort(withHub, UsbSpeed::kHigh), 1);
  EXPECT_EQ(freeVhciPort(withHub, UsbSpeed::kSuper), 2);
  const std::string old =
      "port sta spd dev      socket           local_busid\n"
      "0000 006 003 00010002         c5a7bb80 1-2.3\n"
      "0001 004 000 00000000 0000000000000000 0-0\n";
  EXPECT_EQ(freeVhciPort(old, UsbSpeed::kHigh), 1);
  EXPECT_FALSE(
      freeVhciPort("hub port sta spd dev      sockfd local_busid\nhs  0000 006 003 1 5 1-1\n", UsbSpeed::kHigh));
  EXPECT_FALSE(freeVhciPort("", UsbSpeed::kHigh));
}

// Makes sure attaching without vhci_hcd says what to load. Example failure: the camera program
// reports "No such file or directory" and nobody knows which file.
TEST(VhciAttach, MissingControllerSaysWhatToLoad) {
  auto camera = makeCamera();
  ManualClock clock;
  auto r = VhciAttachment::attach(camera, clock, "/nonexistent/vhci_hcd.0");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code(), Errc::kNotFound);
  EXPECT_NE(r.error().message().find("modprobe vhci-hcd"), std::string::npos) << r.error().message();
}

// ---- usbredir ---------------------------------------------------------------------------------

struct Packet {
  std::uint32_t type = 0;
  std::uint64_t id = 0;
  Bytes body;
};

class UsbredirTest : public testing::Test {
 protected:
  UsbredirTest() : camera_(makeCamera()) {
    auto [ours, theirs] = socketPair();
    link_.emplace(std::move(ours), camera_, clock_);
    host_.emplace(std::move(theirs));
  }

  Packet readPacket() {
    Packet p;
    const Bytes h = host_->read(ids64_ ? 16 : 12);
    if (h.size() < 12) {
      ADD_FAILURE() << "no packet from the device";
      return p;
    }
    p.type = readLe32(h, 0);
    const std::uint32_t length = readLe32(h, 4);
    p.id = ids64_ ? readLe64(h, 8) : readLe32(h, 8);
    p.body = host_->read(length);
    EXPECT_EQ(p.body.size(), length);
    return p;
  }
  void sendPacket(std::uint32_t type, std::uint64_t id, const Bytes& body) {
    Bytes msg;
    usbredir::appendHeader(msg, {type, static_cast<std::uint32_t>(body.size()), id}, ids64_);
    msg.insert(msg.end(), body.begin(), body.end());
    host_->write(msg);
    ASSERT_TRUE(link_->onReadable());
  }
  /// qemu's side of the handshake: our hello in, its hello out, the device announced.
  void handshake(std::uint32_t caps) {
    ASSERT_TRUE(link_->start());
    const Packet hello = readPacket();
    EXPECT_EQ(hello.type, usbredir::kHello);
    ASSERT_EQ(hello.body.size(), 68U);
    EXPECT_STREQ(reinterpret_cast<const char*>(hello.body.data()), "basalt-vlab-uvc-camera");
    EXPECT_EQ(readLe32(hello.body, 64), usbredir::kOurCaps);
    Bytes qemuHello(64, 0);
    std::memcpy(qemuHello.data(), "qemu usb-redir guest 7.2.22", 27);
    appendLe32(qemuHello, caps);
    sendPacket(usbredir::kHello, 0, qemuHello);
    ids64_ = (caps & usbredir::kCap64BitIds) != 0;
  }
  static Bytes control(std::uint8_t type, std::uint8_t request, std::uint16_t value, std::uint16_t index,
                       std::uint16_t length, const Bytes& out = {}) {
    Bytes body = {0x80, request, type, 0};
    appendLe16(body, value);
    appendLe16(body, index);
    appendLe16(body, length);
    body.insert(body.end(), out.begin(), out.end());
    return body;
  }

  static constexpr std::uint32_t kQemuCaps = usbredir::kCapConnectDeviceVersion | usbredir::kCapFilter |
                                             usbredir::kCapDeviceDisconnectAck | usbredir::kCapEpInfoMaxPacketSize |
                                             usbredir::kCap64BitIds | usbredir::kCap32BitBulkLength;
  ManualClock clock_{Nanos{1'000'000'000}};
  UvcCamera camera_;
  std::optional<UsbredirLink> link_;
  std::optional<Host> host_;
  bool ids64_ = false;
};

// Makes sure the device is announced as the protocol requires: ep_info and interface_info before
// device_connect, with the bulk endpoint, the two video interfaces and the camera's ids. Example
// failure: device_connect goes first, and qemu rejects the device ("No interface info for
// device").
TEST_F(UsbredirTest, HandshakeAnnouncesTheCamera) {
  handshake(kQemuCaps);
  EXPECT_TRUE(link_->connected());
  EXPECT_EQ(link_->peerVersion(), "qemu usb-redir guest 7.2.22");
  const Packet ep = readPacket();
  ASSERT_EQ(ep.type, usbredir::kEpInfo);
  ASSERT_EQ(ep.body.size(), 32U * 3 + 64);
  EXPECT_EQ(ep.body[0], 0) << "endpoint 0 OUT is control";
  EXPECT_EQ(ep.body[16], 0) << "endpoint 0 IN is control";
  EXPECT_EQ(ep.body[17], 2) << "endpoint 1 IN is bulk";
  EXPECT_EQ(ep.body[32 + 32 + 17], 1) << "on interface 1";
  EXPECT_EQ(readLe16(ep.body, 96 + 2 * 17), 512);
  EXPECT_EQ(ep.body[1], 255) << "endpoint 1 OUT does not exist";
  const Packet interfaces = readPacket();
  ASSERT_EQ(interfaces.type, usbredir::kInterfaceInfo);
  EXPECT_EQ(readLe32(interfaces.body, 0), 2U);
  EXPECT_EQ(interfaces.body[4 + 32], 0x0e) << "video class";
  EXPECT_EQ(interfaces.body[4 + 64 + 1], 0x02) << "streaming subclass";
  const Packet connect = readPacket();
  ASSERT_EQ(connect.type, usbredir::kDeviceConnect);
  ASSERT_EQ(connect.body.size(), 10U);
  EXPECT_EQ(connect.body[0], 2) << "high speed";
  EXPECT_EQ(connect.body[1], 0xef);
  EXPECT_EQ(readLe16(connect.body, 4), 0x1209);
  EXPECT_EQ(readLe16(connect.body, 6), 0x0002);
  EXPECT_EQ(readLe16(connect.body, 8), 0x0100);
}

// Makes sure control packets come back with their id, the status and the data, and
// set_configuration with the endpoint and interface info before its status. Example failure: the
// reply's length says 64 for an 18-byte descriptor, and qemu copies 46 bytes of garbage.
TEST_F(UsbredirTest, ControlAndConfigurationPackets) {
  handshake(kQemuCaps);
  for (int i = 0; i < 3; ++i) readPacket();
  sendPacket(usbredir::kControlPacket, 0x1'0000'0042ULL, control(0x80, 0x06, 0x0100, 0, 64));
  const Packet desc = readPacket();
  EXPECT_EQ(desc.type, usbredir::kControlPacket);
  EXPECT_EQ(desc.id, 0x1'0000'0042ULL) << "64-bit ids come back whole";
  ASSERT_EQ(desc.body.size(), 10U + 18);
  EXPECT_EQ(desc.body[3], usbredir::kSuccess);
  EXPECT_EQ(readLe16(desc.body, 8), 18);

  sendPacket(usbredir::kControlPacket, 43, control(0x80, 0x06, 0x0600, 0, 10));
  EXPECT_EQ(readPacket().body[3], usbredir::kStall) << "no device qualifier";

  sendPacket(usbredir::kSetConfiguration, 44, {1});
  EXPECT_EQ(readPacket().type, usbredir::kEpInfo);
  EXPECT_EQ(readPacket().type, usbredir::kInterfaceInfo);
  const Packet status = readPacket();
  ASSERT_EQ(status.type, usbredir::kConfigurationStatus);
  EXPECT_EQ(status.id, 44U);
  EXPECT_EQ(status.body, (Bytes{usbredir::kSuccess, 1}));
  EXPECT_TRUE(camera_.configured());
  sendPacket(usbredir::kGetAltSetting, 45, {1});
  EXPECT_EQ(readPacket().body, (Bytes{usbredir::kSuccess, 1, 0}));
  sendPacket(usbredir::kStartIsoStream, 46, {0x81, 8, 4});
  EXPECT_EQ(readPacket().body[0], usbredir::kInval) << "no isochronous streams";
}

// Makes sure bulk IN packets wait, complete with the camera's payloads (32-bit lengths), and
// that cancel_data_packet answers a waiting one with status cancelled under the same id.
// Example failure: a cancelled packet is dropped silently, and qemu's guest waits on a transfer
// that never completes.
TEST_F(UsbredirTest, BulkPacketsWaitCompleteAndCancel) {
  handshake(kQemuCaps);
  for (int i = 0; i < 3; ++i) readPacket();
  sendPacket(usbredir::kSetConfiguration, 1, {1});
  for (int i = 0; i < 3; ++i) readPacket();
  Bytes bulk = {0x81, 0, 0x00, 0x40, 0, 0, 0, 0, 0, 0};  // endpoint, status, length 16384, stream, length_high
  sendPacket(usbredir::kBulkPacket, 100, bulk);
  EXPECT_TRUE(host_->quiet()) << "no stream yet";
  sendPacket(usbredir::kCancelDataPacket, 100, {});
  const Packet cancelled = readPacket();
  EXPECT_EQ(cancelled.type, usbredir::kBulkPacket);
  EXPECT_EQ(cancelled.id, 100U);
  EXPECT_EQ(cancelled.body[1], usbredir::kCancelled);

  sendPacket(usbredir::kControlPacket, 2, control(0x21, 0x01, 0x0200, 1, 34, probe320()));  // commit
  EXPECT_EQ(readPacket().body[3], usbredir::kSuccess);
  sendPacket(usbredir::kBulkPacket, 101, bulk);
  const Packet data = readPacket();
  EXPECT_EQ(data.id, 101U);
  ASSERT_EQ(data.body.size(), 10U + 16384);
  EXPECT_EQ(data.body[1], usbredir::kSuccess);
  EXPECT_EQ(readLe16(data.body, 2) | (readLe16(data.body, 8) << 16), 16384);
  EXPECT_EQ(data.body[10], UvcPayloadWriter::kHeaderSize);
  sendPacket(usbredir::kCancelDataPacket, 101, {});
  EXPECT_TRUE(host_->quiet()) << "cancelling a completed packet sends nothing";
}

// Makes sure a peer without 64-bit ids gets 12-byte headers after the hello. Example failure:
// the link always writes 16-byte headers and an older qemu reads every packet four bytes off.
TEST_F(UsbredirTest, PeerWithout64BitIdsGetsShortHeaders) {
  handshake(usbredir::kCapEpInfoMaxPacketSize);
  const Packet ep = readPacket();
  EXPECT_EQ(ep.type, usbredir::kEpInfo);
  readPacket();
  const Packet connect = readPacket();
  EXPECT_EQ(connect.type, usbredir::kDeviceConnect);
  EXPECT_EQ(connect.body.size(), 8U) << "no device version without the capability";
}

// Makes sure a packet before the hello, an absurd length, a filter rejection and a closed
// connection end the link with an error that says so. Example failure: a 2 GiB length makes the
// link wait forever for the rest of the packet.
TEST_F(UsbredirTest, ProtocolErrorsEndTheLink) {
  Bytes early;
  usbredir::appendHeader(early, {usbredir::kControlPacket, 0, 1}, false);
  host_->write(early);
  auto r = link_->onReadable();
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message().find("before qemu's hello"), std::string::npos);

  auto [ours, theirs] = socketPair();
  link_.emplace(std::move(ours), camera_, clock_);
  host_.emplace(std::move(theirs));
  ids64_ = false;
  handshake(kQemuCaps);
  Bytes huge;
  usbredir::appendHeader(huge, {usbredir::kBulkPacket, 0x80000000U, 1}, true);
  host_->write(huge);
  r = link_->onReadable();
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code(), Errc::kParse);

  auto [ours2, theirs2] = socketPair();
  link_.emplace(std::move(ours2), camera_, clock_);
  host_.emplace(std::move(theirs2));
  ids64_ = false;
  handshake(kQemuCaps);
  Bytes reject;
  usbredir::appendHeader(reject, {usbredir::kFilterReject, 0, 0}, true);
  host_->write(reject);
  r = link_->onReadable();
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message().find("rejected"), std::string::npos);

  host_->close();
  r = link_->onReadable();
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code(), Errc::kDeviceLost);
}

}  // namespace
}  // namespace basalt::sim::vlab
