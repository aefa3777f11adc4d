// Trace video: a video source's frames to and from Matroska, with their original timestamps.
//
// Serves: `basalt record` (the devices effort taps cameras into a trace) and the `replay`
// backend. Frames are stored as the device gave them: MJPEG stays MJPEG and raw YUV stays raw
// (Matroska's V_UNCOMPRESSED), so a replay decodes exactly what the camera sent. Limits: NV12
// and NV21 are rearranged to I420, which Matroska can hold (lossless). Timestamps are kept to
// the microsecond (Matroska's default scale is the millisecond; V4L2 stamps in microseconds).
// Configuration: none.

#include "media/trace_video.h"

#include <algorithm>
#include <cstring>
#include <system_error>

#include <fmt/format.h>
#include <fmt/std.h>

#include "media/gst_support.h"

namespace basalt::media {

namespace {

/// Caps of what the writer's appsrc takes, and whether it must be rearranged for Matroska.
Result<std::string> writerCaps(PixelFormat format, std::uint32_t width, std::uint32_t height, std::string& rearrange) {
  rearrange.clear();
  if (format == PixelFormat::kMjpeg) return fmt::format("image/jpeg,width={},height={},framerate=0/1", width, height);
  const GstVideoFormat gf = toGstFormat(format);
  if (gf == GST_VIDEO_FORMAT_UNKNOWN) {
    return fail(Errc::kUnsupported, fmt::format("{} frames cannot go into a trace", pixelFormatName(format)));
  }
  // Matroska holds I420, YV12, YUY2, UYVY, GRAY8, RGB and BGR as they are.
  if (format == PixelFormat::kNv12 || format == PixelFormat::kNv21) rearrange = "I420";
  if (format == PixelFormat::kRgba8 || format == PixelFormat::kBgra8) rearrange = "RGB";
  return fmt::format("video/x-raw,format={},width={},height={},framerate=0/1", gst_video_format_to_string(gf), width,
                     height);
}

}  // namespace

struct TraceVideoWriter::Impl {
  Pipeline pipeline;
  GstElement* src = nullptr;  // borrowed
  PixelFormat format = PixelFormat::kUnknown;
  std::uint32_t width = 0, height = 0;
  GstVideoInfo info{};
  std::optional<Nanos> origin;
  Nanos lastPts{-1};
  std::optional<Error> failure;

  Result<void> checkBus(const std::filesystem::path& path) {
    if (failure) return std::unexpected(*failure);
    BusPtr bus(gst_element_get_bus(pipeline.get()));
    MessagePtr m(gst_bus_pop_filtered(bus.get(), GST_MESSAGE_ERROR));
    if (!m) return {};
    failure =
        Error(Errc::kIo, fmt::format("writing the trace video failed: {}", describeGstMessage(m.get())), path.string());
    return std::unexpected(*failure);
  }
};

TraceVideoWriter::TraceVideoWriter(std::unique_ptr<Impl> impl, std::filesystem::path path)
    : impl_(std::move(impl)), path_(std::move(path)) {}

TraceVideoWriter::~TraceVideoWriter() {
  if (!finished_) {
    if (auto r = finish(); !r) log::warn(kLogMedia, "{}", r.error().describe());
  }
}

Result<std::unique_ptr<TraceVideoWriter>> TraceVideoWriter::create(const std::filesystem::path& path,
                                                                   PixelFormat format, std::uint32_t width,
                                                                   std::uint32_t height, std::optional<Nanos> origin) {
  if (width == 0 || height == 0) return fail(Errc::kInvalidArgument, "the trace video needs a size", path.string());
  std::string rearrange;
  auto caps = writerCaps(format, width, height, rearrange);
  if (!caps) return std::unexpected(caps.error().at(path.string()));
  if (path.string().find('"') != std::string::npos) {
    return fail(Errc::kInvalidArgument, "the trace video's path may not contain '\"'", path.string());
  }
  std::error_code ec;
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path(), ec);
  const std::string description = fmt::format(
      "appsrc name=src format=time is-live=false block=true max-bytes=67108864 caps={} ! {}matroskamux "
      "timecodescale=1000 ! "
      "filesink location=\"{}\"",
      *caps, rearrange.empty() ? std::string{} : fmt::format("videoconvert ! video/x-raw,format={} ! ", rearrange),
      path.string());
  auto pipeline = parsePipeline(description, "trace video");
  if (!pipeline) return std::unexpected(pipeline.error().at(path.string()));
  auto impl = std::make_unique<Impl>();
  impl->pipeline = std::move(*pipeline);
  impl->src = impl->pipeline.child("src");
  impl->format = format;
  impl->width = width;
  impl->height = height;
  impl->origin = origin;
  if (format != PixelFormat::kMjpeg) gst_video_info_set_format(&impl->info, toGstFormat(format), width, height);
  if (gst_element_set_state(impl->pipeline.get(), GST_STATE_PLAYING) == GST_STATE_CHANGE_FAILURE) {
    auto r = impl->checkBus(path);
    return fail(Errc::kIo, r ? "cannot start writing the trace video" : r.error().message(), path.string());
  }
  return std::unique_ptr<TraceVideoWriter>(new TraceVideoWriter(std::move(impl), path));
}

