#pragma once

/// \file
/// \brief Private to media/: owners of GStreamer handles, lazy initialisation, and the small
/// helpers the player, the recorder, the MJPEG decoder and the trace files share. GStreamer is
/// included here and in media/*.cpp only.

#include <gst/app/gstappsink.h>
#include <gst/app/gstappsrc.h>
#include <gst/gst.h>
#include <gst/video/video.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <string>
#include <string_view>

#include "runtime/error.h"
#include "runtime/frame.h"
#include "runtime/log.h"

namespace basalt::media {

BASALT_LOG_CATEGORY(Media, "media");

/// \brief Initialises GStreamer once per process, on first use (never on the start-up path of a
/// show without video). Thread-safe. The error says what to install when GStreamer is broken.
[[nodiscard]] Result<void> ensureGstreamer();

struct GstObjectUnref {
  void operator()(gpointer object) const {
    if (object) gst_object_unref(object);
  }
};
struct GstSampleUnref {
  void operator()(GstSample* s) const {
    if (s) gst_sample_unref(s);
  }
};
struct GstMessageUnref {
  void operator()(GstMessage* m) const {
    if (m) gst_message_unref(m);
  }
};
struct GstCapsUnref {
  void operator()(GstCaps* c) const {
    if (c) gst_caps_unref(c);
  }
};
struct GstBufferUnref {
  void operator()(GstBuffer* b) const {
    if (b) gst_buffer_unref(b);
  }
};

template <typename T>
using GstPtr = std::unique_ptr<T, GstObjectUnref>;
using ElementPtr = GstPtr<GstElement>;
using BusPtr = GstPtr<GstBus>;
using PadPtr = GstPtr<GstPad>;
using SamplePtr = std::unique_ptr<GstSample, GstSampleUnref>;
using MessagePtr = std::unique_ptr<GstMessage, GstMessageUnref>;
using CapsPtr = std::unique_ptr<GstCaps, GstCapsUnref>;
using BufferPtr = std::unique_ptr<GstBuffer, GstBufferUnref>;

/// \brief A pipeline that is set to NULL before it is unreferenced (GStreamer's rule: never
/// drop the last reference of an element that is not in the NULL state).
class Pipeline {
 public:
  Pipeline() = default;
  explicit Pipeline(GstElement* adopted) : element_(adopted) {}
  Pipeline(Pipeline&&) noexcept = default;
  Pipeline& operator=(Pipeline&& other) noexcept {
    if (this != &other) {
      reset();
      element_ = std::move(other.element_);
    }
    return *this;
  }
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;
  ~Pipeline() { reset(); }

  void reset() {
    if (element_) gst_element_set_state(element_.get(), GST_STATE_NULL);
    element_.reset();
  }
  [[nodiscard]] GstElement* get() const { return element_.get(); }
  [[nodiscard]] GstPipeline* pipeline() const { return GST_PIPELINE(element_.get()); }
  explicit operator bool() const { return element_ != nullptr; }
  /// \brief The named child element (borrowed reference; the pipeline keeps it alive).
  [[nodiscard]] GstElement* child(const char* name) const;

 private:
  ElementPtr element_;
};

/// \brief Makes a pipeline from a gst-launch description; the error names `what`.
[[nodiscard]] Result<Pipeline> parsePipeline(const std::string& description, std::string_view what);

/// \brief "message (debug detail)" of an ERROR or WARNING message.
std::string describeGstMessage(GstMessage* message);

/// \brief Waits on the bus until the pipeline reaches `target` (ASYNC_DONE or state change), an
/// ERROR arrives, or `timeout` passes. The error carries GStreamer's message.
[[nodiscard]] Result<void> waitForState(const Pipeline& pipeline, GstState target, std::chrono::milliseconds timeout);

/// \brief Basalt's pixel format for a GStreamer raw video format, or kUnknown.
PixelFormat fromGstFormat(GstVideoFormat format);
/// \brief GStreamer's raw video format for a Basalt pixel format (GST_VIDEO_FORMAT_UNKNOWN for
/// MJPEG and unknown).
GstVideoFormat toGstFormat(PixelFormat format);
/// \brief The stream's YUV matrix and range.
Colorimetry fromGstColorimetry(const GstVideoColorimetry& colorimetry);

/// \brief The caps string of every raw format the renderer uploads without conversion.
std::string_view uploadableFormatsCaps();

/// \brief A Frame's hold on a mapped GStreamer video buffer, released by the Frame's release hook
/// (from whichever thread drops the last reference).
struct VideoFrameSlot {
  GstVideoFrame frame{};
  std::atomic<bool> inUse{false};  // set by the producer, cleared by the release hook
};

/// \brief Wraps a decoded buffer as a pooled Frame without copying: maps it (keeping a reference)
/// into a free slot and fills format, size and planes. Empty when no frame or slot is free (the
/// renderer still holds them) or the buffer cannot be mapped.
FrameRef wrapVideoBuffer(GstBuffer* buffer, const GstVideoInfo& info, FramePool& pool, VideoFrameSlot* slots,
                         std::size_t slotCount);

/// \brief Nanoseconds from a GstClockTime (GST_CLOCK_TIME_NONE becomes -1).
inline Nanos fromGstTime(GstClockTime t) {
  return GST_CLOCK_TIME_IS_VALID(t) ? Nanos{static_cast<std::int64_t>(t)} : Nanos{-1};
}
inline GstClockTime toGstTime(Nanos t) {
  return t.count() < 0 ? GST_CLOCK_TIME_NONE : static_cast<GstClockTime>(t.count());
}

}  // namespace basalt::media
