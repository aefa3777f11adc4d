// Cameras through libcamera (Debian 12: libcamera 0.0.3).
//
// Hardware: whatever libcamera's pipeline handlers manage: CSI sensors behind an ISP (Raspberry
// Pi, Rockchip, i.MX) and UVC webcams. One stream per camera (the VideoRecording role), mmap'd
// FrameBuffers handed out without a copy (with their dmabuf fds), sensor timestamps kept. Hotplug
// comes from libcamera's cameraAdded/cameraRemoved signals and each camera's disconnected
// signal. Limits: one stream; controls beyond the frame rate (FrameDurationLimits) are not
// exposed; mirroring is done by the renderer.

#include "devices/libcamera/libcamera_camera.h"

#include <sys/mman.h>

#include <libcamera/libcamera.h>

#include <atomic>
#include <charconv>
#include <cstdlib>
#include <cstring>
#include <map>
#include <mutex>

#include <fmt/format.h>

#include "devices/v4l2/v4l2_camera.h"

namespace basalt::devices {

namespace lc = libcamera;

namespace {

struct FormatPair {
  PixelFormat basalt;
  lc::PixelFormat libcamera;
};

const std::vector<FormatPair>& formatTable() {
  static const std::vector<FormatPair> table = {
      {PixelFormat::kYuyv, lc::formats::YUYV},      {PixelFormat::kUyvy, lc::formats::UYVY},
      {PixelFormat::kNv12, lc::formats::NV12},      {PixelFormat::kNv21, lc::formats::NV21},
      {PixelFormat::kI420, lc::formats::YUV420},    {PixelFormat::kYv12, lc::formats::YVU420},
      {PixelFormat::kMjpeg, lc::formats::MJPEG},    {PixelFormat::kGray8, lc::formats::R8},
      {PixelFormat::kRgba8, lc::formats::XBGR8888}, {PixelFormat::kBgra8, lc::formats::XRGB8888},
      {PixelFormat::kRgb8, lc::formats::BGR888},
  };
  return table;
}

PixelFormat fromLibcamera(const lc::PixelFormat& f) {
  for (const auto& p : formatTable()) {
    if (p.libcamera == f) return p.basalt;
  }
  return PixelFormat::kUnknown;
}

}  // namespace

struct LibcameraProvider::State {
  std::unique_ptr<lc::CameraManager> manager;
  std::string error;
  std::mutex mutex;  // guards notify
  std::function<void(HotplugEvent)> notify;

  // libcamera's signals pass the camera by value.
  void added(std::shared_ptr<lc::Camera> camera) {  // NOLINT(performance-unnecessary-value-param)
    std::lock_guard lock(mutex);
    if (notify) notify({HotplugEvent::Action::kAdded, "libcamera", camera->id()});
  }
  void removed(std::shared_ptr<lc::Camera> camera) {  // NOLINT(performance-unnecessary-value-param)
    std::lock_guard lock(mutex);
    if (notify) notify({HotplugEvent::Action::kRemoved, "libcamera", camera->id()});
  }
};

namespace {

std::weak_ptr<LibcameraProvider::State>& sharedState() {
  static std::weak_ptr<LibcameraProvider::State> state;
  return state;
}
std::mutex& sharedStateMutex() {
  static std::mutex m;
  return m;
}

/// One configured, running camera. Frames out in the show hold references (refs_); the last one
/// releases the camera. Requests are re-queued when a frame is released while running.
class Session {
 public:
  Session(std::shared_ptr<lc::Camera> camera, std::shared_ptr<LibcameraProvider::State> keep)
      : camera_(std::move(camera)), keep_(std::move(keep)) {}
  ~Session() {
    for (auto& [buffer, maps] : maps_) {
      for (auto& [addr, len] : maps) ::munmap(addr, len);
    }
    requests_.clear();
    allocator_.reset();
    camera_->release();
  }
  void ref() { refs_.fetch_add(1); }
  void unref() {
    if (refs_.fetch_sub(1) == 1) delete this;
  }
  static void release(void* context, Frame& frame) {
    auto* s = static_cast<Session*>(context);
    {
      std::lock_guard lock(s->mutex_);
      auto* request = reinterpret_cast<lc::Request*>(frame.producerCookie);
      if (s->running_) {
        request->reuse(lc::Request::ReuseBuffers);
        s->camera_->queueRequest(request);
      }
    }
    s->unref();
  }

