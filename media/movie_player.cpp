// MoviePlayer: movie files through GStreamer, decoded on the player's own thread into pooled
// Frames, with LAVA's VCR controls and gapless loops and playlists.
//
// Serves: any container and codec this machine's GStreamer plugins decode, within the codecs
// Basalt supports (kSupportedVideo below: MPEG-1/2, Motion-JPEG, H.264, H.265, VP8, VP9, AV1,
// Theora, raw), so that a show behaves the same on every node whatever extra plugins it has.
// Frames leave in the decoder's own format (I420, NV12, YUY2, ...): the renderer converts them
// in a shader. Only formats the renderer cannot upload go through videoconvert.
// Limits: audio, when enabled, plays on GStreamer's clock and is not locked to the VCR timeline
// (it keeps playing through pause and ignores the shuttle). Reverse shuttle is made of accurate
// seeks, one per shown frame. Configuration: MoviePlayerOptions (queue depth, audio).

#include "media/movie_player.h"

#include <gst/pbutils/pbutils.h>

#include <unistd.h>
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <system_error>
#include <thread>

#include <fmt/format.h>
#include <fmt/std.h>

#include "media/gst_support.h"

namespace basalt::media {

namespace {

constexpr std::chrono::milliseconds kOpenTimeout{10000};
constexpr std::chrono::milliseconds kPoll{20};

/// Video codecs Basalt plays (caps structure names; MPEG video only in versions 1 and 2).
bool supportedVideoCaps(const GstStructure* s) {
  const std::string_view name = gst_structure_get_name(s);
  if (name == "video/mpeg") {
    gint version = 0;
    gst_structure_get_int(s, "mpegversion", &version);
    return version == 1 || version == 2;
  }
  static constexpr std::array<std::string_view, 8> kSupportedVideo = {"video/x-h264",   "video/x-h265", "video/x-vp8",
                                                                      "video/x-vp9",    "video/x-av1",  "image/jpeg",
                                                                      "video/x-theora", "video/x-raw"};
  return std::find(kSupportedVideo.begin(), kSupportedVideo.end(), name) != kSupportedVideo.end();
}

/// True for caps of coded or raw video, false for containers (which are "video/..." too).
bool isVideoCaps(const GstStructure* s) {
  const std::string_view name = gst_structure_get_name(s);
  static constexpr std::array<std::string_view, 8> kContainers = {
      "video/quicktime", "video/x-msvideo", "video/x-matroska", "video/webm",
      "video/mpegts",    "video/x-flv",     "video/x-ms-asf",   "video/x-dv"};
  if (std::find(kContainers.begin(), kContainers.end(), name) != kContainers.end()) return false;
  gboolean system = FALSE;
  if (gst_structure_get_boolean(s, "systemstream", &system) && system) return false;
  return name.starts_with("video/") || name == "image/jpeg";
}

std::string codecDescription(const GstCaps* caps) {
  gchar* d = gst_pb_utils_get_codec_description(caps);
  std::string text = d ? d : "";
  g_free(d);
  if (text.empty() && gst_caps_get_size(caps) > 0) text = gst_structure_get_name(gst_caps_get_structure(caps, 0));
  return text;
}

}  // namespace

/// One opened movie file: its pipeline, what the streaming threads learnt about it, and where
/// its frames go on the timeline. Owned by the decoder thread; the callbacks' fields are
/// guarded by `mutex`.
struct Clip {
  Clip() = default;
  Clip(const Clip&) = delete;
  Clip& operator=(const Clip&) = delete;
  // The pipeline stops first: its streaming threads call back into the fields below.
  ~Clip() { pipeline.reset(); }

  std::filesystem::path path;
  std::size_t entry = 0;
  Pipeline pipeline;
  GstElement* convert = nullptr;  // borrowed from the pipeline
  GstElement* sink = nullptr;     // borrowed from the pipeline
  bool audio = false;
  std::string name;

  std::mutex mutex;
  bool videoLinked = false;       // guarded by mutex
  bool noMorePads = false;        // guarded by mutex
  bool hasAudio = false;          // guarded by mutex
  bool audioUnavailable = false;  // guarded by mutex: sound asked for, no audio output here
  std::string codec;              // guarded by mutex
  std::string unsupported;        // guarded by mutex: a video codec Basalt does not play

