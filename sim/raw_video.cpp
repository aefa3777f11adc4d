#include "sim/raw_video.h"

#include <cstring>

#include <fmt/format.h>

namespace basalt::sim {

namespace {

constexpr char kMagic[8] = {'B', 'S', 'L', 'T', 'R', 'A', 'W', '1'};
constexpr std::uint32_t kMaxDimension = 16384;

template <typename T>
void put(std::vector<std::uint8_t>& out, T value) {
  std::uint8_t bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  out.insert(out.end(), bytes, bytes + sizeof(T));
}

template <typename T>
bool get(std::FILE* f, T& value) {
  return std::fread(&value, sizeof(T), 1, f) == 1;
}

}  // namespace

Result<std::unique_ptr<RawVideoWriter>> RawVideoWriter::create(const std::filesystem::path& path,
                                                               const devices::VideoMode& mode) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return fail(Errc::kIo, systemErrorText("cannot create the trace video", errno), path.string());
  std::vector<std::uint8_t> header(kMagic, kMagic + 8);
  put(header, static_cast<std::uint32_t>(mode.format));
  put(header, mode.width);
  put(header, mode.height);
  put(header, mode.fps);
  if (std::fwrite(header.data(), 1, header.size(), f) != header.size()) {
    std::fclose(f);
    return fail(Errc::kIo, "cannot write the trace video header (disk full?)", path.string());
  }
  return std::unique_ptr<RawVideoWriter>(new RawVideoWriter(f, path, mode));
}

RawVideoWriter::~RawVideoWriter() {
  if (auto r = finish(); !r) return;  // a destructor cannot report: call finish() to see the error
}

Result<void> RawVideoWriter::write(const Frame& frame, Nanos pts) {
  if (!file_) return fail(Errc::kIo, "the trace video is closed", path_.string());
  if (frame.width != mode_.width || frame.height != mode_.height || frame.format != mode_.format) {
    return fail(Errc::kUnsupported,
                fmt::format("the source changed to {} {}x{} during the recording; a .bvraw file holds one mode",
                            pixelFormatName(frame.format), frame.width, frame.height),
                path_.string());
  }
  scratch_.clear();
  put(scratch_, pts.count());
  put(scratch_, frame.captureTime.count());
  put(scratch_, frame.sequence);
  if (frame.format == PixelFormat::kMjpeg) {
    if (!frame.planes[0].data) return fail(Errc::kUnsupported, "the frame is not in CPU memory", path_.string());
    put(scratch_, static_cast<std::uint32_t>(frame.bytesUsed));
    scratch_.insert(scratch_.end(), frame.planes[0].data, frame.planes[0].data + frame.bytesUsed);
  } else {
    const FrameLayout packed = computeLayout(frame.format, frame.width, frame.height);
    put(scratch_, static_cast<std::uint32_t>(packed.totalSize));
    for (int i = 0; i < packed.planeCount; ++i) {
      const auto& src = frame.planes[static_cast<std::size_t>(i)];
      const auto& dst = packed.planes[static_cast<std::size_t>(i)];
      if (!src.data) return fail(Errc::kUnsupported, "the frame is not in CPU memory", path_.string());
      const std::size_t rows = dst.stride ? dst.size / dst.stride : 0;
      for (std::size_t y = 0; y < rows; ++y) {
        const std::uint8_t* row = src.data + y * src.stride;
        scratch_.insert(scratch_.end(), row, row + dst.stride);
      }
    }
  }
  if (std::fwrite(scratch_.data(), 1, scratch_.size(), file_) != scratch_.size()) {
    return fail(Errc::kIo, "cannot write to the trace video (disk full?)", path_.string());
  }
  return {};
}

Result<void> RawVideoWriter::finish() {
  if (!file_) return {};
  const bool ok = std::fclose(file_) == 0;
  file_ = nullptr;
  if (!ok) return fail(Errc::kIo, "cannot finish the trace video (disk full?)", path_.string());
  return {};
}

