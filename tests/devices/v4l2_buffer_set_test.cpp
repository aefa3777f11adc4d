// The V4L2 buffer set's ownership, without a capture device: buffers mapped from a memfd stand
// in for the driver's. A frame lent out of the set keeps it (and its mappings) alive after the
// camera let go of it, as when the camera closes or renegotiates while the show still draws the
// last frame; the last frame given back unmaps the buffers; a set no frame holds goes with the
// camera at once; the camera's wait for the show's frames sees every frame come back.
// Example failures: the buffers unmapped at close while the renderer still reads a frame (a
// crash, or garbage on screen); a set that is never freed once a frame outlived the camera (its
// buffers and descriptors leak at every renegotiation); a wait that never sees the last frame
// come back and stalls the capture thread for its whole timeout.

#include <gtest/gtest.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <memory>
#include <thread>
#include <vector>

#include "devices/v4l2/v4l2_buffer_set.h"
#include "runtime/frame.h"
#include "runtime/unique_fd.h"

namespace basalt::devices {
namespace {

using namespace std::chrono_literals;

constexpr std::size_t kBufferBytes = std::size_t{64} * 64;  // one GRAY8 64x64 frame
constexpr std::uint32_t kBuffers = 2;

/// True when the page at `address` is mapped in this process (mincore fails with ENOMEM for an
/// unmapped range).
bool mapped(const void* address) {
  const auto page = static_cast<std::uintptr_t>(::sysconf(_SC_PAGESIZE));
  auto* start = reinterpret_cast<void*>(reinterpret_cast<std::uintptr_t>(address) & ~(page - 1));
  unsigned char resident = 0;
  return ::mincore(start, 1, &resident) == 0;
}

class V4l2BufferSetTest : public ::testing::Test {
 protected:
  void SetUp() override {
    memory_ = UniqueFd(::memfd_create("basalt-v4l2-buffers", MFD_CLOEXEC));
    ASSERT_TRUE(memory_) << "memfd_create: " << std::strerror(errno);
    ASSERT_EQ(::ftruncate(memory_.get(), static_cast<off_t>(kBufferBytes * kBuffers)), 0);
    std::vector<V4l2MappedBuffer> buffers;
    for (std::uint32_t i = 0; i < kBuffers; ++i) {
      void* data = ::mmap(nullptr, kBufferBytes, PROT_READ | PROT_WRITE, MAP_SHARED, memory_.get(),
                          static_cast<off_t>(kBufferBytes * i));
      ASSERT_NE(data, MAP_FAILED);
      static_cast<std::uint8_t*>(data)[0] = static_cast<std::uint8_t>(0xa0 + i);
      addresses_.push_back(data);
      buffers.emplace_back(data, kBufferBytes);
    }
    set_ = V4l2BufferSet::create(memory_.duplicate(), std::move(buffers));
    pool_ = FramePool::create({PixelFormat::kGray8, 64, 64, kBuffers, 1, false});
  }

  /// A frame showing buffer `index`, as the camera's dequeue makes it.
  FrameRef lend(std::uint32_t index) {
    FrameRef frame = pool_->acquire();
    frame->planes[0].data = static_cast<std::uint8_t*>(set_->buffers()[index].data());
    frame->planes[0].size = kBufferBytes;
    set_->lend(*frame, index);
    return frame;
  }

