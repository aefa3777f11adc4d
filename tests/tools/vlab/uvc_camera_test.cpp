// The virtual lab's UVC camera (tools/vlab/uvc): its test picture and frame counter, its JPEG
// encoder (checked with a real decoder, OpenImageIO's), its payloads (reassembled the way Linux's
// uvcvideo reassembles a bulk stream), its descriptors and its control requests. The camera's
// life with a real kernel is tested in the virtual lab (tests/tools/vlab/lab_selftest.cpp); these
// tests pin down the behaviour that the lab's tests rely on, quickly and without qemu.

#include "tools/vlab/uvc/uvc_camera.h"

#include <gtest/gtest.h>

#include <fstream>
#include <map>

#include "media/image_io.h"
#include "sim/jpeg_encoder.h"
#include "support/test_paths.h"
#include "tools/vlab/uvc/test_picture.h"

namespace basalt::sim::vlab {
namespace {

using namespace std::chrono_literals;

// What uvcvideo does with the transfers of a bulk stream (drivers/media/usb/uvc/uvc_video.c,
// uvc_video_decode_bulk): a payload starts with a header in its first transfer, ends with a
// short transfer or at dwMaxPayloadTransferSize bytes; the frame id toggles between frames and
// the end-of-frame bit closes one. Records every frame and any protocol fault.
class BulkStreamReader {
 public:
  explicit BulkStreamReader(std::size_t maxPayload) : maxPayload_(maxPayload) {}

  void transfer(std::span<const std::uint8_t> data, std::size_t asked) {
    if (data.empty() && headerSize_ == 0) return;  // a zero-length transfer outside a payload
    payloadSize_ += data.size();
    std::size_t at = 0;
    if (headerSize_ == 0) {
      if (data.size() < 2 || data[0] < 2 || data[0] > data.size()) {
        faults_.push_back("bad payload header");
        skip_ = true;
      } else {
        headerSize_ = data[0];
        info_ = data[1];
        if ((info_ & 0x80) == 0) faults_.push_back("no end-of-header bit");
        const bool fid = (info_ & 0x01) != 0;
        if (inFrame_ && fid != fid_) faults_.push_back("frame id toggled inside a frame");
        if (!inFrame_ && haveFid_ && fid == fid_) faults_.push_back("frame id did not toggle for a new frame");
        fid_ = fid;
        haveFid_ = true;
        inFrame_ = true;
        if ((info_ & 0x04) != 0 && headerSize_ >= 6) {
          pts_ = static_cast<std::uint32_t>(data[2] | (data[3] << 8) | (data[4] << 16) | (data[5] << 24));
        }
        at = headerSize_;
      }
    }
    if (!skip_) current_.insert(current_.end(), data.begin() + static_cast<std::ptrdiff_t>(at), data.end());
    if (data.size() < asked || payloadSize_ >= maxPayload_) {
      if (!skip_ && (info_ & 0x02) != 0) {
        frames_.push_back(std::move(current_));
        ptsList_.push_back(pts_);
        current_.clear();
        inFrame_ = false;
      }
      headerSize_ = 0;
      payloadSize_ = 0;
      skip_ = false;
    }
  }

  [[nodiscard]] const std::vector<std::vector<std::uint8_t>>& frames() const { return frames_; }
  [[nodiscard]] const std::vector<std::uint32_t>& pts() const { return ptsList_; }
  [[nodiscard]] const std::vector<std::string>& faults() const { return faults_; }

