// Webcams and HDMI capture cards through Video4Linux2.
//
// Hardware: any single-planar V4L2 video capture node with streaming I/O: UVC webcams and
// UVC-class HDMI grabbers, vivid, bt8xx/saa7134-style cards, HDMI receivers with the DV timings
// API (tc358743, adv7604 and the like). Frames are mmap buffers handed out without a copy; with
// `dmabuf` (default) each buffer is also exported (VIDIOC_EXPBUF) so the renderer can import it.
// Driver timestamps (CLOCK_MONOTONIC) become the frame's capture time. HDMI inputs: the node
// subscribes to source-change events; when the signal is lost, regained or changes resolution
// the capture thread stops streaming, waits for the show to give the buffers back, queries the
// new timings, renegotiates the format and streams again: the source goes lost and comes back
// by itself, no reopen. Controls: mirror (V4L2_CID_HFLIP, else the renderer flips), quality
// (V4L2_CID_JPEG_COMPRESSION_QUALITY), frames per second (VIDIOC_S_PARM, and the frame-rate
// limit of VideoSource), input (VIDIOC_S_INPUT).
// Limits: multi-planar nodes (V4L2_CAP_VIDEO_CAPTURE_MPLANE) and read()-only devices are refused
// with a message; MJPEG frames are delivered compressed (media/ decodes them).

#include "devices/v4l2/v4l2_camera.h"

#include <fcntl.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <optional>
#include <thread>

#include <fmt/format.h>

#include "devices/v4l2/v4l2_buffer_set.h"
#include "runtime/log.h"
#include "runtime/unique_fd.h"

