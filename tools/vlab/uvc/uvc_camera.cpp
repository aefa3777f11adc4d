// The virtual lab's UVC 1.1 camera (see uvc_camera.h). The descriptors follow the USB Video
// Class 1.1 specification and its payload specifications for uncompressed (YUY2) and MJPEG
// formats; where the specification leaves a choice, the camera does what common webcams do and
// what Linux's uvcvideo expects (a bulk endpoint in alternate setting 0 of the streaming
// interface, stream stop by CLEAR_FEATURE(ENDPOINT_HALT) on it).

#include "tools/vlab/uvc/uvc_camera.h"

#include <cstring>
#include <limits>
#include <utility>

#include <fmt/format.h>

namespace basalt::sim::vlab {
namespace {

using namespace usb;  // USB 2.0 chapter 9

// UVC 1.1 appendix A.
constexpr std::uint8_t kClassVideo = 0x0e;
constexpr std::uint8_t kSubclassControl = 0x01;
constexpr std::uint8_t kSubclassStreaming = 0x02;
constexpr std::uint8_t kSubclassCollection = 0x03;
constexpr std::uint8_t kCsInterface = 0x24;
constexpr std::uint8_t kVcHeader = 0x01;
constexpr std::uint8_t kVcInputTerminal = 0x02;
constexpr std::uint8_t kVcOutputTerminal = 0x03;
constexpr std::uint8_t kVcProcessingUnit = 0x05;
constexpr std::uint8_t kVsInputHeader = 0x01;
constexpr std::uint8_t kVsFormatUncompressed = 0x04;
constexpr std::uint8_t kVsFrameUncompressed = 0x05;
constexpr std::uint8_t kVsFormatMjpeg = 0x06;
constexpr std::uint8_t kVsFrameMjpeg = 0x07;
constexpr std::uint8_t kVsColorFormat = 0x0d;
constexpr std::uint16_t kIttCamera = 0x0201;
constexpr std::uint16_t kTtStreaming = 0x0101;
constexpr std::uint8_t kSetCur = 0x01;
constexpr std::uint8_t kGetCur = 0x81;
constexpr std::uint8_t kGetMin = 0x82;
constexpr std::uint8_t kGetMax = 0x83;
constexpr std::uint8_t kGetRes = 0x84;
constexpr std::uint8_t kGetLen = 0x85;
constexpr std::uint8_t kGetInfo = 0x86;
constexpr std::uint8_t kGetDef = 0x87;
constexpr std::uint8_t kVcRequestErrorCodeControl = 0x02;
constexpr std::uint8_t kPuBrightnessControl = 0x02;
constexpr std::uint8_t kVsProbeControl = 0x01;
constexpr std::uint8_t kVsCommitControl = 0x02;
// Request error codes (UVC 1.1 4.2.1.2).
constexpr std::uint8_t kErrWrongState = 0x02;
constexpr std::uint8_t kErrOutOfRange = 0x04;
constexpr std::uint8_t kErrInvalidUnit = 0x05;
constexpr std::uint8_t kErrInvalidControl = 0x06;
constexpr std::uint8_t kErrInvalidRequest = 0x07;
// GET_INFO bits: GET and SET supported.
constexpr std::uint8_t kInfoGetSet = 0x03;

constexpr std::uint16_t kBrightnessMin = 0;
constexpr std::uint16_t kBrightnessMax = 255;
constexpr std::uint16_t kHighSpeedBulkPacket = 512;

// The YUY2 GUID of the uncompressed payload specification.
constexpr std::uint8_t kGuidYuy2[16] = {'Y',  'U',  'Y',  '2',  0x00, 0x00, 0x10, 0x00,
                                        0x80, 0x00, 0x00, 0xaa, 0x00, 0x38, 0x9b, 0x71};

// Little-endian descriptor bytes.
class Bytes {
 public:
  Bytes& u8(unsigned v) {
    v_.push_back(static_cast<std::uint8_t>(v));
    return *this;
  }
  Bytes& u16(unsigned v) { return u8(v & 0xffU).u8(v >> 8U); }
  Bytes& u32(std::uint32_t v) { return u16(v & 0xffffU).u16(v >> 16U); }
  Bytes& raw(std::span<const std::uint8_t> b) {
    v_.insert(v_.end(), b.begin(), b.end());
    return *this;
  }
  [[nodiscard]] std::size_t size() const { return v_.size(); }
  void patch16(std::size_t at, std::size_t v) {
    v_[at] = static_cast<std::uint8_t>(v);
    v_[at + 1] = static_cast<std::uint8_t>(v >> 8U);
  }
  std::vector<std::uint8_t> take() { return std::move(v_); }

