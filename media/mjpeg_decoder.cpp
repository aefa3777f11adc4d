// MjpegDecoder: a camera's Motion-JPEG frames to I420 Frames through GStreamer.
//
// Serves: USB cameras and capture cards that deliver MJPEG (most UVC cameras above 640x480).
// appsrc takes the camera's frames without copying them; jpegdec decodes on appsrc's streaming
// thread; 4:2:2 JPEGs (what YUYV sensors make) are resampled to I420 by videoconvert, the only
// CPU step (chroma subsampling, not colour conversion). Limits: CPU decoding (no VA-API here).
// Configuration: MjpegDecoderOptions.

#include "media/mjpeg_decoder.h"

#include <array>
#include <condition_variable>
#include <mutex>

#include <fmt/format.h>

#include "media/gst_support.h"

namespace basalt::media {

struct MjpegDecoder::Impl {
  explicit Impl(MjpegDecoderOptions o)
      : options(std::move(o)),
        queue(options.queueFrames),
        poolSize(options.queueFrames + 3),
        slots(std::make_unique<VideoFrameSlot[]>(poolSize)) {
    FramePool::Config config;
    config.format = PixelFormat::kUnknown;
    config.count = poolSize;
    config.allocateStorage = false;
    pool = FramePool::create(config);
  }
  ~Impl() {
    pipeline.reset();
    queue.clear();
  }

  MjpegDecoderOptions options;
  FrameQueue queue;
  std::size_t poolSize;
  std::shared_ptr<FramePool> pool;
  std::unique_ptr<VideoFrameSlot[]> slots;
  Pipeline pipeline;
  GstElement* src = nullptr;   // borrowed
  GstElement* sink = nullptr;  // borrowed
  GstElement* dec = nullptr;   // borrowed

  // Sequence numbers and capture times do not survive the decoder: they are looked up by pts.
  struct Stamp {
    std::int64_t pts = -1;
    std::uint64_t sequence = 0;
    Nanos captureTime{0};
  };
  std::mutex mutex;
  std::condition_variable decodedCv;
  std::array<Stamp, 32> stamps{};  // guarded by mutex
  std::size_t nextStamp = 0;       // guarded by mutex
  std::thread::id decodeThread;    // guarded by mutex
  CapsPtr lastCaps;                // streaming thread only; held so that its address stays its own
  GstVideoInfo info{};             // streaming thread only
  std::atomic<std::uint64_t> decoded{0};
  std::atomic<std::uint64_t> dropped{0};
  std::atomic<std::uint64_t> corrupt{0};