  // Decoder thread only:
  bool prerolled = false;
  MovieInfo info;
  Nanos start{-1};   // stream pts of frame 0
  CapsPtr lastCaps;  // held, so that a new caps cannot reuse its address
  GstVideoInfo videoInfo{};
};

namespace {

/// The audio sink this machine can open (its factory name), or empty where it has none (no
/// sound device, no sound server). Probed once per process, as autoaudiosink chooses: by rank,
/// the first sink that reaches READY. autoaudiosink itself falls back to a fake sink without a
/// word, so a show would play silently and nobody would know why.
const std::string& usableAudioSink() {
  static const std::string found = [] {
    GList* factories = gst_element_factory_list_get_elements(
        GST_ELEMENT_FACTORY_TYPE_SINK | GST_ELEMENT_FACTORY_TYPE_MEDIA_AUDIO, GST_RANK_MARGINAL);
    factories = g_list_sort(factories, reinterpret_cast<GCompareFunc>(gst_plugin_feature_rank_compare_func));
    std::string name;
    for (GList* l = factories; l && name.empty(); l = l->next) {
      auto* factory = static_cast<GstElementFactory*>(l->data);
      GstElement* sink = gst_element_factory_create(factory, nullptr);
      if (!sink) continue;
      gst_object_ref_sink(sink);
      if (gst_element_set_state(sink, GST_STATE_READY) == GST_STATE_CHANGE_SUCCESS) {
        name = gst_plugin_feature_get_name(GST_PLUGIN_FEATURE(factory));
      }
      gst_element_set_state(sink, GST_STATE_NULL);
      gst_object_unref(sink);
    }
    gst_plugin_feature_list_free(factories);
    return name;
  }();
  return found;
}

/// Says once per process that sound is asked for but the machine cannot play it.
void noteNoAudioSink(const std::string& player, const std::filesystem::path& file) {
  static log::Once once;
  if (once.first()) {
    log::warn(kLogMedia,
              "{}: {}: sound is on (--audio) but this machine has no audio output (no sound device or sound "
              "server reachable); movies play without sound",
              player, file.string());
  }
}

void onPadAdded(GstElement*, GstPad* pad, gpointer data) {
  auto* clip = static_cast<Clip*>(data);
  CapsPtr caps(gst_pad_get_current_caps(pad));
  if (!caps) caps.reset(gst_pad_query_caps(pad, nullptr));
  if (!caps || gst_caps_get_size(caps.get()) == 0) return;
  const GstStructure* s = gst_caps_get_structure(caps.get(), 0);
  const std::string_view name = gst_structure_get_name(s);
  GstElement* bin = clip->pipeline.get();
  if (name == "video/x-raw") {
    std::lock_guard lock(clip->mutex);
    if (!clip->videoLinked) {
      PadPtr sinkPad(gst_element_get_static_pad(clip->convert, "sink"));
      clip->videoLinked = gst_pad_link(pad, sinkPad.get()) == GST_PAD_LINK_OK;
      return;
    }
  } else if (isVideoCaps(s)) {
    std::lock_guard lock(clip->mutex);
    if (!clip->videoLinked && clip->unsupported.empty()) clip->unsupported = codecDescription(caps.get());
  }
  // Everything else (sound, subtitles, data, extra video tracks) ends in a sink that never waits.
  GstElement* tail = nullptr;
  if (name == "audio/x-raw" && clip->audio && !usableAudioSink().empty()) {
    const std::string description = fmt::format("queue ! audioconvert ! audioresample ! {}", usableAudioSink());
    tail = gst_parse_bin_from_description(description.c_str(), TRUE, nullptr);
  }
  if (!tail) {
    tail = gst_element_factory_make("fakesink", nullptr);
    if (!tail) return;
    g_object_set(tail, "sync", FALSE, "async", FALSE, nullptr);
  }
  gst_bin_add(reinterpret_cast<GstBin*>(bin), tail);
  PadPtr tailPad(gst_element_get_static_pad(tail, "sink"));
  gst_pad_link(pad, tailPad.get());
  gst_element_sync_state_with_parent(tail);
}

void onNoMorePads(GstElement*, gpointer data) {
  auto* clip = static_cast<Clip*>(data);
  std::lock_guard lock(clip->mutex);
  clip->noMorePads = true;
}

/// Decodes only what Basalt plays: unsupported video stays encoded (and is reported), and
/// sound is not decoded at all when the player discards it or the machine cannot play it.
gboolean onAutoplugContinue(GstElement*, GstPad*, GstCaps* caps, gpointer data) {
  auto* clip = static_cast<Clip*>(data);
  if (gst_caps_get_size(caps) == 0) return TRUE;
  const GstStructure* s = gst_caps_get_structure(caps, 0);
  const std::string_view name = gst_structure_get_name(s);
  if (name.starts_with("audio/")) {
    std::lock_guard lock(clip->mutex);
    clip->hasAudio = true;
    if (clip->audio && usableAudioSink().empty()) {
      clip->audioUnavailable = true;
      noteNoAudioSink(clip->name, clip->path);
    }
    return clip->audio && !clip->audioUnavailable ? TRUE : FALSE;
  }
  if (isVideoCaps(s) && name != "video/x-raw") {
    std::lock_guard lock(clip->mutex);
    if (!supportedVideoCaps(s)) {
      if (clip->unsupported.empty()) clip->unsupported = codecDescription(caps);
      return FALSE;
    }
    // The most specific description wins (the parser's caps name the profile).
    if (gst_structure_has_field(s, "profile") || clip->codec.empty()) clip->codec = codecDescription(caps);
  }
  return TRUE;
}

/// Answers the file source's allocation query at once, with "no preference", instead of letting
/// it wait in the queue. A file source asks again whenever decodebin relinks (a reconfigure),
/// often after its last read; the query is serialized, so it sits in the queue behind the file's
/// data. When the demuxer has every sample before that data is pushed (push mode with the index
/// after the media data: it seeked to the index and back), it answers EOS, the queue drops what
/// it holds, and on this GStreamer the waiting source is never woken: it never sends EOS, and
/// the decoder keeps its last frames for ever. A file source needs nothing from downstream's
/// allocation answer, so failing the query costs nothing (it already fails it at start-up).
GstPadProbeReturn refuseAllocationQuery(GstPad*, GstPadProbeInfo* info, gpointer) {
  GstQuery* query = GST_PAD_PROBE_INFO_QUERY(info);
  if (query != nullptr && GST_QUERY_TYPE(query) == GST_QUERY_ALLOCATION) return GST_PAD_PROBE_DROP;
  return GST_PAD_PROBE_OK;
}

}  // namespace

struct MoviePlayer::Impl {
  explicit Impl(MoviePlayerOptions o)
      : options(std::move(o)),
        queue(options.queueFrames),
        poolSize(options.queueFrames + 4),
        slots(std::make_unique<VideoFrameSlot[]>(poolSize)) {
    FramePool::Config config;
    config.format = PixelFormat::kUnknown;
    config.count = poolSize;
    config.allocateStorage = false;
    pool = FramePool::create(config);
  }

  MoviePlayerOptions options;
  FrameQueue queue;
  std::size_t poolSize;
  std::shared_ptr<FramePool> pool;
  std::unique_ptr<VideoFrameSlot[]> slots;
  std::thread worker;

  struct Command {
    enum class Kind : std::uint8_t { kLoad, kSeek, kUnload, kRepeat, kInjectStall, kQuit } kind;
    std::uint64_t generation = 0;
    std::vector<std::filesystem::path> paths;
    std::int64_t index = 0;
    Nanos base{0};
    bool flag = false;
  };

  mutable std::mutex mutex;
  std::condition_variable commandCv;      // commands arrived
  std::condition_variable progressCv;     // a frame was pushed, the state changed or a clip ended
  std::deque<Command> commands;           // guarded by mutex
  MovieState state = MovieState::kEmpty;  // guarded by mutex
  std::optional<Error> error;             // guarded by mutex
  MovieInfo info;                         // guarded by mutex
  std::uint64_t pushedGeneration = 0;     // guarded by mutex: generation of the newest frame pushed
  Nanos newestPts{-1};                    // guarded by mutex: its pts
  std::uint64_t endedGeneration = 0;      // guarded by mutex: the generation whose clip ended for good
  bool ended = false;                     // guarded by mutex

  std::atomic<std::uint64_t> decoded{0};
  std::atomic<std::uint64_t> shown{0};
  std::atomic<std::uint64_t> loops{0};
  std::atomic<std::int64_t> passNs{0};         // one pass of a looping clip on the timeline (0: not looped yet)
  std::atomic<std::int64_t> endedEarlyNs{-1};  // MovieInfo::endedEarlyAt of the loaded clip, read each frame
  std::atomic<std::uint64_t> stalls{0};

  // Decoder thread only:
  std::vector<std::filesystem::path> playlist;
  std::unique_ptr<Clip> current;
  std::unique_ptr<Clip> next;
  bool repeat = false;
  std::uint64_t generation = 0;
  Nanos base{0};               // timeline position of the current pass's frame 0
  bool rebase = false;         // after a seek: set `base` from the first frame
  Nanos seekTimeline{0};       // ... so that it lands here
  std::int64_t dropBelow = 0;  // after an accurate seek: frames before the target are dropped
  Nanos lastPts{-1};           // timeline pts of the last frame pushed
  std::int64_t lastIndex = -1;
  bool clipEnded = false;
  // Since when the clip playing has had room in the queue and delivered nothing (the stall
  // watchdog); reset by every frame, full queue, end of clip and command.
  std::optional<std::chrono::steady_clock::time_point> starvedSince;
  bool recovering = false;  // a stalled pipeline was built again; its first frame says so

  void post(Command c) {
    {
      std::lock_guard lock(mutex);
      commands.push_back(std::move(c));
    }
    commandCv.notify_one();
  }

  void setFailed(const Error& e) {
    {
      std::lock_guard lock(mutex);
      state = MovieState::kFailed;
      error = e;
    }
    progressCv.notify_all();
    if (!options.logFailures) return;
    log::error(kLogMedia, "{}: {}; showing the fallback texture (load the movie again to retry)", options.name,
               e.describe());
  }