 private:
  std::size_t maxPayload_;
  std::size_t headerSize_ = 0;
  std::size_t payloadSize_ = 0;
  std::uint8_t info_ = 0;
  bool skip_ = false;
  bool fid_ = false;
  bool haveFid_ = false;
  bool inFrame_ = false;
  std::uint32_t pts_ = 0;
  std::vector<std::uint8_t> current_;
  std::vector<std::vector<std::uint8_t>> frames_;
  std::vector<std::uint32_t> ptsList_;
  std::vector<std::string> faults_;
};

std::vector<std::uint8_t> sequence(std::size_t n) {
  std::vector<std::uint8_t> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<std::uint8_t>(i * 7 + i / 251);
  return v;
}

/// Decodes a JPEG file's bytes with OpenImageIO (libjpeg underneath).
// Each call has a folder of its own: ctest runs the cases in parallel processes, and scratchDir()
// empties the folder it gives.
Result<Image> decodeJpeg(std::span<const std::uint8_t> jpeg, const std::string& name) {
  const auto path = test::scratchDir("uvc_camera_test-" + name) / (name + ".jpg");
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(jpeg.data()), static_cast<std::streamsize>(jpeg.size()));
  return media::readImage(path);
}

UsbSetup setup(std::uint8_t type, std::uint8_t request, std::uint16_t value, std::uint16_t index,
               std::uint16_t length) {
  return {type, request, value, index, length};
}

// ---- the test picture --------------------------------------------------------------------------

// Makes sure sizes the counter cells cannot fit are refused with a message, not drawn wrong.
// Example failure: a 160x120 picture is accepted and its counter cells run off the right edge.
TEST(UvcTestPicture, RefusesSizesTheCounterDoesNotFit) {
  EXPECT_FALSE(TestPicture::create(160, 120));
  EXPECT_FALSE(TestPicture::create(322, 240));  // not a multiple of 16
  EXPECT_FALSE(TestPicture::create(320, 244));  // not a multiple of 8
  auto bad = TestPicture::create(0, 0);
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().code(), Errc::kInvalidArgument);
  EXPECT_NE(bad.error().message().find("multiple of 16"), std::string::npos) << bad.error().message();
  EXPECT_TRUE(TestPicture::create(320, 240));
  EXPECT_TRUE(TestPicture::create(1280, 720));
}

// Makes sure the counter drawn into a YUYV frame reads back exactly, at every size the lab
// camera offers and at the extremes of brightness. Example failure: the complement row is drawn
// one cell off, so no frame's counter checks.
TEST(UvcTestPicture, CounterReadsBackFromYuyv) {
  for (const auto& [w, h] : {std::pair{320U, 240U}, std::pair{640U, 480U}, std::pair{1280U, 720U}}) {
    auto picture = TestPicture::create(w, h);
    ASSERT_TRUE(picture) << picture.error().describe();
    Yuv422Planes scratch;
    std::vector<std::uint8_t> frame(std::size_t{w} * h * 2);
    for (const std::uint32_t counter : {0U, 1U, 2U, 12345U, 0x80000000U, 0xffffffffU}) {
      for (const int brightness : {0, 128, 255}) {
        picture->renderYuyv(counter, brightness, scratch, frame);
        EXPECT_EQ(readFrameCounterYuyv(frame, w, h), counter) << w << "x" << h << " brightness " << brightness;
      }
    }
  }
}

// Makes sure a picture without the cells is not read as a counter. Example failure: a grey
// frame (a camera that sends nothing useful) reads as counter 0 and a test passes.
TEST(UvcTestPicture, FlatPictureHasNoCounter) {
  std::vector<std::uint8_t> grey(std::size_t{320} * 240 * 2, 128);
  EXPECT_FALSE(readFrameCounterYuyv(grey, 320, 240));
  EXPECT_FALSE(readFrameCounterYuyv(std::span<const std::uint8_t>(grey).first(100), 320, 240));
}

// Makes sure consecutive frames differ (the bar moves) and that brightness moves luma. Example
// failure: the picture is static, so a capture that repeats one frame would go unnoticed.
TEST(UvcTestPicture, PictureMovesAndFollowsBrightness) {
  auto picture = TestPicture::create(320, 240);
  ASSERT_TRUE(picture);
  Yuv422Planes a;
  Yuv422Planes b;
  picture->renderPlanar(10, 128, a);
  picture->renderPlanar(11, 128, b);
  EXPECT_NE(a.y, b.y);
  picture->renderPlanar(10, 200, b);
  EXPECT_GT(b.y[std::size_t{320} * 50 + 300], a.y[std::size_t{320} * 50 + 300]);
}

// ---- JPEG ------------------------------------------------------------------------------------

