#pragma once

/// \file
/// \brief The virtual lab's webcam: a USB Video Class 1.1 camera emulated in user space, which
/// the kernel's uvcvideo driver binds as it binds a real one. It streams over a bulk endpoint
/// (uvcvideo drives bulk cameras as well as isochronous ones, and bulk needs no bus timing), in
/// YUYV and MJPEG at the sizes and frame intervals of its configuration, with UVC payload headers
/// (frame id, end of frame, presentation time) and the lab's moving test picture, which carries
/// the frame counter (test_picture.h). It answers the standard requests, the probe and commit
/// controls of the streaming interface, the request error code control and a brightness
/// control on its processing unit.
///
/// The device knows no transport: usbip.h and usbredir.h carry it to a host.

#include <algorithm>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/error.h"
#include "sim/jpeg_encoder.h"
#include "tools/vlab/uvc/test_picture.h"
#include "tools/vlab/uvc/usb_device.h"

namespace basalt::sim::vlab {

enum class UvcPixelFormat : std::uint8_t { kYuyv, kMjpeg };

/// \brief One frame size of a format and the frame intervals offered at it.
struct UvcFrameSize {
  std::uint16_t width = 0;
  std::uint16_t height = 0;
  /// Frame intervals in 100 ns units (333333 is 30 frames per second), shortest first; the
  /// first is the default.
  std::vector<std::uint32_t> intervals;
};

/// \brief A format of the streaming interface (bFormatIndex is its position + 1).
struct UvcFormat {
  UvcPixelFormat pixelFormat = UvcPixelFormat::kYuyv;
  std::vector<UvcFrameSize> frames;  ///< bFrameIndex is the position + 1; the first is the default
};

/// \brief What the camera is and offers.
struct UvcCameraConfig {
  std::uint16_t vendor = 0x1209;   ///< pid.codes, the open-source vendor id
  std::uint16_t product = 0x0002;  ///< pid.codes' test product 0002
  std::string manufacturer = "Basalt virtual lab";
  std::string productName = "Basalt Lab Camera";
  std::string serial = "vlab-uvc";
  std::vector<UvcFormat> formats;
  /// dwMaxPayloadTransferSize: the bytes of one payload (header included). uvcvideo reads a
  /// bulk camera with transfers of at most 32 packets of 512 bytes, so 16384 makes each
  /// transfer one payload.
  std::uint32_t maxPayloadTransferSize = 16384;
  int jpegQuality = 85;

  /// \brief The lab's camera: YUYV at 640x480 and 320x240, MJPEG at 1280x720 and 640x480, each
  /// at 30, 15 and 5 frames per second.
  static UvcCameraConfig labDefault();
};

/// \brief The probe and commit controls of UVC 1.1 (34 bytes, little-endian; UVC 1.1 table 4-47).
struct UvcStreamingControl {
  static constexpr std::size_t kSize = 34;
  static constexpr std::size_t kSizeUvc10 = 26;  ///< what UVC 1.0 hosts send

  std::uint16_t hint = 0;
  std::uint8_t formatIndex = 0;
  std::uint8_t frameIndex = 0;
  std::uint32_t frameInterval = 0;
  std::uint16_t keyFrameRate = 0;
  std::uint16_t pFrameRate = 0;
  std::uint16_t compQuality = 0;
  std::uint16_t compWindowSize = 0;
  std::uint16_t delay = 0;
  std::uint32_t maxVideoFrameSize = 0;
  std::uint32_t maxPayloadTransferSize = 0;
  std::uint32_t clockFrequency = 0;
  std::uint8_t framingInfo = 0;
  std::uint8_t preferredVersion = 0;
  std::uint8_t minVersion = 0;
  std::uint8_t maxVersion = 0;

