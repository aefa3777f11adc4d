#include "kiosk/show/trace_video_glue.h"

#include <optional>

#include <fmt/format.h>

#include "media/trace_video.h"

namespace basalt::kiosk {

namespace {

class MatroskaWriter final : public sim::TraceVideoWriter {
 public:
  MatroskaWriter(std::filesystem::path path, devices::VideoMode mode) : path_(std::move(path)), mode_(mode) {}
  ~MatroskaWriter() override = default;  // media's writer finishes its file when destroyed
  MatroskaWriter(const MatroskaWriter&) = delete;
  MatroskaWriter& operator=(const MatroskaWriter&) = delete;

  Result<void> write(const Frame& frame, Nanos pts) override {
    if (!writer_) {
      // The file starts with the first frame: its origin puts that frame at `pts` after the
      // trace's start, so the gap before it is kept.
      if (auto r = create(frame.format, frame.width, frame.height, frame.pts - pts); !r) return r;
    }
    if (frame.format != format_ || frame.width != width_ || frame.height != height_) {
      return fail(Errc::kUnsupported,
                  fmt::format("the source changed to {} {}x{} during the recording; a trace video holds one mode",
                              pixelFormatName(frame.format), frame.width, frame.height),
                  path_.string());
    }
    return writer_->write(frame);
  }

  Result<void> finish() override {
    if (!writer_) {
      // No frame came: an empty file of the mode the camera announced, so the trace stays whole.
      if (auto r = create(mode_.format, mode_.width, mode_.height, Nanos{0}); !r) return r;
    }
    auto r = writer_->finish();
    writer_.reset();
    return r;
  }

 private:
  Result<void> create(PixelFormat format, std::uint32_t width, std::uint32_t height, Nanos origin) {
    auto w = media::TraceVideoWriter::create(path_, format, width, height, origin);
    if (!w) return std::unexpected(w.error());
    writer_ = std::move(*w);
    format_ = format;
    width_ = width;
    height_ = height;
    return {};
  }

  std::filesystem::path path_;
  devices::VideoMode mode_;
  std::unique_ptr<media::TraceVideoWriter> writer_;
  PixelFormat format_ = PixelFormat::kUnknown;
  std::uint32_t width_ = 0;
  std::uint32_t height_ = 0;
};

class MatroskaReader final : public sim::TraceVideoReader {
 public:
  static Result<std::unique_ptr<MatroskaReader>> open(const std::filesystem::path& path) {
    auto reader = std::unique_ptr<MatroskaReader>(new MatroskaReader(path));
    if (auto r = reader->rewind(); !r) return std::unexpected(r.error());
    return reader;
  }

  [[nodiscard]] devices::VideoMode mode() const override { return mode_; }

  Result<FrameRef> next() override {
    if (!ahead_.empty()) {
      FrameRef f = std::move(ahead_.front());
      ahead_.erase(ahead_.begin());
      return f;
    }
    return reader_->next();
  }

  Result<void> rewind() override {
    ahead_.clear();
    reader_.reset();
    auto reader = media::TraceVideoReader::open(path_);
    if (!reader) return std::unexpected(reader.error());
    reader_ = std::move(*reader);
    mode_.format = reader_->format();
    mode_.width = reader_->width();
    mode_.height = reader_->height();
    // The frame rate is not stored: the first two frames' interval gives it (kept to be read).
    for (int i = 0; i < 2; ++i) {
      auto f = reader_->next();
      if (!f) return std::unexpected(f.error());
      if (!*f) break;
      ahead_.push_back(std::move(*f));
    }
    if (ahead_.size() == 2 && ahead_[1]->pts > ahead_[0]->pts) {
      mode_.fps = 1.0 / toSeconds(ahead_[1]->pts - ahead_[0]->pts);
    }
    return {};
  }

 private:
  explicit MatroskaReader(std::filesystem::path path) : path_(std::move(path)) {}
  std::filesystem::path path_;
  std::unique_ptr<media::TraceVideoReader> reader_;
  std::vector<FrameRef> ahead_;
  devices::VideoMode mode_{};
};

}  // namespace

sim::TraceVideoWriterFactory matroskaTraceWriterFactory() {
  return [](const std::filesystem::path& folder, const std::string& stem, const devices::VideoMode& mode,
            std::string& fileName) -> Result<std::unique_ptr<sim::TraceVideoWriter>> {
    fileName = stem + ".mkv";
    return std::make_unique<MatroskaWriter>(folder / fileName, mode);
  };
}

sim::TraceVideoReaderFactory matroskaTraceReaderFactory() {
  return [](const std::filesystem::path& file) -> Result<std::unique_ptr<sim::TraceVideoReader>> {
    if (file.extension() != ".mkv") {
      return fail(Errc::kUnsupported, "trace videos are .mkv (Matroska) or .bvraw files", file.string());
    }
    auto reader = MatroskaReader::open(file);
    if (!reader) return std::unexpected(reader.error());
    return std::unique_ptr<sim::TraceVideoReader>(std::move(*reader));
  };
}

}  // namespace basalt::kiosk