  Result<std::unique_ptr<Clip>> openClip(std::size_t entry, bool wait);
  Result<void> finishOpen(Clip& clip, std::chrono::milliseconds timeout);
  void run();
  bool handleCommands();
  void load(const Command& c);
  void seek(const Command& c);
  bool pollBus(Clip& clip);
  void deliver(GstSample* sample);
  void endOfClip();
  void prerollNext();
  void watchStarvation();
  void restartStalled(std::chrono::steady_clock::duration starved);
  void blockVideo();
  Nanos frameDuration() const { return current ? current->info.frameDuration : Nanos{33333333}; }
};

Result<std::unique_ptr<Clip>> MoviePlayer::Impl::openClip(std::size_t entry, bool wait) {
  auto clip = std::make_unique<Clip>();
  clip->path = playlist[entry];
  clip->entry = entry;
  clip->audio = options.audio;
  clip->name = options.name;
  if (auto r = ensureGstreamer(); !r) return std::unexpected(r.error());
  // filesrc ! queue ! decodebin, linked by hand in onPadAdded so that sound and other streams
  // are routed and unsupported codecs reported. The queue puts the demuxer in push mode: in pull
  // mode decodebin can swallow a demuxer's error raised while it is still being set up (a
  // damaged file then never prerolls and never says why).
  GstElement* pipeline = gst_pipeline_new(nullptr);
  GstElement* src = gst_element_factory_make("filesrc", nullptr);
  GstElement* pushQueue = gst_element_factory_make("queue", nullptr);
  GstElement* dec = gst_element_factory_make("decodebin", "dec");
  GError* parseError = nullptr;
  const std::string formats =
      options.cpuConvertTo == PixelFormat::kUnknown
          ? std::string(uploadableFormatsCaps())
          : fmt::format("video/x-raw,format={}", gst_video_format_to_string(toGstFormat(options.cpuConvertTo)));
  const std::string tailDescription = fmt::format("videoconvert ! {} ! appsink name=sink", formats);
  GstElement* tail = gst_parse_bin_from_description(tailDescription.c_str(), TRUE, &parseError);
  if (!pipeline || !src || !pushQueue || !dec || !tail) {
    if (parseError) g_error_free(parseError);
    for (GstElement* e : {pipeline, src, pushQueue, dec, tail}) {
      if (e) gst_object_unref(gst_object_ref_sink(e));
    }
    return fail(Errc::kUnsupported,
                "GStreamer lacks filesrc, queue, decodebin, videoconvert or appsink; install "
                "gstreamer1.0-plugins-base",
                clip->path.string());
  }
  gst_object_ref_sink(pipeline);
  clip->pipeline = Pipeline(pipeline);
  gst_bin_add_many(reinterpret_cast<GstBin*>(pipeline), src, pushQueue, dec, tail, nullptr);
  gst_element_link_many(src, pushQueue, dec, nullptr);
  clip->convert = tail;
  clip->sink = gst_bin_get_by_name(reinterpret_cast<GstBin*>(tail), "sink");
  gst_object_unref(clip->sink);  // the bin keeps it alive
  g_object_set(src, "location", clip->path.c_str(), nullptr);
  if (GstPad* srcPad = gst_element_get_static_pad(src, "src")) {
    gst_pad_add_probe(srcPad, GST_PAD_PROBE_TYPE_QUERY_DOWNSTREAM, refuseAllocationQuery, nullptr, nullptr);
    gst_object_unref(srcPad);
  }
  g_object_set(clip->sink, "sync", FALSE, "max-buffers", 2U, "drop", FALSE, "emit-signals", FALSE, "enable-last-sample",
               FALSE, nullptr);
  g_signal_connect(dec, "pad-added", G_CALLBACK(onPadAdded), clip.get());
  g_signal_connect(dec, "no-more-pads", G_CALLBACK(onNoMorePads), clip.get());
  g_signal_connect(dec, "autoplug-continue", G_CALLBACK(onAutoplugContinue), clip.get());

  if (gst_element_set_state(clip->pipeline.get(), GST_STATE_PAUSED) == GST_STATE_CHANGE_FAILURE) {
    BusPtr bus(gst_element_get_bus(clip->pipeline.get()));
    MessagePtr m(gst_bus_pop_filtered(bus.get(), GST_MESSAGE_ERROR));
    return fail(Errc::kUnsupported, m ? describeGstMessage(m.get()) : "GStreamer cannot open it", clip->path.string());
  }
  if (wait) {
    if (auto r = finishOpen(*clip, kOpenTimeout); !r) return std::unexpected(r.error());
  }
  return clip;
}

Result<void> MoviePlayer::Impl::finishOpen(Clip& clip, std::chrono::milliseconds timeout) {
  if (clip.prerolled) return {};
  BusPtr bus(gst_element_get_bus(clip.pipeline.get()));
  const SystemClock clock;
  const Nanos deadline = clock.now() + timeout;
  const std::string where = clip.path.string();
  for (;;) {
    {
      std::lock_guard lock(clip.mutex);
      if (!clip.unsupported.empty() && !clip.videoLinked && clip.noMorePads) {
        return fail(Errc::kUnsupported,
                    fmt::format("unsupported video codec: {}; Basalt plays H.264, H.265, VP8, VP9, AV1, MPEG-1/2, "
                                "Motion-JPEG and Theora: re-encode the movie (e.g. to H.264)",
                                clip.unsupported),
                    where);
      }
      if (clip.noMorePads && !clip.videoLinked) {
        return fail(Errc::kUnsupported, "the file has no video stream Basalt can show", where);
      }
    }
    MessagePtr m(gst_bus_timed_pop_filtered(
        bus.get(), static_cast<GstClockTime>(std::chrono::nanoseconds(kPoll).count()),
        static_cast<GstMessageType>(GST_MESSAGE_ERROR | GST_MESSAGE_ASYNC_DONE | GST_MESSAGE_ELEMENT)));
    if (m && GST_MESSAGE_TYPE(m.get()) == GST_MESSAGE_ERROR) {
      std::string why = describeGstMessage(m.get());
      std::lock_guard lock(clip.mutex);
      if (!clip.unsupported.empty()) {
        why = fmt::format("unsupported video codec: {}; re-encode the movie (e.g. to H.264)", clip.unsupported);
      }
      return fail(Errc::kUnsupported, fmt::format("cannot play the movie: {}", why), where);
    }
    if (m && GST_MESSAGE_TYPE(m.get()) == GST_MESSAGE_ELEMENT && gst_is_missing_plugin_message(m.get())) {
      gchar* d = gst_missing_plugin_message_get_description(m.get());
      std::string what = d ? d : "a plugin";
      g_free(d);
      return fail(Errc::kUnsupported,
                  fmt::format("this machine's GStreamer lacks {} for this movie; install gstreamer1.0-libav and "
                              "gstreamer1.0-plugins-good/-bad/-ugly",
                              what),
                  where);
    }
    if (m && GST_MESSAGE_TYPE(m.get()) == GST_MESSAGE_ASYNC_DONE) break;
    GstState now = GST_STATE_VOID_PENDING;
    if (gst_element_get_state(clip.pipeline.get(), &now, nullptr, 0) == GST_STATE_CHANGE_SUCCESS &&
        now >= GST_STATE_PAUSED) {
      break;  // prerolled while nobody was reading the bus
    }
    if (clock.now() > deadline) {
      return fail(Errc::kTimeout, fmt::format("the movie did not open within {} s", timeout.count() / 1000), where);
    }
  }
  // What the sink negotiated: size, rate, format and colorimetry.
  PadPtr pad(gst_element_get_static_pad(clip.sink, "sink"));
  CapsPtr caps(gst_pad_get_current_caps(pad.get()));
  GstVideoInfo vi;
  if (!caps || !gst_video_info_from_caps(&vi, caps.get())) {
    return fail(Errc::kUnsupported, "the decoder produced no usable video format", where);
  }
  MovieInfo& mi = clip.info;
  mi.path = clip.path;
  mi.width = static_cast<std::uint32_t>(GST_VIDEO_INFO_WIDTH(&vi));
  mi.height = static_cast<std::uint32_t>(GST_VIDEO_INFO_HEIGHT(&vi));
  mi.pixelAspect =
      GST_VIDEO_INFO_PAR_D(&vi) > 0 ? static_cast<double>(GST_VIDEO_INFO_PAR_N(&vi)) / GST_VIDEO_INFO_PAR_D(&vi) : 1.0;
  const int fn = GST_VIDEO_INFO_FPS_N(&vi), fd = GST_VIDEO_INFO_FPS_D(&vi);
  mi.fps = fn > 0 && fd > 0 ? static_cast<double>(fn) / fd : 0;
  mi.format = fromGstFormat(GST_VIDEO_INFO_FORMAT(&vi));
  mi.colorimetry = fromGstColorimetry(vi.colorimetry);
  gint64 duration = -1;
  if (gst_element_query_duration(clip.pipeline.get(), GST_FORMAT_TIME, &duration) && duration > 0) {
    mi.duration = Nanos{duration};
  }
  if (mi.fps <= 0) mi.fps = 25;  // variable rate without a nominal rate: frame numbers at 25
  mi.frameDuration = fromSeconds(1.0 / mi.fps);
  if (mi.duration.count() > 0) {
    mi.frameCount = std::llround(toSeconds(mi.duration) * mi.fps);
  }
  GstQuery* query = gst_query_new_seeking(GST_FORMAT_TIME);
  if (gst_element_query(clip.pipeline.get(), query)) {
    gboolean seekable = FALSE;
    gst_query_parse_seeking(query, nullptr, &seekable, nullptr, nullptr);
    mi.seekable = seekable != FALSE;
  }
  gst_query_unref(query);
  {
    std::lock_guard lock(clip.mutex);
    mi.codec = clip.codec;
    mi.hasAudio = clip.hasAudio;
    mi.audioOutputMissing = clip.audioUnavailable;
  }
  if (clip.start.count() < 0) {
    // Frame 0's timestamp from the preroll sample (pull_sample hands the same sample out again),
    // not from whichever buffer deliver() sees first: after an accurate seek that is the target
    // frame, clipped a quarter frame late, which would shift every later frame of the clip and
    // make one node's loop a fraction of a frame shorter than another's.
    SamplePtr preroll(gst_app_sink_try_pull_preroll(reinterpret_cast<GstAppSink*>(clip.sink), 0));
    GstBuffer* first = preroll ? gst_sample_get_buffer(preroll.get()) : nullptr;
    if (first && GST_BUFFER_PTS_IS_VALID(first)) clip.start = fromGstTime(GST_BUFFER_PTS(first));
  }
  clip.prerolled = true;
  log::info(kLogMedia, "{}: {} {}x{} {:.3f} fps {} ({}), {} frames{}; upload path: {} planes + shader", clip.name,
            clip.path.filename(), mi.width, mi.height, mi.fps, mi.codec, pixelFormatName(mi.format), mi.frameCount,
            !mi.hasAudio            ? ""
            : mi.audioOutputMissing ? ", sound discarded (no audio output here)"
            : options.audio         ? ", sound on"
                                    : ", sound discarded",
            pixelFormatName(mi.format));
  return {};
}

bool MoviePlayer::Impl::pollBus(Clip& clip) {
  BusPtr bus(gst_element_get_bus(clip.pipeline.get()));
  while (MessagePtr m{gst_bus_pop_filtered(bus.get(), GST_MESSAGE_ERROR)}) {
    setFailed(Error(Errc::kIo, fmt::format("decoding failed: {}", describeGstMessage(m.get())), clip.path.string()));
    return false;
  }
  return true;
}

void MoviePlayer::Impl::deliver(GstSample* sample) {
  Clip& clip = *current;
  GstBuffer* buffer = gst_sample_get_buffer(sample);
  GstCaps* caps = gst_sample_get_caps(sample);
  if (!buffer || !caps) return;
  if (caps != clip.lastCaps.get()) {
    if (!gst_video_info_from_caps(&clip.videoInfo, caps)) return;
    clip.lastCaps.reset(gst_caps_ref(caps));
  }
  const Nanos dur = clip.info.frameDuration;
  Nanos pts = fromGstTime(GST_BUFFER_PTS(buffer));
  if (pts.count() < 0) pts = clip.start.count() < 0 ? Nanos{0} : clip.start + dur * (lastIndex + 1);
  if (clip.start.count() < 0) clip.start = pts;
  const auto index = static_cast<std::int64_t>(
      std::llround(static_cast<double>((pts - clip.start).count()) / static_cast<double>(dur.count())));
  if (index < dropBelow) return;  // decoded on the way to an accurate seek's target
  dropBelow = 0;
  // After a seek the first frame lands on seekTimeline and the rest follow it by their
  // timestamps. The base comes from the frame's number, not its timestamp: an accurate seek's
  // first frame is clipped to the seek's target (a quarter frame past its start).
  bool rebased = false;
  if (rebase) {
    base = seekTimeline - dur * index;
    rebase = false;
    rebased = true;
  }
  Nanos timeline = base + (rebased ? dur * index : pts - clip.start);
  if (lastPts.count() >= 0 && timeline <= lastPts) timeline = lastPts + Nanos{1};  // keep the queue ordered

  FrameRef frame;
  for (int attempt = 0; attempt < 500 && !frame; ++attempt) {
    frame = wrapVideoBuffer(buffer, clip.videoInfo, *pool, slots.get(), poolSize);
    if (!frame) std::this_thread::sleep_for(std::chrono::milliseconds(2));  // the renderer still holds frames
  }
  if (!frame) return;
  Frame& f = *frame;
  f.pts = timeline;
  f.sequence = static_cast<std::uint64_t>(index);
  f.producerCookie = (generation << 16) | (clip.entry & 0xffff);
  lastPts = timeline;
  lastIndex = index;
  decoded.fetch_add(1, std::memory_order_relaxed);
  if (recovering) {
    recovering = false;
    log::info(kLogMedia, "{}: frames flow again from frame {} of {}", options.name, index,
              clip.path.filename().string());
  }
  if (queue.tryPush(std::move(frame))) {
    {
      std::lock_guard lock(mutex);
      pushedGeneration = generation;
      newestPts = timeline;
    }
    progressCv.notify_all();
  }
}

void MoviePlayer::Impl::prerollNext() {
  if (playlist.size() < 2 || next) return;
  const std::size_t entry = (current->entry + 1) % playlist.size();
  if (entry == 0 && !repeat) return;
  auto clip = openClip(entry, false);
  if (!clip) {
    setFailed(clip.error());
    return;
  }
  next = std::move(*clip);
}

void MoviePlayer::Impl::endOfClip() {
  Clip& clip = *current;
  if (lastIndex >= 0 && clip.info.frameCount != lastIndex + 1 && dropBelow == 0) {
    // Now the count is exact (the container's duration may round or lie).
    clip.info.frameCount = lastIndex + 1;
  }
  clip.info.frameCountExact = true;
  if (dropBelow == 0 && lastIndex >= 0 && clip.info.duration > Nanos{0}) {
    // The picture ends well before the container's duration: the file lost its end. (A sound
    // track a little longer than the picture stays under the bound.)
    const Nanos played = clip.info.frameDuration * (lastIndex + 1);
    const Nanos bound = std::max<Nanos>(std::chrono::seconds(1), clip.info.duration / 20);
    if (clip.info.duration - played > bound) clip.info.endedEarlyAt = played;
  }
  {
    std::lock_guard lock(mutex);
    if (info.path == clip.path) {
      info.frameCount = clip.info.frameCount;
      info.frameCountExact = true;
      info.endedEarlyAt = clip.info.endedEarlyAt;
      endedEarlyNs.store(clip.info.endedEarlyAt.count(), std::memory_order_relaxed);
    }
  }
  const Nanos nextBase = lastPts.count() >= 0 ? lastPts + clip.info.frameDuration : base;
  const bool moreClips = playlist.size() > 1 && (clip.entry + 1 < playlist.size() || repeat);
  if (moreClips) {
    prerollNext();
    if (!next) return;
    if (auto r = finishOpen(*next, kOpenTimeout); !r) {
      setFailed(r.error());
      return;
    }
    gst_element_set_state(next->pipeline.get(), GST_STATE_PLAYING);
    current = std::move(next);
    {
      std::lock_guard lock(mutex);
      info = current->info;
    }
    base = nextBase;
    lastIndex = -1;
    loops.fetch_add(1, std::memory_order_relaxed);
    prerollNext();
    return;
  }
  if (!repeat) {
    clipEnded = true;
    {
      std::lock_guard lock(mutex);
      ended = true;
      endedGeneration = generation;
    }
    progressCv.notify_all();
    return;
  }
  // Loop the one clip: back to its start on the same pipeline. The frames still queued cover
  // the time the seek takes, so the picture never stops.
  const bool seeked = clip.info.seekable &&
                      gst_element_seek_simple(clip.pipeline.get(), GST_FORMAT_TIME,
                                              static_cast<GstSeekFlags>(GST_SEEK_FLAG_FLUSH | GST_SEEK_FLAG_ACCURATE),
                                              static_cast<gint64>(std::max<std::int64_t>(0, clip.start.count())));
  if (!seeked) {
    // Not seekable (an elementary stream): start it again from the top.
    gst_element_set_state(clip.pipeline.get(), GST_STATE_READY);
    gst_element_set_state(clip.pipeline.get(), GST_STATE_PLAYING);
  }
  passNs.store((nextBase - base).count(), std::memory_order_relaxed);
  base = nextBase;
  lastIndex = -1;
  dropBelow = 0;
  loops.fetch_add(1, std::memory_order_relaxed);
}

void MoviePlayer::Impl::load(const Command& c) {
  next.reset();
  current.reset();
  queue.clear();
  generation = c.generation;
  playlist = c.paths;
  clipEnded = false;
  lastPts = Nanos{-1};
  lastIndex = -1;
  base = Nanos{0};
  rebase = false;
  dropBelow = 0;
  auto clip = openClip(0, true);
  if (!clip) {
    setFailed(clip.error());
    return;
  }
  current = std::move(*clip);
  gst_element_set_state(current->pipeline.get(), GST_STATE_PLAYING);
  {
    std::lock_guard lock(mutex);
    if (generation == c.generation) {
      info = current->info;
      state = MovieState::kReady;
      error.reset();
    }
  }
  progressCv.notify_all();
  prerollNext();
}

void MoviePlayer::Impl::seek(const Command& c) {
  generation = c.generation;
  if (!current) return;
  // A seek into another playlist entry is not offered: seeks stay within the shown clip.
  Clip& clip = *current;
  const Nanos dur = clip.info.frameDuration;
  const Nanos start = std::max(Nanos{0}, clip.start);
  // A quarter frame past the target's start: the decoder drops the frame before it (which ends
  // at the target) and keeps the target (which ends after).
  const Nanos target = start + dur * c.index + dur / 4;
  clipEnded = false;
  {
    std::lock_guard lock(mutex);
    ended = false;
  }
  const bool ok = gst_element_seek_simple(clip.pipeline.get(), GST_FORMAT_TIME,
                                          static_cast<GstSeekFlags>(GST_SEEK_FLAG_FLUSH | GST_SEEK_FLAG_ACCURATE),
                                          static_cast<gint64>(target.count()));
  if (!ok) {
    // Not seekable: decode from the top and drop frames up to the target.
    gst_element_set_state(clip.pipeline.get(), GST_STATE_READY);
    gst_element_set_state(clip.pipeline.get(), GST_STATE_PLAYING);
  }
  queue.clear();
  dropBelow = c.index;
  rebase = true;
  seekTimeline = c.base;
  lastPts = Nanos{-1};
  lastIndex = c.index - 1;
}

bool MoviePlayer::Impl::handleCommands() {
  for (;;) {
    Command c;
    {
      std::lock_guard lock(mutex);
      if (commands.empty()) return true;
      c = std::move(commands.front());
      commands.pop_front();
    }
    starvedSince.reset();
    switch (c.kind) {
      case Command::Kind::kQuit: return false;
      case Command::Kind::kLoad: load(c); break;
      case Command::Kind::kSeek: seek(c); break;
      case Command::Kind::kUnload:
        generation = c.generation;
        next.reset();
        current.reset();
        queue.clear();
        break;
      case Command::Kind::kInjectStall: blockVideo(); break;
      case Command::Kind::kRepeat:
        repeat = c.flag;
        if (repeat && clipEnded && current) {
          clipEnded = false;
          {
            std::lock_guard lock(mutex);
            ended = false;
          }
          endOfClip();
        } else if (current) {
          prerollNext();
        }
        break;
    }
  }
}

void MoviePlayer::Impl::watchStarvation() {
  const auto now = std::chrono::steady_clock::now();
  if (!starvedSince) {
    starvedSince = now;
    return;
  }
  const auto limit = std::max<std::chrono::steady_clock::duration>(options.stallTimeout, 4 * frameDuration());
  if (now - *starvedSince < limit) return;
  const auto starved = now - *starvedSince;
  starvedSince.reset();
  restartStalled(starved);
}

void MoviePlayer::Impl::restartStalled(std::chrono::steady_clock::duration starved) {
  const std::size_t entry = current->entry;
  const Nanos start = current->start;
  const std::int64_t resumeAt = lastIndex + 1;
  stalls.fetch_add(1, std::memory_order_relaxed);
  log::warn(kLogMedia,
            "{}: no frame from {} for {:.1f} s though there was room for one: its pipeline stalled; building it "
            "again and resuming at frame {}",
            options.name, current->path.filename().string(), std::chrono::duration<double>(starved).count(), resumeAt);
  // Torn down first: stopping flushes its pads, which releases the threads that hang.
  next.reset();
  current.reset();
  auto clip = openClip(entry, true);
  if (!clip) {
    setFailed(clip.error());
    return;
  }
  current = std::move(*clip);
  // The same file: frame 0 has the same stream time, so the timeline goes on where it was.
  current->start = start;
  if (resumeAt > 0 && start.count() >= 0) {
    const Nanos dur = current->info.frameDuration;
    const bool seeked = current->info.seekable &&
                        gst_element_seek_simple(current->pipeline.get(), GST_FORMAT_TIME,
                                                static_cast<GstSeekFlags>(GST_SEEK_FLAG_FLUSH | GST_SEEK_FLAG_ACCURATE),
                                                static_cast<gint64>((start + dur * resumeAt + dur / 4).count()));
    (void)seeked;  // not seekable: decoded from the top, the frames before resumeAt dropped
    dropBelow = resumeAt;
    // The next frame is due one frame after the last one queued, as if nothing had happened.
    rebase = true;
    seekTimeline = lastPts + dur;
  }
  gst_element_set_state(current->pipeline.get(), GST_STATE_PLAYING);
  recovering = true;
  prerollNext();
}

void MoviePlayer::Impl::blockVideo() {
  if (!current || !current->sink) return;
  GstPad* pad = gst_element_get_static_pad(current->sink, "sink");
  if (!pad) return;
  gst_pad_add_probe(
      pad, GST_PAD_PROBE_TYPE_BLOCK_DOWNSTREAM,
      [](GstPad*, GstPadProbeInfo*, gpointer) -> GstPadProbeReturn { return GST_PAD_PROBE_OK; }, nullptr, nullptr);
  gst_object_unref(pad);
  log::warn(kLogMedia, "{}: its video stream is blocked on purpose (a stall drill)", options.name);
}

void MoviePlayer::Impl::run() {
  for (;;) {
    {
      std::unique_lock lock(mutex);
      const bool idle = !current || clipEnded || state == MovieState::kFailed;
      if (idle && commands.empty()) commandCv.wait_for(lock, std::chrono::milliseconds(200));
    }
    if (!handleCommands()) break;
    {
      std::lock_guard lock(mutex);
      if (state == MovieState::kFailed) {
        // Drop the pipelines of a failed movie; a load() starts afresh.
        if (current) {
          current.reset();
          next.reset();
        }
        continue;
      }
    }
    if (!current || clipEnded) continue;
    if (!pollBus(*current)) continue;
    if (!queue.waitForRoom(kPoll)) {
      starvedSince.reset();  // the decoder is ahead of the show: nothing is wrong
      continue;
    }
    SamplePtr sample(gst_app_sink_try_pull_sample(reinterpret_cast<GstAppSink*>(current->sink),
                                                  static_cast<GstClockTime>(std::chrono::nanoseconds(kPoll).count())));
    if (!sample) {
      if (gst_app_sink_is_eos(reinterpret_cast<GstAppSink*>(current->sink))) {
        starvedSince.reset();
        endOfClip();
      } else {
        watchStarvation();
      }
      continue;
    }
    starvedSince.reset();
    deliver(sample.get());
  }
  next.reset();
  current.reset();
  queue.clear();
}

// ---------------------------------------------------------------------------------------------

MoviePlayer::MoviePlayer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

Result<std::unique_ptr<MoviePlayer>> MoviePlayer::create(MoviePlayerOptions options) {
  if (auto r = ensureGstreamer(); !r) return std::unexpected(r.error());
  gst_pb_utils_init();
  if (options.queueFrames < 2) options.queueFrames = 2;
  std::unique_ptr<MoviePlayer> player(new MoviePlayer(std::make_unique<Impl>(std::move(options))));
  Impl* impl = player->impl_.get();
  impl->worker = std::thread([impl] { impl->run(); });
  return player;
}

MoviePlayer::~MoviePlayer() {
  impl_->queue.close();
  impl_->post({Impl::Command::Kind::kQuit, 0, {}, 0, Nanos{0}, false});
  impl_->worker.join();
  carry_.reset();
}

Result<void> MoviePlayer::load(const std::filesystem::path& path) { return loadPlaylist({path}); }

Result<void> MoviePlayer::loadPlaylist(const std::vector<std::filesystem::path>& paths) {
  if (paths.empty()) return fail(Errc::kInvalidArgument, "the playlist is empty");
  for (const auto& p : paths) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(p, ec)) {
      return fail(Errc::kNotFound, "no such movie file; check the path", p.string());
    }
    if (::access(p.c_str(), R_OK) != 0) {
      return fail(Errc::kPermissionDenied, "the movie file is not readable; check its permissions", p.string());
    }
  }
  ++generation_;
  carry_.reset();
  transport_ = Transport::kStopped;
  speed_ = 1;
  awaitFirst_ = true;
  needShowAnchor_ = false;
  seekDueAt_.reset();
  pendingIndex_ = 0;
  shownIndex_ = -1;
  shownClip_ = 0;
  {
    std::lock_guard lock(impl_->mutex);
    impl_->state = MovieState::kLoading;
    impl_->error.reset();
    impl_->info = MovieInfo{};
    impl_->info.path = paths.front();
    impl_->ended = false;
    impl_->endedEarlyNs.store(-1, std::memory_order_relaxed);
  }
  impl_->post({Impl::Command::Kind::kLoad, generation_, paths, 0, Nanos{0}, false});
  if (repeat_) impl_->post({Impl::Command::Kind::kRepeat, generation_, {}, 0, Nanos{0}, true});
  return {};
}