  /// \brief Reads 26 or 34 bytes (the fields a shorter buffer lacks stay 0).
  static UvcStreamingControl parse(std::span<const std::uint8_t> bytes);
  [[nodiscard]] std::vector<std::uint8_t> bytes() const;
  bool operator==(const UvcStreamingControl&) const = default;
};

/// \brief Cuts frames into UVC payloads carried by bulk IN transfers, as uvcvideo reassembles
/// them: a payload starts with its header in the first transfer and ends with a transfer
/// shorter than asked for or when it reaches the negotiated maximum payload size; a frame's last
/// payload has the end-of-frame bit. When a payload's data ends exactly at the end of a full
/// transfer, a zero-length transfer follows to end it.
class UvcPayloadWriter {
 public:
  /// bHeaderLength, bmHeaderInfo and a 32-bit presentation time (no SCR: it needs the host's
  /// USB frame number, which vhci_hcd does not keep).
  static constexpr std::size_t kHeaderSize = 6;
  static constexpr std::uint8_t kFid = 0x01;
  static constexpr std::uint8_t kEof = 0x02;
  static constexpr std::uint8_t kPts = 0x04;
  static constexpr std::uint8_t kEoh = 0x80;

  /// \brief The maximum payload, header included (at least kHeaderSize + 1).
  void setMaxPayload(std::size_t bytes) { maxPayload_ = std::max(bytes, kHeaderSize + 1); }
  [[nodiscard]] std::size_t maxPayload() const { return maxPayload_; }
  /// \brief Starts sending `frame`, which must stay unchanged until busy() is false.
  void startFrame(std::span<const std::uint8_t> frame, bool fid, std::uint32_t pts);
  /// \brief Whether a frame (or the zero-length transfer that ends its last payload) is left.
  [[nodiscard]] bool busy() const { return busy_; }
  /// \brief Fills one IN transfer; returns its length (0 for a zero-length transfer).
  std::size_t fill(std::span<std::uint8_t> transfer);
  /// \brief Drops the rest of the frame (the host stopped the stream).
  void abort() { busy_ = false; }

 private:
  std::span<const std::uint8_t> frame_;
  std::size_t offset_ = 0;          // bytes of the frame sent
  std::size_t payloadLeft_ = 0;     // frame bytes still to go in the current payload
  std::size_t payloadBytes_ = 0;    // bytes of the current payload sent, header included
  std::size_t maxPayload_ = 16384;  // dwMaxPayloadTransferSize
  bool inPayload_ = false;
  bool needZeroLength_ = false;
  bool busy_ = false;
  bool eof_ = false;  // the current payload is the frame's last
  std::uint8_t info_ = 0;
  std::uint32_t pts_ = 0;
};

/// \brief The frame number an MJPEG frame of the camera carries in its COM segment
/// ("basalt-vlab-uvc frame N"), for checks that cannot afford to decode it; nothing when absent.
std::optional<std::uint32_t> mjpegFrameNumber(std::span<const std::uint8_t> jpeg);

/// \brief The camera. Threading: one thread (the transport's) uses it.
class UvcCamera final : public UsbDevice {
 public:
  static constexpr std::uint8_t kControlInterface = 0;
  static constexpr std::uint8_t kStreamingInterface = 1;
  static constexpr std::uint8_t kCameraTerminal = 1;
  static constexpr std::uint8_t kProcessingUnit = 2;
  static constexpr std::uint8_t kOutputTerminal = 3;
  static constexpr std::uint8_t kStreamingEndpoint = 0x81;
  static constexpr std::uint32_t kClockFrequency = 48'000'000;                 ///< dwClockFrequency, Hz
  static constexpr std::string_view kFrameComment = "basalt-vlab-uvc frame ";  ///< + the counter

  /// \brief Fails with kInvalidArgument for a configuration a host could not use (no format, a
  /// format without sizes or intervals, a size the test picture cannot have, more than 32
  /// formats or sizes, a payload size outside 512..3 MB).
  [[nodiscard]] static Result<UvcCamera> create(UvcCameraConfig config);

  // UsbDevice
  [[nodiscard]] const UsbIdentity& identity() const override { return identity_; }
  void reset() override;
  ControlReply control(const UsbSetup& setup, std::span<const std::uint8_t> data, Nanos now) override;
  std::optional<InCompletion> transferIn(std::uint8_t endpoint, std::span<std::uint8_t> buffer, Nanos now) override;
  [[nodiscard]] Nanos readyAt() const override;
  [[nodiscard]] std::string describe() const override;

