// BoundedQueue and FramePool: the two structures devices and media push through.
// Example failures: a full queue that blocks a device thread or grows without bound; a frame
// returned to its pool while still held; a pool freed while a frame is in flight.

#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "runtime/bounded_queue.h"
#include "runtime/frame.h"
#include "runtime/frame_queue.h"

namespace basalt {
namespace {

TEST(BoundedQueue, DropsAndCountsWhenFull) {
  BoundedQueue<int> q(2);
  EXPECT_TRUE(q.push(1));
  EXPECT_TRUE(q.push(2));
  EXPECT_FALSE(q.push(3));
  EXPECT_EQ(q.dropped(), 1u);
  int v = 0;
  ASSERT_TRUE(q.pop(v));
  EXPECT_EQ(v, 1);
  EXPECT_TRUE(q.push(4));
  ASSERT_TRUE(q.pop(v));
  EXPECT_EQ(v, 2);
  ASSERT_TRUE(q.pop(v));
  EXPECT_EQ(v, 4);
  EXPECT_FALSE(q.pop(v));
}

TEST(BoundedQueue, WakesOnlyWhenBecomingNonEmpty) {
  int wakes = 0;
  BoundedQueue<int> q(8, [&] { ++wakes; });
  q.push(1);
  q.push(2);
  EXPECT_EQ(wakes, 1);
  int v;
  q.pop(v);
  q.pop(v);
  q.push(3);
  EXPECT_EQ(wakes, 2);
}

TEST(BoundedQueue, DrainWhileStopsAtTheFirstItemNotDue) {
  BoundedQueue<int> q(8);
  for (int i : {1, 2, 5, 3}) q.push(i);
  std::vector<int> got;
  q.drainWhile([](int v) { return v < 4; }, [&](int v) { got.push_back(v); });
  EXPECT_EQ(got, (std::vector<int>{1, 2}));
  EXPECT_EQ(q.size(), 2u) << "items after the first one not due must stay queued, in order";
}

TEST(BoundedQueue, ManyProducersLoseNothingBelowCapacity) {
  BoundedQueue<int> q(4000);
  std::vector<std::thread> producers;
  producers.reserve(4);
  for (int t = 0; t < 4; ++t) {
    producers.emplace_back([&q, t] {
      for (int i = 0; i < 1000; ++i) q.push(t * 1000 + i);
    });
  }
  for (auto& p : producers) p.join();
  EXPECT_EQ(q.size(), 4000u);
  EXPECT_EQ(q.dropped(), 0u);
}

TEST(FrameLayout, PlanesOfCommonFormats) {
  const FrameLayout i420 = computeLayout(PixelFormat::kI420, 640, 360);
  ASSERT_EQ(i420.planeCount, 3);
  EXPECT_EQ(i420.planes[0].stride, 640u);
  EXPECT_EQ(i420.planes[1].stride, 320u);
  EXPECT_EQ(i420.planes[1].offset, 640u * 360u);
  EXPECT_EQ(i420.totalSize, 640u * 360u * 3 / 2);
  const FrameLayout nv12 = computeLayout(PixelFormat::kNv12, 5, 3);  // odd sizes round chroma up
  ASSERT_EQ(nv12.planeCount, 2);
  EXPECT_EQ(nv12.planes[1].stride, 6u);
  EXPECT_EQ(nv12.planes[1].size, 6u * 2u);
  const FrameLayout yuyv = computeLayout(PixelFormat::kYuyv, 640, 480, 64);
  EXPECT_EQ(yuyv.planes[0].stride, 1280u);
  const FrameLayout padded = computeLayout(PixelFormat::kRgb8, 10, 2, 16);
  EXPECT_EQ(padded.planes[0].stride, 32u);
}

TEST(FramePool, HandsOutEachFrameOnceAndTakesItBack) {
  auto pool = FramePool::create({PixelFormat::kRgba8, 4, 4, 2});
  FrameRef a = pool->acquire();
  FrameRef b = pool->acquire();
  ASSERT_TRUE(a);
  ASSERT_TRUE(b);
  EXPECT_NE(a.get(), b.get());
  EXPECT_FALSE(pool->acquire()) << "an exhausted pool must say so, not allocate";
  FrameRef copy = a;
  a.reset();
  EXPECT_EQ(pool->available(), 0u) << "a frame went back while a copy still held it";
  copy.reset();
  EXPECT_EQ(pool->available(), 1u);
  ASSERT_NE(b->planes[0].data, nullptr);
  EXPECT_EQ(b->planes[0].stride, 16u);
}

TEST(FramePool, ReleaseHookRunsOnceWhenTheLastReferenceGoes) {
  auto pool = FramePool::create({PixelFormat::kNv12, 8, 8, 1, 1, false});
  int released = 0;
  FrameRef f = pool->acquire();
  ASSERT_TRUE(f);
  EXPECT_EQ(f->storage(), nullptr) << "shell frames carry no storage";
  f->setRelease([](void* ctx, Frame&) { ++*static_cast<int*>(ctx); }, &released);
  FrameRef g = f;
  f.reset();
  EXPECT_EQ(released, 0);
  g.reset();
  EXPECT_EQ(released, 1);
  FrameRef again = pool->acquire();
  ASSERT_TRUE(again);
  again.reset();
  EXPECT_EQ(released, 1) << "the release hook must be cleared when the frame returns";
}

TEST(FramePool, OutlivesItsOwnerWhileFramesAreHeld) {
  FrameRef held;
  {
    auto pool = FramePool::create({PixelFormat::kGray8, 2, 2, 1});
    held = pool->acquire();
  }
  ASSERT_TRUE(held);
  held->planes[0].data[0] = 42;  // the storage must still be alive (ASan would catch a use after free)
  held.reset();
}

TEST(FramePool, FramesCrossThreads) {
  auto pool = FramePool::create({PixelFormat::kRgba8, 16, 16, 3});
  std::atomic<int> released{0};
  for (int round = 0; round < 200; ++round) {
    FrameRef f = pool->acquire();
    ASSERT_TRUE(f);
    f->setRelease([](void* ctx, Frame&) { static_cast<std::atomic<int>*>(ctx)->fetch_add(1); }, &released);
    std::thread consumer([g = f]() mutable { g.reset(); });
    f.reset();
    consumer.join();
  }
  EXPECT_EQ(released.load(), 200);
  EXPECT_EQ(pool->available(), 3u);
}

}  // namespace
}  // namespace basalt

