// Movie sound on a real audio output: in the virtual lab, ALSA's loopback card (snd-aloop) is the
// machine's only sound card, so the player's sink (chosen as autoaudiosink would: ALSA here)
// plays into it, and what it played is recorded back from the loopback's capture side. A clip
// with a 440 Hz tone must come out as a 440 Hz tone while its picture plays on every frame.
// Outside the lab it skips, saying why. Example failures: sound routed to a fake sink while the
// player claims an output; the audio branch blocking the picture (frames stop once the sink
// prerolls); a tone resampled to the wrong pitch.

#include <gtest/gtest.h>

#include <gst/app/gstappsink.h>
#include <gst/gst.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "media/movie_player.h"
#include "support/numbered_clip.h"
#include "support/process.h"
#include "support/test_paths.h"

namespace basalt::media {
namespace {

using namespace std::chrono_literals;

std::string env(const char* name) {
  const char* v = std::getenv(name);
  return v && *v ? v : "";
}

/// Records mono 16-bit samples at 48 kHz from an ALSA capture device while it runs.
class Recorder {
 public:
  explicit Recorder(const std::string& device) {
    const std::string description = "alsasrc device=" + device +
                                    " ! audioconvert ! audioresample ! audio/x-raw,format=S16LE,channels=1,"
                                    "rate=48000 ! appsink name=sink sync=false";
    GError* error = nullptr;
    pipeline_ = gst_parse_launch(description.c_str(), &error);
    if (error) {
      why_ = error->message;
      g_error_free(error);
      return;
    }
    sink_ = gst_bin_get_by_name(GST_BIN(pipeline_), "sink");
    if (gst_element_set_state(pipeline_, GST_STATE_PLAYING) == GST_STATE_CHANGE_FAILURE) {
      why_ = "cannot start capturing from " + device;
    }
  }
  ~Recorder() {
    if (pipeline_) {
      gst_element_set_state(pipeline_, GST_STATE_NULL);
      gst_object_unref(pipeline_);
    }
    if (sink_) gst_object_unref(sink_);
  }
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;
  [[nodiscard]] const std::string& why() const { return why_; }

  /// Takes what was captured so far.
  void drain() {
    while (GstSample* sample = gst_app_sink_try_pull_sample(GST_APP_SINK(sink_), 0)) {
      GstBuffer* buffer = gst_sample_get_buffer(sample);
      GstMapInfo map;
      if (buffer && gst_buffer_map(buffer, &map, GST_MAP_READ)) {
        const std::size_t n = map.size / 2;
        const std::size_t at = samples_.size();
        samples_.resize(at + n);
        std::memcpy(samples_.data() + at, map.data, n * 2);
        gst_buffer_unmap(buffer, &map);
      }
      gst_sample_unref(sample);
    }
  }
  [[nodiscard]] const std::vector<std::int16_t>& samples() const { return samples_; }

 private:
  GstElement* pipeline_ = nullptr;
  GstElement* sink_ = nullptr;
  std::string why_;
  std::vector<std::int16_t> samples_;
};

TEST(AudioOutput, MovieSoundReachesTheSoundCardAtItsPitch) {
  const std::string capture = env("BASALT_VLAB_ALSA_LOOPBACK");
  if (capture.empty()) {
    GTEST_SKIP() << "needs the virtual lab (make vlab): BASALT_VLAB_ALSA_LOOPBACK (ALSA's loopback card)";
  }
  const auto dir = test::scratchDir("media-audio-output");
  constexpr int kFrames = 90;  // 3 s at 30 fps
  auto numbered = test::makeNumberedClip(dir / "numbered.avi", kFrames, 30, VideoCodec::kMjpeg, 160, 120, 0);
  ASSERT_TRUE(numbered) << numbered.error().describe();
  const auto clip = dir / "tone.mkv";
  const auto made = test::addTone(*numbered, clip, 150, 440, 0.5);
  if (!made && made.error().code() == Errc::kUnavailable) GTEST_SKIP() << made.error().describe();
  ASSERT_TRUE(made) << made.error().describe();

  // Capture first: the loopback takes its rate and format from the side opened first.
  gst_init(nullptr, nullptr);
  Recorder recorder(capture);
  ASSERT_TRUE(recorder.why().empty()) << recorder.why();

  MoviePlayerOptions options;
  options.audio = true;
  options.name = "tone";
  auto player = MoviePlayer::create(options);
  ASSERT_TRUE(player) << player.error().describe();
  ASSERT_TRUE((*player)->load(clip));
  auto info = (*player)->waitUntilLoaded(20s);
  ASSERT_TRUE(info) << info.error().describe();
  ASSERT_TRUE(info->hasAudio);
  ASSERT_FALSE(info->audioOutputMissing) << "the lab has a sound card; the player must use it";
  (*player)->play();
  Nanos t{0};
  int shown = 0;
  for (int i = 0; i < kFrames; ++i) {
    (*player)->waitForFrameDue(t, 5s);
    if ((*player)->frameAt(t)) ++shown;
    t += fromSeconds(1.0 / 30);
    std::this_thread::sleep_for(std::chrono::milliseconds(30));  // the sound plays in real time
    recorder.drain();
  }
  EXPECT_EQ(shown, kFrames) << "the picture plays on every frame while the sound plays";
  for (int i = 0; i < 20; ++i) {
    std::this_thread::sleep_for(50ms);
    recorder.drain();
  }

  // The loudest stretch of the recording: a 440 Hz tone (counted by rising zero crossings).
  const auto& s = recorder.samples();
  ASSERT_GT(s.size(), 48000u) << "at least a second recorded";
  std::size_t loud = 0;
  std::size_t crossings = 0;
  std::size_t first = 0;
  std::size_t last = 0;
  for (std::size_t i = 1; i < s.size(); ++i) {
    if (std::abs(s[i]) > 3000) {
      if (loud == 0) first = i;
      last = i;
      ++loud;
    }
  }
  ASSERT_GT(loud, 24000u) << "no tone in the recording (" << s.size() << " samples)";
  for (std::size_t i = first + 1; i <= last; ++i) {
    if (s[i - 1] < 0 && s[i] >= 0) ++crossings;
  }
  const double seconds = static_cast<double>(last - first) / 48000.0;
  const double pitch = static_cast<double>(crossings) / seconds;
  EXPECT_NEAR(pitch, 440.0, 15.0) << "over " << seconds << " s";
}

}  // namespace
}  // namespace basalt::media