Result<std::unique_ptr<RawVideoReader>> RawVideoReader::open(const std::filesystem::path& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return fail(Errc::kNotFound, systemErrorText("cannot open the trace video", errno), path.string());
  char magic[8];
  std::uint32_t format = 0;
  devices::VideoMode mode;
  if (std::fread(magic, 1, 8, f) != 8 || std::memcmp(magic, kMagic, 8) != 0 || !get(f, format) || !get(f, mode.width) ||
      !get(f, mode.height) || !get(f, mode.fps)) {
    std::fclose(f);
    return fail(Errc::kParse, "not a Basalt raw trace video (.bvraw)", path.string());
  }
  if (format == 0 || format > static_cast<std::uint32_t>(PixelFormat::kMjpeg) || mode.width == 0 || mode.height == 0 ||
      mode.width > kMaxDimension || mode.height > kMaxDimension || !(mode.fps >= 0)) {
    std::fclose(f);
    return fail(Errc::kParse, "the trace video header is damaged", path.string());
  }
  mode.format = static_cast<PixelFormat>(format);
  auto reader = std::unique_ptr<RawVideoReader>(new RawVideoReader(f, path, mode));
  reader->pool_ = FramePool::create({mode.format, mode.width, mode.height, 6, 1, true});
  reader->frameBytes_ = computeLayout(mode.format, mode.width, mode.height).totalSize;
  return reader;
}

RawVideoReader::~RawVideoReader() {
  if (file_) std::fclose(file_);
}

Result<FrameRef> RawVideoReader::next() {
  std::int64_t pts = 0, capture = 0;
  std::uint64_t sequence = 0;
  std::uint32_t bytes = 0;
  if (!get(file_, pts)) return FrameRef{};  // end of file
  if (!get(file_, capture) || !get(file_, sequence) || !get(file_, bytes)) {
    return fail(Errc::kParse, "the trace video ends in the middle of a frame", path_.string());
  }
  if (bytes > frameBytes_ || (mode_.format != PixelFormat::kMjpeg && bytes != frameBytes_)) {
    return fail(Errc::kParse, fmt::format("a frame of {} bytes does not fit the video's size", bytes), path_.string());
  }
  FrameRef frame = pool_->acquire();
  if (!frame) return fail(Errc::kResourceExhausted, "every frame of the replay pool is in use", path_.string());
  if (std::fread(frame->storage(), 1, bytes, file_) != bytes) {
    return fail(Errc::kParse, "the trace video ends in the middle of a frame", path_.string());
  }
  frame->bytesUsed = bytes;
  frame->pts = Nanos{pts};
  frame->captureTime = Nanos{capture};
  frame->sequence = sequence;
  return frame;
}

Result<void> RawVideoReader::rewind() {
  if (std::fseek(file_, 8 + 3 * 4 + 8, SEEK_SET) != 0) return fail(Errc::kIo, "cannot rewind", path_.string());
  return {};
}

TraceVideoWriterFactory rawVideoWriterFactory() {
  return [](const std::filesystem::path& folder, const std::string& stem, const devices::VideoMode& mode,
            std::string& fileName) -> Result<std::unique_ptr<TraceVideoWriter>> {
    fileName = stem + ".bvraw";
    auto w = RawVideoWriter::create(folder / fileName, mode);
    if (!w) return std::unexpected(w.error());
    return std::unique_ptr<TraceVideoWriter>(std::move(*w));
  };
}

TraceVideoReaderFactory videoReaderFactory(TraceVideoReaderFactory other) {
  return [other = std::move(other)](const std::filesystem::path& file) -> Result<std::unique_ptr<TraceVideoReader>> {
    if (file.extension() == ".bvraw") {
      auto r = RawVideoReader::open(file);
      if (!r) return std::unexpected(r.error());
      return std::unique_ptr<TraceVideoReader>(std::move(*r));
    }
    if (other) return other(file);
    return fail(Errc::kUnsupported,
                "this build cannot read this trace video: Matroska traces are read by media/, which is not wired "
                "here; record with the raw format or use a build with media's trace reader",
                file.string());
  };
}

}  // namespace basalt::sim
