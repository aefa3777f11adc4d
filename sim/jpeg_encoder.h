#pragma once

/// \file
/// \brief A small baseline JPEG encoder for the MJPEG frames of Basalt's simulated cameras (the
/// synthetic camera and the virtual lab's UVC webcam): Y'CbCr 4:2:2 (as UVC webcams send), the quantisation tables of
/// the JPEG standard scaled by a quality as IJG does, its typical Huffman tables, a JFIF header and the Huffman tables
/// in every frame, so that each frame is a complete JPEG file any decoder reads.

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace basalt::sim {

/// \brief A picture in planar Y'CbCr 4:2:2 (BT.601): `y` is width x height, `cb` and `cr` are
/// width/2 x height. Drawn pictures are limited range; the encoder takes full range.
struct Yuv422Planes {
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  std::vector<std::uint8_t> y;
  std::vector<std::uint8_t> cb;
  std::vector<std::uint8_t> cr;

  void resize(std::uint32_t w, std::uint32_t h);
};

/// \brief Encodes 4:2:2 pictures. Holds only its tables, so encoding allocates nothing once the
/// output vector has grown to a frame's size.
class JpegEncoder {
 public:
  /// \brief `quality` 1-100 (values outside are clamped), as IJG's cjpeg takes it.
  explicit JpegEncoder(int quality = 85);

  /// \brief Replaces `out` with the JPEG file of `picture` (full-range Y'CbCr, as JFIF defines
  /// it), with `comment` (at most 65533 bytes) in a COM segment when it is not empty. Sizes that
  /// are not a multiple of the 16x8 MCU are padded by repeating the edge.
  void encode(const Yuv422Planes& picture, std::vector<std::uint8_t>& out, std::string_view comment = {}) const;

  [[nodiscard]] int quality() const { return quality_; }

 private:
  struct HuffmanCode {
    std::uint16_t code = 0;
    std::uint8_t length = 0;
  };
  using HuffmanTable = std::array<HuffmanCode, 256>;

  int quality_;
  std::array<std::uint8_t, 64> lumaQuant_{};    // natural (row-major) order
  std::array<std::uint8_t, 64> chromaQuant_{};  // natural order
  HuffmanTable dcLuma_{};
  HuffmanTable acLuma_{};
  HuffmanTable dcChroma_{};
  HuffmanTable acChroma_{};
};

/// \brief What the headers of a JPEG file say, read without decoding it.
struct JpegInfo {
  std::uint32_t width = 0;  ///< from the first start-of-frame segment
  std::uint32_t height = 0;
  bool baseline = false;  ///< SOF0
  std::string comment;    ///< the first COM segment
  bool complete = false;  ///< starts with SOI and ends with EOI
};

/// \brief Reads the segments of `jpeg` up to the start of scan; nothing when it is not a JPEG
/// file (no SOI, a segment running past the end, no start of frame).
std::optional<JpegInfo> inspectJpeg(std::span<const std::uint8_t> jpeg);

/// \brief Converts limited-range (16-235, 16-240) planes to the full range JFIF expects.
void expandToFullRange(Yuv422Planes& planes);

}  // namespace basalt::sim