  [[nodiscard]] const UvcCameraConfig& config() const { return config_; }
  [[nodiscard]] const std::vector<std::uint8_t>& deviceDescriptor() const { return deviceDescriptor_; }
  [[nodiscard]] const std::vector<std::uint8_t>& configurationDescriptor() const { return configDescriptor_; }
  [[nodiscard]] bool configured() const { return configuration_ != 0; }
  [[nodiscard]] bool streaming() const { return streaming_; }
  [[nodiscard]] const UvcStreamingControl& probe() const { return probe_; }
  [[nodiscard]] const UvcStreamingControl& commit() const { return commit_; }
  [[nodiscard]] int brightness() const { return brightness_; }
  /// \brief Frames started since the camera was made (over every stream).
  [[nodiscard]] std::uint64_t framesSent() const { return framesSent_; }
  /// \brief The counter of the last frame started (frames are numbered from 0 at each stream start).
  [[nodiscard]] std::uint32_t lastFrameCounter() const { return lastCounter_; }
  /// \brief Frames whose encoding was larger than dwMaxVideoFrameSize (sent anyway; the host
  /// drops them).
  [[nodiscard]] std::uint64_t oversizedFrames() const { return oversizedFrames_; }

  UvcCamera(UvcCamera&&) noexcept = default;
  UvcCamera& operator=(UvcCamera&&) noexcept = default;
  UvcCamera(const UvcCamera&) = delete;
  UvcCamera& operator=(const UvcCamera&) = delete;
  ~UvcCamera() override = default;

 private:
  explicit UvcCamera(UvcCameraConfig config) : config_(std::move(config)), jpeg_(config_.jpegQuality) {}

  ControlReply standardRequest(const UsbSetup& setup, std::span<const std::uint8_t> data);
  ControlReply classRequest(const UsbSetup& setup, std::span<const std::uint8_t> data, Nanos now);
  ControlReply streamingControl(const UsbSetup& setup, std::span<const std::uint8_t> data, Nanos now);
  ControlReply brightnessControl(const UsbSetup& setup, std::span<const std::uint8_t> data);
  ControlReply refuse(std::uint8_t errorCode);
  /// The control the camera answers to `request` for probe/commit: the host's wishes adjusted
  /// to what it offers.
  [[nodiscard]] UvcStreamingControl negotiate(const UvcStreamingControl& wanted) const;
  [[nodiscard]] UvcStreamingControl defaults() const;
  void startStreaming(Nanos now);
  void stopStreaming();
  void produceFrame(Nanos now);
  [[nodiscard]] const UvcFrameSize& frameSize(const UvcStreamingControl& c) const;

  UvcCameraConfig config_;
  UsbIdentity identity_;
  std::vector<std::uint8_t> deviceDescriptor_;
  std::vector<std::uint8_t> configDescriptor_;
  std::vector<std::vector<std::uint8_t>> strings_;  // string descriptors by index
  std::vector<std::vector<TestPicture>> pictures_;  // [format][frame]
  JpegEncoder jpeg_;

  std::uint8_t configuration_ = 0;
  std::uint8_t errorCode_ = 0;  // VC_REQUEST_ERROR_CODE_CONTROL
  int brightness_ = TestPicture::kNeutralBrightness;
  UvcStreamingControl probe_;
  UvcStreamingControl commit_;

  bool streaming_ = false;
  bool fid_ = false;
  Nanos streamStart_{0};
  Nanos frameInterval_{0};
  Nanos nextFrameDue_{0};
  std::int64_t lastFrameIndex_ = -1;
  std::uint32_t lastCounter_ = 0;
  std::uint32_t counterBase_ = 0;  ///< the first counter of the current stream
  std::uint64_t framesSent_ = 0;
  std::uint64_t oversizedFrames_ = 0;
  const TestPicture* picture_ = nullptr;
  UvcPixelFormat pixelFormat_ = UvcPixelFormat::kYuyv;
  Yuv422Planes planes_;
  std::vector<std::uint8_t> frame_;
  UvcPayloadWriter writer_;
};

}  // namespace basalt::sim::vlab