void MoviePlayer::unload() {
  ++generation_;
  carry_.reset();
  transport_ = Transport::kStopped;
  awaitFirst_ = false;
  shownIndex_ = -1;
  {
    std::lock_guard lock(impl_->mutex);
    impl_->state = MovieState::kEmpty;
    impl_->error.reset();
    impl_->info = MovieInfo{};
  }
  impl_->post({Impl::Command::Kind::kUnload, generation_, {}, 0, Nanos{0}, false});
}

bool MoviePlayer::atEnd() const {
  {
    std::lock_guard lock(impl_->mutex);
    if (!impl_->ended || impl_->endedGeneration != generation_) return false;
  }
  return !awaitFirst_ && !carry_ && impl_->queue.size() == 0;
}

MovieState MoviePlayer::state() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->state;
}

std::optional<Error> MoviePlayer::error() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->error;
}

MovieInfo MoviePlayer::info() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->info;
}

MoviePlayerStats MoviePlayer::stats() const {
  MoviePlayerStats s;
  s.decoded = impl_->decoded.load(std::memory_order_relaxed);
  s.shown = impl_->shown.load(std::memory_order_relaxed);
  s.passed = impl_->queue.dropped();
  s.loops = impl_->loops.load(std::memory_order_relaxed);
  s.stalls = impl_->stalls.load(std::memory_order_relaxed);
  return s;
}

