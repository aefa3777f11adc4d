// Recorder: rendered frames to a movie file through GStreamer.
//
// Serves: LAVA's Rec (and `basalt run --record`). RGBA frames go through a fixed pool of
// GstBuffers (no allocation per frame) into appsrc, then videoconvert (the encoders want YUV),
// the encoder, the muxer and filesink. Limits: encoding runs on the CPU (x264 ultrafast, jpegenc,
// libvpx realtime). Configuration: RecorderOptions; the container comes from the extension.

#include "media/recorder.h"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <optional>
#include <system_error>

#include <fmt/format.h>
#include <fmt/std.h>

#include "media/gst_support.h"

namespace basalt::media {

std::string_view videoCodecName(VideoCodec codec) {
  switch (codec) {
    case VideoCodec::kAuto: return "auto";
    case VideoCodec::kH264: return "h264";
    case VideoCodec::kMjpeg: return "mjpeg";
    case VideoCodec::kVp8: return "vp8";
    case VideoCodec::kVp9: return "vp9";
  }
  return "auto";
}

Result<VideoCodec> parseVideoCodec(std::string_view name) {
  for (VideoCodec c : {VideoCodec::kAuto, VideoCodec::kH264, VideoCodec::kMjpeg, VideoCodec::kVp8, VideoCodec::kVp9}) {
    if (name == videoCodecName(c)) return c;
  }
  return fail(Errc::kInvalidArgument, fmt::format("unknown video codec '{}'; use h264, mjpeg, vp8, vp9 or auto", name));
}

namespace {

std::string lowerExtension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

struct Container {
  std::string_view muxer;
  std::string_view name;
  VideoCodec defaultCodec;
};

Result<Container> containerFor(const std::filesystem::path& path) {
  const std::string ext = lowerExtension(path);
  if (ext == ".mkv") return Container{"matroskamux", "Matroska", VideoCodec::kH264};
  if (ext == ".mp4") return Container{"mp4mux", "MP4", VideoCodec::kH264};
  if (ext == ".mov") return Container{"qtmux", "QuickTime", VideoCodec::kH264};
  if (ext == ".avi") return Container{"avimux", "AVI", VideoCodec::kMjpeg};
  if (ext == ".webm") return Container{"webmmux", "WebM", VideoCodec::kVp9};
  return fail(Errc::kInvalidArgument,
              fmt::format("cannot tell the movie format from '{}'; name the file .mkv, .mp4, .mov, .avi or .webm",
                          path.filename().string()));
}

std::string encoderFor(VideoCodec codec, const RecorderOptions& o) {
  const int q = std::clamp(o.quality, 1, 100);
  // A rate that grows with the picture and the quality: about 0.1 bit per pixel at 85.
  const double pixelsPerSecond = static_cast<double>(o.width) * o.height * o.fps;
  const auto kbps = static_cast<unsigned>(std::max(200.0, pixelsPerSecond * 0.12 * q / 85.0 / 1000.0));
  const auto keyInterval = static_cast<unsigned>(std::max(1.0, o.fps));
  switch (codec) {
    case VideoCodec::kMjpeg: return fmt::format("videoconvert ! video/x-raw,format=I420 ! jpegenc quality={}", q);
    case VideoCodec::kVp8:
      return fmt::format(
          "videoconvert ! video/x-raw,format=I420 ! vp8enc deadline=1 cpu-used=8 target-bitrate={} "
          "keyframe-max-dist={}",
          kbps * 1000, keyInterval);
    case VideoCodec::kVp9:
      return fmt::format(
          "videoconvert ! video/x-raw,format=I420 ! vp9enc deadline=1 cpu-used=8 target-bitrate={} "
          "keyframe-max-dist={}",
          kbps * 1000, keyInterval);
    case VideoCodec::kH264:
    case VideoCodec::kAuto:
      return fmt::format(
          "videoconvert ! video/x-raw,format=I420 ! x264enc speed-preset=ultrafast tune=zerolatency bitrate={} "
          "key-int-max={} ! h264parse",
          kbps, keyInterval);
  }
  return {};
}

std::string_view codecTitle(VideoCodec codec) {
  switch (codec) {
    case VideoCodec::kMjpeg: return "Motion-JPEG";
    case VideoCodec::kVp8: return "VP8";
    case VideoCodec::kVp9: return "VP9";
    default: return "H.264";
  }
}

}  // namespace

struct Recorder::Impl {
  Pipeline pipeline;
  GstElement* src = nullptr;  // borrowed
  GstBufferPool* pool = nullptr;
  Nanos frameDuration{0};
  std::string container;
  VideoCodec codec = VideoCodec::kH264;