  GstFlowReturn onSample() {
    SamplePtr sample(gst_app_sink_pull_sample(reinterpret_cast<GstAppSink*>(sink)));
    if (!sample) return GST_FLOW_OK;
    GstBuffer* buffer = gst_sample_get_buffer(sample.get());
    GstCaps* caps = gst_sample_get_caps(sample.get());
    if (!buffer || !caps) return GST_FLOW_OK;
    if (caps != lastCaps.get()) {
      if (!gst_video_info_from_caps(&info, caps)) return GST_FLOW_OK;
      lastCaps.reset(gst_caps_ref(caps));
    }
    FrameRef frame = wrapVideoBuffer(buffer, info, *pool, slots.get(), poolSize);
    if (!frame) {
      dropped.fetch_add(1, std::memory_order_relaxed);
      return GST_FLOW_OK;
    }
    const Nanos pts = fromGstTime(GST_BUFFER_PTS(buffer));
    frame->pts = pts;
    {
      std::lock_guard lock(mutex);
      for (const Stamp& s : stamps) {
        if (s.pts == pts.count()) {
          frame->sequence = s.sequence;
          frame->captureTime = s.captureTime;
          break;
        }
      }
    }
    queue.pushDroppingOldest(std::move(frame));
    {
      std::lock_guard lock(mutex);  // so that a waiter cannot miss the notification
      decodeThread = std::this_thread::get_id();
      decoded.fetch_add(1, std::memory_order_relaxed);
    }
    decodedCv.notify_all();
    return GST_FLOW_OK;
  }
};

MjpegDecoder::MjpegDecoder(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

MjpegDecoder::~MjpegDecoder() = default;

Result<std::unique_ptr<MjpegDecoder>> MjpegDecoder::create(MjpegDecoderOptions options) {
  if (options.queueFrames < 1) options.queueFrames = 1;
  auto pipeline = parsePipeline(
      "appsrc name=src is-live=true format=time do-timestamp=false block=false max-bytes=33554432 "
      "caps=image/jpeg,framerate=0/1 ! jpegdec name=dec ! videoconvert ! video/x-raw,format=I420 ! "
      "appsink name=sink sync=false max-buffers=2 drop=true enable-last-sample=false",
      "MJPEG decoder");
  if (!pipeline) return std::unexpected(pipeline.error().at(options.name));
  auto impl = std::make_unique<Impl>(std::move(options));
  impl->pipeline = std::move(*pipeline);
  impl->src = impl->pipeline.child("src");
  impl->sink = impl->pipeline.child("sink");
  // A damaged JPEG is dropped, never fatal: a camera glitch must not end the stream.
  impl->dec = impl->pipeline.child("dec");
  if (impl->dec) g_object_set(impl->dec, "max-errors", -1, nullptr);
  GstAppSinkCallbacks callbacks{};
  callbacks.new_sample = [](GstAppSink*, gpointer data) { return static_cast<Impl*>(data)->onSample(); };
  gst_app_sink_set_callbacks(reinterpret_cast<GstAppSink*>(impl->sink), &callbacks, impl.get(), nullptr);
  BusPtr bus(gst_element_get_bus(impl->pipeline.get()));
  gst_bus_set_sync_handler(
      bus.get(),
      [](GstBus*, GstMessage* message, gpointer data) {
        auto* self = static_cast<Impl*>(data);
        const GstMessageType type = GST_MESSAGE_TYPE(message);
        // jpegdec drops a JPEG it cannot read with a QoS message (with max-errors = -1 it posts
        // no warning since GStreamer 1.16 or so); nothing else makes it drop here, as the sink
        // does not sync to a clock. Posted on the streaming thread: waiters are woken.
        const bool dropped =
            type == GST_MESSAGE_QOS && GST_MESSAGE_SRC(message) == reinterpret_cast<GstObject*>(self->dec);
        if (dropped) {
          {
            std::lock_guard lock(self->mutex);
            self->corrupt.fetch_add(1, std::memory_order_relaxed);
          }
          self->decodedCv.notify_all();
        }
        if (dropped || type == GST_MESSAGE_WARNING || type == GST_MESSAGE_ERROR) {
          static log::Once once;
          if (once.first()) {
            log::warn(kLogMedia, "{}: a JPEG frame could not be decoded ({}); such frames are dropped and counted",
                      self->options.name,
                      dropped ? std::string("the decoder dropped it") : describeGstMessage(message));
          }
        }
        return GST_BUS_DROP;  // nobody reads this bus: keep it from growing
      },
      impl.get(), nullptr);
  if (gst_element_set_state(impl->pipeline.get(), GST_STATE_PLAYING) == GST_STATE_CHANGE_FAILURE) {
    return fail(Errc::kUnavailable, "the MJPEG decoder did not start", impl->options.name);
  }
  return std::unique_ptr<MjpegDecoder>(new MjpegDecoder(std::move(impl)));
}

bool MjpegDecoder::push(const FrameRef& jpeg) {
  if (!jpeg || jpeg->format != PixelFormat::kMjpeg || jpeg->bytesUsed == 0 || !jpeg->planes[0].data) {
    impl_->dropped.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  // A JPEG cut short (a USB transfer that lost its end) has no end-of-image marker; jpegdec's
  // parser would wait for one forever and the frame would be neither shown nor counted. Cameras
  // may pad a frame after the marker, so look back over the padding.
  {
    const std::uint8_t* bytes = jpeg->planes[0].data;
    std::size_t end = jpeg->bytesUsed;
    const std::size_t floor = end > 4096 ? end - 4096 : 0;
    while (end > floor && bytes[end - 1] == 0) --end;
    if (end < 4 || bytes[end - 2] != 0xFF || bytes[end - 1] != 0xD9) {
      impl_->corrupt.fetch_add(1, std::memory_order_relaxed);
      impl_->decodedCv.notify_all();
      return false;
    }
  }
  // The buffer wraps the camera's memory and holds the frame until the decoder is done.
  auto* hold = new FrameRef(jpeg);
  GstBuffer* buffer =
      gst_buffer_new_wrapped_full(GST_MEMORY_FLAG_READONLY, jpeg->planes[0].data, jpeg->bytesUsed, 0, jpeg->bytesUsed,
                                  hold, [](gpointer data) { delete static_cast<FrameRef*>(data); });
  GST_BUFFER_PTS(buffer) = toGstTime(jpeg->pts);
  {
    std::lock_guard lock(impl_->mutex);
    impl_->stamps[impl_->nextStamp] = {jpeg->pts.count(), jpeg->sequence, jpeg->captureTime};
    impl_->nextStamp = (impl_->nextStamp + 1) % impl_->stamps.size();
  }
  if (gst_app_src_push_buffer(reinterpret_cast<GstAppSrc*>(impl_->src), buffer) != GST_FLOW_OK) {
    impl_->dropped.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  return true;
}

FrameRef MjpegDecoder::frameAt(Nanos showTime) { return impl_->queue.takeDue(showTime); }

bool MjpegDecoder::waitForDecoded(std::uint64_t count, std::chrono::milliseconds timeout) {
  std::unique_lock lock(impl_->mutex);
  return impl_->decodedCv.wait_for(lock, timeout,
                                   [this, count] { return impl_->decoded.load(std::memory_order_relaxed) >= count; });
}

bool MjpegDecoder::waitForFinished(std::uint64_t count, std::chrono::milliseconds timeout) {
  std::unique_lock lock(impl_->mutex);
  return impl_->decodedCv.wait_for(lock, timeout, [this, count] {
    return impl_->decoded.load(std::memory_order_relaxed) + impl_->corrupt.load(std::memory_order_relaxed) >= count;
  });
}

std::thread::id MjpegDecoder::decodeThread() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->decodeThread;
}

std::uint64_t MjpegDecoder::decoded() const { return impl_->decoded.load(std::memory_order_relaxed); }
std::uint64_t MjpegDecoder::dropped() const {
  return impl_->dropped.load(std::memory_order_relaxed) + impl_->queue.dropped();
}
std::uint64_t MjpegDecoder::corrupt() const { return impl_->corrupt.load(std::memory_order_relaxed); }

}  // namespace basalt::media