void MoviePlayer::injectStall() { impl_->post({Impl::Command::Kind::kInjectStall, 0, {}, 0, Nanos{0}, false}); }

std::int64_t MoviePlayer::frameCount() const { return info().frameCount; }

Nanos MoviePlayer::frameDuration() const {
  const MovieInfo i = info();
  return i.frameDuration.count() > 0 ? i.frameDuration : Nanos{33333333};
}

std::int64_t MoviePlayer::logicalIndex() const {
  return awaitFirst_ ? pendingIndex_ : std::max<std::int64_t>(0, shownIndex_);
}

void MoviePlayer::requestSeek(std::int64_t index, std::optional<Nanos> timeline) {
  seekDueAt_.reset();
  const std::int64_t count = frameCount();
  if (count > 0) index = std::min(index, count - 1);
  index = std::max<std::int64_t>(0, index);
  ++generation_;
  carry_.reset();
  awaitFirst_ = true;
  pendingIndex_ = index;
  // The target lands one frame after the shown one on the timeline, so that pts only grow.
  const Nanos base = timeline ? *timeline : shownIndex_ >= 0 ? shownPts_ + frameDuration() : anchorPts_;
  impl_->post({Impl::Command::Kind::kSeek, generation_, {}, index, base, false});
}

void MoviePlayer::anchorAtShown() {
  // The press happened while the shown frame was on screen: time runs from that frame's show
  // time, so the next frame comes one frame later.
  anchorPts_ = shownPts_;
  if (shownIndex_ >= 0) {
    anchorShow_ = lastShowTime_;
    needShowAnchor_ = false;
  } else {
    needShowAnchor_ = true;
  }
}

