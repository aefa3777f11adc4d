// Faults while a movie plays, which must never reach the screen as a crash or a hang:
// - sound asked for (--audio) on a machine with no audio output: said once, in one clear line
//   naming the movie, and the picture plays on every frame. Failure caught: autoaudiosink's
//   silent fallback (a show without sound and nobody told), the message repeated per movie or
//   per loop, or the video stalling on an audio sink that never prerolls.
// - a clip whose middle is damaged (made here: the middle of a numbered clip overwritten with
//   noise): the good frames before the damage play in order, then the player fails with one
//   message naming the file and the cause (the show shows the fallback), and the player loads
//   another movie afterwards. Failure caught: a hang waiting for frames that never come, a
//   crash in the demuxer's error path, an error without the file's name, a player left unusable.
// - a pipeline that stalls while it plays (its video stream blocked on purpose, as a hung
//   decoder or a deadlocked queue leaves it): the player's watchdog notices that no frame came
//   though there was room, builds the pipeline again and resumes at the next frame, so every
//   frame still shows, in order, once. Failure caught: a texture frozen for good (what a kiosk
//   showed before), a restart from frame 0, a skipped or repeated frame, a stall not logged.

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "media/movie_player.h"
#include "runtime/log.h"
#include "support/numbered_clip.h"
#include "support/process.h"
#include "support/test_paths.h"

namespace basalt::media {
namespace {

constexpr double kFps = 30;
const Nanos kStep = fromSeconds(1.0 / kFps);

/// Records log lines while a test runs.
class LogCapture {
 public:
  LogCapture() : sink_(std::make_shared<log::RingSink>(4096)) { log::addSink(sink_); }
  ~LogCapture() { log::removeSink(sink_); }
  LogCapture(const LogCapture&) = delete;
  LogCapture& operator=(const LogCapture&) = delete;
  [[nodiscard]] std::vector<std::string> containing(std::string_view needle) const {
    std::vector<std::string> out;
    for (const auto& r : sink_->snapshot()) {
      if (r.message.find(needle) != std::string::npos) out.push_back(r.message);
    }
    return out;
  }