namespace basalt {
namespace {

FrameRef frameAt(const std::shared_ptr<FramePool>& pool, std::int64_t ptsMs) {
  FrameRef f = pool->acquire();
  f->pts = std::chrono::milliseconds(ptsMs);
  return f;
}

TEST(FrameQueue, TakesTheNewestDueFrameAndNeverOneFromTheFuture) {
  auto pool = FramePool::create({PixelFormat::kGray8, 2, 2, 8});
  FrameQueue q(8);
  for (int ms : {0, 33, 66, 100}) ASSERT_TRUE(q.tryPush(frameAt(pool, ms)));
  EXPECT_FALSE(q.takeDue(std::chrono::milliseconds(-1))) << "nothing is due before the first pts";
  FrameRef f = q.takeDue(std::chrono::milliseconds(70));
  ASSERT_TRUE(f);
  EXPECT_EQ(f->pts, std::chrono::milliseconds(66));
  EXPECT_EQ(q.dropped(), 2u) << "frames 0 and 33 were passed over";
  EXPECT_EQ(q.size(), 1u);
  EXPECT_FALSE(q.takeDue(std::chrono::milliseconds(99))) << "frame 100 is still in the future";
  f.reset();
  EXPECT_EQ(pool->available(), 7u) << "passed-over frames must go back to their pool";
}

TEST(FrameQueue, LiveSourcesDropTheOldestWhenFull) {
  auto pool = FramePool::create({PixelFormat::kGray8, 2, 2, 8});
  FrameQueue q(2);
  q.pushDroppingOldest(frameAt(pool, 1));
  q.pushDroppingOldest(frameAt(pool, 2));
  q.pushDroppingOldest(frameAt(pool, 3));
  Nanos front{};
  ASSERT_TRUE(q.frontPts(front));
  EXPECT_EQ(front, std::chrono::milliseconds(2));
  EXPECT_EQ(q.dropped(), 1u);
  EXPECT_FALSE(q.tryPush(frameAt(pool, 4)));
}

TEST(FrameQueue, ProducerWaitsForRoomUntilTheConsumerTakes) {
  auto pool = FramePool::create({PixelFormat::kGray8, 2, 2, 8});
  FrameQueue q(1);
  ASSERT_TRUE(q.tryPush(frameAt(pool, 0)));
  std::atomic<bool> gotRoom{false};
  std::thread producer([&] { gotRoom = q.waitForRoom(std::chrono::seconds(10)); });
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_FALSE(gotRoom.load());
  EXPECT_TRUE(q.takeDue(std::chrono::milliseconds(5)));
  producer.join();
  EXPECT_TRUE(gotRoom.load());
  q.close();
  EXPECT_FALSE(q.waitForRoom(std::chrono::seconds(10))) << "a closed queue must not keep producers waiting";
}

}  // namespace
}  // namespace basalt
