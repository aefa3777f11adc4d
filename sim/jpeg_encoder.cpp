#include "sim/jpeg_encoder.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <span>

namespace basalt::sim {

void Yuv422Planes::resize(std::uint32_t w, std::uint32_t h) {
  width = w;
  height = h;
  y.resize(std::size_t{w} * h);
  cb.resize(std::size_t{w / 2} * h);
  cr.resize(std::size_t{w / 2} * h);
}

namespace {

// ITU-T T.81 Annex K.1: the example quantisation tables, natural order.
constexpr std::array<std::uint8_t, 64> kLumaQuant = {
    16, 11,  10,  16, 24, 40, 51, 61, 12,  12,  14,  19,  26, 58, 60, 55,  14,  13,  16,  24, 40, 57,
    69, 56,  14,  17, 22, 29, 51, 87, 80,  62,  18,  22,  37, 56, 68, 109, 103, 77,  24,  35, 55, 64,
    81, 104, 113, 92, 49, 64, 78, 87, 103, 121, 120, 101, 72, 92, 95, 98,  112, 100, 103, 99};
constexpr std::array<std::uint8_t, 64> kChromaQuant = {17, 18, 24, 47, 99, 99, 99, 99, 18, 21, 26, 66, 99, 99, 99, 99,
                                                       24, 26, 56, 99, 99, 99, 99, 99, 47, 66, 99, 99, 99, 99, 99, 99,
                                                       99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99,
                                                       99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99, 99};

// Position in natural order of the k-th coefficient in zig-zag order (T.81 figure A.6).
constexpr std::array<std::uint8_t, 64> kZigzag = {0,  1,  8,  16, 9,  2,  3,  10, 17, 24, 32, 25, 18, 11, 4,  5,
                                                  12, 19, 26, 33, 40, 48, 41, 34, 27, 20, 13, 6,  7,  14, 21, 28,
                                                  35, 42, 49, 56, 57, 50, 43, 36, 29, 22, 15, 23, 30, 37, 44, 51,
                                                  58, 59, 52, 45, 38, 31, 39, 46, 53, 60, 61, 54, 47, 55, 62, 63};

// T.81 Annex K.3: typical Huffman tables, as counts of codes of each length 1-16 and the values.
constexpr std::array<std::uint8_t, 16> kDcLumaBits = {0, 1, 5, 1, 1, 1, 1, 1, 1, 0, 0, 0, 0, 0, 0, 0};
constexpr std::array<std::uint8_t, 12> kDcLumaValues = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11};
constexpr std::array<std::uint8_t, 16> kDcChromaBits = {0, 3, 1, 1, 1, 1, 1, 1, 1, 1, 1, 0, 0, 0, 0, 0};
constexpr std::array<std::uint8_t, 12> kDcChromaValues = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11};
constexpr std::array<std::uint8_t, 16> kAcLumaBits = {0, 2, 1, 3, 3, 2, 4, 3, 5, 5, 4, 4, 0, 0, 1, 0x7d};
constexpr std::array<std::uint8_t, 162> kAcLumaValues = {
    0x01, 0x02, 0x03, 0x00, 0x04, 0x11, 0x05, 0x12, 0x21, 0x31, 0x41, 0x06, 0x13, 0x51, 0x61, 0x07, 0x22, 0x71,
    0x14, 0x32, 0x81, 0x91, 0xa1, 0x08, 0x23, 0x42, 0xb1, 0xc1, 0x15, 0x52, 0xd1, 0xf0, 0x24, 0x33, 0x62, 0x72,
    0x82, 0x09, 0x0a, 0x16, 0x17, 0x18, 0x19, 0x1a, 0x25, 0x26, 0x27, 0x28, 0x29, 0x2a, 0x34, 0x35, 0x36, 0x37,
    0x38, 0x39, 0x3a, 0x43, 0x44, 0x45, 0x46, 0x47, 0x48, 0x49, 0x4a, 0x53, 0x54, 0x55, 0x56, 0x57, 0x58, 0x59,
    0x5a, 0x63, 0x64, 0x65, 0x66, 0x67, 0x68, 0x69, 0x6a, 0x73, 0x74, 0x75, 0x76, 0x77, 0x78, 0x79, 0x7a, 0x83,
    0x84, 0x85, 0x86, 0x87, 0x88, 0x89, 0x8a, 0x92, 0x93, 0x94, 0x95, 0x96, 0x97, 0x98, 0x99, 0x9a, 0xa2, 0xa3,
    0xa4, 0xa5, 0xa6, 0xa7, 0xa8, 0xa9, 0xaa, 0xb2, 0xb3, 0xb4, 0xb5, 0xb6, 0xb7, 0xb8, 0xb9, 0xba, 0xc2, 0xc3,
    0xc4, 0xc5, 0xc6, 0xc7, 0xc8, 0xc9, 0xca, 0xd2, 0xd3, 0xd4, 0xd5, 0xd6, 0xd7, 0xd8, 0xd9, 0xda, 0xe1, 0xe2,
    0xe3, 0xe4, 0xe5, 0xe6, 0xe7, 0xe8, 0xe9, 0xea, 0xf1, 0xf2, 0xf3, 0xf4, 0xf5, 0xf6, 0xf7, 0xf8, 0xf9, 0xfa};