Result<void> TraceVideoWriter::write(const Frame& frame) {
  if (finished_) return fail(Errc::kInvalidArgument, "the trace video is finished", path_.string());
  if (auto r = impl_->checkBus(path_); !r) return r;
  if (frame.format != impl_->format || frame.width != impl_->width || frame.height != impl_->height) {
    return fail(Errc::kInvalidArgument,
                fmt::format("a {} {}x{} frame does not match the trace video's {} {}x{}", pixelFormatName(frame.format),
                            frame.width, frame.height, pixelFormatName(impl_->format), impl_->width, impl_->height),
                path_.string());
  }
  GstBuffer* buffer = nullptr;
  if (frame.format == PixelFormat::kMjpeg) {
    if (!frame.planes[0].data || frame.bytesUsed == 0) {
      return fail(Errc::kInvalidArgument, "an empty MJPEG frame", path_.string());
    }
    buffer = gst_buffer_new_memdup(frame.planes[0].data, frame.bytesUsed);
  } else {
    // Rows into GStreamer's default layout for the format (the frame's strides may differ).
    buffer = gst_buffer_new_allocate(nullptr, GST_VIDEO_INFO_SIZE(&impl_->info), nullptr);
    GstVideoFrame out;
    if (!gst_video_frame_map(&out, &impl_->info, buffer, GST_MAP_WRITE)) {
      gst_buffer_unref(buffer);
      return fail(Errc::kInternal, "cannot map a trace buffer", path_.string());
    }
    for (int p = 0; p < frame.planeCount && p < static_cast<int>(GST_VIDEO_FRAME_N_PLANES(&out)); ++p) {
      const Plane& in = frame.planes[static_cast<std::size_t>(p)];
      auto* dst = static_cast<std::uint8_t*>(GST_VIDEO_FRAME_PLANE_DATA(&out, p));
      const auto dstStride = static_cast<std::size_t>(GST_VIDEO_FRAME_PLANE_STRIDE(&out, p));
      const auto rows = static_cast<std::size_t>(GST_VIDEO_FRAME_COMP_HEIGHT(&out, p));
      const std::size_t rowBytes = std::min<std::size_t>(dstStride, in.stride);
      for (std::size_t y = 0; y < rows && in.data; ++y) {
        std::memcpy(dst + y * dstStride, in.data + y * in.stride, rowBytes);
      }
    }
    gst_video_frame_unmap(&out);
  }
  if (!impl_->origin) impl_->origin = frame.pts;
  Nanos pts = frame.pts - *impl_->origin;
  if (pts.count() < 0) pts = Nanos{0};
  if (impl_->lastPts.count() >= 0 && pts <= impl_->lastPts) pts = impl_->lastPts + Nanos{1000};  // strictly rising
  impl_->lastPts = pts;
  GST_BUFFER_PTS(buffer) = toGstTime(pts);
  GST_BUFFER_DTS(buffer) = toGstTime(pts);
  if (gst_app_src_push_buffer(reinterpret_cast<GstAppSrc*>(impl_->src), buffer) != GST_FLOW_OK) {
    if (auto r = impl_->checkBus(path_); !r) return r;
    return fail(Errc::kIo, "the trace video stopped taking frames", path_.string());
  }
  ++frames_;
  return {};
}