// Makes sure the encoder's files decode with libjpeg (through OpenImageIO) to the picture it
// was given, with the counter intact, at each MJPEG size of the lab camera. Example failure: a
// Huffman table typo, so libjpeg stops with "Corrupt JPEG data" and every MJPEG capture in the
// lab is garbage.
TEST(UvcJpeg, FramesDecodeWithLibjpegToThePicture) {
  for (const auto& [w, h] : {std::pair{640U, 480U}, std::pair{1280U, 720U}}) {
    auto picture = TestPicture::create(w, h);
    ASSERT_TRUE(picture);
    Yuv422Planes planes;
    picture->renderPlanar(4242, 128, planes);
    expandToFullRange(planes);
    JpegEncoder encoder(85);
    std::vector<std::uint8_t> jpeg;
    encoder.encode(planes, jpeg);
    ASSERT_GT(jpeg.size(), 1000U);
    EXPECT_LT(jpeg.size(), std::size_t{w} * h) << "a JPEG larger than one byte per pixel";
    EXPECT_EQ(jpeg[0], 0xff);
    EXPECT_EQ(jpeg[1], 0xd8);
    EXPECT_EQ(jpeg[jpeg.size() - 2], 0xff);
    EXPECT_EQ(jpeg.back(), 0xd9);
    auto image = decodeJpeg(jpeg, "picture" + std::to_string(w));
    ASSERT_TRUE(image) << image.error().describe();
    ASSERT_EQ(image->width, w);
    ASSERT_EQ(image->height, h);
    EXPECT_EQ(readFrameCounterRgb(*image), 4242U);
    // The first colour bar is 75% white (sampled right of the moving bar, which is at 2 to 3
    // cells for this counter); the sixth is 75% red.
    const std::uint32_t y = h / 4;
    const std::uint32_t white = w / 7 - 2 * (w / 40);
    for (std::uint32_t c = 0; c < 3; ++c) EXPECT_NEAR(image->at(white, y, c), 191, 8) << "channel " << c;
    const std::uint32_t red = w * 11 / 14;
    EXPECT_NEAR(image->at(red, y, 0), 191, 10);
    EXPECT_NEAR(image->at(red, y, 1), 0, 10);
    EXPECT_NEAR(image->at(red, y, 2), 0, 10);
  }
}

// Makes sure sizes that are not a whole number of 16x8 blocks still make a valid file (the
// edge repeated). Example failure: the encoder reads past the end of the planes.
TEST(UvcJpeg, OddSizesArePadded) {
  Yuv422Planes planes;
  planes.resize(40, 20);
  std::fill(planes.y.begin(), planes.y.end(), 200);
  std::fill(planes.cb.begin(), planes.cb.end(), 128);
  std::fill(planes.cr.begin(), planes.cr.end(), 128);
  std::vector<std::uint8_t> jpeg;
  JpegEncoder(50).encode(planes, jpeg);
  auto image = decodeJpeg(jpeg, "odd");
  ASSERT_TRUE(image) << image.error().describe();
  EXPECT_EQ(image->width, 40U);
  EXPECT_EQ(image->height, 20U);
  EXPECT_NEAR(image->at(39, 19, 1), 200, 4);
}

// Makes sure the JPEG header reader finds size and comment in the encoder's files and refuses
// what is not a JPEG file or is cut short. Example failure: a frame cut off inside a segment is
// read past its end.
TEST(UvcJpeg, HeaderReaderFindsSizeAndComment) {
  auto picture = TestPicture::create(320, 240);
  ASSERT_TRUE(picture);
  Yuv422Planes planes;
  picture->renderPlanar(7, 128, planes);
  std::vector<std::uint8_t> jpeg;
  JpegEncoder().encode(planes, jpeg, "basalt-vlab-uvc frame 7");
  const auto info = inspectJpeg(jpeg);
  ASSERT_TRUE(info);
  EXPECT_EQ(info->width, 320U);
  EXPECT_EQ(info->height, 240U);
  EXPECT_TRUE(info->baseline);
  EXPECT_TRUE(info->complete);
  EXPECT_EQ(info->comment, "basalt-vlab-uvc frame 7");
  EXPECT_EQ(mjpegFrameNumber(jpeg), 7U);
  auto decoded = decodeJpeg(jpeg, "comment");
  ASSERT_TRUE(decoded) << "a COM segment must not upset a decoder: " << decoded.error().describe();
  EXPECT_EQ(readFrameCounterRgb(*decoded), 7U);

  const auto cut = std::span<const std::uint8_t>(jpeg).first(jpeg.size() - 100);
  ASSERT_TRUE(inspectJpeg(cut));
  EXPECT_FALSE(inspectJpeg(cut)->complete);
  EXPECT_FALSE(inspectJpeg(std::span<const std::uint8_t>(jpeg).first(30)));
  EXPECT_FALSE(inspectJpeg(std::span<const std::uint8_t>(jpeg).subspan(2)));
  std::vector<std::uint8_t> noComment;
  JpegEncoder().encode(planes, noComment);
  EXPECT_FALSE(mjpegFrameNumber(noComment));
  EXPECT_EQ(noComment.size() + 4 + 23, jpeg.size());
}

