// GStreamer's discoverer (gst-plugins-base pbutils) prerolls the file's demuxer and parsers in a
// private pipeline and reports its streams, without a main loop and with a timeout of its own.

#include "media/movie_probe.h"

#include <gst/pbutils/pbutils.h>

#include <cmath>

#include <fmt/format.h>
#include <fmt/std.h>

#include "media/gst_support.h"

namespace basalt::media {

namespace {

struct DiscovererInfoUnref {
  void operator()(GstDiscovererInfo* info) const {
    if (info) g_object_unref(info);
  }
};

struct StreamListFree {
  void operator()(GList* list) const {
    if (list) gst_discoverer_stream_info_list_free(list);
  }
};

struct ErrorFree {
  void operator()(GError* error) const {
    if (error) g_error_free(error);
  }
};

std::string codecOf(GstDiscovererStreamInfo* stream) {
  std::unique_ptr<GstCaps, GstCapsUnref> caps(gst_discoverer_stream_info_get_caps(stream));
  if (!caps) return {};
  gchar* description = gst_pb_utils_get_codec_description(caps.get());
  std::string out = description ? description : "";
  g_free(description);
  return out;
}

}  // namespace

Result<MovieInfo> probeMovie(const std::filesystem::path& file, std::chrono::milliseconds timeout) {
  const std::string where = file.string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) return fail(Errc::kNotFound, "the movie file is missing", where);
  if (auto r = ensureGstreamer(); !r) return std::unexpected(r.error());
  gst_pb_utils_init();
  GError* raw = nullptr;
  GstPtr<GstDiscoverer> discoverer(gst_discoverer_new(toGstTime(timeout), &raw));
  std::unique_ptr<GError, ErrorFree> error(raw);
  if (!discoverer) {
    return fail(Errc::kUnavailable,
                fmt::format("GStreamer's discoverer cannot start: {}", error ? error->message : "no reason given"),
                where);
  }
  const std::filesystem::path absolute = std::filesystem::absolute(file, ec);
  gchar* uri = gst_filename_to_uri(absolute.c_str(), nullptr);
  if (!uri) return fail(Errc::kInvalidArgument, "cannot make a URI of the file name", where);
  raw = nullptr;
  std::unique_ptr<GstDiscovererInfo, DiscovererInfoUnref> info(
      gst_discoverer_discover_uri(discoverer.get(), uri, &raw));
  g_free(uri);
  error.reset(raw);
  const std::string why = error ? error->message : "no reason given";
  if (!info) return fail(Errc::kIo, fmt::format("cannot be read as a movie: {}", why), where);
  switch (gst_discoverer_info_get_result(info.get())) {
    case GST_DISCOVERER_OK: break;
    case GST_DISCOVERER_TIMEOUT:
      return fail(Errc::kTimeout,
                  fmt::format("reading it as a movie took longer than {} ms; the file may be damaged or on a "
                              "slow disk",
                              timeout.count()),
                  where);
    case GST_DISCOVERER_MISSING_PLUGINS: {
      std::string missing;
      if (const gchar** details = gst_discoverer_info_get_missing_elements_installer_details(info.get())) {
        for (const gchar** d = details; *d; ++d) missing += fmt::format("{}{}", missing.empty() ? "" : ", ", *d);
      }
      return fail(Errc::kUnsupported,
                  fmt::format("this machine has no GStreamer plugin for it ({}); install the matching "
                              "gstreamer1.0-plugins-* package or convert the file (e.g. to VP9 in WebM)",
                              missing.empty() ? why : missing),
                  where);
    }
    case GST_DISCOVERER_URI_INVALID:
    case GST_DISCOVERER_ERROR:
    case GST_DISCOVERER_BUSY:
    default: return fail(Errc::kParse, fmt::format("cannot be read as a movie: {}", why), where);
  }
  std::unique_ptr<GList, StreamListFree> videos(gst_discoverer_info_get_video_streams(info.get()));
  if (!videos) return fail(Errc::kParse, "has no video stream (sound only, or not a movie)", where);
  auto* video = static_cast<GstDiscovererVideoInfo*>(videos->data);
  MovieInfo out;
  out.path = file;
  out.width = gst_discoverer_video_info_get_width(video);
  out.height = gst_discoverer_video_info_get_height(video);
  if (out.width == 0 || out.height == 0) return fail(Errc::kParse, "its video stream has no picture size", where);
  const guint parNum = gst_discoverer_video_info_get_par_num(video);
  const guint parDen = gst_discoverer_video_info_get_par_denom(video);
  out.pixelAspect = parNum > 0 && parDen > 0 ? static_cast<double>(parNum) / parDen : 1.0;
  const guint fpsNum = gst_discoverer_video_info_get_framerate_num(video);
  const guint fpsDen = gst_discoverer_video_info_get_framerate_denom(video);
  out.fps = fpsNum > 0 && fpsDen > 0 ? static_cast<double>(fpsNum) / fpsDen : 0;
  if (out.fps > 0) out.frameDuration = Nanos{static_cast<std::int64_t>(1e9 / out.fps)};
  const GstClockTime duration = gst_discoverer_info_get_duration(info.get());
  if (fromGstTime(duration) > Nanos{0}) {
    out.duration = fromGstTime(duration);
    if (out.fps > 0) out.frameCount = std::llround(toSeconds(out.duration) * out.fps);
  }
  out.codec = codecOf(static_cast<GstDiscovererStreamInfo*>(videos->data));
  std::unique_ptr<GList, StreamListFree> audios(gst_discoverer_info_get_audio_streams(info.get()));
  out.hasAudio = audios != nullptr;
  out.seekable = gst_discoverer_info_get_seekable(info.get()) != FALSE;
  return out;
}

}  // namespace basalt::media