void MoviePlayer::play() { shuttle(1.0); }

void MoviePlayer::pause() {
  if (transport_ == Transport::kPlaying) anchorPts_ = shownPts_;
  transport_ = Transport::kPaused;
  speed_ = 1;
}

void MoviePlayer::stop() {
  transport_ = Transport::kStopped;
  speed_ = 1;
  requestSeek(0);
}

void MoviePlayer::stepForward() {
  pause();
  std::int64_t target = logicalIndex() + 1;
  const std::int64_t count = frameCount();
  if (count > 0 && target >= count) target = repeat_ ? 0 : count - 1;
  if (target != logicalIndex() || awaitFirst_) requestSeek(target);
}

void MoviePlayer::stepBack() {
  pause();
  std::int64_t target = logicalIndex() - 1;
  const std::int64_t count = frameCount();
  if (target < 0) target = repeat_ && count > 0 ? count - 1 : 0;
  if (target != logicalIndex()) requestSeek(target);
}

void MoviePlayer::rewind() { requestSeek(0); }

void MoviePlayer::fastForward(std::int64_t frames) {
  std::int64_t target = logicalIndex() + frames;
  const std::int64_t count = frameCount();
  if (count > 0 && target >= count) target = repeat_ ? target % count : count - 1;
  requestSeek(target);
}

