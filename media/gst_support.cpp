// GStreamer set-up shared by media/: lazy gst_init, pipeline owners, bus waits and format maps.
//
// GStreamer is initialised the first time a show needs video (a movie, a recording, an MJPEG
// camera), never at process start: a show without video does not pay for the plugin registry.

#include "media/gst_support.h"

#include <mutex>

#include <fmt/format.h>

#include "runtime/clock.h"

namespace basalt::media {

Result<void> ensureGstreamer() {
  static std::once_flag once;
  static std::string failure;
  std::call_once(once, [] {
    const SystemClock clock;
    const Nanos start = clock.now();
    GError* error = nullptr;
    if (!gst_init_check(nullptr, nullptr, &error)) {
      failure = fmt::format(
          "GStreamer could not start: {}; install GStreamer (apt-get install gstreamer1.0-plugins-base "
          "gstreamer1.0-plugins-good gstreamer1.0-libav)",
          error ? error->message : "unknown error");
      if (error) g_error_free(error);
      return;
    }
    log::debug(kLogMedia, "GStreamer {} started in {:.1f} ms", gst_version_string(),
               toSeconds(clock.now() - start) * 1e3);
  });
  if (!failure.empty()) return fail(Errc::kUnavailable, failure);
  return {};
}

GstElement* Pipeline::child(const char* name) const {
  if (!element_) return nullptr;
  GstElement* e = gst_bin_get_by_name(reinterpret_cast<GstBin*>(element_.get()), name);
  if (e) gst_object_unref(e);  // the bin keeps its child alive
  return e;
}

Result<Pipeline> parsePipeline(const std::string& description, std::string_view what) {
  if (auto r = ensureGstreamer(); !r) return std::unexpected(r.error());
  GError* error = nullptr;
  GstElement* element = gst_parse_launch_full(description.c_str(), nullptr, GST_PARSE_FLAG_FATAL_ERRORS, &error);
  if (error) {
    std::string message = error->message;
    g_error_free(error);
    if (element) gst_object_unref(element);
    return fail(Errc::kUnsupported, fmt::format("cannot build the {} pipeline: {}; is the GStreamer plugin installed "
                                                "(gstreamer1.0-plugins-good, -bad, -ugly, gstreamer1.0-libav)?",
                                                what, message));
  }
  if (!element) return fail(Errc::kInternal, fmt::format("cannot build the {} pipeline", what));
  // Floating when parse made a single element; then it becomes ours (STYLE.md: sink on adoption).
  if (g_object_is_floating(element)) gst_object_ref_sink(element);
  Pipeline pipeline(element);
  return pipeline;
}

std::string describeGstMessage(GstMessage* message) {
  GError* error = nullptr;
  gchar* debug = nullptr;
  if (GST_MESSAGE_TYPE(message) == GST_MESSAGE_ERROR) {
    gst_message_parse_error(message, &error, &debug);
  } else if (GST_MESSAGE_TYPE(message) == GST_MESSAGE_WARNING) {
    gst_message_parse_warning(message, &error, &debug);
  }
  std::string text = error ? error->message : "unknown GStreamer error";
  if (debug && *debug) {
    // GStreamer's debug text is "file.c(line): function (): /element/path:\nreason"; only the
    // reason helps a person, and only when there is one.
    const std::string_view d = debug;
    const auto newline = d.rfind('\n');
    if (newline != std::string_view::npos && newline + 1 < d.size())
      text += fmt::format(" ({})", d.substr(newline + 1));
  }
  if (error) g_error_free(error);
  g_free(debug);
  return text;
}

Result<void> waitForState(const Pipeline& pipeline, GstState target, std::chrono::milliseconds timeout) {
  const GstStateChangeReturn change = gst_element_set_state(pipeline.get(), target);
  BusPtr bus(gst_element_get_bus(pipeline.get()));
  if (change != GST_STATE_CHANGE_FAILURE && change != GST_STATE_CHANGE_ASYNC) {
    // Done already; an error may still be waiting on the bus.
    MessagePtr m(gst_bus_pop_filtered(bus.get(), GST_MESSAGE_ERROR));
    if (m) return fail(Errc::kUnsupported, describeGstMessage(m.get()));
    return {};
  }
  const SystemClock clock;
  const Nanos deadline = clock.now() + timeout;
  for (;;) {
    const Nanos left = deadline - clock.now();
    if (left <= Nanos{0}) {
      return fail(Errc::kTimeout, fmt::format("GStreamer did not get ready within {} ms", timeout.count()));
    }
    MessagePtr m(gst_bus_timed_pop_filtered(
        bus.get(), static_cast<GstClockTime>(left.count()),
        static_cast<GstMessageType>(GST_MESSAGE_ERROR | GST_MESSAGE_ASYNC_DONE | GST_MESSAGE_STATE_CHANGED)));
    if (!m) continue;
    if (GST_MESSAGE_TYPE(m.get()) == GST_MESSAGE_ERROR) {
      return fail(Errc::kUnsupported, describeGstMessage(m.get()));
    }
    if (GST_MESSAGE_TYPE(m.get()) == GST_MESSAGE_ASYNC_DONE) return {};
    if (GST_MESSAGE_SRC(m.get()) == reinterpret_cast<GstObject*>(pipeline.get())) {
      GstState old = GST_STATE_VOID_PENDING, now = GST_STATE_VOID_PENDING, pending = GST_STATE_VOID_PENDING;
      gst_message_parse_state_changed(m.get(), &old, &now, &pending);
      if (now == target) return {};
    }
  }
}

PixelFormat fromGstFormat(GstVideoFormat format) {
  switch (format) {
    case GST_VIDEO_FORMAT_I420: return PixelFormat::kI420;
    case GST_VIDEO_FORMAT_YV12: return PixelFormat::kYv12;
    case GST_VIDEO_FORMAT_NV12: return PixelFormat::kNv12;
    case GST_VIDEO_FORMAT_NV21: return PixelFormat::kNv21;
    case GST_VIDEO_FORMAT_YUY2: return PixelFormat::kYuyv;
    case GST_VIDEO_FORMAT_UYVY: return PixelFormat::kUyvy;
    case GST_VIDEO_FORMAT_RGBA: return PixelFormat::kRgba8;
    case GST_VIDEO_FORMAT_BGRA: return PixelFormat::kBgra8;
    case GST_VIDEO_FORMAT_RGB: return PixelFormat::kRgb8;
    case GST_VIDEO_FORMAT_GRAY8: return PixelFormat::kGray8;
    default: return PixelFormat::kUnknown;
  }
}

GstVideoFormat toGstFormat(PixelFormat format) {
  switch (format) {
    case PixelFormat::kI420: return GST_VIDEO_FORMAT_I420;
    case PixelFormat::kYv12: return GST_VIDEO_FORMAT_YV12;
    case PixelFormat::kNv12: return GST_VIDEO_FORMAT_NV12;
    case PixelFormat::kNv21: return GST_VIDEO_FORMAT_NV21;
    case PixelFormat::kYuyv: return GST_VIDEO_FORMAT_YUY2;
    case PixelFormat::kUyvy: return GST_VIDEO_FORMAT_UYVY;
    case PixelFormat::kRgba8: return GST_VIDEO_FORMAT_RGBA;
    case PixelFormat::kBgra8: return GST_VIDEO_FORMAT_BGRA;
    case PixelFormat::kRgb8: return GST_VIDEO_FORMAT_RGB;
    case PixelFormat::kGray8: return GST_VIDEO_FORMAT_GRAY8;
    default: return GST_VIDEO_FORMAT_UNKNOWN;
  }
}

Colorimetry fromGstColorimetry(const GstVideoColorimetry& colorimetry) {
  Colorimetry c;
  switch (colorimetry.matrix) {
    case GST_VIDEO_COLOR_MATRIX_BT709: c.matrix = Colorimetry::Matrix::kBt709; break;
    case GST_VIDEO_COLOR_MATRIX_BT2020: c.matrix = Colorimetry::Matrix::kBt2020; break;
    default: c.matrix = Colorimetry::Matrix::kBt601; break;
  }
  c.range = colorimetry.range == GST_VIDEO_COLOR_RANGE_0_255 ? Colorimetry::Range::kFull : Colorimetry::Range::kLimited;
  return c;
}

FrameRef wrapVideoBuffer(GstBuffer* buffer, const GstVideoInfo& info, FramePool& pool, VideoFrameSlot* slots,
                         std::size_t slotCount) {
  FrameRef frame = pool.acquire();
  if (!frame) return {};
  VideoFrameSlot* slot = nullptr;
  for (std::size_t i = 0; i < slotCount && !slot; ++i) {
    bool expected = false;
    if (slots[i].inUse.compare_exchange_strong(expected, true)) slot = &slots[i];
  }
  if (!slot) return {};
  if (!gst_video_frame_map(&slot->frame, &info, buffer, GST_MAP_READ)) {
    slot->inUse = false;
    return {};
  }
  Frame& f = *frame;
  f.format = fromGstFormat(GST_VIDEO_INFO_FORMAT(&info));
  f.width = static_cast<std::uint32_t>(GST_VIDEO_INFO_WIDTH(&info));
  f.height = static_cast<std::uint32_t>(GST_VIDEO_INFO_HEIGHT(&info));
  f.planeCount = static_cast<int>(GST_VIDEO_FRAME_N_PLANES(&slot->frame));
  for (int p = 0; p < f.planeCount && p < 4; ++p) {
    Plane& plane = f.planes[static_cast<std::size_t>(p)];
    plane.data = static_cast<std::uint8_t*>(GST_VIDEO_FRAME_PLANE_DATA(&slot->frame, p));
    plane.stride = static_cast<std::uint32_t>(GST_VIDEO_FRAME_PLANE_STRIDE(&slot->frame, p));
    plane.offset = 0;
    plane.size = std::size_t{plane.stride} * static_cast<std::uint32_t>(GST_VIDEO_FRAME_COMP_HEIGHT(&slot->frame, p));
    plane.dmabufFd = -1;
  }
  f.colorimetry = fromGstColorimetry(info.colorimetry);
  f.setRelease(
      [](void* context, Frame&) {
        auto* s = static_cast<VideoFrameSlot*>(context);
        gst_video_frame_unmap(&s->frame);
        s->inUse.store(false, std::memory_order_release);
      },
      slot);
  return frame;
}

std::string_view uploadableFormatsCaps() {
  return "video/x-raw,format=(string){I420,YV12,NV12,NV21,YUY2,UYVY,RGBA,BGRA,GRAY8}";
}

}  // namespace basalt::media