 private:
  std::vector<std::uint8_t> v_;
};

ControlReply reply(std::vector<std::uint8_t> data, std::uint16_t wLength) {
  return controlReply(std::move(data), wLength);
}

ControlReply reply16(unsigned v, std::uint16_t wLength) {
  return reply({static_cast<std::uint8_t>(v), static_cast<std::uint8_t>(v >> 8U)}, wLength);
}

ControlReply ok() { return {UsbStatus::kOk, {}}; }

std::uint16_t get16(std::span<const std::uint8_t> b, std::size_t at) {
  return static_cast<std::uint16_t>(b[at] | (b[at + 1] << 8U));
}
std::uint32_t get32(std::span<const std::uint8_t> b, std::size_t at) {
  return static_cast<std::uint32_t>(get16(b, at)) | (static_cast<std::uint32_t>(get16(b, at + 2)) << 16U);
}

std::uint32_t frameBytes(const UvcFrameSize& f) { return std::uint32_t{f.width} * f.height * 2; }

}  // namespace

UvcCameraConfig UvcCameraConfig::labDefault() {
  const std::vector<std::uint32_t> rates = {333'333, 666'666, 2'000'000};  // 30, 15, 5 per second
  UvcCameraConfig c;
  c.formats = {
      {UvcPixelFormat::kYuyv, {{640, 480, rates}, {320, 240, rates}}},
      {UvcPixelFormat::kMjpeg, {{1280, 720, rates}, {640, 480, rates}}},
  };
  return c;
}

// ---- probe and commit ------------------------------------------------------------------------

UvcStreamingControl UvcStreamingControl::parse(std::span<const std::uint8_t> b) {
  std::array<std::uint8_t, kSize> full{};
  std::memcpy(full.data(), b.data(), std::min(b.size(), full.size()));
  const std::span<const std::uint8_t> f(full);
  UvcStreamingControl c;
  c.hint = get16(f, 0);
  c.formatIndex = f[2];
  c.frameIndex = f[3];
  c.frameInterval = get32(f, 4);
  c.keyFrameRate = get16(f, 8);
  c.pFrameRate = get16(f, 10);
  c.compQuality = get16(f, 12);
  c.compWindowSize = get16(f, 14);
  c.delay = get16(f, 16);
  c.maxVideoFrameSize = get32(f, 18);
  c.maxPayloadTransferSize = get32(f, 22);
  c.clockFrequency = get32(f, 26);
  c.framingInfo = f[30];
  c.preferredVersion = f[31];
  c.minVersion = f[32];
  c.maxVersion = f[33];
  return c;
}

std::vector<std::uint8_t> UvcStreamingControl::bytes() const {
  Bytes b;
  b.u16(hint).u8(formatIndex).u8(frameIndex).u32(frameInterval).u16(keyFrameRate).u16(pFrameRate);
  b.u16(compQuality).u16(compWindowSize).u16(delay).u32(maxVideoFrameSize).u32(maxPayloadTransferSize);
  b.u32(clockFrequency).u8(framingInfo).u8(preferredVersion).u8(minVersion).u8(maxVersion);
  return b.take();
}

// ---- payloads ----------------------------------------------------------------------------------

void UvcPayloadWriter::startFrame(std::span<const std::uint8_t> frame, bool fid, std::uint32_t pts) {
  frame_ = frame;
  offset_ = 0;
  payloadLeft_ = 0;
  payloadBytes_ = 0;
  inPayload_ = false;
  needZeroLength_ = false;
  eof_ = false;
  busy_ = true;
  info_ = static_cast<std::uint8_t>(kEoh | kPts | (fid ? kFid : 0));
  pts_ = pts;
}

std::size_t UvcPayloadWriter::fill(std::span<std::uint8_t> transfer) {
  if (!busy_) return 0;
  auto endPayload = [this] {
    inPayload_ = false;
    if (eof_) busy_ = false;
  };
  if (needZeroLength_) {
    needZeroLength_ = false;
    endPayload();
    return 0;
  }
  std::size_t written = 0;
  if (!inPayload_) {
    if (transfer.size() < kHeaderSize) return 0;  // a host that asks for less than a header gets nothing
    const std::size_t remaining = frame_.size() - offset_;
    payloadLeft_ = std::min(remaining, maxPayload_ - kHeaderSize);
    eof_ = payloadLeft_ == remaining;
    transfer[0] = kHeaderSize;
    transfer[1] = static_cast<std::uint8_t>(info_ | (eof_ ? kEof : 0));
    for (std::size_t i = 0; i < 4; ++i) transfer[2 + i] = static_cast<std::uint8_t>(pts_ >> (8 * i));
    written = kHeaderSize;
    payloadBytes_ = kHeaderSize;
    inPayload_ = true;
  }
  const std::size_t n = std::min(payloadLeft_, transfer.size() - written);
  if (n != 0) std::memcpy(transfer.data() + written, frame_.data() + offset_, n);
  offset_ += n;
  payloadLeft_ -= n;
  payloadBytes_ += n;
  written += n;
  if (payloadLeft_ == 0) {
    // A full transfer tells the host the payload goes on unless it reached the maximum size.
    if (written == transfer.size() && payloadBytes_ < maxPayload_) {
      needZeroLength_ = true;
    } else {
      endPayload();
    }
  }
  return written;
}

std::optional<std::uint32_t> mjpegFrameNumber(std::span<const std::uint8_t> jpeg) {
  const auto info = inspectJpeg(jpeg);
  if (!info || !info->comment.starts_with(UvcCamera::kFrameComment)) return std::nullopt;
  const std::string digits = info->comment.substr(UvcCamera::kFrameComment.size());
  if (digits.empty() || digits.size() > 10 || digits.find_first_not_of("0123456789") != std::string::npos) {
    return std::nullopt;
  }
  const unsigned long long v = std::stoull(digits);
  if (v > std::numeric_limits<std::uint32_t>::max()) return std::nullopt;
  return static_cast<std::uint32_t>(v);
}

// ---- the camera ---------------------------------------------------------------------------------

Result<UvcCamera> UvcCamera::create(UvcCameraConfig config) {
  if (config.formats.empty() || config.formats.size() > 32) {
    return failf(Errc::kInvalidArgument, "a UVC camera needs 1 to 32 formats, not {}", config.formats.size());
  }
  if (config.maxPayloadTransferSize < 512 || config.maxPayloadTransferSize > 3 * 1024 * 1024) {
    return failf(Errc::kInvalidArgument, "dwMaxPayloadTransferSize {} is outside 512..3145728",
                 config.maxPayloadTransferSize);
  }
  for (const std::string* s : {&config.manufacturer, &config.productName, &config.serial}) {
    if (s->empty() || s->size() > 126) {
      return fail(Errc::kInvalidArgument, "a UVC camera's strings must have 1 to 126 characters");
    }
  }
  UvcCamera cam(std::move(config));
  const UvcCameraConfig& c = cam.config_;
  for (const auto& format : c.formats) {
    if (format.frames.empty() || format.frames.size() > 32) {
      return failf(Errc::kInvalidArgument, "a UVC format needs 1 to 32 frame sizes, not {}", format.frames.size());
    }
    auto& pictures = cam.pictures_.emplace_back();
    for (const auto& frame : format.frames) {
      if (frame.intervals.empty() || frame.intervals.size() > 32) {
        return failf(Errc::kInvalidArgument, "frame size {}x{} needs 1 to 32 frame intervals", frame.width,
                     frame.height);
      }
      for (const auto interval : frame.intervals) {
        if (interval == 0)
          return failf(Errc::kInvalidArgument, "frame size {}x{} has a zero interval", frame.width, frame.height);
      }
      auto picture = TestPicture::create(frame.width, frame.height);
      if (!picture) return std::unexpected(picture.error());
      pictures.push_back(std::move(*picture));
    }
  }

  // Identity (what usbredir announces before descriptors are read).
  cam.identity_.speed = UsbSpeed::kHigh;
  cam.identity_.deviceClass = 0xef;  // miscellaneous: an interface association follows
  cam.identity_.deviceSubClass = 0x02;
  cam.identity_.deviceProtocol = 0x01;
  cam.identity_.vendor = c.vendor;
  cam.identity_.product = c.product;
  cam.identity_.bcdDevice = 0x0100;
  cam.identity_.interfaces = {{kControlInterface, kClassVideo, kSubclassControl, 0},
                              {kStreamingInterface, kClassVideo, kSubclassStreaming, 0}};
  cam.identity_.endpoints = {
      {kStreamingEndpoint, UsbEndpointType::kBulk, kHighSpeedBulkPacket, 0, kStreamingInterface}};

  Bytes dev;
  dev.u8(18).u8(kDescDevice).u16(0x0200).u8(0xef).u8(0x02).u8(0x01).u8(64);
  dev.u16(c.vendor).u16(c.product).u16(0x0100).u8(1).u8(2).u8(3).u8(1);
  cam.deviceDescriptor_ = dev.take();
  cam.strings_ = {{4, kDescString, 0x09, 0x04},
                  stringDescriptor(c.manufacturer),
                  stringDescriptor(c.productName),
                  stringDescriptor(c.serial)};

  Bytes d;
  d.u8(9).u8(kDescConfiguration).u16(0).u8(2).u8(1).u8(0).u8(0x80).u8(50);  // bus powered, 100 mA
  d.u8(8).u8(kDescInterfaceAssociation).u8(kControlInterface).u8(2).u8(kClassVideo).u8(kSubclassCollection);
  d.u8(0).u8(2);
  // VideoControl: header, camera terminal (no controls), processing unit (brightness), output terminal.
  d.u8(9).u8(kDescInterface).u8(kControlInterface).u8(0).u8(0).u8(kClassVideo).u8(kSubclassControl).u8(0).u8(2);
  const std::size_t vcHeader = d.size();
  d.u8(13).u8(kCsInterface).u8(kVcHeader).u16(0x0110).u16(0).u32(kClockFrequency).u8(1).u8(kStreamingInterface);
  d.u8(18).u8(kCsInterface).u8(kVcInputTerminal).u8(kCameraTerminal).u16(kIttCamera).u8(0).u8(0);
  d.u16(0).u16(0).u16(0).u8(3).u8(0).u8(0).u8(0);
  d.u8(12).u8(kCsInterface).u8(kVcProcessingUnit).u8(kProcessingUnit).u8(kCameraTerminal).u16(0);
  d.u8(2).u16(0x0001).u8(0).u8(0);  // bmControls: brightness; iProcessing; bmVideoStandards
  d.u8(9).u8(kCsInterface).u8(kVcOutputTerminal).u8(kOutputTerminal).u16(kTtStreaming).u8(0);
  d.u8(kProcessingUnit).u8(0);
  d.patch16(vcHeader + 5, d.size() - vcHeader);
  // VideoStreaming: one bulk endpoint in alternate setting 0.
  d.u8(9).u8(kDescInterface).u8(kStreamingInterface).u8(0).u8(1).u8(kClassVideo).u8(kSubclassStreaming);
  d.u8(0).u8(0);
  const std::size_t vsHeader = d.size();
  const auto formats = static_cast<unsigned>(c.formats.size());
  d.u8(13 + formats).u8(kCsInterface).u8(kVsInputHeader).u8(formats).u16(0).u8(kStreamingEndpoint).u8(0);
  d.u8(kOutputTerminal).u8(0).u8(0).u8(0).u8(1);
  for (unsigned i = 0; i < formats; ++i) d.u8(0);
  for (unsigned fi = 0; fi < formats; ++fi) {
    const UvcFormat& format = c.formats[fi];
    const bool mjpeg = format.pixelFormat == UvcPixelFormat::kMjpeg;
    const auto frames = static_cast<unsigned>(format.frames.size());
    if (mjpeg) {
      d.u8(11).u8(kCsInterface).u8(kVsFormatMjpeg).u8(fi + 1).u8(frames).u8(0x01).u8(1).u8(0).u8(0).u8(0).u8(0);
    } else {
      d.u8(27).u8(kCsInterface).u8(kVsFormatUncompressed).u8(fi + 1).u8(frames).raw(kGuidYuy2).u8(16).u8(1);
      d.u8(0).u8(0).u8(0).u8(0);
    }
    for (unsigned k = 0; k < frames; ++k) {
      const UvcFrameSize& f = format.frames[k];
      const auto n = static_cast<unsigned>(f.intervals.size());
      const std::uint64_t bitsPerFrame = std::uint64_t{f.width} * f.height * 16;
      const auto bitRate = [&](std::uint32_t interval) {
        return static_cast<std::uint32_t>(
            std::min<std::uint64_t>(bitsPerFrame * 10'000'000 / interval, std::numeric_limits<std::uint32_t>::max()));
      };
      d.u8(26 + 4 * n).u8(kCsInterface).u8(mjpeg ? kVsFrameMjpeg : kVsFrameUncompressed).u8(k + 1).u8(0);
      d.u16(f.width).u16(f.height).u32(bitRate(f.intervals.back())).u32(bitRate(f.intervals.front()));
      d.u32(frameBytes(f)).u32(f.intervals.front()).u8(n);
      for (const auto interval : f.intervals) d.u32(interval);
    }
    d.u8(6).u8(kCsInterface).u8(kVsColorFormat).u8(1).u8(1).u8(4);  // BT.709 primaries, BT.709 transfer, BT.601 matrix
  }
  d.patch16(vsHeader + 4, d.size() - vsHeader);
  d.u8(7).u8(kDescEndpoint).u8(kStreamingEndpoint).u8(0x02).u16(kHighSpeedBulkPacket).u8(0);
  d.patch16(2, d.size());
  cam.configDescriptor_ = d.take();

  cam.probe_ = cam.defaults();
  cam.commit_ = cam.probe_;
  return cam;
}

std::string UvcCamera::describe() const {
  return fmt::format("{:04x}:{:04x} {} (UVC 1.1, bulk streaming)", config_.vendor, config_.product,
                     config_.productName);
}

void UvcCamera::reset() {
  stopStreaming();
  configuration_ = 0;
  errorCode_ = 0;
  probe_ = defaults();
  commit_ = probe_;
}

ControlReply UvcCamera::control(const UsbSetup& setup, std::span<const std::uint8_t> data, Nanos now) {
  switch (setup.type()) {
    case 0: return standardRequest(setup, data);
    case 1: return classRequest(setup, data, now);
    default: return ControlReply::stall();
  }
}

ControlReply UvcCamera::refuse(std::uint8_t errorCode) {
  errorCode_ = errorCode;
  return ControlReply::stall();
}

ControlReply UvcCamera::standardRequest(const UsbSetup& s, std::span<const std::uint8_t> /*data*/) {
  const unsigned recipient = s.recipient();
  switch (s.request) {
    case kGetDescriptor: {
      if (!s.isIn() || recipient != 0) return ControlReply::stall();
      const unsigned type = s.value >> 8U;
      const unsigned index = s.value & 0xffU;
      if (type == kDescDevice) return reply(deviceDescriptor_, s.length);
      if (type == kDescConfiguration && index == 0) return reply(configDescriptor_, s.length);
      if (type == kDescString && index < strings_.size()) return reply(strings_[index], s.length);
      return ControlReply::stall();  // no device qualifier (a high-speed-only device), no BOS (USB 2.0)
    }
    case kSetAddress: return ok();
    case kSetConfiguration: {
      const unsigned value = s.value & 0xffU;
      if (value > 1) return ControlReply::stall();
      if (value != configuration_) stopStreaming();
      configuration_ = static_cast<std::uint8_t>(value);
      return ok();
    }
    case kGetConfiguration: return reply({configuration_}, s.length);
    case kGetStatus: return reply({0, 0}, s.length);  // bus powered, no remote wake-up, no halt
    case kClearFeature:
      if (recipient == 2 && s.value == kFeatureEndpointHalt) {
        // uvcvideo stops a bulk stream this way (as Windows does).
        if ((s.index & 0xffU) == kStreamingEndpoint) stopStreaming();
        return ok();
      }
      if (recipient == 0 && s.value == kFeatureRemoteWakeup) return ok();
      return ControlReply::stall();
    case kSetFeature:
      if ((recipient == 2 && s.value == kFeatureEndpointHalt) || (recipient == 0 && s.value == kFeatureRemoteWakeup)) {
        return ok();
      }
      return ControlReply::stall();
    case kSetInterface: {
      const unsigned interface = s.index & 0xffU;
      if (s.value != 0 || interface > kStreamingInterface) return ControlReply::stall();
      if (interface == kStreamingInterface) stopStreaming();
      return ok();
    }
    case kGetInterface:
      if ((s.index & 0xffU) > kStreamingInterface) return ControlReply::stall();
      return reply({0}, s.length);
    default: return ControlReply::stall();
  }
}

ControlReply UvcCamera::classRequest(const UsbSetup& s, std::span<const std::uint8_t> data, Nanos now) {
  if (s.recipient() != 1) return refuse(kErrInvalidRequest);
  if (configuration_ == 0) return refuse(kErrWrongState);
  const unsigned interface = s.index & 0xffU;
  const unsigned entity = s.index >> 8U;
  const unsigned selector = s.value >> 8U;
  if (interface == kControlInterface) {
    if (entity == 0) {
      if (selector != kVcRequestErrorCodeControl) return refuse(kErrInvalidControl);
      if (s.request == kGetCur) return reply({errorCode_}, s.length);  // reading it leaves it as it is
      if (s.request == kGetInfo) return reply({0x01}, s.length);
      return refuse(kErrInvalidRequest);
    }
    if (entity == kProcessingUnit && selector == kPuBrightnessControl) return brightnessControl(s, data);
    if (entity == kProcessingUnit || entity == kCameraTerminal || entity == kOutputTerminal) {
      return refuse(kErrInvalidControl);
    }
    return refuse(kErrInvalidUnit);
  }
  if (interface == kStreamingInterface) {
    if (entity != 0) return refuse(kErrInvalidUnit);
    if (selector != kVsProbeControl && selector != kVsCommitControl) return refuse(kErrInvalidControl);
    return streamingControl(s, data, now);
  }
  return refuse(kErrInvalidRequest);
}

ControlReply UvcCamera::brightnessControl(const UsbSetup& s, std::span<const std::uint8_t> data) {
  if (s.request == kSetCur) {
    if (s.isIn() || data.size() != 2) return refuse(kErrInvalidRequest);
    const auto value = static_cast<std::int16_t>(get16(data, 0));
    if (value < kBrightnessMin || value > kBrightnessMax) return refuse(kErrOutOfRange);
    brightness_ = value;
    errorCode_ = 0;
    return ok();
  }
  if (!s.isIn()) return refuse(kErrInvalidRequest);
  errorCode_ = 0;
  switch (s.request) {
    case kGetCur: return reply16(static_cast<unsigned>(brightness_), s.length);
    case kGetMin: return reply16(kBrightnessMin, s.length);
    case kGetMax: return reply16(kBrightnessMax, s.length);
    case kGetRes: return reply16(1, s.length);
    case kGetDef: return reply16(TestPicture::kNeutralBrightness, s.length);
    case kGetLen: return reply16(2, s.length);
    case kGetInfo: return reply({kInfoGetSet}, s.length);
    default: return refuse(kErrInvalidRequest);
  }
}

ControlReply UvcCamera::streamingControl(const UsbSetup& s, std::span<const std::uint8_t> data, Nanos now) {
  const bool commit = (s.value >> 8U) == kVsCommitControl;
  if (s.request == kSetCur) {
    if (s.isIn() || (data.size() != UvcStreamingControl::kSize && data.size() != UvcStreamingControl::kSizeUvc10)) {
      return refuse(kErrInvalidRequest);
    }
    const UvcStreamingControl wanted = negotiate(UvcStreamingControl::parse(data));
    errorCode_ = 0;
    if (commit) {
      commit_ = wanted;
      startStreaming(now);
    } else {
      probe_ = wanted;
    }
    return ok();
  }
  if (!s.isIn()) return refuse(kErrInvalidRequest);
  switch (s.request) {
    case kGetCur: errorCode_ = 0; return reply((commit ? commit_ : probe_).bytes(), s.length);
    case kGetInfo: errorCode_ = 0; return reply({kInfoGetSet}, s.length);
    case kGetLen: errorCode_ = 0; return reply16(UvcStreamingControl::kSize, s.length);
    case kGetMin:
    case kGetMax:
    case kGetDef: {
      if (commit) return refuse(kErrInvalidRequest);  // the commit control has GET_CUR only
      UvcStreamingControl c = s.request == kGetDef ? defaults() : probe_;
      const UvcFrameSize& f = frameSize(c);
      if (s.request == kGetMin) {
        c.frameInterval = f.intervals.front();
        c.compQuality = 0;
      } else if (s.request == kGetMax) {
        c.frameInterval = f.intervals.back();
        c.compQuality = config_.formats[c.formatIndex - 1U].pixelFormat == UvcPixelFormat::kMjpeg ? 10000 : 0;
      }
      errorCode_ = 0;
      return reply(c.bytes(), s.length);
    }
    default: return refuse(kErrInvalidRequest);  // GET_RES
  }
}

const UvcFrameSize& UvcCamera::frameSize(const UvcStreamingControl& c) const {
  return config_.formats[c.formatIndex - 1U].frames[c.frameIndex - 1U];
}

UvcStreamingControl UvcCamera::negotiate(const UvcStreamingControl& wanted) const {
  UvcStreamingControl c;
  c.hint = wanted.hint;
  c.formatIndex = wanted.formatIndex >= 1 && wanted.formatIndex <= config_.formats.size() ? wanted.formatIndex : 1;
  const UvcFormat& format = config_.formats[c.formatIndex - 1U];
  c.frameIndex = wanted.frameIndex >= 1 && wanted.frameIndex <= format.frames.size() ? wanted.frameIndex : 1;
  const UvcFrameSize& f = format.frames[c.frameIndex - 1U];
  c.frameInterval = f.intervals.front();
  if (wanted.frameInterval != 0) {
    // The offered interval nearest to the one asked for.
    std::uint32_t best = std::numeric_limits<std::uint32_t>::max();
    for (const auto interval : f.intervals) {
      const std::uint32_t distance =
          interval > wanted.frameInterval ? interval - wanted.frameInterval : wanted.frameInterval - interval;
      if (distance < best) {
        best = distance;
        c.frameInterval = interval;
      }
    }
  }
  const bool mjpeg = format.pixelFormat == UvcPixelFormat::kMjpeg;
  c.compQuality = mjpeg ? std::min<std::uint16_t>(wanted.compQuality, 10000) : 0;
  c.maxVideoFrameSize = frameBytes(f);
  c.maxPayloadTransferSize = config_.maxPayloadTransferSize;
  c.clockFrequency = kClockFrequency;
  c.framingInfo = 0x03;  // frame id and end of frame in every payload header
  c.preferredVersion = 1;
  c.minVersion = 1;
  c.maxVersion = 1;
  return c;
}

UvcStreamingControl UvcCamera::defaults() const { return negotiate(UvcStreamingControl{}); }

void UvcCamera::startStreaming(Nanos now) {
  const UvcFormat& format = config_.formats[commit_.formatIndex - 1U];
  picture_ = &pictures_[commit_.formatIndex - 1U][commit_.frameIndex - 1U];
  pixelFormat_ = format.pixelFormat;
  frameInterval_ = Nanos{std::int64_t{commit_.frameInterval} * 100};
  writer_.abort();
  writer_.setMaxPayload(commit_.maxPayloadTransferSize);
  streamStart_ = now;
  // The counter runs over the camera's life: a stream started again (uvcvideo commits at
  // VIDIOC_S_FMT and again at STREAMON) never goes back behind a frame already sent.
  counterBase_ = framesSent_ > 0 ? lastCounter_ + 1 : 0;
  nextFrameDue_ = now;
  lastFrameIndex_ = -1;
  fid_ = false;
  streaming_ = true;
}

void UvcCamera::stopStreaming() {
  streaming_ = false;
  writer_.abort();
}

std::optional<InCompletion> UvcCamera::transferIn(std::uint8_t endpoint, std::span<std::uint8_t> buffer, Nanos now) {
  if (endpoint != kStreamingEndpoint || configuration_ == 0) return InCompletion{UsbStatus::kStall, 0};
  if (!streaming_) return std::nullopt;
  if (!writer_.busy()) {
    if (now < nextFrameDue_) return std::nullopt;
    produceFrame(now);
  }
  return InCompletion{UsbStatus::kOk, writer_.fill(buffer)};
}

Nanos UvcCamera::readyAt() const {
  if (!streaming_) return Nanos::max();
  if (writer_.busy()) return Nanos::min();
  return nextFrameDue_;
}

void UvcCamera::produceFrame(Nanos now) {
  // The sensor runs on its own clock: frame n is captured at start + n * interval, and a host
  // that reads late misses frames (their counters are skipped), as with a real camera.
  std::int64_t index = (now - streamStart_) / frameInterval_;
  if (index <= lastFrameIndex_) index = lastFrameIndex_ + 1;
  const Nanos captured = streamStart_ + index * frameInterval_;
  nextFrameDue_ = captured + frameInterval_;
  const auto counter = counterBase_ + static_cast<std::uint32_t>(index);
  if (pixelFormat_ == UvcPixelFormat::kYuyv) {
    frame_.resize(std::size_t{picture_->width()} * picture_->height() * 2);
    picture_->renderYuyv(counter, brightness_, planes_, frame_);
  } else {
    picture_->renderPlanar(counter, brightness_, planes_);
    expandToFullRange(planes_);
    // The frame number in a COM segment too: the lab checks MJPEG frames by it without decoding
    // them (a decoder under TCG costs minutes); the unit tests decode the picture's own counter.
    jpeg_.encode(planes_, frame_, fmt::format("{}{}", kFrameComment, counter));
    if (frame_.size() > commit_.maxVideoFrameSize) ++oversizedFrames_;
  }
  // dwPresentationTime in units of dwClockFrequency (48 MHz: 6/125 per nanosecond), wrapping.
  const auto pts = static_cast<std::uint32_t>(static_cast<std::uint64_t>(captured.count()) * 6 / 125);
  writer_.startFrame(frame_, fid_, pts);
  fid_ = !fid_;
  lastFrameIndex_ = index;
  lastCounter_ = counter;
  ++framesSent_;
}

}  // namespace basalt::sim::vlab