Result<void> TraceVideoWriter::finish(std::chrono::milliseconds timeout) {
  if (finished_) {
    if (impl_->failure) return std::unexpected(*impl_->failure);
    return {};
  }
  finished_ = true;
  gst_app_src_end_of_stream(reinterpret_cast<GstAppSrc*>(impl_->src));
  BusPtr bus(gst_element_get_bus(impl_->pipeline.get()));
  MessagePtr m(gst_bus_timed_pop_filtered(bus.get(), static_cast<GstClockTime>(Nanos(timeout).count()),
                                          static_cast<GstMessageType>(GST_MESSAGE_EOS | GST_MESSAGE_ERROR)));
  if (!m) {
    impl_->failure = Error(Errc::kTimeout, "the trace video was not finished in time", path_.string());
  } else if (GST_MESSAGE_TYPE(m.get()) == GST_MESSAGE_ERROR) {
    impl_->failure = Error(Errc::kIo, fmt::format("writing the trace video failed: {}", describeGstMessage(m.get())),
                           path_.string());
  }
  impl_->pipeline.reset();
  if (impl_->failure) return std::unexpected(*impl_->failure);
  return {};
}

// --- Reader ---------------------------------------------------------------------------------

struct TraceVideoReader::Impl {
  Pipeline pipeline;
  GstElement* sink = nullptr;  // borrowed
  Nanos origin{0};
  std::shared_ptr<FramePool> pool;
  GstVideoInfo info{};
  bool jpeg = false;
  std::uint64_t sequence = 0;
};

TraceVideoReader::TraceVideoReader(std::unique_ptr<Impl> impl, std::filesystem::path path)
    : impl_(std::move(impl)), path_(std::move(path)) {}

TraceVideoReader::~TraceVideoReader() = default;

Result<std::unique_ptr<TraceVideoReader>> TraceVideoReader::open(const std::filesystem::path& path, Nanos origin) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    return fail(Errc::kNotFound, "no such trace video file", path.string());
  }
  if (path.string().find('"') != std::string::npos) {
    return fail(Errc::kInvalidArgument, "the trace video's path may not contain '\"'", path.string());
  }
  auto pipeline =
      parsePipeline(fmt::format("filesrc location=\"{}\" ! matroskademux ! appsink name=sink sync=false max-buffers=4 "
                                "enable-last-sample=false caps=\"image/jpeg;video/x-raw\"",
                                path.string()),
                    "trace video reader");
  if (!pipeline) return std::unexpected(pipeline.error().at(path.string()));
  auto impl = std::make_unique<Impl>();
  impl->pipeline = std::move(*pipeline);
  impl->sink = impl->pipeline.child("sink");
  impl->origin = origin;
  if (auto r = waitForState(impl->pipeline, GST_STATE_PAUSED, std::chrono::seconds(10)); !r) {
    return fail(Errc::kParse, fmt::format("not a readable trace video: {}", r.error().message()), path.string());
  }
  PadPtr pad(gst_element_get_static_pad(impl->sink, "sink"));
  CapsPtr caps(gst_pad_get_current_caps(pad.get()));
  if (!caps || gst_caps_get_size(caps.get()) == 0) {
    return fail(Errc::kParse, "the trace video has no video track", path.string());
  }
  std::unique_ptr<TraceVideoReader> reader(new TraceVideoReader(std::move(impl), path));
  Impl& i = *reader->impl_;
  const GstStructure* s = gst_caps_get_structure(caps.get(), 0);
  gint w = 0, h = 0;
  gst_structure_get_int(s, "width", &w);
  gst_structure_get_int(s, "height", &h);
  reader->width_ = static_cast<std::uint32_t>(std::max(w, 0));
  reader->height_ = static_cast<std::uint32_t>(std::max(h, 0));
  i.jpeg = std::string_view(gst_structure_get_name(s)) == "image/jpeg";
  if (i.jpeg) {
    reader->format_ = PixelFormat::kMjpeg;
  } else {
    if (!gst_video_info_from_caps(&i.info, caps.get()))
      return fail(Errc::kParse, "unreadable video caps", path.string());
    reader->format_ = fromGstFormat(GST_VIDEO_INFO_FORMAT(&i.info));
  }
  if (reader->format_ == PixelFormat::kUnknown || reader->width_ == 0 || reader->height_ == 0) {
    return fail(Errc::kUnsupported, "the trace video's format is not one Basalt replays", path.string());
  }
  i.pool = FramePool::create({reader->format_, reader->width_, reader->height_, 8, 1, true});
  gst_element_set_state(i.pipeline.get(), GST_STATE_PLAYING);
  return reader;
}