void MoviePlayer::shuttle(double speed) {
  if (speed == 0) {
    pause();
    return;
  }
  bool ended = false;
  {
    std::lock_guard lock(impl_->mutex);
    ended = impl_->ended && impl_->endedGeneration == generation_;
  }
  transport_ = Transport::kPlaying;
  speed_ = speed;
  anchorAtShown();
  if (speed < 0) {
    reverseAnchorIndex_ = logicalIndex();
    reverseAnchorShow_ = lastShowTime_;
  }
  // Play at the end of a clip that does not repeat starts it again, as a VCR would.
  if (ended && speed > 0 && !awaitFirst_ && impl_->queue.size() == 0) requestSeek(0);
}

void MoviePlayer::setRepeat(bool on) {
  repeat_ = on;
  impl_->post({Impl::Command::Kind::kRepeat, generation_, {}, 0, Nanos{0}, on});
}

void MoviePlayer::seekFrame(std::int64_t frame) { requestSeek(frame); }

void MoviePlayer::seekFrameDueAt(std::int64_t frame, Nanos due, Nanos timeline) {
  requestSeek(frame, timeline);
  seekDueAt_ = due;
}

Nanos MoviePlayer::passDuration() const { return Nanos{impl_->passNs.load(std::memory_order_relaxed)}; }

Nanos MoviePlayer::endedEarlyAt() const { return Nanos{impl_->endedEarlyNs.load(std::memory_order_relaxed)}; }

void MoviePlayer::seekTime(Nanos time) {
  const Nanos dur = frameDuration();
  requestSeek(time.count() <= 0 ? 0 : time / dur);
}

Nanos MoviePlayer::targetTime(Nanos showTime) const {
  if (awaitFirst_ || needShowAnchor_ || transport_ != Transport::kPlaying || speed_ < 0) return anchorPts_;
  const double elapsed = static_cast<double>((showTime - anchorShow_).count()) * speed_;
  // Containers round timestamps (Matroska and most MP4s to the millisecond): a frame stamped
  // up to this much after the target is the frame the target means, not an early one.
  constexpr Nanos kTimestampRounding = std::chrono::microseconds(1500);
  return anchorPts_ + Nanos{static_cast<std::int64_t>(elapsed)} + kTimestampRounding;
}

FrameRef MoviePlayer::frameAt(Nanos showTime) {
  lastShowTime_ = showTime;
  if (needShowAnchor_ && !awaitFirst_) {
    anchorShow_ = showTime;
    needShowAnchor_ = false;
  }
  if (transport_ == Transport::kPlaying && speed_ < 0 && !awaitFirst_) {
    // Reverse shuttle: one accurate seek to the frame the clock asks for.
    const double back = toSeconds(showTime - reverseAnchorShow_) * -speed_ / toSeconds(frameDuration());
    std::int64_t target = reverseAnchorIndex_ - static_cast<std::int64_t>(std::floor(back + 1e-9));
    if (target < 0) target = 0;
    if (target != shownIndex_) requestSeek(target);
  }
  FrameRef f;
  const std::uint64_t want = generation_;
  if (awaitFirst_) {
    Nanos front{0};
    while (impl_->queue.frontPts(front)) {
      f = impl_->queue.takeDue(front);
      if (f && (f->producerCookie >> 16) == want) break;
      f.reset();
    }
    if (!f && carry_ && (carry_->producerCookie >> 16) == want) f = std::move(carry_);
    if (!f) return {};
    awaitFirst_ = false;
    anchorPts_ = f->pts;
    anchorShow_ = seekDueAt_ ? *seekDueAt_ : showTime;
    seekDueAt_.reset();
    needShowAnchor_ = false;
  } else {
    f = impl_->queue.takeDue(targetTime(showTime));
    if (carry_) {
      if (!f) f = std::move(carry_);
      carry_.reset();
    }
    if (f && (f->producerCookie >> 16) != want) f.reset();
  }
  if (!f) return {};
  shownIndex_ = static_cast<std::int64_t>(f->sequence);
  shownClip_ = static_cast<std::size_t>(f->producerCookie & 0xffff);
  shownPts_ = f->pts;
  shownGeneration_ = want;
  impl_->shown.fetch_add(1, std::memory_order_relaxed);
  return f;
}

