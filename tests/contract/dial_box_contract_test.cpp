// The DialBox contract, run against every backend (STYLE.md "Device adapters"): the state
// machine, event tagging and ordering, and a full queue. Backends that cannot run here skip
// with the reason.
// Example failures: a backend that pushes events before open() or after close(); events
// arriving out of time order; a full queue blocking the backend.

#include <gtest/gtest.h>

#include <functional>
#include <memory>
#include <ostream>
#include <string>

#include "devices/dial_box.h"
#include "sim/synthetic_dial.h"

namespace basalt::devices {
namespace {

/// A way to make a backend for the contract, or the reason it cannot run here.
struct DialBackend {
  std::string name;
  /// Makes a device that will produce at least 3 dial events within 1 s of Clock time.
  std::function<std::unique_ptr<DialBox>(const Clock&, std::string& skipReason)> make;
};

/// Names the backend in test output (instead of the parameter's bytes).
void PrintTo(const DialBackend& backend, std::ostream* os) { *os << backend.name; }

std::unique_ptr<DialBox> makeSynthetic(const Clock& clock, std::string&) {
  std::vector<sim::ScriptedInput> script = {
      {std::chrono::milliseconds(100), EventKind::kDialDelta, 0, 0.1},
      {std::chrono::milliseconds(200), EventKind::kDialDelta, 1, -0.2},
      {std::chrono::milliseconds(300), EventKind::kButton, 2, 1},
      {std::chrono::milliseconds(400), EventKind::kDialDelta, 7, 0.05},
  };
  return std::make_unique<sim::SyntheticDial>(std::move(script), clock);
}

class DialBoxContract : public ::testing::TestWithParam<DialBackend> {
 protected:
  void SetUp() override {
    std::string reason;
    device_ = GetParam().make(clock_, reason);
    if (!device_) GTEST_SKIP() << GetParam().name << " backend cannot run here: " << reason;
  }
  ManualClock clock_;
  std::unique_ptr<DialBox> device_;
};

TEST_P(DialBoxContract, OpensLiveAndClosesAbsent) {
  BoundedQueue<Event> events(64);
  EXPECT_EQ(device_->state(), DeviceState::kAbsent);
  ASSERT_TRUE(device_->open(7, events));
  EXPECT_EQ(device_->state(), DeviceState::kLive);
  EXPECT_GT(device_->dialCount(), 0);
  EXPECT_TRUE(device_->open(7, events)) << "opening a live device is a no-op, not an error";
  device_->close();
  EXPECT_EQ(device_->state(), DeviceState::kAbsent);
  device_->close();  // closing twice is safe
}

TEST_P(DialBoxContract, EventsAreTaggedOrderedAndNeverEarly) {
  BoundedQueue<Event> events(64);
  ASSERT_TRUE(device_->open(42, events));
  Nanos last{-1};
  int count = 0;
  for (int step = 0; step < 100; ++step) {
    clock_.advance(std::chrono::milliseconds(10));
    device_->service(clock_.now());
    Event e;
    while (events.pop(e)) {
      EXPECT_EQ(e.device, 42u);
      EXPECT_GE(e.time, last) << "events out of time order";
      EXPECT_LE(e.time, clock_.now()) << "an event from the future";
      if (e.kind == EventKind::kDialDelta) {
        EXPECT_LT(e.index, device_->dialCount());
      }
      last = e.time;
      ++count;
    }
  }
  EXPECT_GE(count, 3);
}

TEST_P(DialBoxContract, NothingFlowsWhenClosed) {
  BoundedQueue<Event> events(64);
  ASSERT_TRUE(device_->open(1, events));
  device_->close();
  clock_.advance(std::chrono::seconds(2));
  device_->service(clock_.now());
  EXPECT_EQ(events.size(), 0u);
}

TEST_P(DialBoxContract, AFullQueueDropsInsteadOfBlocking) {
  BoundedQueue<Event> events(1);
  ASSERT_TRUE(device_->open(1, events));
  clock_.advance(std::chrono::seconds(2));
  device_->service(clock_.now());  // must return although the queue fills after one event
  EXPECT_EQ(events.size(), 1u);
  EXPECT_GE(events.dropped(), 1u);
}

INSTANTIATE_TEST_SUITE_P(Backends, DialBoxContract, ::testing::Values(DialBackend{"synthetic", makeSynthetic}),
                         [](const ::testing::TestParamInfo<DialBackend>& param) { return param.param.name; });

}  // namespace
}  // namespace basalt::devices