constexpr std::array<std::uint8_t, 16> kAcChromaBits = {0, 2, 1, 2, 4, 4, 3, 4, 7, 5, 4, 4, 0, 1, 2, 0x77};
constexpr std::array<std::uint8_t, 162> kAcChromaValues = {
    0x00, 0x01, 0x02, 0x03, 0x11, 0x04, 0x05, 0x21, 0x31, 0x06, 0x12, 0x41, 0x51, 0x07, 0x61, 0x71, 0x13, 0x22,
    0x32, 0x81, 0x08, 0x14, 0x42, 0x91, 0xa1, 0xb1, 0xc1, 0x09, 0x23, 0x33, 0x52, 0xf0, 0x15, 0x62, 0x72, 0xd1,
    0x0a, 0x16, 0x24, 0x34, 0xe1, 0x25, 0xf1, 0x17, 0x18, 0x19, 0x1a, 0x26, 0x27, 0x28, 0x29, 0x2a, 0x35, 0x36,
    0x37, 0x38, 0x39, 0x3a, 0x43, 0x44, 0x45, 0x46, 0x47, 0x48, 0x49, 0x4a, 0x53, 0x54, 0x55, 0x56, 0x57, 0x58,
    0x59, 0x5a, 0x63, 0x64, 0x65, 0x66, 0x67, 0x68, 0x69, 0x6a, 0x73, 0x74, 0x75, 0x76, 0x77, 0x78, 0x79, 0x7a,
    0x82, 0x83, 0x84, 0x85, 0x86, 0x87, 0x88, 0x89, 0x8a, 0x92, 0x93, 0x94, 0x95, 0x96, 0x97, 0x98, 0x99, 0x9a,
    0xa2, 0xa3, 0xa4, 0xa5, 0xa6, 0xa7, 0xa8, 0xa9, 0xaa, 0xb2, 0xb3, 0xb4, 0xb5, 0xb6, 0xb7, 0xb8, 0xb9, 0xba,
    0xc2, 0xc3, 0xc4, 0xc5, 0xc6, 0xc7, 0xc8, 0xc9, 0xca, 0xd2, 0xd3, 0xd4, 0xd5, 0xd6, 0xd7, 0xd8, 0xd9, 0xda,
    0xe2, 0xe3, 0xe4, 0xe5, 0xe6, 0xe7, 0xe8, 0xe9, 0xea, 0xf2, 0xf3, 0xf4, 0xf5, 0xf6, 0xf7, 0xf8, 0xf9, 0xfa};

// The DCT basis, cos((2x+1)u pi/16) * C(u)/2 with C(0) = 1/sqrt(2), scaled by 2^12.
struct DctBasis {
  std::array<std::array<int, 8>, 8> m{};
  DctBasis() {
    for (int u = 0; u < 8; ++u) {
      const double c = u == 0 ? 1.0 / std::sqrt(2.0) : 1.0;
      for (int x = 0; x < 8; ++x) {
        const double v = c / 2 * std::cos((2 * x + 1) * u * M_PI / 16);
        m[static_cast<std::size_t>(u)][static_cast<std::size_t>(x)] = static_cast<int>(std::lround(v * 4096));
      }
    }
  }
};
const DctBasis& basis() {
  static const DctBasis kBasis;
  return kBasis;
}

