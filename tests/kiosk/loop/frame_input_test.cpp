// The run's one input queue as the show director drains it (kiosk::takeDueInput): the show's
// devices and a replayed trace push from threads of their own, each in the order of its own
// events, and a frame takes every event due by its time in the order of their times, keeping the
// rest for a later frame.
// Example failures: a replayed turn applied before a dial box's earlier one because the replay's
// thread ran first; an event of the next frame applied early; a replayed turn held back a frame
// by a dial box's event that is not due yet.

#include <gtest/gtest.h>

#include <chrono>
#include <thread>
#include <vector>

#include "kiosk/loop/frame_loop.h"

namespace basalt::kiosk {
namespace {

using namespace std::chrono_literals;

Event turn(Nanos time, DeviceId device, std::uint16_t dial) {
  return Event{time, device, EventKind::kDialDelta, dial, 0.1};
}

TEST(FrameInput, TheDueEventsOfAllDevicesComeInTheOrderOfTheirTimes) {
  BoundedQueue<Event> events(64);
  // A show's dial box (id 1) pushed its batch, then the replay's thread (id 0x10000) pushed its.
  for (const Nanos t : {10ms, 30ms, 50ms, 70ms}) ASSERT_TRUE(events.push(turn(t, 1, 0)));
  for (const Nanos t : {20ms, 30ms, 40ms, 90ms}) ASSERT_TRUE(events.push(turn(t, 0x10000, 1)));
  std::vector<Event> batch;
  std::vector<Event> later;
  takeDueInput(events, 60ms, batch, later);
  std::vector<std::pair<Nanos, DeviceId>> got;
  got.reserve(batch.size());
  for (const Event& e : batch) got.emplace_back(e.time, e.device);
  // Equal times keep the order they were pushed in (the show's 30 ms before the replay's).
  const std::vector<std::pair<Nanos, DeviceId>> expected{{10ms, 1},       {20ms, 0x10000}, {30ms, 1},
                                                         {30ms, 0x10000}, {40ms, 0x10000}, {50ms, 1}};
  EXPECT_EQ(got, expected);
  // 70 ms and 90 ms wait for a later frame; an event pushed meanwhile that is due comes first.
  EXPECT_EQ(later.size(), 2u);
  ASSERT_TRUE(events.push(turn(80ms, 0x10000, 1)));
  takeDueInput(events, 85ms, batch, later);
  ASSERT_EQ(batch.size(), 2u);
  EXPECT_EQ(batch[0].time, 70ms);
  EXPECT_EQ(batch[1].time, 80ms);
  takeDueInput(events, 100ms, batch, later);
  ASSERT_EQ(batch.size(), 1u);
  EXPECT_EQ(batch[0].time, 90ms);
  EXPECT_TRUE(later.empty());
  EXPECT_EQ(events.size(), 0u);
}

TEST(FrameInput, TwoProducerThreadsInterleaveIntoOneTimeOrder) {
  BoundedQueue<Event> events(4096);
  // Each thread pushes its own events in order; between them the queue's order is whatever the
  // threads' timing made it.
  auto producer = [&events](DeviceId device, Nanos offset) {
    for (int i = 0; i < 1000; ++i) {
      (void)events.push(turn(offset + Nanos{std::chrono::microseconds(100) * i}, device, 0));
      if (i % 50 == 0) std::this_thread::yield();
    }
  };
  std::thread a(producer, DeviceId{1}, Nanos{0});
  std::thread b(producer, DeviceId{2}, Nanos{std::chrono::microseconds(50)});
  a.join();
  b.join();
  std::vector<Event> batch;
  std::vector<Event> later;
  takeDueInput(events, 1s, batch, later);
  ASSERT_EQ(batch.size(), 2000u);
  for (std::size_t i = 1; i < batch.size(); ++i) {
    ASSERT_LE(batch[i - 1].time, batch[i].time) << "event " << i << " is out of order";
  }
}

}  // namespace
}  // namespace basalt::kiosk