// ---- payloads -------------------------------------------------------------------------------

struct PayloadCase {
  std::size_t frameSize;
  std::size_t transferSize;
  std::size_t maxPayload;
};

// Makes sure frames cut into payloads come back whole and in order from a uvcvideo-style
// reassembly, for payloads that fit a transfer, that span transfers, that are smaller than a
// transfer, and that end exactly at a transfer's end (which needs a zero-length transfer).
// Example failure: a payload ending on a full transfer is not closed, so uvcvideo glues the
// next frame's header into this frame's data.
TEST(UvcPayloads, FramesSurviveUvcvideoReassembly) {
  const std::vector<PayloadCase> cases = {
      {153600, 16384, 16384},                      // 320x240 YUYV, one payload per transfer
      {153600, 512, 16384},                        // payloads spanning 32 transfers
      {10000, 16384, 4096},                        // payloads shorter than the transfer
      {16384 - 6, 16384, 32768},                   // payload data ends exactly at a full transfer: zero-length follows
      {1, 512, 16384},           {0, 512, 16384},  // an empty frame is a header with the end-of-frame bit
  };
  for (const auto& c : cases) {
    UvcPayloadWriter writer;
    writer.setMaxPayload(c.maxPayload);
    BulkStreamReader reader(c.maxPayload);
    std::vector<std::vector<std::uint8_t>> sent;
    for (std::uint32_t f = 0; f < 3; ++f) {
      sent.push_back(sequence(c.frameSize + f));
      writer.startFrame(sent.back(), f % 2 == 1, 1000 * f);
      std::vector<std::uint8_t> transfer(c.transferSize);
      int guard = 0;
      while (writer.busy() && ++guard < 100000) {
        const std::size_t n = writer.fill(transfer);
        reader.transfer(std::span<const std::uint8_t>(transfer).first(n), transfer.size());
      }
    }
    EXPECT_TRUE(reader.faults().empty()) << reader.faults().front();
    ASSERT_EQ(reader.frames().size(), 3U) << "frame " << c.frameSize << " transfer " << c.transferSize;
    for (std::size_t f = 0; f < 3; ++f) {
      EXPECT_EQ(reader.frames()[f], sent[f]) << "frame " << f << " of case " << c.frameSize << "/" << c.transferSize;
      EXPECT_EQ(reader.pts()[f], 1000 * f);
    }
  }
}

// ---- the camera --------------------------------------------------------------------------------

class UvcCameraTest : public testing::Test {
 protected:
  void SetUp() override {
    auto cam = UvcCamera::create(UvcCameraConfig::labDefault());
    ASSERT_TRUE(cam) << cam.error().describe();
    camera_.emplace(std::move(*cam));
    ASSERT_EQ(control(setup(0x00, 0x09, 1, 0, 0)).status, UsbStatus::kOk);  // SET_CONFIGURATION 1
  }