// Appends bits MSB first, stuffing a 0x00 after every 0xFF byte (T.81 F.1.2.3).
class BitWriter {
 public:
  explicit BitWriter(std::vector<std::uint8_t>& out) : out_(out) {}
  void put(std::uint32_t bits, unsigned count) {
    for (unsigned i = count; i-- > 0;) {
      acc_ = static_cast<std::uint8_t>((static_cast<unsigned>(acc_) << 1U) | ((bits >> i) & 1U));
      if (++n_ == 8) flushByte();
    }
  }
  void finish() {
    while (n_ != 0) put(1, 1);  // pad with 1 bits
  }

 private:
  void flushByte() {
    out_.push_back(acc_);
    if (acc_ == 0xff) out_.push_back(0);
    acc_ = 0;
    n_ = 0;
  }
  std::vector<std::uint8_t>& out_;
  std::uint8_t acc_ = 0;
  unsigned n_ = 0;
};

unsigned magnitudeBits(int v) {
  unsigned a = static_cast<unsigned>(v < 0 ? -v : v);
  unsigned n = 0;
  while (a != 0) {
    ++n;
    a >>= 1U;
  }
  return n;
}

void put16(std::vector<std::uint8_t>& out, unsigned v) {
  out.push_back(static_cast<std::uint8_t>(v >> 8U));
  out.push_back(static_cast<std::uint8_t>(v));
}

void marker(std::vector<std::uint8_t>& out, std::uint8_t code, unsigned length) {
  out.push_back(0xff);
  out.push_back(code);
  put16(out, length);
}

template <std::size_t N>
void putHuffmanTable(std::vector<std::uint8_t>& out, std::uint8_t classAndId, const std::array<std::uint8_t, 16>& bits,
                     const std::array<std::uint8_t, N>& values) {
  out.push_back(classAndId);
  out.insert(out.end(), bits.begin(), bits.end());
  out.insert(out.end(), values.begin(), values.end());
}

// Builds code words from counts per length (T.81 Annex C), indexed by value.
template <std::size_t N>
void buildTable(const std::array<std::uint8_t, 16>& bits, const std::array<std::uint8_t, N>& values,
                std::array<std::pair<std::uint16_t, std::uint8_t>, 256>& table) {
  unsigned code = 0;
  std::size_t k = 0;
  for (unsigned length = 1; length <= 16; ++length) {
    for (unsigned i = 0; i < bits[length - 1]; ++i) {
      table[values[k++]] = {static_cast<std::uint16_t>(code), static_cast<std::uint8_t>(length)};
      ++code;
    }
    code <<= 1U;
  }
}

}  // namespace

JpegEncoder::JpegEncoder(int quality) : quality_(std::clamp(quality, 1, 100)) {
  const int scale = quality_ < 50 ? 5000 / quality_ : 200 - 2 * quality_;
  for (std::size_t i = 0; i < 64; ++i) {
    lumaQuant_[i] = static_cast<std::uint8_t>(std::clamp((kLumaQuant[i] * scale + 50) / 100, 1, 255));
    chromaQuant_[i] = static_cast<std::uint8_t>(std::clamp((kChromaQuant[i] * scale + 50) / 100, 1, 255));
  }
  auto fill = [](auto bits, auto values, HuffmanTable& table) {
    std::array<std::pair<std::uint16_t, std::uint8_t>, 256> t{};
    buildTable(bits, values, t);
    for (std::size_t i = 0; i < 256; ++i) table[i] = {t[i].first, t[i].second};
  };
  fill(kDcLumaBits, kDcLumaValues, dcLuma_);
  fill(kAcLumaBits, kAcLumaValues, acLuma_);
  fill(kDcChromaBits, kDcChromaValues, dcChroma_);
  fill(kAcChromaBits, kAcChromaValues, acChroma_);
}