namespace basalt::devices {

BASALT_LOG_CATEGORY(V4l2, "devices");

namespace {

int xioctl(int fd, unsigned long request, void* arg) {
  int r = 0;
  do {
    r = ::ioctl(fd, request, arg);
  } while (r == -1 && errno == EINTR);
  return r;
}

std::string fourccText(std::uint32_t f) {
  std::string s;
  for (int i = 0; i < 4; ++i) {
    const char c = static_cast<char>((f >> (8 * i)) & 0xff);
    s += (c >= 32 && c < 127) ? c : '?';
  }
  return s;
}

PixelFormat fromFourcc(std::uint32_t f) {
  switch (f) {
    case V4L2_PIX_FMT_YUYV: return PixelFormat::kYuyv;
    case V4L2_PIX_FMT_UYVY: return PixelFormat::kUyvy;
    case V4L2_PIX_FMT_NV12: return PixelFormat::kNv12;
    case V4L2_PIX_FMT_NV21: return PixelFormat::kNv21;
    case V4L2_PIX_FMT_YUV420: return PixelFormat::kI420;
    case V4L2_PIX_FMT_YVU420: return PixelFormat::kYv12;
    case V4L2_PIX_FMT_RGB24: return PixelFormat::kRgb8;
    case V4L2_PIX_FMT_ABGR32: return PixelFormat::kBgra8;  // B G R A in memory
    case V4L2_PIX_FMT_RGBA32: return PixelFormat::kRgba8;
    case V4L2_PIX_FMT_GREY: return PixelFormat::kGray8;
    case V4L2_PIX_FMT_MJPEG:
    case V4L2_PIX_FMT_JPEG: return PixelFormat::kMjpeg;
    default: return PixelFormat::kUnknown;
  }
}

std::uint32_t toFourcc(PixelFormat f) {
  switch (f) {
    case PixelFormat::kYuyv: return V4L2_PIX_FMT_YUYV;
    case PixelFormat::kUyvy: return V4L2_PIX_FMT_UYVY;
    case PixelFormat::kNv12: return V4L2_PIX_FMT_NV12;
    case PixelFormat::kNv21: return V4L2_PIX_FMT_NV21;
    case PixelFormat::kI420: return V4L2_PIX_FMT_YUV420;
    case PixelFormat::kYv12: return V4L2_PIX_FMT_YVU420;
    case PixelFormat::kRgb8: return V4L2_PIX_FMT_RGB24;
    case PixelFormat::kBgra8: return V4L2_PIX_FMT_ABGR32;
    case PixelFormat::kRgba8: return V4L2_PIX_FMT_RGBA32;
    case PixelFormat::kGray8: return V4L2_PIX_FMT_GREY;
    case PixelFormat::kMjpeg: return V4L2_PIX_FMT_MJPEG;
    case PixelFormat::kUnknown: return 0;
  }
  return 0;
}

/// Preference when the show does not choose: formats the renderer uploads without help first.
int formatRank(PixelFormat f) {
  switch (f) {
    case PixelFormat::kNv12: return 0;
    case PixelFormat::kYuyv: return 1;
    case PixelFormat::kI420: return 2;
    case PixelFormat::kUyvy: return 3;
    case PixelFormat::kMjpeg: return 9;
    default: return 5;
  }
}

Colorimetry colorimetryOf(const v4l2_pix_format& p) {
  Colorimetry c;
  if (p.ycbcr_enc == V4L2_YCBCR_ENC_709 || p.colorspace == V4L2_COLORSPACE_REC709)
    c.matrix = Colorimetry::Matrix::kBt709;
  if (p.ycbcr_enc == V4L2_YCBCR_ENC_BT2020 || p.colorspace == V4L2_COLORSPACE_BT2020)
    c.matrix = Colorimetry::Matrix::kBt2020;
  const bool full = p.quantization == V4L2_QUANTIZATION_FULL_RANGE ||
                    (p.quantization == V4L2_QUANTIZATION_DEFAULT && p.colorspace == V4L2_COLORSPACE_JPEG);
  c.range = full ? Colorimetry::Range::kFull : Colorimetry::Range::kLimited;
  return c;
}

Error sysError(const std::string& path, std::string_view what, int e) {
  if (e == EACCES || e == EPERM) {
    return Error(
        Errc::kPermissionDenied,
        systemErrorText(what, e) + "; add the user to the 'video' group or install configs/udev/70-basalt.rules", path);
  }
  if (e == ENODEV || e == ENXIO) return Error(Errc::kDeviceLost, systemErrorText(what, e), path);
  if (e == EBUSY) return Error(Errc::kUnavailable, systemErrorText(what, e) + " (another program is using it?)", path);
  return Error(e == ENOENT ? Errc::kNotFound : Errc::kIo, systemErrorText(what, e), path);
}

/// "inputs 0 'Camera 0', 1 'HDMI 1'" (or "no input"), for an input that does not exist.
std::string describeInputs(int fd) {
  std::string names;
  std::uint32_t count = 0;
  for (std::uint32_t i = 0; i < 32; ++i) {
    v4l2_input in{};
    in.index = i;
    if (xioctl(fd, VIDIOC_ENUMINPUT, &in) != 0) break;
    names += fmt::format("{}{} '{}'", names.empty() ? "" : ", ", i, reinterpret_cast<const char*>(in.name));
    ++count;
  }
  if (count == 0) return "no input";
  return fmt::format("{} {}", count == 1 ? "only input" : "inputs", names);
}

void usbIds(const std::string& path, std::uint16_t& vendor, std::uint16_t& product) {
  // /sys/class/video4linux/videoN/device is the USB interface; its parent has idVendor.
  std::error_code ec;
  auto dev = std::filesystem::canonical(
      std::filesystem::path("/sys/class/video4linux") / std::filesystem::path(path).filename() / "device", ec);
  if (ec) return;
  for (int up = 0; up < 3 && !dev.empty(); ++up, dev = dev.parent_path()) {
    std::ifstream v(dev / "idVendor"), p(dev / "idProduct");
    std::string vs, ps;
    if (v >> vs && p >> ps) {
      unsigned x = 0, y = 0;
      std::from_chars(vs.data(), vs.data() + vs.size(), x, 16);
      std::from_chars(ps.data(), ps.data() + ps.size(), y, 16);
      vendor = static_cast<std::uint16_t>(x);
      product = static_cast<std::uint16_t>(y);
      return;
    }
  }
}

class V4l2Camera final : public VideoSource {
 public:
  V4l2Camera(DeviceInfo info, std::string path, V4l2Options options, const Clock& clock)
      : VideoSource(std::move(info), clock), path_(std::move(path)), options_(options) {}
  ~V4l2Camera() override { close(); }

 private:
  Result<void> doOpen() override;
  void doClose() override;
  Result<void> doApplyControls(const VideoControls& controls) override;

  Result<void> negotiate(bool* noSignal);
  Result<void> startStreaming();
  void stopStreaming(bool waitForShow);
  void captureLoop();
  void handleEvents();
  bool dequeue();