  std::shared_ptr<lc::Camera> camera_;
  std::shared_ptr<LibcameraProvider::State> keep_;  // the CameraManager outlives its cameras
  std::unique_ptr<lc::CameraConfiguration> config_;
  std::unique_ptr<lc::FrameBufferAllocator> allocator_;
  std::vector<std::unique_ptr<lc::Request>> requests_;
  std::map<const lc::FrameBuffer*, std::vector<std::pair<void*, std::size_t>>> maps_;
  lc::Stream* stream_ = nullptr;
  std::mutex mutex_;      // guards running_ and queueRequest against stop()
  bool running_ = false;  // guarded by mutex_
  std::atomic<int> refs_{1};
};

class LibcameraCamera final : public VideoSource {
 public:
  LibcameraCamera(DeviceInfo info, std::shared_ptr<LibcameraProvider::State> state, V4l2Options options,
                  const Clock& clock)
      : VideoSource(std::move(info), clock), state_(std::move(state)), options_(options) {}
  ~LibcameraCamera() override { close(); }

 private:
  Result<void> doOpen() override {
    const std::string& id = info().path;
    std::shared_ptr<lc::Camera> camera = state_->manager->get(id);
    if (!camera) return fail(Errc::kNotFound, "libcamera no longer lists this camera", id);
    if (camera->acquire() != 0) return fail(Errc::kUnavailable, "the camera is in use by another program", id);
    auto* session = new Session(camera, state_);
    auto cleanup = [&] { session->unref(); };
    session->config_ = camera->generateConfiguration({lc::StreamRole::VideoRecording});
    if (!session->config_ || session->config_->empty()) {
      cleanup();
      return fail(Errc::kUnsupported, "the camera offers no video stream", id);
    }
    lc::StreamConfiguration& sc = session->config_->at(0);
    if (options_.format) {
      bool found = false;
      for (const auto& p : formatTable()) {
        if (p.basalt == *options_.format) {
          sc.pixelFormat = p.libcamera;
          found = true;
        }
      }
      if (!found) {
        cleanup();
        return fail(Errc::kUnsupported, fmt::format("libcamera has no {}", pixelFormatName(*options_.format)), id);
      }
    }
    if (options_.width && options_.height) sc.size = lc::Size(options_.width, options_.height);
    sc.bufferCount = std::max(sc.bufferCount, 4u);
    if (session->config_->validate() == lc::CameraConfiguration::Invalid ||
        camera->configure(session->config_.get()) != 0) {
      cleanup();
      return fail(Errc::kUnsupported, fmt::format("the camera refused {}", sc.toString()), id);
    }
    const PixelFormat format = fromLibcamera(sc.pixelFormat);
    if (format == PixelFormat::kUnknown) {
      cleanup();
      return fail(Errc::kUnsupported,
                  fmt::format("the camera chose {}, which Basalt cannot show", sc.pixelFormat.toString()), id);
    }
    session->stream_ = sc.stream();
    session->allocator_ = std::make_unique<lc::FrameBufferAllocator>(camera);
    if (session->allocator_->allocate(session->stream_) < 0) {
      cleanup();
      return fail(Errc::kResourceExhausted, "cannot allocate camera buffers", id);
    }
    for (const auto& buffer : session->allocator_->buffers(session->stream_)) {
      auto& maps = session->maps_[buffer.get()];
      for (const auto& plane : buffer->planes()) {
        void* addr = ::mmap(nullptr, plane.offset + plane.length, PROT_READ, MAP_SHARED, plane.fd.get(), 0);
        if (addr == MAP_FAILED) {
          cleanup();
          return fail(Errc::kIo, systemErrorText("cannot map a camera buffer", errno), id);
        }
        maps.emplace_back(addr, plane.offset + plane.length);
      }
      std::unique_ptr<lc::Request> request = camera->createRequest();
      if (!request || request->addBuffer(session->stream_, buffer.get()) != 0) {
        cleanup();
        return fail(Errc::kResourceExhausted, "cannot create a capture request", id);
      }
      session->requests_.push_back(std::move(request));
    }
    mode_ = VideoMode{format, sc.size.width, sc.size.height, options_.fps};
    stride_ = sc.stride;
    setMode(mode_);
    pool_ = FramePool::create({format, sc.size.width, sc.size.height, session->requests_.size() + 1, 1, false});
    camera->requestCompleted.connect(this, &LibcameraCamera::completed);
    camera->disconnected.connect(this, &LibcameraCamera::disconnected);
    lc::ControlList startControls(lc::controls::controls);
    if (options_.fps > 0) {
      const auto us = static_cast<std::int64_t>(1e6 / options_.fps);
      startControls.set(lc::controls::FrameDurationLimits, lc::Span<const std::int64_t, 2>({us, us}));
    }
    if (camera->start(&startControls) != 0) {
      camera->requestCompleted.disconnect(this);
      camera->disconnected.disconnect(this);
      cleanup();
      return fail(Errc::kIo, "the camera would not start", id);
    }
    {
      std::lock_guard lock(session->mutex_);
      session->running_ = true;
      for (auto& r : session->requests_) camera->queueRequest(r.get());
    }
    session_ = session;
    return {};
  }