void JpegEncoder::encode(const Yuv422Planes& picture, std::vector<std::uint8_t>& out, std::string_view comment) const {
  out.clear();
  const unsigned width = picture.width;
  const unsigned height = picture.height;
  if (width == 0 || height == 0 || width > 65535 || height > 65535) return;

  out.push_back(0xff);
  out.push_back(0xd8);    // SOI
  marker(out, 0xe0, 16);  // APP0: JFIF 1.1, no density
  for (const char c : {'J', 'F', 'I', 'F', '\0'}) out.push_back(static_cast<std::uint8_t>(c));
  out.insert(out.end(), {1, 1, 0, 0, 1, 0, 1, 0, 0});
  if (!comment.empty()) {
    comment = comment.substr(0, 65533);
    marker(out, 0xfe, static_cast<unsigned>(2 + comment.size()));  // COM
    out.insert(out.end(), comment.begin(), comment.end());
  }
  marker(out, 0xdb, 2 + 2 * 65);  // DQT: table 0 luma, table 1 chroma, zig-zag order
  out.push_back(0);
  for (const auto z : kZigzag) out.push_back(lumaQuant_[z]);
  out.push_back(1);
  for (const auto z : kZigzag) out.push_back(chromaQuant_[z]);
  marker(out, 0xc0, 17);  // SOF0: baseline, 8 bits, 3 components, Y 2x1, Cb and Cr 1x1
  out.push_back(8);
  put16(out, height);
  put16(out, width);
  out.push_back(3);
  out.insert(out.end(), {1, 0x21, 0, 2, 0x11, 1, 3, 0x11, 1});
  marker(out, 0xc4, 2 + 4 * 17 + 12 + 162 + 12 + 162);  // DHT: all four tables
  putHuffmanTable(out, 0x00, kDcLumaBits, kDcLumaValues);
  putHuffmanTable(out, 0x10, kAcLumaBits, kAcLumaValues);
  putHuffmanTable(out, 0x01, kDcChromaBits, kDcChromaValues);
  putHuffmanTable(out, 0x11, kAcChromaBits, kAcChromaValues);
  marker(out, 0xda, 12);  // SOS: the three components, tables 0/0, 1/1, 1/1
  out.insert(out.end(), {3, 1, 0x00, 2, 0x11, 3, 0x11, 0, 63, 0});

  BitWriter bits(out);
  const auto& m = basis().m;
  int lastDc[3] = {0, 0, 0};

  auto encodeBlock = [&](const std::uint8_t* plane, unsigned planeWidth, unsigned x0, unsigned y0, int component) {
    // Samples, level-shifted, with the edge repeated past the picture.
    std::array<int, 64> s{};
    for (unsigned y = 0; y < 8; ++y) {
      const unsigned py = std::min(y0 + y, height - 1);
      for (unsigned x = 0; x < 8; ++x) {
        const unsigned px = std::min(x0 + x, planeWidth - 1);
        s[y * 8 + x] = int{plane[std::size_t{py} * planeWidth + px]} - 128;
      }
    }
    // Separable DCT in fixed point: rows (keeping 2 fractional bits), then columns.
    std::array<int, 64> rows{};
    for (std::size_t y = 0; y < 8; ++y) {
      for (std::size_t u = 0; u < 8; ++u) {
        int acc = 0;
        for (std::size_t x = 0; x < 8; ++x) acc += s[y * 8 + x] * m[u][x];
        rows[y * 8 + u] = (acc + (1 << 9)) >> 10;
      }
    }
    const auto& quant = component == 0 ? lumaQuant_ : chromaQuant_;
    std::array<int, 64> q{};
    for (std::size_t v = 0; v < 8; ++v) {
      for (std::size_t u = 0; u < 8; ++u) {
        int acc = 0;
        for (std::size_t y = 0; y < 8; ++y) acc += m[v][y] * rows[y * 8 + u];
        const int coefficient = (acc + (1 << 13)) >> 14;
        const int divisor = quant[v * 8 + u];
        q[v * 8 + u] =
            coefficient >= 0 ? (coefficient + divisor / 2) / divisor : -((-coefficient + divisor / 2) / divisor);
      }
    }
    const HuffmanTable& dc = component == 0 ? dcLuma_ : dcChroma_;
    const HuffmanTable& ac = component == 0 ? acLuma_ : acChroma_;
    auto putValue = [&](const HuffmanCode& code, int value, unsigned size) {
      bits.put(code.code, code.length);
      if (size != 0) {
        const int raw = value < 0 ? value - 1 : value;
        bits.put(static_cast<std::uint32_t>(raw) & ((1U << size) - 1U), size);
      }
    };
    const int diff = q[0] - lastDc[component];
    lastDc[component] = q[0];
    const unsigned dcSize = magnitudeBits(diff);
    putValue(dc[dcSize], diff, dcSize);
    unsigned run = 0;
    for (std::size_t k = 1; k < 64; ++k) {
      const int v = q[kZigzag[k]];
      if (v == 0) {
        ++run;
        continue;
      }
      while (run >= 16) {
        bits.put(ac[0xf0].code, ac[0xf0].length);  // ZRL: sixteen zeros
        run -= 16;
      }
      const unsigned size = magnitudeBits(v);
      putValue(ac[(run << 4U) | size], v, size);
      run = 0;
    }
    if (run != 0) bits.put(ac[0x00].code, ac[0x00].length);  // EOB
  };

  const unsigned chromaWidth = width / 2;
  for (unsigned y = 0; y < height; y += 8) {
    for (unsigned x = 0; x < width; x += 16) {
      encodeBlock(picture.y.data(), width, x, y, 0);
      encodeBlock(picture.y.data(), width, x + 8, y, 0);
      encodeBlock(picture.cb.data(), chromaWidth, x / 2, y, 1);
      encodeBlock(picture.cr.data(), chromaWidth, x / 2, y, 2);
    }
  }
  bits.finish();
  out.push_back(0xff);
  out.push_back(0xd9);  // EOI
}