  std::string path_;
  V4l2Options options_;
  UniqueFd fd_;
  UniqueFd stopFd_;
  std::thread thread_;
  bool dvTimings_ = false;
  std::optional<v4l2_dv_timings> timings_;  // what the receiver was set to, while streaming
  v4l2_pix_format fmt_{};
  VideoMode mode_{};
  std::shared_ptr<V4l2BufferSet> buffers_;  // capture thread (and open/close) only; shared with lent frames
  std::shared_ptr<FramePool> pool_;
  std::mutex controlMutex_;     // S_CTRL from the manager thread vs renegotiation
  bool qualityWarned_ = false;  // guarded by controlMutex_
};

Result<void> V4l2Camera::doOpen() {
  UniqueFd fd(::open(path_.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC));
  if (!fd) return std::unexpected(sysError(path_, "cannot open", errno));
  v4l2_capability cap{};
  if (xioctl(fd.get(), VIDIOC_QUERYCAP, &cap) != 0) {
    return fail(Errc::kUnsupported, systemErrorText("not a V4L2 device", errno), path_);
  }
  const std::uint32_t caps = (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
  if (!(caps & V4L2_CAP_VIDEO_CAPTURE)) {
    if (caps & V4L2_CAP_VIDEO_CAPTURE_MPLANE) {
      return fail(Errc::kUnsupported, "multi-planar capture nodes are not supported by Basalt yet", path_);
    }
    return fail(Errc::kUnsupported, "not a video capture node (a metadata or output node?)", path_);
  }
  if (!(caps & V4L2_CAP_STREAMING)) {
    return fail(Errc::kUnsupported, "the device cannot stream (read() only); Basalt needs streaming I/O", path_);
  }
  fd_ = std::move(fd);
  int input = options_.input;
  if (const int c = controls().input; c >= 0) input = c;
  if (input >= 0 && xioctl(fd_.get(), VIDIOC_S_INPUT, &input) != 0) {
    const int e = errno;
    const Error error =
        e == EINVAL
            ? Error(Errc::kNotFound,
                    fmt::format("there is no input {}; the device has {}", input, describeInputs(fd_.get())), path_)
            : sysError(path_, fmt::format("cannot select input {}", input), e);
    fd_.reset();
    return std::unexpected(error);
  }
  int current = 0;
  xioctl(fd_.get(), VIDIOC_G_INPUT, &current);
  v4l2_input in{};
  in.index = static_cast<std::uint32_t>(current);
  dvTimings_ = xioctl(fd_.get(), VIDIOC_ENUMINPUT, &in) == 0 && (in.capabilities & V4L2_IN_CAP_DV_TIMINGS);
  if (dvTimings_) {
    v4l2_event_subscription sub{};
    sub.type = V4L2_EVENT_SOURCE_CHANGE;
    if (xioctl(fd_.get(), VIDIOC_SUBSCRIBE_EVENT, &sub) != 0) {
      log::warn(kLogV4l2, "{}: no source-change events ({}); signal changes are noticed by read errors only", path_,
                std::strerror(errno));
    }
  }
  stopFd_.reset(::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK));
  bool noSignal = false;
  if (auto r = negotiate(&noSignal); !r) {
    fd_.reset();
    return r;
  }
  if (noSignal) {
    reportLost(Error(Errc::kUnavailable, "no signal on the HDMI input; waiting for one", path_), true);
  } else if (auto r = startStreaming(); !r) {
    fd_.reset();
    return r;
  }
  thread_ = std::thread([this] { captureLoop(); });
  return {};
}

Result<void> V4l2Camera::negotiate(bool* noSignal) {
  *noSignal = false;
  std::uint32_t width = options_.width, height = options_.height;
  if (dvTimings_) {
    v4l2_dv_timings t{};
    if (xioctl(fd_.get(), VIDIOC_QUERY_DV_TIMINGS, &t) != 0) {
      if (errno == ENOLINK || errno == ENOLCK || errno == ERANGE) {
        *noSignal = true;
        return {};
      }
      return std::unexpected(sysError(path_, "cannot query the DV timings", errno));
    }
    if (xioctl(fd_.get(), VIDIOC_S_DV_TIMINGS, &t) != 0) {
      if (errno == EINVAL || errno == ERANGE) {
        // The source sends timings this receiver cannot take (a pixel clock out of its range,
        // say): no usable signal until the source changes again.
        return fail(Errc::kUnsupported,
                    fmt::format("the HDMI source sends {}x{}{} at {:.2f} MHz, which this receiver cannot capture; "
                                "set the source to another mode",
                                std::uint32_t{t.bt.width}, std::uint32_t{t.bt.height}, t.bt.interlaced ? "i" : "p",
                                static_cast<double>(std::uint64_t{t.bt.pixelclock}) / 1e6),
                    path_);
      }
      return std::unexpected(sysError(path_, "cannot set the DV timings", errno));
    }
    width = t.bt.width;
    height = t.bt.height;
    timings_ = t;
  }
  // Choose a format: the one asked for, else the device's best that Basalt handles.
  std::vector<std::uint32_t> offered;
  for (std::uint32_t i = 0; i < 64; ++i) {
    v4l2_fmtdesc d{};
    d.index = i;
    d.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (xioctl(fd_.get(), VIDIOC_ENUM_FMT, &d) != 0) break;
    offered.push_back(d.pixelformat);
  }
  std::uint32_t fourcc = 0;
  if (options_.format) {
    fourcc = toFourcc(*options_.format);
    if (std::find(offered.begin(), offered.end(), fourcc) == offered.end()) {
      std::string list;
      for (auto f : offered) list += (list.empty() ? "" : ", ") + fourccText(f);
      return fail(Errc::kUnsupported,
                  fmt::format("the device does not offer {}; it offers {}", pixelFormatName(*options_.format), list),
                  path_);
    }
  } else {
    int best = 100;
    for (auto f : offered) {
      const PixelFormat p = fromFourcc(f);
      if (p != PixelFormat::kUnknown && formatRank(p) < best) {
        best = formatRank(p);
        fourcc = f;
      }
    }
    if (!fourcc) return fail(Errc::kUnsupported, "the device offers no pixel format Basalt can show", path_);
  }
  v4l2_format f{};
  f.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (xioctl(fd_.get(), VIDIOC_G_FMT, &f) != 0)
    return std::unexpected(sysError(path_, "cannot read the format", errno));
  f.fmt.pix.pixelformat = fourcc;
  if (width && height) {
    f.fmt.pix.width = width;
    f.fmt.pix.height = height;
  }
  f.fmt.pix.field = V4L2_FIELD_NONE;
  f.fmt.pix.bytesperline = 0;
  if (xioctl(fd_.get(), VIDIOC_S_FMT, &f) != 0) return std::unexpected(sysError(path_, "cannot set the format", errno));
  if (f.fmt.pix.pixelformat != fourcc || fromFourcc(fourcc) == PixelFormat::kUnknown) {
    return fail(Errc::kUnsupported, fmt::format("the driver chose {} instead", fourccText(f.fmt.pix.pixelformat)),
                path_);
  }
  fmt_ = f.fmt.pix;
  double fps = options_.fps > 0 ? options_.fps : controls().maxFps;
  v4l2_streamparm parm{};
  parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (xioctl(fd_.get(), VIDIOC_G_PARM, &parm) == 0) {
    if (fps > 0 && (parm.parm.capture.capability & V4L2_CAP_TIMEPERFRAME)) {
      parm.parm.capture.timeperframe.numerator = 1000;
      parm.parm.capture.timeperframe.denominator = static_cast<std::uint32_t>(std::lround(fps * 1000));
      xioctl(fd_.get(), VIDIOC_S_PARM, &parm);
    }
    const auto& tpf = parm.parm.capture.timeperframe;
    fps = tpf.numerator ? static_cast<double>(tpf.denominator) / tpf.numerator : fps;
  }
  mode_ = VideoMode{fromFourcc(fourcc), fmt_.width, fmt_.height, fps};
  setMode(mode_);
  if (fps > 0) setStallTimeout(std::max<Nanos>(std::chrono::seconds(1), fromSeconds(10.0 / fps)));
  return {};
}

Result<void> V4l2Camera::startStreaming() {
  v4l2_requestbuffers req{};
  req.count = std::clamp(options_.buffers, 2u, 32u);
  req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  req.memory = V4L2_MEMORY_MMAP;
  if (xioctl(fd_.get(), VIDIOC_REQBUFS, &req) != 0 || req.count < 2) {
    return std::unexpected(sysError(path_, "cannot allocate capture buffers", errno));
  }
  std::vector<V4l2MappedBuffer> buffers;
  buffers.reserve(req.count);
  bool exported = options_.exportDmabuf;
  for (std::uint32_t i = 0; i < req.count; ++i) {
    v4l2_buffer b{};
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b.memory = V4L2_MEMORY_MMAP;
    b.index = i;
    if (xioctl(fd_.get(), VIDIOC_QUERYBUF, &b) != 0) return std::unexpected(sysError(path_, "QUERYBUF", errno));
    void* data = ::mmap(nullptr, b.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd_.get(), b.m.offset);
    if (data == MAP_FAILED) return std::unexpected(sysError(path_, "cannot map the capture buffers", errno));
    V4l2MappedBuffer& buffer = buffers.emplace_back(data, b.length);
    if (exported) {
      v4l2_exportbuffer x{};
      x.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      x.index = i;
      x.flags = O_RDONLY | O_CLOEXEC;
      if (xioctl(fd_.get(), VIDIOC_EXPBUF, &x) == 0) {
        buffer.dmabuf.reset(x.fd);
      } else {
        exported = false;  // the driver cannot export: frames stay CPU-only
        log::debug(kLogV4l2, "{}: no dmabuf export ({})", path_, std::strerror(errno));
      }
    }
  }
  buffers_ = V4l2BufferSet::create(fd_.duplicate(), std::move(buffers));
  pool_ = FramePool::create({mode_.format, mode_.width, mode_.height, req.count + 1, 1, false});
  buffers_->setStreaming(true);
  for (std::uint32_t i = 0; i < req.count; ++i) {
    if (!buffers_->queue(i)) return std::unexpected(sysError(path_, "cannot queue the capture buffers", errno));
  }
  int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (xioctl(fd_.get(), VIDIOC_STREAMON, &type) != 0) {
    return std::unexpected(sysError(path_, "cannot start streaming", errno));
  }
  return {};
}

void V4l2Camera::stopStreaming(bool waitForShow) {
  if (!buffers_) return;
  buffers_->setStreaming(false);
  int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (xioctl(fd_.get(), VIDIOC_STREAMOFF, &type) != 0) {
    log::warn(kLogV4l2, "{}: cannot stop streaming: {}", path_, std::strerror(errno));
  }
  if (waitForShow && !buffers_->waitForFrames(std::chrono::milliseconds(1000))) {
    log::warn(kLogV4l2, "{}: the show still holds {} frame(s) after 1 s", path_, buffers_->outstanding());
  }
  buffers_.reset();  // unmaps now, or when the show gives the last frame back
  v4l2_requestbuffers req{};
  req.count = 0;
  req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  req.memory = V4L2_MEMORY_MMAP;
  if (xioctl(fd_.get(), VIDIOC_REQBUFS, &req) != 0) {
    // The driver keeps the buffers, and refuses a new format or new timings while it does.
    log::warn(kLogV4l2, "{}: cannot free the capture buffers: {}", path_, std::strerror(errno));
  }
}

bool V4l2Camera::dequeue() {
  v4l2_buffer b{};
  b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  b.memory = V4L2_MEMORY_MMAP;
  if (xioctl(fd_.get(), VIDIOC_DQBUF, &b) != 0) {
    if (errno == EAGAIN) return true;
    if (errno == EPIPE && dvTimings_) return true;  // the signal went: a source-change event follows
    reportLost(sysError(path_, "capture failed", errno));
    return false;
  }
  if (b.flags & V4L2_BUF_FLAG_ERROR || b.bytesused == 0) {
    countDrop();
    (void)buffers_->queue(b.index);
    return true;
  }
  FrameRef frame = pool_->acquire();
  if (!frame) {
    countDrop();
    (void)buffers_->queue(b.index);
    return true;
  }
  const auto& buf = buffers_->buffers()[b.index];
  auto* base = static_cast<std::uint8_t*>(buf.data());
  const FrameLayout layout = computeLayout(mode_.format, fmt_.width, fmt_.height, 1);
  frame->planeCount = layout.planeCount;
  // Planes follow each other in one buffer; rows are bytesperline apart (chroma rows of planar
  // formats are half that, as V4L2 defines them).
  std::size_t offset = 0;
  for (int i = 0; i < layout.planeCount; ++i) {
    Plane& p = frame->planes[static_cast<std::size_t>(i)];
    const std::uint32_t stride = i == 0 || mode_.format == PixelFormat::kNv12 || mode_.format == PixelFormat::kNv21
                                     ? fmt_.bytesperline
                                     : fmt_.bytesperline / 2;
    const std::size_t rows =
        layout.planes[static_cast<std::size_t>(i)].stride
            ? layout.planes[static_cast<std::size_t>(i)].size / layout.planes[static_cast<std::size_t>(i)].stride
            : 0;
    p.data = base + offset;
    p.stride = mode_.format == PixelFormat::kMjpeg ? 0 : stride;
    p.offset = static_cast<std::uint32_t>(offset);
    p.size = mode_.format == PixelFormat::kMjpeg ? b.bytesused : stride * rows;
    p.dmabufFd = buf.dmabuf.get();
    offset += p.size;
  }
  frame->bytesUsed = b.bytesused;
  frame->sequence = b.sequence;
  frame->colorimetry = colorimetryOf(fmt_);
  const bool monotonic = (b.flags & V4L2_BUF_FLAG_TIMESTAMP_MASK) == V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC;
  const Nanos driver{static_cast<std::int64_t>(b.timestamp.tv_sec) * 1'000'000'000 + b.timestamp.tv_usec * 1000};
  // The SystemClock is CLOCK_MONOTONIC: the driver's timestamp is on the show's clock.
  frame->captureTime = monotonic && !clock().isManual() ? driver : clock().now();
  frame->pts = frame->captureTime;
  buffers_->lend(*frame, b.index);
  deliver(std::move(frame));
  return true;
}

void V4l2Camera::handleEvents() {
  v4l2_event ev{};
  bool sourceChanged = false;
  while (xioctl(fd_.get(), VIDIOC_DQEVENT, &ev) == 0) {
    if (ev.type == V4L2_EVENT_SOURCE_CHANGE) sourceChanged = true;
  }
  if (!sourceChanged) return;
  if (buffers_ && timings_) {
    // A source change that leaves the timings as they are (a source re-sending its mode, a
    // control touched) needs no renegotiation: capture goes on without a gap.
    v4l2_dv_timings now{};
    if (xioctl(fd_.get(), VIDIOC_QUERY_DV_TIMINGS, &now) == 0 && now.bt.width == timings_->bt.width &&
        now.bt.height == timings_->bt.height && now.bt.interlaced == timings_->bt.interlaced &&
        now.bt.pixelclock == timings_->bt.pixelclock) {
      log::debug(kLogV4l2, "{}: the HDMI source changed nothing; capture goes on", path_);
      return;
    }
  }
  reportLost(Error(Errc::kUnavailable, "the HDMI source changed; renegotiating", path_), true);
  std::lock_guard lock(controlMutex_);
  stopStreaming(true);
  // A mode that cannot be captured is not the end of the input: the source may change again (the
  // next source-change event renegotiates), unless the device itself went away.
  auto cannotCapture = [this](const Error& e) {
    log::warn(kLogV4l2, "{}: the HDMI source changed and cannot be captured: {}; waiting for it to change again", path_,
              e.describe());
    stopStreaming(false);
    reportLost(e, e.code() != Errc::kDeviceLost);
  };
  bool noSignal = false;
  if (auto r = negotiate(&noSignal); !r) {
    cannotCapture(r.error());
    return;
  }
  if (noSignal) {
    reportLost(Error(Errc::kUnavailable, "no signal on the HDMI input; waiting for one", path_), true);
    return;
  }
  if (auto r = startStreaming(); !r) {
    cannotCapture(r.error());
    return;
  }
  log::info(kLogV4l2, "{}: signal back as {}", path_, describeMode(mode_));
  reportRecovered();
}

void V4l2Camera::captureLoop() {
  for (;;) {
    // POLLIN only while streaming: polling a capture queue that has no buffers for input makes
    // videobuf2 start its read() emulation, which allocates buffers behind Basalt's back, and a
    // queue with buffers refuses new DV timings and formats (EBUSY) for good.
    const short input = buffers_ ? POLLIN : 0;
    pollfd fds[2] = {{fd_.get(), static_cast<short>(input | POLLPRI), 0}, {stopFd_.get(), POLLIN, 0}};
    if (::poll(fds, 2, 1000) < 0) {
      if (errno == EINTR) continue;
      reportLost(sysError(path_, "poll", errno));
      return;
    }
    if (fds[1].revents) return;
    if (fds[0].revents & POLLPRI) handleEvents();
    if (fds[0].revents & POLLERR) {
      if (!buffers_) {  // not streaming (no signal): only events matter; do not spin
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
        continue;
      }
      reportLost(Error(Errc::kDeviceLost, "the device reported an error (unplugged?)", path_));
      return;
    }
    if ((fds[0].revents & POLLIN) && buffers_ && !dequeue()) return;
  }
}

void V4l2Camera::doClose() {
  if (thread_.joinable()) {
    const std::uint64_t one = 1;
    (void)!::write(stopFd_.get(), &one, sizeof one);
    thread_.join();
  }
  stopStreaming(false);
  pool_.reset();
  fd_.reset();
  stopFd_.reset();
}

Result<void> V4l2Camera::doApplyControls(const VideoControls& controls) {
  std::lock_guard lock(controlMutex_);
  bool mirrored = false;
  v4l2_control c{};
  c.id = V4L2_CID_HFLIP;
  c.value = controls.mirror ? 1 : 0;
  if (fd_ && xioctl(fd_.get(), VIDIOC_S_CTRL, &c) == 0) mirrored = true;
  setMirrorInRenderer(controls.mirror && !mirrored);
  if (controls.quality >= 0 && fd_) {
    v4l2_control q{};
    q.id = V4L2_CID_JPEG_COMPRESSION_QUALITY;
    q.value = controls.quality;
    if (xioctl(fd_.get(), VIDIOC_S_CTRL, &q) != 0) {
      // Said once per camera (a show may ask every camera for a quality), and only "no control"
      // when the driver says so: a busy or failing device gets its own reason.
      const int e = errno;
      if (!qualityWarned_) {
        qualityWarned_ = true;
        if (e == EINVAL) {
          log::warn(kLogV4l2, "{}: the device has no JPEG quality control; quality {} ignored", path_,
                    controls.quality);
        } else {
          log::warn(kLogV4l2, "{}: {}; quality {} ignored", path_, systemErrorText("cannot set the JPEG quality", e),
                    controls.quality);
        }
      }
    }
  }
  if (controls.input >= 0 && fd_) {
    int current = -1;
    xioctl(fd_.get(), VIDIOC_G_INPUT, &current);
    if (current != controls.input) {
      return fail(Errc::kUnsupported, "changing the input of a streaming device needs a reopen; set it before opening",
                  path_);
    }
  }
  return {};
}

}  // namespace

Result<V4l2Description> describeV4l2Device(const std::string& path) {
  UniqueFd fd(::open(path.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC));
  if (!fd) return std::unexpected(sysError(path, "cannot open", errno));
  v4l2_capability cap{};
  if (xioctl(fd.get(), VIDIOC_QUERYCAP, &cap) != 0) return fail(Errc::kUnsupported, "not a V4L2 device", path);
  const std::uint32_t caps = (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
  V4l2Description d;
  d.path = path;
  d.card = reinterpret_cast<const char*>(cap.card);
  d.driver = reinterpret_cast<const char*>(cap.driver);
  d.busInfo = reinterpret_cast<const char*>(cap.bus_info);
  d.streaming = (caps & V4L2_CAP_STREAMING) != 0;
  d.multiplanar = (caps & V4L2_CAP_VIDEO_CAPTURE_MPLANE) != 0;
  if (!(caps & (V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_VIDEO_CAPTURE_MPLANE))) {
    return fail(Errc::kUnsupported, "not a video capture node", path);
  }
  usbIds(path, d.vendor, d.product);
  xioctl(fd.get(), VIDIOC_G_INPUT, &d.currentInput);
  for (std::uint32_t i = 0; i < 32; ++i) {
    v4l2_input in{};
    in.index = i;
    if (xioctl(fd.get(), VIDIOC_ENUMINPUT, &in) != 0) break;
    d.inputs.push_back({static_cast<int>(i), reinterpret_cast<const char*>(in.name), in.type == V4L2_INPUT_TYPE_CAMERA,
                        (in.capabilities & V4L2_IN_CAP_DV_TIMINGS) != 0,
                        (in.status & (V4L2_IN_ST_NO_SIGNAL | V4L2_IN_ST_NO_SYNC)) != 0});
  }
  const std::uint32_t type = d.multiplanar && !(caps & V4L2_CAP_VIDEO_CAPTURE) ? V4L2_BUF_TYPE_VIDEO_CAPTURE_MPLANE
                                                                               : V4L2_BUF_TYPE_VIDEO_CAPTURE;
  for (std::uint32_t i = 0; i < 64; ++i) {
    v4l2_fmtdesc f{};
    f.index = i;
    f.type = type;
    if (xioctl(fd.get(), VIDIOC_ENUM_FMT, &f) != 0) break;
    const PixelFormat pf = fromFourcc(f.pixelformat);
    if (pf == PixelFormat::kUnknown) {
      d.otherFormats.push_back(fourccText(f.pixelformat));
      continue;
    }
    bool any = false;
    for (std::uint32_t s = 0; s < 64; ++s) {
      v4l2_frmsizeenum size{};
      size.index = s;
      size.pixel_format = f.pixelformat;
      if (xioctl(fd.get(), VIDIOC_ENUM_FRAMESIZES, &size) != 0) break;
      if (size.type != V4L2_FRMSIZE_TYPE_DISCRETE) {
        d.modes.push_back({pf, size.stepwise.max_width, size.stepwise.max_height, 0});
        any = true;
        break;
      }
      double best = 0;
      for (std::uint32_t r = 0; r < 32; ++r) {
        v4l2_frmivalenum iv{};
        iv.index = r;
        iv.pixel_format = f.pixelformat;
        iv.width = size.discrete.width;
        iv.height = size.discrete.height;
        if (xioctl(fd.get(), VIDIOC_ENUM_FRAMEINTERVALS, &iv) != 0 || iv.type != V4L2_FRMIVAL_TYPE_DISCRETE) break;
        if (iv.discrete.numerator)
          best = std::max(best, static_cast<double>(iv.discrete.denominator) / iv.discrete.numerator);
      }
      d.modes.push_back({pf, size.discrete.width, size.discrete.height, best});
      any = true;
    }
    if (!any) {
      v4l2_format cur{};
      cur.type = type;
      if (xioctl(fd.get(), VIDIOC_G_FMT, &cur) == 0) d.modes.push_back({pf, cur.fmt.pix.width, cur.fmt.pix.height, 0});
    }
  }
  return d;
}

Result<V4l2Options> v4l2OptionsFrom(const DeviceRequest& request) {
  V4l2Options o;
  auto bad = [&](const std::string& what) {
    return fail(Errc::kInvalidArgument, what, fmt::format("device '{}'", request.name));
  };
  for (const auto& [key, value] : request.options) {
    if (key == "format") {
      PixelFormat f = PixelFormat::kUnknown;
      for (int i = 1; i <= static_cast<int>(PixelFormat::kMjpeg); ++i) {
        if (pixelFormatName(static_cast<PixelFormat>(i)) == value) f = static_cast<PixelFormat>(i);
      }
      if (f == PixelFormat::kUnknown) return bad(fmt::format("unknown format '{}' (YUYV, NV12, MJPEG, ...)", value));
      o.format = f;
    } else if (key == "size") {
      const auto x = value.find('x');
      unsigned w = 0, h = 0;
      if (x == std::string::npos || std::from_chars(value.data(), value.data() + x, w).ec != std::errc{} ||
          std::from_chars(value.data() + x + 1, value.data() + value.size(), h).ec != std::errc{} || !w || !h) {
        return bad(fmt::format("size '{}' is not WIDTHxHEIGHT", value));
      }
      o.width = w;
      o.height = h;
    } else if (key == "fps") {
      if (std::from_chars(value.data(), value.data() + value.size(), o.fps).ec != std::errc{} || !(o.fps > 0)) {
        return bad(fmt::format("fps '{}' is not a positive number", value));
      }
    } else if (key == "input") {
      if (std::from_chars(value.data(), value.data() + value.size(), o.input).ec != std::errc{} || o.input < 0) {
        return bad(fmt::format("input '{}' is not an input number", value));
      }
    } else if (key == "dmabuf") {
      if (value != "true" && value != "false") return bad("dmabuf must be true or false");
      o.exportDmabuf = value == "true";
    } else if (key == "buffers") {
      if (std::from_chars(value.data(), value.data() + value.size(), o.buffers).ec != std::errc{} || o.buffers < 2 ||
          o.buffers > 32) {
        return bad("buffers must be 2..32");
      }
    }
  }
  return o;
}

std::shared_ptr<VideoSource> makeV4l2Camera(const std::string& path, V4l2Options options, const Clock& clock,
                                            DeviceInfo info) {
  if (info.path.empty()) {
    info.path = path;
    info.backend = "v4l2";
    if (auto d = describeV4l2Device(path)) {
      info.name = d->card;
      info.bus = d->busInfo;
      info.vendor = d->vendor;
      info.product = d->product;
    }
  }
  return std::make_shared<V4l2Camera>(std::move(info), path, options, clock);
}

Result<void> setV4l2ControlByName(const std::string& path, const std::string& name, int value) {
  UniqueFd fd(::open(path.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC));
  if (!fd) return std::unexpected(sysError(path, "cannot open", errno));
  v4l2_queryctrl q{};
  q.id = V4L2_CTRL_FLAG_NEXT_CTRL;
  while (xioctl(fd.get(), VIDIOC_QUERYCTRL, &q) == 0) {
    if (name == reinterpret_cast<const char*>(q.name)) {
      v4l2_control c{};
      c.id = q.id;
      c.value = value;
      if (xioctl(fd.get(), VIDIOC_S_CTRL, &c) != 0) {
        return std::unexpected(sysError(path, fmt::format("cannot set '{}' to {}", name, value), errno));
      }
      return {};
    }
    q.id |= V4L2_CTRL_FLAG_NEXT_CTRL;
  }
  return fail(Errc::kNotFound, fmt::format("the device has no control named '{}'", name), path);
}

std::vector<DeviceCandidate> V4l2Provider::enumerate() {
  std::vector<DeviceCandidate> out;
  std::vector<std::string> nodes;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(folder_, ec)) {
    const std::string name = e.path().filename().string();
    if (name.starts_with("video") && name.size() > 5 && std::isdigit(static_cast<unsigned char>(name[5]))) {
      nodes.push_back(e.path().string());
    }
  }
  std::sort(nodes.begin(), nodes.end(), [](const std::string& a, const std::string& b) {
    return a.size() != b.size() ? a.size() < b.size() : a < b;
  });
  for (const std::string& node : nodes) {
    DeviceCandidate c;
    c.kind = DeviceKind::kVideoSource;
    c.info.path = node;
    c.info.backend = "v4l2";
    auto d = describeV4l2Device(node);
    if (!d) {
      if (d.error().code() == Errc::kUnsupported) continue;  // metadata and output nodes
      c.info.name = std::filesystem::path(node).filename().string();
      c.problem = d.error().describe();
      out.push_back(std::move(c));
      continue;
    }
    c.info.name = d->card;
    c.info.bus = d->busInfo;
    c.info.vendor = d->vendor;
    c.info.product = d->product;
    std::string modes;
    for (std::size_t i = 0; i < d->modes.size() && i < 4; ++i) modes += (i ? ", " : "") + describeMode(d->modes[i]);
    if (d->modes.size() > 4) modes += fmt::format(" and {} more", d->modes.size() - 4);
    std::string inputs;
    for (const auto& in : d->inputs) {
      inputs += fmt::format("{}{} {}{}{}", inputs.empty() ? "" : ", ", in.index, in.name, in.dvTimings ? " (HDMI)" : "",
                            in.noSignal ? " no signal" : "");
    }
    c.usage = fmt::format("{} via {}: {}{}", d->card, d->driver, modes.empty() ? "no usable format" : modes,
                          inputs.empty() ? "" : "; inputs " + inputs);
    if (d->multiplanar && d->modes.empty()) c.problem = "multi-planar capture is not supported yet";
    if (!d->streaming) c.problem = "the device cannot stream";
    out.push_back(std::move(c));
  }
  return out;
}

Result<std::shared_ptr<VideoSource>> V4l2Provider::openVideoSource(const DeviceCandidate& candidate,
                                                                   const DeviceRequest& request, const Clock& clock) {
  auto options = v4l2OptionsFrom(request);
  if (!options) return std::unexpected(options.error());
  return makeV4l2Camera(candidate.info.path, *options, clock, candidate.info);
}

}  // namespace basalt::devices