  void doClose() override {
    if (!session_) return;
    {
      std::lock_guard lock(session_->mutex_);
      session_->running_ = false;
    }
    session_->camera_->stop();
    session_->camera_->requestCompleted.disconnect(this);
    session_->camera_->disconnected.disconnect(this);
    session_->unref();
    session_ = nullptr;
    pool_.reset();
  }

  // libcamera's thread.
  void completed(lc::Request* request) {
    if (!session_) return;
    Session* s = session_;
    if (request->status() == lc::Request::RequestCancelled) {
      // Cancelled: the camera is stopping or cannot take buffers any more (unplugged). Nothing is
      // queued again from here on: a request queued now could come back after stop(), which
      // libcamera treats as fatal.
      std::lock_guard lock(s->mutex_);
      s->running_ = false;
      return;
    }
    auto it = request->buffers().find(s->stream_);
    if (it == request->buffers().end()) return;
    const lc::FrameBuffer* buffer = it->second;
    FrameRef frame = pool_->acquire();
    if (!frame) {
      countDrop();
      std::lock_guard lock(s->mutex_);
      if (s->running_) {
        request->reuse(lc::Request::ReuseBuffers);
        s->camera_->queueRequest(request);
      }
      return;
    }
    const auto& maps = s->maps_[buffer];
    const auto& planes = buffer->planes();
    const FrameLayout layout = computeLayout(mode_.format, mode_.width, mode_.height, 1);
    frame->planeCount = layout.planeCount;
    for (int i = 0; i < layout.planeCount; ++i) {
      Plane& p = frame->planes[static_cast<std::size_t>(i)];
      // Planar formats may come in one FrameBuffer plane (consecutive) or one per plane.
      const std::size_t src = std::min<std::size_t>(static_cast<std::size_t>(i), planes.size() - 1);
      const std::uint32_t stride =
          i == 0 || mode_.format == PixelFormat::kNv12 || mode_.format == PixelFormat::kNv21 ? stride_ : stride_ / 2;
      const std::size_t offset =
          planes.size() > 1
              ? planes[src].offset
              : planes[0].offset + (i == 0 ? 0
                                           : std::size_t{stride_} * mode_.height +
                                                 (i == 2 ? std::size_t{stride} * ((mode_.height + 1) / 2) : 0));
      p.data = static_cast<std::uint8_t*>(maps[src].first) + offset;
      p.stride = stride;
      p.offset = static_cast<std::uint32_t>(offset);
      p.size = layout.planes[static_cast<std::size_t>(i)].size;
      p.dmabufFd = planes[src].fd.get();
    }
    const auto& meta = buffer->metadata();
    frame->bytesUsed = meta.planes().empty() ? 0 : meta.planes()[0].bytesused;
    frame->sequence = meta.sequence;
    frame->captureTime = clock().isManual() ? clock().now() : Nanos{static_cast<std::int64_t>(meta.timestamp)};
    frame->pts = frame->captureTime;
    frame->producerCookie = reinterpret_cast<std::uint64_t>(request);
    s->ref();
    frame->setRelease(&Session::release, s);
    deliver(std::move(frame));
  }

