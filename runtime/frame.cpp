#include "runtime/frame.h"

#include <utility>

namespace basalt {

std::string_view pixelFormatName(PixelFormat format) {
  switch (format) {
    case PixelFormat::kUnknown: return "unknown";
    case PixelFormat::kRgba8: return "RGBA";
    case PixelFormat::kBgra8: return "BGRA";
    case PixelFormat::kRgb8: return "RGB";
    case PixelFormat::kGray8: return "GRAY8";
    case PixelFormat::kI420: return "I420";
    case PixelFormat::kYv12: return "YV12";
    case PixelFormat::kNv12: return "NV12";
    case PixelFormat::kNv21: return "NV21";
    case PixelFormat::kYuyv: return "YUYV";
    case PixelFormat::kUyvy: return "UYVY";
    case PixelFormat::kMjpeg: return "MJPEG";
  }
  return "unknown";
}

int planeCount(PixelFormat format) {
  switch (format) {
    case PixelFormat::kI420:
    case PixelFormat::kYv12: return 3;
    case PixelFormat::kNv12:
    case PixelFormat::kNv21: return 2;
    default: return 1;
  }
}

bool isYuv(PixelFormat format) {
  switch (format) {
    case PixelFormat::kI420:
    case PixelFormat::kYv12:
    case PixelFormat::kNv12:
    case PixelFormat::kNv21:
    case PixelFormat::kYuyv:
    case PixelFormat::kUyvy: return true;
    default: return false;
  }
}

namespace {
std::uint32_t alignUp(std::uint32_t v, std::uint32_t a) { return a <= 1 ? v : (v + a - 1) / a * a; }
}  // namespace

FrameLayout computeLayout(PixelFormat format, std::uint32_t width, std::uint32_t height, std::uint32_t alignment) {
  FrameLayout layout;
  const std::uint32_t cw = (width + 1) / 2, ch = (height + 1) / 2;
  auto add = [&](std::uint32_t rowBytes, std::uint32_t rows) {
    Plane& p = layout.planes[static_cast<std::size_t>(layout.planeCount++)];
    p.stride = alignUp(rowBytes, alignment);
    p.offset = static_cast<std::uint32_t>(layout.totalSize);
    p.size = std::size_t{p.stride} * rows;
    layout.totalSize += p.size;
  };
  switch (format) {
    case PixelFormat::kRgba8:
    case PixelFormat::kBgra8: add(width * 4, height); break;
    case PixelFormat::kRgb8: add(width * 3, height); break;
    case PixelFormat::kGray8: add(width, height); break;
    case PixelFormat::kYuyv:
    case PixelFormat::kUyvy: add(cw * 4, height); break;
    case PixelFormat::kI420:
    case PixelFormat::kYv12:
      add(width, height);
      add(cw, ch);
      add(cw, ch);
      break;
    case PixelFormat::kNv12:
    case PixelFormat::kNv21:
      add(width, height);
      add(cw * 2, ch);
      break;
    case PixelFormat::kMjpeg:
      // Worst case for a JPEG: larger than the raw 4:2:2 image is not plausible.
      add(width * 2, height);
      break;
    case PixelFormat::kUnknown: break;
  }
  return layout;
}

FrameRef::FrameRef(const FrameRef& other) : frame_(other.frame_) {
  if (frame_) frame_->refs_.fetch_add(1, std::memory_order_relaxed);
}

FrameRef::FrameRef(FrameRef&& other) noexcept : frame_(std::exchange(other.frame_, nullptr)) {}

FrameRef& FrameRef::operator=(const FrameRef& other) {
  if (this != &other) {
    if (other.frame_) other.frame_->refs_.fetch_add(1, std::memory_order_relaxed);
    reset();
    frame_ = other.frame_;
  }
  return *this;
}

FrameRef& FrameRef::operator=(FrameRef&& other) noexcept {
  if (this != &other) {
    reset();
    frame_ = std::exchange(other.frame_, nullptr);
  }
  return *this;
}

FrameRef::~FrameRef() { reset(); }

void FrameRef::reset() {
  Frame* f = std::exchange(frame_, nullptr);
  if (!f) return;
  if (f->refs_.fetch_sub(1, std::memory_order_acq_rel) != 1) return;
  if (f->releaseFn_) f->releaseFn_(f->releaseContext_, *f);
  f->releaseFn_ = nullptr;
  f->releaseContext_ = nullptr;
  // Move the owner out first: giving the frame back may drop the last reference to the pool.
  std::shared_ptr<FramePool> owner = std::move(f->owner_);
  owner->giveBack(f);
}

std::shared_ptr<FramePool> FramePool::create(const Config& config) {
  return std::make_shared<FramePool>(Token{}, config);
}

FramePool::FramePool(Token, const Config& config)
    : config_(config), layout_(computeLayout(config.format, config.width, config.height, config.rowAlignment)) {
  frames_.reserve(config.count);
  free_.reserve(config.count);
  for (std::size_t i = 0; i < config.count; ++i) {
    auto frame = std::make_unique<Frame>();
    if (config.allocateStorage) frame->storage_.resize(layout_.totalSize);
    free_.push_back(frame.get());
    frames_.push_back(std::move(frame));
  }
}

FrameRef FramePool::acquire() {
  Frame* f = nullptr;
  {
    std::lock_guard lock(mutex_);
    if (free_.empty()) return FrameRef{};
    f = free_.back();
    free_.pop_back();
  }
  f->format = config_.format;
  f->width = config_.width;
  f->height = config_.height;
  f->planeCount = layout_.planeCount;
  f->planes = layout_.planes;
  if (!f->storage_.empty()) {
    for (int i = 0; i < f->planeCount; ++i) {
      auto& p = f->planes[static_cast<std::size_t>(i)];
      p.data = f->storage_.data() + p.offset;
    }
  }
  f->bytesUsed = 0;
  f->pts = Nanos{0};
  f->captureTime = Nanos{0};
  f->sequence = 0;
  f->colorimetry = {};
  f->producerCookie = 0;
  f->owner_ = shared_from_this();
  f->refs_.store(1, std::memory_order_relaxed);
  return FrameRef{f};
}

std::size_t FramePool::available() const {
  std::lock_guard lock(mutex_);
  return free_.size();
}

void FramePool::giveBack(Frame* frame) {
  std::lock_guard lock(mutex_);
  free_.push_back(frame);  // never reallocates: capacity reserved for every frame
}

}  // namespace basalt