  UniqueFd memory_;
  std::vector<void*> addresses_;
  std::shared_ptr<V4l2BufferSet> set_;
  std::shared_ptr<FramePool> pool_;
};

TEST_F(V4l2BufferSetTest, AFrameKeepsTheSetMappedAfterTheCameraLetsGo) {
  FrameRef held = lend(1);
  EXPECT_EQ(set_->outstanding(), 1);
  std::weak_ptr<V4l2BufferSet> watch = set_;
  set_.reset();  // the camera closes (or renegotiates) while the show holds the frame
  EXPECT_FALSE(watch.expired()) << "the lent frame keeps the set";
  ASSERT_TRUE(mapped(addresses_[0]));
  ASSERT_TRUE(mapped(addresses_[1]));
  EXPECT_EQ(held->planes[0].data[0], 0xa1) << "the frame still reads its buffer";
  held.reset();
  EXPECT_TRUE(watch.expired()) << "the last frame back frees the set";
  EXPECT_FALSE(mapped(addresses_[0])) << "buffer 0 unmapped by the last owner";
  EXPECT_FALSE(mapped(addresses_[1])) << "buffer 1 unmapped by the last owner";
}

TEST_F(V4l2BufferSetTest, TheSetGoesWithTheCameraWhenNoFrameIsOut) {
  FrameRef frame = lend(0);
  frame.reset();  // back before the camera closes
  EXPECT_EQ(set_->outstanding(), 0);
  std::weak_ptr<V4l2BufferSet> watch = set_;
  set_.reset();
  EXPECT_TRUE(watch.expired()) << "nothing else holds the set";
  EXPECT_FALSE(mapped(addresses_[0]));
  EXPECT_FALSE(mapped(addresses_[1]));
}

TEST_F(V4l2BufferSetTest, CopiesOfAFrameHoldTheSetUntilTheLastGoes) {
  FrameRef first = lend(0);
  FrameRef copy = first;  // two parts of the show draw the same frame
  std::weak_ptr<V4l2BufferSet> watch = set_;
  set_.reset();
  first.reset();
  EXPECT_FALSE(watch.expired()) << "a copy of the frame still holds the set";
  EXPECT_TRUE(mapped(addresses_[0]));
  copy.reset();
  EXPECT_TRUE(watch.expired());
  EXPECT_FALSE(mapped(addresses_[0]));
}

TEST_F(V4l2BufferSetTest, TheCameraSeesEveryFrameComeBack) {
  FrameRef a = lend(0);
  FrameRef b = lend(1);
  EXPECT_EQ(set_->outstanding(), 2);
  EXPECT_FALSE(set_->waitForFrames(0ms));
  a.reset();
  EXPECT_EQ(set_->outstanding(), 1);
  EXPECT_FALSE(set_->waitForFrames(10ms)) << "one frame is still out";
  // The last one comes back on another thread while the capture thread waits.
  std::thread show([&b] {
    std::this_thread::sleep_for(20ms);
    b.reset();
  });
  const auto start = std::chrono::steady_clock::now();
  EXPECT_TRUE(set_->waitForFrames(5000ms));
  EXPECT_LT(std::chrono::steady_clock::now() - start, 2000ms) << "woken by the frame's return, not the timeout";
  show.join();
  EXPECT_EQ(set_->outstanding(), 0);
  // A buffer given back can be lent again.
  FrameRef again = lend(0);
  EXPECT_EQ(set_->outstanding(), 1);
}

TEST_F(V4l2BufferSetTest, MovedBuffersUnmapOnce) {
  // The mapped buffer's owner moves into the set: the moved-from one unmaps nothing.
  void* data = ::mmap(nullptr, kBufferBytes, PROT_READ | PROT_WRITE, MAP_SHARED, memory_.get(), 0);
  ASSERT_NE(data, MAP_FAILED);
  {
    V4l2MappedBuffer first(data, kBufferBytes);
    V4l2MappedBuffer second(std::move(first));
    EXPECT_EQ(first.data(), nullptr);  // NOLINT(bugprone-use-after-move): what a move leaves
    {
      V4l2MappedBuffer gone(std::move(first));
    }
    EXPECT_TRUE(mapped(data)) << "an empty owner unmapped the buffer";
    V4l2MappedBuffer third;
    third = std::move(second);
    EXPECT_TRUE(mapped(data));
    EXPECT_EQ(third.length(), kBufferBytes);
  }
  EXPECT_FALSE(mapped(data)) << "the last owner unmaps";
}

}  // namespace
}  // namespace basalt::devices