NumberedFrame MoviePlayer::frameNumbered(std::int64_t index, Nanos showTime, std::chrono::milliseconds patience) {
  lastShowTime_ = showTime;
  if (needShowAnchor_ && !awaitFirst_) {
    anchorShow_ = showTime;
    needShowAnchor_ = false;
  }
  NumberedFrame out;
  const MovieInfo movie = info();
  const std::int64_t count = movie.frameCount;
  if (index < 0 || (movie.frameCountExact && count > 0 && index >= count)) {
    out.outcome = NumberedOutcome::kLate;  // not a frame of this clip: nothing to wait for
    return out;
  }
  // Frames from `from` on to `to`, through the end of the clip into the next loop.
  const auto forward = [count](std::int64_t from, std::int64_t to) {
    return count > 0 ? ((to - from) % count + count) % count : to - from;
  };
  const auto generationOf = [](const FrameRef& f) { return f->producerCookie >> 16; };
  if (!awaitFirst_ && shownIndex_ == index && shownGeneration_ == generation_) {
    // On screen already; the player's own timeline would move on if the next frame were due
    // (one frame later when it is not decoded yet).
    const FrameRef next = carry_ ? carry_ : impl_->queue.peekFront();
    const Nanos nextPts = next && generationOf(next) == generation_ ? next->pts : shownPts_ + frameDuration();
    const bool movesOn = nextPts <= targetTime(showTime);
    out.outcome = movesOn ? NumberedOutcome::kCorrected : NumberedOutcome::kAgreed;
    return out;
  }
  // What the player's own timeline picks now: the newest frame due at this target.
  const Nanos target = targetTime(showTime);
  const bool seekPending = awaitFirst_;
  // The frame before the next one the player hands out: the one on screen, or the one before a
  // pending seek's target.
  std::int64_t before = awaitFirst_ ? pendingIndex_ - 1 : shownIndex_;
  std::int64_t ahead = forward(before, index);
  // A pending seek's first frame is what the player's own path shows next.
  bool corrected = seekPending && index != pendingIndex_;
  const bool behind = count > 0 ? ahead == 0 || ahead > count / 2 : ahead <= 0;
  if (behind) {
    requestSeek(index);
    seekDueAt_ = showTime;
    before = pendingIndex_ - 1;
    ahead = forward(before, index);
    corrected = true;
  }
  const SystemClock clock;
  const Nanos deadline = clock.now() + patience;
  FrameRef taken;
  for (;;) {
    FrameRef front = carry_ ? carry_ : impl_->queue.peekFront();
    if (front) {
      const bool carried = static_cast<bool>(carry_);
      const auto pop = [&](bool passOver) {
        if (carried) {
          carry_.reset();
        } else {
          (void)impl_->queue.takeFront(passOver);
        }
      };
      if (generationOf(front) != generation_) {
        pop(true);  // decoded before a seek
        continue;
      }
      if (awaitFirst_) {
        // The seek's first frame anchors the timeline as frameAt() would anchor it.
        awaitFirst_ = false;
        anchorPts_ = front->pts;
        anchorShow_ = seekDueAt_ ? *seekDueAt_ : showTime;
        seekDueAt_.reset();
        needShowAnchor_ = false;
      }
      const auto number = static_cast<std::int64_t>(front->sequence);
      if (number == index) {
        pop(false);
        taken = std::move(front);
        break;
      }
      if (forward(before, number) < ahead) {
        pop(true);  // before the frame asked for
        continue;
      }
      break;  // past it: the decoder never made it
    }
    std::unique_lock lock(impl_->mutex);
    if (impl_->state == MovieState::kFailed || impl_->state == MovieState::kEmpty) break;
    if (impl_->ended && impl_->endedGeneration == generation_) break;
    if (clock.now() >= deadline) break;
    impl_->progressCv.wait_for(lock, std::chrono::milliseconds(5));
  }
  if (!taken) {
    out.outcome = NumberedOutcome::kLate;
    return out;
  }
  if (!corrected && !seekPending) {
    // The own timeline shows it now if it is due and the frame after it is not.
    const FrameRef next = impl_->queue.peekFront();
    const Nanos nextPts = next && generationOf(next) == generation_ ? next->pts : taken->pts + frameDuration();
    corrected = taken->pts > target || nextPts <= target;
  }
  shownIndex_ = index;
  shownClip_ = static_cast<std::size_t>(taken->producerCookie & 0xffff);
  shownPts_ = taken->pts;
  shownGeneration_ = generation_;
  impl_->shown.fetch_add(1, std::memory_order_relaxed);
  out.frame = std::move(taken);
  out.outcome = corrected ? NumberedOutcome::kCorrected : NumberedOutcome::kAgreed;
  return out;
}

Result<MovieInfo> MoviePlayer::waitUntilLoaded(std::chrono::milliseconds timeout) {
  std::unique_lock lock(impl_->mutex);
  const bool done = impl_->progressCv.wait_for(lock, timeout, [this] {
    return impl_->state == MovieState::kReady || impl_->state == MovieState::kFailed ||
           impl_->state == MovieState::kEmpty;
  });
  if (!done) return fail(Errc::kTimeout, "the movie did not load in time", impl_->info.path.string());
  if (impl_->state == MovieState::kFailed && impl_->error) return std::unexpected(*impl_->error);
  if (impl_->state == MovieState::kEmpty) return fail(Errc::kNotFound, "no movie is loaded");
  return impl_->info;
}

bool MoviePlayer::waitForFrameDue(Nanos showTime, std::chrono::milliseconds timeout) {
  const SystemClock clock;
  const Nanos deadline = clock.now() + timeout;
  if (needShowAnchor_ && !awaitFirst_) {
    anchorShow_ = showTime;
    needShowAnchor_ = false;
  }
  const std::uint64_t want = generation_;
  for (;;) {
    const Nanos target = targetTime(showTime);
    {
      std::unique_lock lock(impl_->mutex);
      if (impl_->state == MovieState::kFailed || impl_->state == MovieState::kEmpty) return false;
      const bool fresh = impl_->pushedGeneration == want;
      if (impl_->ended && impl_->endedGeneration == want) return true;
      if (awaitFirst_ ? (fresh && impl_->queue.size() > 0) || (carry_ && (carry_->producerCookie >> 16) == want)
                      : (fresh && impl_->newestPts >= target) || (transport_ != Transport::kPlaying) || speed_ < 0) {
        return true;
      }
    }
    if (!awaitFirst_ && impl_->queue.size() == impl_->queue.capacity()) {
      // The queue is full of frames before the target (fast shuttle): pass them over.
      FrameRef f = impl_->queue.takeDue(target);
      if (f) carry_ = std::move(f);
      continue;
    }
    std::unique_lock lock(impl_->mutex);
    if (clock.now() >= deadline) return false;
    impl_->progressCv.wait_for(lock, std::chrono::milliseconds(5));
  }
}

}  // namespace basalt::media