  ControlReply control(const UsbSetup& s, std::span<const std::uint8_t> data = {}) {
    return camera_->control(s, data, now_);
  }
  // Class requests on the streaming interface (1) and the processing unit (unit 2 of interface 0).
  ControlReply streaming(std::uint8_t request, std::uint8_t selector, std::span<const std::uint8_t> data = {},
                         std::uint16_t length = UvcStreamingControl::kSize) {
    const std::uint8_t type = request & 0x80 ? 0xa1 : 0x21;
    return control(setup(type, request, static_cast<std::uint16_t>(selector << 8), 1,
                         request & 0x80 ? length : static_cast<std::uint16_t>(data.size())),
                   data);
  }
  ControlReply brightness(std::uint8_t request, std::span<const std::uint8_t> data = {}) {
    const std::uint8_t type = request & 0x80 ? 0xa1 : 0x21;
    return control(setup(type, request, 0x0200, 0x0200, 2), data);
  }
  std::uint8_t errorCode() {
    const auto r = control(setup(0xa1, 0x81, 0x0200, 0x0000, 1));
    return r.data.empty() ? 0xff : r.data[0];
  }
  UvcStreamingControl commit(std::uint8_t format, std::uint8_t frame, std::uint32_t interval) {
    UvcStreamingControl c;
    c.formatIndex = format;
    c.frameIndex = frame;
    c.frameInterval = interval;
    EXPECT_EQ(streaming(0x01, 1, c.bytes()).status, UsbStatus::kOk);   // SET_CUR probe
    const auto probe = streaming(0x81, 1);                             // GET_CUR probe
    EXPECT_EQ(streaming(0x01, 2, probe.data).status, UsbStatus::kOk);  // SET_CUR commit
    return UvcStreamingControl::parse(probe.data);
  }
  /// Reads transfers until `frames` more frames have come or the camera has nothing to send.
  void readFrames(BulkStreamReader& reader, std::size_t frames, std::size_t transferSize = 16384) {
    std::vector<std::uint8_t> transfer(transferSize);
    const std::size_t target = reader.frames().size() + frames;
    int guard = 0;
    while (reader.frames().size() < target && ++guard < 100000) {
      auto done = camera_->transferIn(UvcCamera::kStreamingEndpoint, transfer, now_);
      if (!done) {
        ASSERT_NE(camera_->readyAt(), Nanos::max()) << "the camera stopped streaming";
        now_ = std::max(now_, camera_->readyAt());
        continue;
      }
      ASSERT_EQ(done->status, UsbStatus::kOk);
      reader.transfer(std::span<const std::uint8_t>(transfer).first(done->length), transfer.size());
    }
  }