std::optional<JpegInfo> inspectJpeg(std::span<const std::uint8_t> jpeg) {
  if (jpeg.size() < 4 || jpeg[0] != 0xff || jpeg[1] != 0xd8) return std::nullopt;
  JpegInfo info;
  info.complete = jpeg[jpeg.size() - 2] == 0xff && jpeg[jpeg.size() - 1] == 0xd9;
  bool haveFrame = false;
  std::size_t at = 2;
  while (at + 4 <= jpeg.size()) {
    if (jpeg[at] != 0xff) return std::nullopt;
    const std::uint8_t code = jpeg[at + 1];
    if (code == 0xff) {  // fill byte
      ++at;
      continue;
    }
    const std::size_t length = (std::size_t{jpeg[at + 2]} << 8U) | jpeg[at + 3];
    if (length < 2 || at + 2 + length > jpeg.size()) return std::nullopt;
    const auto body = jpeg.subspan(at + 4, length - 2);
    if (code == 0xda) break;  // start of scan: entropy-coded data follows
    if ((code == 0xc0 || code == 0xc1 || code == 0xc2) && !haveFrame && body.size() >= 5) {
      info.baseline = code == 0xc0;
      info.height = (std::uint32_t{body[1]} << 8U) | body[2];
      info.width = (std::uint32_t{body[3]} << 8U) | body[4];
      haveFrame = true;
    }
    if (code == 0xfe && info.comment.empty()) info.comment.assign(body.begin(), body.end());
    at += 2 + length;
  }
  if (!haveFrame) return std::nullopt;
  return info;
}

void expandToFullRange(Yuv422Planes& planes) {
  static const auto kTables = [] {
    std::array<std::array<std::uint8_t, 256>, 2> t{};
    for (int v = 0; v < 256; ++v) {
      t[0][static_cast<std::size_t>(v)] =
          static_cast<std::uint8_t>(std::clamp(static_cast<int>(std::lround((v - 16) * 255.0 / 219)), 0, 255));
      t[1][static_cast<std::size_t>(v)] =
          static_cast<std::uint8_t>(std::clamp(static_cast<int>(std::lround((v - 128) * 255.0 / 224 + 128)), 0, 255));
    }
    return t;
  }();
  for (auto& v : planes.y) v = kTables[0][v];
  for (auto& v : planes.cb) v = kTables[1][v];
  for (auto& v : planes.cr) v = kTables[1][v];
}

}  // namespace basalt::sim
