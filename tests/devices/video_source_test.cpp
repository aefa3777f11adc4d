// The VideoSource base every camera backend shares: frames that a producer stamps with the same
// time (a ManualClock read between two steps of the show, a driver with coarse timestamps) still
// come out in capture order with rising presentation times, and the frame-rate limit still drops
// the second of two frames from one instant.
// Example failure: two frames dequeued within one tick of a manual clock carried the same pts and
// the show saw them "out of order" (the V4L2 HDMI contract case in the virtual lab).

#include <gtest/gtest.h>

#include <chrono>
#include <memory>

#include "devices/video_source.h"
#include "runtime/clock.h"
#include "runtime/frame.h"

namespace basalt::devices {
namespace {

using namespace std::chrono_literals;

// A source whose frames the test stamps and hands over itself.
class StampedSource final : public VideoSource {
 public:
  explicit StampedSource(const Clock& clock)
      : VideoSource(DeviceInfo{"Stamped camera", "synthetic", "virtual", 0, 0, "synthetic:stamped", ""}, clock) {}

  bool push(Nanos pts, std::uint64_t sequence) {
    FrameRef f = pool_->acquire();
    if (!f) return false;
    f->pts = pts;
    f->captureTime = pts;
    f->sequence = sequence;
    return deliver(std::move(f));
  }

 private:
  Result<void> doOpen() override {
    setMode({PixelFormat::kRgba8, 8, 8, 30});
    return {};
  }
  void doClose() override {}

  std::shared_ptr<FramePool> pool_ = FramePool::create({PixelFormat::kRgba8, 8, 8, 8, 1, true});
};

TEST(VideoSourceBase, FramesStampedAtOneInstantComeOutInCaptureOrder) {
  ManualClock clock{Nanos{1s}};
  StampedSource source(clock);
  ASSERT_TRUE(source.open(1));
  ASSERT_TRUE(source.push(Nanos{1s}, 1));
  ASSERT_TRUE(source.push(Nanos{1s}, 2));  // kept: no frame-rate limit is set
  ASSERT_TRUE(source.push(Nanos{1s}, 3));

  // The queue hands out the newest due frame; take them one by one as the show would, each time
  // after the next was delivered, by reading before every push.
  StampedSource again(clock);
  ASSERT_TRUE(again.open(2));
  Nanos last{-1};
  for (std::uint64_t i = 1; i <= 5; ++i) {
    ASSERT_TRUE(again.push(Nanos{1s}, i));
    clock.advance(1ms);
    FrameRef f = again.frameAt(clock.now());
    ASSERT_TRUE(f) << "frame " << i;
    EXPECT_EQ(f->sequence, i);
    EXPECT_GT(f->pts, last) << "frame " << i << " is not after the one before it";
    EXPECT_LE(f->pts, clock.now()) << "frame " << i << " is from the future";
    last = f->pts;
  }
  EXPECT_EQ(again.framesDropped(), 0u);

  FrameRef newest = source.frameAt(clock.now());
  ASSERT_TRUE(newest);
  EXPECT_EQ(newest->sequence, 3u);
  EXPECT_EQ(newest->pts, Nanos{1s} + Nanos{2});
}

TEST(VideoSourceBase, TheFrameRateLimitStillDropsTheSecondFrameOfAnInstant) {
  ManualClock clock{Nanos{1s}};
  StampedSource source(clock);
  ASSERT_TRUE(source.open(1));
  VideoControls controls;
  controls.maxFps = 30;
  ASSERT_TRUE(source.setControls(controls));
  EXPECT_TRUE(source.push(Nanos{1s}, 1));
  EXPECT_FALSE(source.push(Nanos{1s}, 2));
  EXPECT_TRUE(source.push(Nanos{1s} + 34ms, 3));
  EXPECT_EQ(source.framesDropped(), 1u);
  clock.advance(40ms);
  FrameRef f = source.frameAt(clock.now());
  ASSERT_TRUE(f);
  EXPECT_EQ(f->sequence, 3u);
  EXPECT_EQ(f->pts, Nanos{1s} + 34ms);
}

}  // namespace
}  // namespace basalt::devices