  std::optional<UvcCamera> camera_;
  Nanos now_{1'000'000'000};
};

// Makes sure the descriptors are what uvcvideo parses: a device with an interface association,
// a VideoControl interface with the camera terminal, processing unit and output terminal, and a
// VideoStreaming interface with both formats, every frame size and interval, and one bulk
// endpoint; wTotalLength fields that match. Example failure: the VC header's wTotalLength
// counts the wrong bytes, so uvcvideo rejects the device ("Found no valid video chain").
TEST_F(UvcCameraTest, DescriptorsDescribeABulkUvcCamera) {
  const auto dev = control(setup(0x80, 0x06, 0x0100, 0, 64));
  ASSERT_EQ(dev.data.size(), 18U);
  EXPECT_EQ(dev.data[4], 0xef);  // miscellaneous class: IAD
  EXPECT_EQ(dev.data[8] | (dev.data[9] << 8), 0x1209);
  EXPECT_EQ(dev.data[10] | (dev.data[11] << 8), 0x0002);
  const auto head = control(setup(0x80, 0x06, 0x0200, 0, 9));
  ASSERT_EQ(head.data.size(), 9U);
  const std::size_t total = head.data[2] | (std::size_t{head.data[3]} << 8U);
  const auto cfg = control(setup(0x80, 0x06, 0x0200, 0, 0xffff));
  ASSERT_EQ(cfg.data.size(), total);

  // Walk the descriptors.
  std::map<std::uint8_t, int> subtypes;  // class-specific subtype -> count (VS ones offset by 0x40)
  int interfaces = 0;
  int endpoints = 0;
  bool inStreaming = false;
  std::size_t vcHeaderAt = 0;
  std::size_t vsHeaderAt = 0;
  for (std::size_t at = 0; at < cfg.data.size();) {
    const std::size_t len = cfg.data[at];
    ASSERT_GE(len, 2U);
    ASSERT_LE(at + len, cfg.data.size());
    const std::uint8_t type = cfg.data[at + 1];
    if (type == 4) {
      ++interfaces;
      inStreaming = cfg.data[at + 6] == 0x02;
    } else if (type == 5) {
      ++endpoints;
      EXPECT_EQ(cfg.data[at + 2], 0x81);
      EXPECT_EQ(cfg.data[at + 3], 0x02) << "not a bulk endpoint";
      EXPECT_EQ(cfg.data[at + 4] | (cfg.data[at + 5] << 8), 512);
    } else if (type == 0x24) {
      const std::uint8_t subtype = cfg.data[at + 2];
      if (!inStreaming && subtype == 0x01) vcHeaderAt = at;
      if (inStreaming && subtype == 0x01) vsHeaderAt = at;
      ++subtypes[static_cast<std::uint8_t>(subtype + (inStreaming ? 0x40 : 0))];
    }
    at += len;
  }
  EXPECT_EQ(interfaces, 2);
  EXPECT_EQ(endpoints, 1);
  EXPECT_EQ(subtypes[0x02], 1);         // camera terminal
  EXPECT_EQ(subtypes[0x05], 1);         // processing unit
  EXPECT_EQ(subtypes[0x03], 1);         // output terminal
  EXPECT_EQ(subtypes[0x40 + 0x04], 1);  // uncompressed format
  EXPECT_EQ(subtypes[0x40 + 0x05], 2);  // its two frame sizes
  EXPECT_EQ(subtypes[0x40 + 0x06], 1);  // MJPEG format
  EXPECT_EQ(subtypes[0x40 + 0x07], 2);
  // VC header: wTotalLength covers the header and the three entities (13 + 18 + 12 + 9).
  EXPECT_EQ(cfg.data[vcHeaderAt + 5] | (cfg.data[vcHeaderAt + 6] << 8), 52);
  // VS input header: wTotalLength runs to the endpoint descriptor (the last 7 bytes).
  EXPECT_EQ(vsHeaderAt + (cfg.data[vsHeaderAt + 4] | (std::size_t{cfg.data[vsHeaderAt + 5]} << 8U)),
            cfg.data.size() - 7);

  const auto product = control(setup(0x80, 0x06, 0x0302, 0x0409, 255));
  ASSERT_EQ(product.data.size(), 2 + 2 * std::string("Basalt Lab Camera").size());
  EXPECT_EQ(product.data[2], 'B');
  EXPECT_EQ(control(setup(0x80, 0x06, 0x0600, 0, 10)).status, UsbStatus::kStall) << "device qualifier";
}

// Makes sure probe negotiates: asked-for values the camera has are kept, others are replaced
// by the nearest it has, and the camera fills in sizes and the clock. Example failure: the
// camera echoes an interval it does not offer, and the stream runs at a rate nobody asked for.
TEST_F(UvcCameraTest, ProbeNegotiatesFormatSizeAndInterval) {
  const auto def = UvcStreamingControl::parse(streaming(0x87, 1).data);  // GET_DEF
  EXPECT_EQ(def.formatIndex, 1);
  EXPECT_EQ(def.frameIndex, 1);
  EXPECT_EQ(def.frameInterval, 333333U);
  EXPECT_EQ(def.maxVideoFrameSize, 640U * 480 * 2);
  EXPECT_EQ(def.maxPayloadTransferSize, 16384U);
  EXPECT_EQ(def.clockFrequency, 48'000'000U);

  UvcStreamingControl want;
  want.formatIndex = 2;
  want.frameIndex = 2;
  want.frameInterval = 700000;  // nearest offered: 666666
  ASSERT_EQ(streaming(0x01, 1, want.bytes()).status, UsbStatus::kOk);
  const auto got = UvcStreamingControl::parse(streaming(0x81, 1).data);
  EXPECT_EQ(got.formatIndex, 2);
  EXPECT_EQ(got.frameIndex, 2);
  EXPECT_EQ(got.frameInterval, 666666U);
  EXPECT_EQ(got.maxVideoFrameSize, 640U * 480 * 2);
  EXPECT_EQ(UvcStreamingControl::parse(streaming(0x82, 1).data).frameInterval, 333333U);   // GET_MIN
  EXPECT_EQ(UvcStreamingControl::parse(streaming(0x83, 1).data).frameInterval, 2000000U);  // GET_MAX

  want.formatIndex = 9;  // no such format: the camera picks its first
  want.frameIndex = 7;
  ASSERT_EQ(streaming(0x01, 1, want.bytes()).status, UsbStatus::kOk);
  const auto fixed = UvcStreamingControl::parse(streaming(0x81, 1).data);
  EXPECT_EQ(fixed.formatIndex, 1);
  EXPECT_EQ(fixed.frameIndex, 1);
  EXPECT_FALSE(camera_->streaming()) << "probing must not start the stream";
}

// Makes sure malformed requests stall and say why through the request error code control, and
// that nothing is streamed before SET_CONFIGURATION. Example failure: a 3-byte SET_CUR on the
// probe control is taken, and the camera negotiates from garbage.
TEST_F(UvcCameraTest, BadRequestsStallWithAnErrorCode) {
  const std::vector<std::uint8_t> shortProbe = {1, 0, 1};
  EXPECT_EQ(streaming(0x01, 1, shortProbe).status, UsbStatus::kStall);
  EXPECT_EQ(errorCode(), 0x07);  // invalid request
  EXPECT_EQ(streaming(0x81, 9).status, UsbStatus::kStall);
  EXPECT_EQ(errorCode(), 0x06);  // invalid control
  EXPECT_EQ(control(setup(0xa1, 0x81, 0x0200, 0x0700, 2)).status, UsbStatus::kStall);
  EXPECT_EQ(errorCode(), 0x05);  // invalid unit
  EXPECT_EQ(streaming(0x87, 2).status, UsbStatus::kStall) << "GET_DEF on commit";
  EXPECT_EQ(streaming(0x81, 1).status, UsbStatus::kOk);
  EXPECT_EQ(errorCode(), 0x00) << "a good request clears the error code";

  std::vector<std::uint8_t> transfer(512);
  auto stalled = camera_->transferIn(0x82, transfer, now_);
  ASSERT_TRUE(stalled);
  EXPECT_EQ(stalled->status, UsbStatus::kStall) << "an endpoint the camera does not have";
  EXPECT_FALSE(camera_->transferIn(0x81, transfer, now_)) << "no stream yet: the transfer waits";

  camera_->reset();
  EXPECT_EQ(streaming(0x81, 1).status, UsbStatus::kStall) << "class request while unconfigured";
}

// Makes sure the brightness control has its range and default and refuses values outside it.
// Example failure: SET_CUR 300 is stored, and the picture wraps around to black.
TEST_F(UvcCameraTest, BrightnessControlKeepsItsRange) {
  auto value = [](const ControlReply& r) { return r.data.size() == 2 ? r.data[0] | (r.data[1] << 8) : -1; };
  EXPECT_EQ(value(brightness(0x82)), 0);
  EXPECT_EQ(value(brightness(0x83)), 255);
  EXPECT_EQ(value(brightness(0x87)), 128);
  EXPECT_EQ(value(brightness(0x84)), 1);
  EXPECT_EQ(brightness(0x86).data, std::vector<std::uint8_t>{0x03});
  const std::vector<std::uint8_t> tooHigh = {0x2c, 0x01};  // 300
  EXPECT_EQ(brightness(0x01, tooHigh).status, UsbStatus::kStall);
  EXPECT_EQ(errorCode(), 0x04);  // out of range
  const std::vector<std::uint8_t> bright = {200, 0};
  EXPECT_EQ(brightness(0x01, bright).status, UsbStatus::kOk);
  EXPECT_EQ(value(brightness(0x81)), 200);
  EXPECT_EQ(camera_->brightness(), 200);
}

// Makes sure a committed YUYV stream sends whole frames of the negotiated size, paced by the
// frame interval, with counters that follow the camera's clock, and stops on CLEAR_FEATURE
// (ENDPOINT_HALT) as uvcvideo stops bulk cameras. Example failure: the camera sends the next
// frame as soon as the host asks, so a "30 fps" camera floods the host.
TEST_F(UvcCameraTest, YuyvStreamIsPacedAndCounted) {
  const auto c = commit(1, 2, 333333);  // YUYV 320x240 at 30 fps
  ASSERT_TRUE(camera_->streaming());
  BulkStreamReader reader(c.maxPayloadTransferSize);
  const Nanos start = now_;
  readFrames(reader, 3);
  ASSERT_EQ(reader.frames().size(), 3U);
  EXPECT_TRUE(reader.faults().empty()) << reader.faults().front();
  for (std::size_t i = 0; i < 3; ++i) {
    ASSERT_EQ(reader.frames()[i].size(), 320U * 240 * 2);
    EXPECT_EQ(readFrameCounterYuyv(reader.frames()[i], 320, 240), i);
  }
  EXPECT_EQ(now_ - start, Nanos{2 * 33'333'300}) << "frame 2 is due two intervals after the start";
  EXPECT_EQ(reader.pts()[1] - reader.pts()[0], 33'333'300U * 6 / 125);

  // A host that comes back late gets the frame of now, not the ones it missed.
  now_ += 1s;
  readFrames(reader, 1);
  ASSERT_EQ(reader.frames().size(), 4U);
  EXPECT_EQ(readFrameCounterYuyv(reader.frames()[3], 320, 240), 32U);

  ASSERT_EQ(control(setup(0x02, 0x01, 0, 0x81, 0)).status, UsbStatus::kOk);  // CLEAR_FEATURE(ENDPOINT_HALT)
  EXPECT_FALSE(camera_->streaming());
  std::vector<std::uint8_t> transfer(16384);
  EXPECT_FALSE(camera_->transferIn(0x81, transfer, now_ + 10s));
  EXPECT_EQ(camera_->readyAt(), Nanos::max());
}

// Makes sure an MJPEG stream sends JPEG files a real decoder reads, with the counter in the
// picture, and that brightness set before streaming shows in it. Example failure: the camera
// sends YUYV bytes for the MJPEG format.
TEST_F(UvcCameraTest, MjpegStreamSendsDecodableFrames) {
  const std::vector<std::uint8_t> bright = {255, 0};
  ASSERT_EQ(brightness(0x01, bright).status, UsbStatus::kOk);
  const auto c = commit(2, 2, 2000000);  // MJPEG 640x480 at 5 fps
  BulkStreamReader reader(c.maxPayloadTransferSize);
  readFrames(reader, 2);
  ASSERT_EQ(reader.frames().size(), 2U);
  EXPECT_TRUE(reader.faults().empty()) << reader.faults().front();
  for (std::size_t i = 0; i < 2; ++i) {
    auto image = decodeJpeg(reader.frames()[i], "stream" + std::to_string(i));
    ASSERT_TRUE(image) << image.error().describe();
    EXPECT_EQ(image->width, 640U);
    EXPECT_EQ(image->height, 480U);
    EXPECT_EQ(readFrameCounterRgb(*image), i);
    EXPECT_EQ(mjpegFrameNumber(reader.frames()[i]), i) << "the COM segment agrees with the picture";
    EXPECT_LE(reader.frames()[i].size(), c.maxVideoFrameSize);
  }
  EXPECT_EQ(camera_->oversizedFrames(), 0U);
  EXPECT_EQ(camera_->framesSent(), 2U);
}

// Makes sure broken configurations are refused with a reason. Example failure: a format with no
// frame sizes makes a descriptor with bNumFrameDescriptors 0, and uvcvideo refuses the device.
TEST(UvcCameraConfigTest, BrokenConfigurationsAreRefused) {
  UvcCameraConfig none;
  EXPECT_FALSE(UvcCamera::create(none));
  UvcCameraConfig noFrames = UvcCameraConfig::labDefault();
  noFrames.formats[0].frames.clear();
  auto r = UvcCamera::create(noFrames);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message().find("frame sizes"), std::string::npos);
  UvcCameraConfig badSize = UvcCameraConfig::labDefault();
  badSize.formats[1].frames[0].width = 100;
  EXPECT_FALSE(UvcCamera::create(badSize));
  UvcCameraConfig zeroInterval = UvcCameraConfig::labDefault();
  zeroInterval.formats[0].frames[0].intervals = {0};
  EXPECT_FALSE(UvcCamera::create(zeroInterval));
}

}  // namespace
}  // namespace basalt::sim::vlab