  ~Impl() {
    pipeline.reset();
    if (pool) {
      gst_buffer_pool_set_active(pool, FALSE);
      gst_object_unref(pool);
    }
  }
};

Recorder::Recorder(const RecorderOptions& options, std::unique_ptr<Impl> impl)
    : options_(options), impl_(std::move(impl)) {}

Recorder::~Recorder() {
  if (!finished_) {
    auto r = finish(std::chrono::seconds(10));
    if (!r) log::warn(kLogMedia, "recording {}: {}", options_.path, r.error().describe());
  }
}

std::string Recorder::describe() const { return fmt::format("{} in {}", codecTitle(impl_->codec), impl_->container); }

Result<std::unique_ptr<Recorder>> Recorder::create(const RecorderOptions& options) {
  const std::string where = options.path.string();
  if (options.width == 0 || options.height == 0 || options.fps <= 0) {
    return fail(Errc::kInvalidArgument, "the recording needs a size and a frame rate", where);
  }
  auto container = containerFor(options.path);
  if (!container) return std::unexpected(container.error().at(where));
  const VideoCodec codec = options.codec == VideoCodec::kAuto ? container->defaultCodec : options.codec;
  if (container->muxer == "webmmux" && codec != VideoCodec::kVp8 && codec != VideoCodec::kVp9) {
    return fail(Errc::kInvalidArgument, "WebM holds only VP8 or VP9; choose --record-codec vp9 or another extension",
                where);
  }
  if ((codec == VideoCodec::kH264 || codec == VideoCodec::kVp8 || codec == VideoCodec::kVp9) &&
      (options.width % 2 != 0 || options.height % 2 != 0)) {
    return fail(
        Errc::kInvalidArgument,
        fmt::format("{} needs an even width and height, not {}x{}", codecTitle(codec), options.width, options.height),
        where);
  }
  const std::filesystem::path folder =
      options.path.has_parent_path() ? options.path.parent_path() : std::filesystem::path(".");
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (ec) {
    return fail(Errc::kIo, fmt::format("cannot create the folder {}: {}", folder, ec.message()), where);
  }
  const auto fpsN = static_cast<int>(std::lround(options.fps * 1000));
  std::string location = options.path.string();
  // Quotes in the path would end the property value early: refuse them rather than escape.
  if (location.find('"') != std::string::npos) {
    return fail(Errc::kInvalidArgument, "the recording's path may not contain '\"'", where);
  }
  const std::string description = fmt::format(
      "appsrc name=src format=time is-live=false block=false "
      "caps=video/x-raw,format=RGBA,width={},height={},framerate={}/1000,colorimetry=sRGB ! {} ! {} ! "
      "filesink name=sink location=\"{}\"",
      options.width, options.height, fpsN, encoderFor(codec, options), container->muxer, location);
  auto pipeline = parsePipeline(description, "recording");
  if (!pipeline) return std::unexpected(pipeline.error().at(where));
  auto impl = std::make_unique<Impl>();
  impl->pipeline = std::move(*pipeline);
  impl->src = impl->pipeline.child("src");
  impl->container = container->name;
  impl->codec = codec;
  impl->frameDuration = fromSeconds(1.0 / options.fps);

  // A fixed set of buffers: the frame loop copies into one and hands it over; the encoder gives
  // it back. Steady-state recording allocates nothing.
  const std::size_t frameBytes = std::size_t{options.width} * options.height * 4;
  impl->pool = gst_buffer_pool_new();
  GstStructure* config = gst_buffer_pool_get_config(impl->pool);
  CapsPtr caps(gst_caps_new_simple("video/x-raw", "format", G_TYPE_STRING, "RGBA", "width", G_TYPE_INT,
                                   static_cast<int>(options.width), "height", G_TYPE_INT,
                                   static_cast<int>(options.height), nullptr));
  const auto count = static_cast<guint>(std::max<std::size_t>(2, options.queueFrames));
  gst_buffer_pool_config_set_params(config, caps.get(), static_cast<guint>(frameBytes), count, count);
  if (!gst_buffer_pool_set_config(impl->pool, config) || !gst_buffer_pool_set_active(impl->pool, TRUE)) {
    return fail(Errc::kResourceExhausted, "cannot allocate the recording's frame buffers", where);
  }
  std::unique_ptr<Recorder> recorder(new Recorder(options, std::move(impl)));
  if (gst_element_set_state(recorder->impl_->pipeline.get(), GST_STATE_PLAYING) == GST_STATE_CHANGE_FAILURE) {
    auto r = recorder->checkBus();
    recorder->finished_ = true;
    return fail(Errc::kIo, r ? "cannot start recording" : r.error().message(), where);
  }
  if (auto r = recorder->checkBus(); !r) {
    recorder->finished_ = true;
    return std::unexpected(r.error());
  }
  log::info(kLogMedia, "recording {}x{} at {} fps to {} ({})", options.width, options.height, options.fps, options.path,
            recorder->describe());
  return recorder;
}

namespace {

/// One message for a failed recording: GStreamer's reason and what to do.
Error recordingError(GstMessage* message, const std::filesystem::path& path) {
  const std::string why = describeGstMessage(message);
  const std::string_view advice = why.find("space") != std::string::npos ? "free some disk space or record elsewhere"
                                                                         : "check the folder and the disk";
  return Error(Errc::kIo, fmt::format("recording failed: {}; {}", why, advice), path.string());
}

}  // namespace

Result<void> Recorder::checkBus() {
  if (failure_) return std::unexpected(*failure_);
  BusPtr bus(gst_element_get_bus(impl_->pipeline.get()));
  MessagePtr m(gst_bus_pop_filtered(bus.get(), GST_MESSAGE_ERROR));
  if (!m) return {};
  failure_ = recordingError(m.get(), options_.path);
  return std::unexpected(*failure_);
}

Result<void> Recorder::push(const Image& rgba) {
  if (finished_) return fail(Errc::kInvalidArgument, "the recording is finished", options_.path.string());
  if (auto r = checkBus(); !r) return r;
  if (full()) return {};
  if (rgba.width != options_.width || rgba.height != options_.height || rgba.channels != 4 ||
      rgba.type != ChannelType::kU8) {
    return fail(Errc::kInvalidArgument,
                fmt::format("frame of {}x{}x{} does not match the recording's {}x{} RGBA", rgba.width, rgba.height,
                            rgba.channels, options_.width, options_.height),
                options_.path.string());
  }
  GstBuffer* buffer = nullptr;
  GstBufferPoolAcquireParams params{};
  params.flags = GST_BUFFER_POOL_ACQUIRE_FLAG_DONTWAIT;
  GstFlowReturn flow = gst_buffer_pool_acquire_buffer(impl_->pool, &buffer, &params);
  if (flow == GST_FLOW_EOS && options_.waitForEncoder) {
    // Offline: wait for the encoder, checking now and then that it is still alive.
    while (flow == GST_FLOW_EOS) {
      if (auto r = checkBus(); !r) return r;
      g_usleep(1000);
      flow = gst_buffer_pool_acquire_buffer(impl_->pool, &buffer, &params);
    }
  }
  if (flow != GST_FLOW_OK || !buffer) {
    ++dropped_;
    return {};
  }
  GstMapInfo map;
  if (!gst_buffer_map(buffer, &map, GST_MAP_WRITE)) {
    gst_buffer_unref(buffer);
    return fail(Errc::kInternal, "cannot map a recording buffer", options_.path.string());
  }
  std::memcpy(map.data, rgba.pixels.data(), std::min<std::size_t>(map.size, rgba.byteSize()));
  gst_buffer_unmap(buffer, &map);
  GST_BUFFER_PTS(buffer) = toGstTime(impl_->frameDuration * frames_);
  GST_BUFFER_DURATION(buffer) = toGstTime(impl_->frameDuration);
  if (gst_app_src_push_buffer(reinterpret_cast<GstAppSrc*>(impl_->src), buffer) != GST_FLOW_OK) {
    if (auto r = checkBus(); !r) return r;
    return fail(Errc::kIo, "the encoder stopped taking frames", options_.path.string());
  }
  ++frames_;
  return {};
}

Result<void> Recorder::finish(std::chrono::milliseconds timeout) {
  if (finished_) {
    if (failure_) return std::unexpected(*failure_);
    return {};
  }
  finished_ = true;
  if (!failure_) {
    gst_app_src_end_of_stream(reinterpret_cast<GstAppSrc*>(impl_->src));
    BusPtr bus(gst_element_get_bus(impl_->pipeline.get()));
    MessagePtr m(gst_bus_timed_pop_filtered(bus.get(), static_cast<GstClockTime>(Nanos(timeout).count()),
                                            static_cast<GstMessageType>(GST_MESSAGE_EOS | GST_MESSAGE_ERROR)));
    if (!m) {
      failure_ = Error(Errc::kTimeout, "the encoder did not finish the file in time", options_.path.string());
    } else if (GST_MESSAGE_TYPE(m.get()) == GST_MESSAGE_ERROR) {
      failure_ = recordingError(m.get(), options_.path);
    }
  }
  impl_->pipeline.reset();
  if (failure_) return std::unexpected(*failure_);
  log::info(kLogMedia, "recorded {} frames to {}", frames_, options_.path);
  return {};
}

}  // namespace basalt::media