  void disconnected() {
    if (session_) {
      // As for a cancelled request: no request is queued again once the camera is gone.
      std::lock_guard lock(session_->mutex_);
      session_->running_ = false;
    }
    reportLost(Error(Errc::kDeviceLost, "the camera was disconnected", info().path));
  }

  std::shared_ptr<LibcameraProvider::State> state_;
  V4l2Options options_;
  Session* session_ = nullptr;
  std::shared_ptr<FramePool> pool_;
  VideoMode mode_;
  std::uint32_t stride_ = 0;
};

}  // namespace

LibcameraProvider::LibcameraProvider() {
  std::lock_guard lock(sharedStateMutex());
  state_ = sharedState().lock();
  if (state_) return;
  state_ = std::make_shared<State>();
  // libcamera logs every INFO line to stderr; keep its warnings unless the user asked otherwise.
  // libcamera reads LIBCAMERA_LOG_LEVELS once, when its logger starts (on first use, here).
  ::setenv("LIBCAMERA_LOG_LEVELS", "*:ERROR", 0);
  state_->manager = std::make_unique<lc::CameraManager>();
  if (const int rc = state_->manager->start(); rc != 0) {
    state_->error = fmt::format("libcamera could not start: {}", std::strerror(-rc));
    state_->manager.reset();
  } else {
    state_->manager->cameraAdded.connect(state_.get(), &State::added);
    state_->manager->cameraRemoved.connect(state_.get(), &State::removed);
  }
  sharedState() = state_;
}

LibcameraProvider::~LibcameraProvider() {
  std::lock_guard lock(state_->mutex);
  state_->notify = nullptr;
}

std::string LibcameraProvider::startError() const { return state_->error; }

void LibcameraProvider::watchHotplug(const std::function<void(HotplugEvent)>& notify) {
  std::lock_guard lock(state_->mutex);
  state_->notify = notify;
}

std::vector<DeviceCandidate> LibcameraProvider::enumerate() {
  std::vector<DeviceCandidate> out;
  if (!state_->manager) return out;
  for (const std::shared_ptr<lc::Camera>& camera : state_->manager->cameras()) {
    DeviceCandidate c;
    c.kind = DeviceKind::kVideoSource;
    c.info.backend = "libcamera";
    c.info.path = camera->id();
    c.info.name = camera->id();
    const auto& props = camera->properties();
    if (auto model = props.get(lc::properties::Model)) c.info.name = *model;
    c.info.bus = "libcamera";
    auto config = camera->generateConfiguration({lc::StreamRole::VideoRecording});
    if (config && !config->empty()) c.usage = fmt::format("libcamera camera: {}", config->at(0).toString());
    out.push_back(std::move(c));
  }
  return out;
}

Result<std::shared_ptr<VideoSource>> LibcameraProvider::openVideoSource(const DeviceCandidate& candidate,
                                                                        const DeviceRequest& request,
                                                                        const Clock& clock) {
  if (!state_->manager) return fail(Errc::kUnavailable, state_->error, candidate.info.path);
  auto options = v4l2OptionsFrom(request);
  if (!options) return std::unexpected(options.error());
  return std::shared_ptr<VideoSource>(std::make_shared<LibcameraCamera>(candidate.info, state_, *options, clock));
}

}  // namespace basalt::devices