Result<FrameRef> TraceVideoReader::next(std::chrono::milliseconds timeout) {
  Impl& i = *impl_;
  if (!i.pipeline) return FrameRef{};
  SamplePtr sample(gst_app_sink_try_pull_sample(reinterpret_cast<GstAppSink*>(i.sink),
                                                static_cast<GstClockTime>(Nanos(timeout).count())));
  if (!sample) {
    BusPtr bus(gst_element_get_bus(i.pipeline.get()));
    MessagePtr m(gst_bus_pop_filtered(bus.get(), GST_MESSAGE_ERROR));
    if (m)
      return fail(Errc::kParse, fmt::format("the trace video is damaged: {}", describeGstMessage(m.get())),
                  path_.string());
    if (gst_app_sink_is_eos(reinterpret_cast<GstAppSink*>(i.sink))) {
      i.pipeline.reset();
      return FrameRef{};
    }
    return fail(Errc::kTimeout, "reading the trace video timed out", path_.string());
  }
  GstBuffer* buffer = gst_sample_get_buffer(sample.get());
  FrameRef frame = i.pool->acquire();
  if (!frame) return fail(Errc::kResourceExhausted, "all replay frames are still held", path_.string());
  if (i.jpeg) {
    GstMapInfo map;
    if (!gst_buffer_map(buffer, &map, GST_MAP_READ)) return fail(Errc::kInternal, "cannot map a frame", path_.string());
    const bool fits = map.size <= frame->storageSize();
    if (fits) {
      std::memcpy(frame->planes[0].data, map.data, map.size);
      frame->bytesUsed = map.size;
    }
    gst_buffer_unmap(buffer, &map);
    if (!fits) return fail(Errc::kResourceExhausted, "an MJPEG frame larger than the raw picture", path_.string());
  } else {
    GstVideoFrame in;
    if (!gst_video_frame_map(&in, &i.info, buffer, GST_MAP_READ)) {
      return fail(Errc::kInternal, "cannot map a frame", path_.string());
    }
    for (int p = 0; p < frame->planeCount && p < static_cast<int>(GST_VIDEO_FRAME_N_PLANES(&in)); ++p) {
      Plane& out = frame->planes[static_cast<std::size_t>(p)];
      const auto* src = static_cast<const std::uint8_t*>(GST_VIDEO_FRAME_PLANE_DATA(&in, p));
      const auto srcStride = static_cast<std::size_t>(GST_VIDEO_FRAME_PLANE_STRIDE(&in, p));
      const std::size_t rows = out.size / out.stride;
      for (std::size_t y = 0; y < rows; ++y) {
        std::memcpy(out.data + y * out.stride, src + y * srcStride, std::min<std::size_t>(out.stride, srcStride));
      }
    }
    gst_video_frame_unmap(&in);
    frame->colorimetry = fromGstColorimetry(i.info.colorimetry);
  }
  frame->pts = fromGstTime(GST_BUFFER_PTS(buffer)) + i.origin;
  frame->captureTime = frame->pts;
  frame->sequence = i.sequence++;
  return frame;
}

}  // namespace basalt::media