 private:
  std::shared_ptr<log::RingSink> sink_;
};

/// Plays `player` from show time `t` for `frames` show frames; returns the frame numbers shown.
std::vector<int> playFrames(MoviePlayer& player, Nanos& t, int frames) {
  std::vector<int> shown;
  for (int i = 0; i < frames; ++i) {
    player.waitForFrameDue(t, std::chrono::seconds(5));
    const FrameRef f = player.frameAt(t);
    if (f) shown.push_back(test::readFrameNumber(*f));
    t += kStep;
  }
  return shown;
}

TEST(MovieFaults, SoundWithoutAnAudioOutputIsSaidOnceAndThePicturePlaysOn) {
  const auto dir = test::scratchDir("media-faults-audio");
  const auto clip = dir / "with-sound.mkv";
  // Numbered video (Motion-JPEG) and a Vorbis tone, made with GStreamer's own tools.
  auto numbered = test::makeNumberedClip(dir / "numbered.avi", 45, kFps, VideoCodec::kMjpeg, 160, 120, 0);
  ASSERT_TRUE(numbered) << numbered.error().describe();
  const auto made = test::addTone(*numbered, clip, 70);
  if (!made) GTEST_SKIP() << "cannot make a clip with sound here: " << made.error().describe();

  LogCapture log;
  MoviePlayerOptions options;
  options.audio = true;
  auto player = MoviePlayer::create(options);
  ASSERT_TRUE(player) << player.error().describe();
  ASSERT_TRUE((*player)->load(clip));
  auto info = (*player)->waitUntilLoaded(std::chrono::seconds(20));
  ASSERT_TRUE(info) << info.error().describe();
  ASSERT_TRUE(info->hasAudio) << "the clip has a sound track";
  if (!info->audioOutputMissing) GTEST_SKIP() << "this machine has an audio output; the message is not due";

  const auto said = log.containing("has no audio output");
  ASSERT_EQ(said.size(), 1u) << "one clear message";
  EXPECT_NE(said[0].find(clip.string()), std::string::npos) << "it names the movie: " << said[0];
  EXPECT_NE(said[0].find("without sound"), std::string::npos) << said[0];

  // The picture plays on: every frame, in order, to the end.
  (*player)->play();
  Nanos t{0};
  const auto shown = playFrames(**player, t, 45);
  ASSERT_EQ(shown.size(), 45u);
  for (int n = 0; n < 45; ++n) EXPECT_EQ(shown[static_cast<std::size_t>(n)], n);

  // A second movie with sound (and a loop of the first) says nothing more.
  auto second = MoviePlayer::create(options);
  ASSERT_TRUE(second);
  ASSERT_TRUE((*second)->load(clip));
  ASSERT_TRUE((*second)->waitUntilLoaded(std::chrono::seconds(20)));
  EXPECT_EQ(log.containing("has no audio output").size(), 1u) << "said once, not once per movie";
}

TEST(MovieFaults, DamageMidStreamIsReportedWithTheFileAndThePlayerRecovers) {
  const auto dir = test::scratchDir("media-faults-damaged");
  constexpr int kFrames = 90;
  auto good = test::makeNumberedClip(dir / "good.mkv", kFrames, kFps, VideoCodec::kH264, 160, 120, 0);
  ASSERT_TRUE(good) << good.error().describe();
  // Noise over the middle of the file, from half-way to three quarters: the header and the
  // first frames stay intact, so the damage is met while the movie plays.
  const auto damaged = dir / "damaged-middle.mkv";
  {
    std::ifstream in(*good, std::ios::binary);
    std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    ASSERT_GT(bytes.size(), 4096u);
    std::mt19937 noise(7);
    for (std::size_t i = bytes.size() / 2; i < bytes.size() * 3 / 4; ++i) bytes[i] = static_cast<char>(noise());
    std::ofstream(damaged, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  }

  LogCapture log;
  auto player = MoviePlayer::create({});
  ASSERT_TRUE(player) << player.error().describe();
  ASSERT_TRUE((*player)->load(damaged));
  auto info = (*player)->waitUntilLoaded(std::chrono::seconds(20));
  ASSERT_TRUE(info) << "the damage is mid-stream, the start loads: " << info.error().describe();
  (*player)->play();
  Nanos t{0};
  const auto shown = playFrames(**player, t, kFrames + 10);  // bounded: never a hang
  ASSERT_GE(shown.size(), 10u) << "the good frames before the damage are shown";
  for (std::size_t i = 1; i < shown.size() && shown[i] < kFrames / 3; ++i) {
    EXPECT_EQ(shown[i], shown[i - 1] + 1) << "the good part plays in order";
  }
  EXPECT_LT(shown.back(), kFrames - 1) << "the damaged part cannot have played to the end";
  // Reported: the player failed with the file and the cause; one log line says the same.
  EXPECT_EQ((*player)->state(), MovieState::kFailed);
  const auto error = (*player)->error();
  ASSERT_TRUE(error.has_value());
  EXPECT_NE(error->describe().find(damaged.string()), std::string::npos) << error->describe();
  EXPECT_NE(error->describe().find("decoding failed"), std::string::npos) << error->describe();
  // The player logs just after it turns to failed: give the line a moment to arrive.
  std::vector<std::string> said;
  for (int i = 0; i < 200 && said.empty(); ++i) {
    said = log.containing("decoding failed");
    if (said.empty()) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_EQ(said.size(), 1u) << "one message, not one per frame";
  EXPECT_NE(said[0].find("fallback"), std::string::npos) << "it says what the show does: " << said[0];

  // The player is not left broken: the good clip loads and plays.
  ASSERT_TRUE((*player)->load(*good));
  ASSERT_TRUE((*player)->waitUntilLoaded(std::chrono::seconds(20)));
  (*player)->play();
  Nanos t2{0};
  const auto again = playFrames(**player, t2, 10);
  ASSERT_EQ(again.size(), 10u);
  EXPECT_EQ(again.back(), 9);
}

TEST(MovieFaults, AStalledPipelineIsBuiltAgainAndPlaysOnFromTheNextFrame) {
  const auto dir = test::scratchDir("media-faults-stall");
  constexpr int kFrames = 90;
  auto clip = test::makeNumberedClip(dir / "numbered.mkv", kFrames, kFps, VideoCodec::kH264, 160, 120, 0);
  ASSERT_TRUE(clip) << clip.error().describe();

  LogCapture log;
  MoviePlayerOptions options;
  options.name = "stall drill";
  options.stallTimeout = std::chrono::milliseconds(500);
  auto player = MoviePlayer::create(options);
  ASSERT_TRUE(player) << player.error().describe();
  ASSERT_TRUE((*player)->load(*clip));
  ASSERT_TRUE((*player)->waitUntilLoaded(std::chrono::seconds(20)));
  (*player)->play();
  Nanos t{0};
  std::vector<int> shown = playFrames(**player, t, 20);
  (*player)->injectStall();
  // The frames already queued play out; then nothing comes until the watchdog acts (half a
  // second), and the rest plays from where it stopped.
  const auto rest = playFrames(**player, t, kFrames - 20);
  shown.insert(shown.end(), rest.begin(), rest.end());
  std::string list;
  for (int n : shown) list += std::to_string(n) + " ";
  ASSERT_EQ(shown.size(), static_cast<std::size_t>(kFrames)) << "every frame shows: " << list;
  for (int n = 0; n < kFrames; ++n) EXPECT_EQ(shown[static_cast<std::size_t>(n)], n) << "in order, once";
  EXPECT_EQ((*player)->stats().stalls, 1u);
  EXPECT_EQ((*player)->state(), MovieState::kReady) << "not failed";
  const auto said = log.containing("its pipeline stalled");
  ASSERT_EQ(said.size(), 1u);
  EXPECT_NE(said[0].find("stall drill: no frame from numbered.mkv for "), std::string::npos) << said[0];
  EXPECT_EQ(log.containing("frames flow again").size(), 1u);
}

}  // namespace
}  // namespace basalt::media
