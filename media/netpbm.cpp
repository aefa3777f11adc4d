// Netpbm codec: P1-P6 (plain and raw PBM, PGM, PPM) and P7 (PAM), first image of a file.
//
// Plain formats allow any blanks and '#' comments between numbers, and plain PBM allows bits
// with no blanks between them. Raw samples are bytes, or big-endian 16-bit words when maxval is
// over 255; raw PBM rows are padded to whole bytes.
// Limits: 16384 x 16384 pixels, 4 channels; samples must be present before they are allocated.

#include "media/netpbm.h"

#include <algorithm>
#include <cstring>
#include <string>

#include <fmt/format.h>

namespace basalt::media {

namespace {

constexpr std::uint32_t kMaxSide = 16384;

bool isSpace(std::uint8_t c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f'; }

class Reader {
 public:
  explicit Reader(std::span<const std::uint8_t> bytes) : b_(bytes) {}

  /// Skips blanks and comments.
  void skip() {
    while (i_ < b_.size()) {
      if (isSpace(b_[i_])) {
        ++i_;
      } else if (b_[i_] == '#') {
        while (i_ < b_.size() && b_[i_] != '\n' && b_[i_] != '\r') ++i_;
      } else {
        break;
      }
    }
  }

  /// An unsigned decimal number after blanks and comments.
  bool number(std::uint32_t& out, std::uint32_t max) {
    skip();
    const std::size_t start = i_;
    std::uint64_t v = 0;
    while (i_ < b_.size() && b_[i_] >= '0' && b_[i_] <= '9') {
      v = v * 10 + static_cast<std::uint64_t>(b_[i_] - '0');
      if (v > max) return false;
      ++i_;
    }
    if (i_ == start) return false;
    out = static_cast<std::uint32_t>(v);
    return true;
  }

  /// One plain-PBM bit ('0' or '1'), which need not be separated from the next.
  bool bit(std::uint8_t& out) {
    skip();
    if (i_ >= b_.size() || (b_[i_] != '0' && b_[i_] != '1')) return false;
    out = b_[i_++] == '1';
    return true;
  }

  /// A line of a PAM header (without its end).
  bool line(std::string& out) {
    if (i_ >= b_.size()) return false;
    const std::size_t start = i_;
    while (i_ < b_.size() && b_[i_] != '\n') ++i_;
    out.assign(reinterpret_cast<const char*>(b_.data() + start), i_ - start);
    if (i_ < b_.size()) ++i_;
    return true;
  }

  /// The single blank that ends a raw header.
  bool oneSpace() {
    if (i_ >= b_.size() || !isSpace(b_[i_])) return false;
    ++i_;
    return true;
  }

  [[nodiscard]] std::size_t left() const { return b_.size() - i_; }
  [[nodiscard]] const std::uint8_t* here() const { return b_.data() + i_; }
  std::size_t& position() { return i_; }

 private:
  std::span<const std::uint8_t> b_;
  std::size_t i_ = 0;
};

struct Header {
  char kind = 0;  // '1' .. '7'
  std::uint32_t width = 0, height = 0, depth = 1, maxval = 1;
};

std::string trimmed(std::string s) {
  while (!s.empty() && (isSpace(static_cast<std::uint8_t>(s.back())))) s.pop_back();
  std::size_t i = 0;
  while (i < s.size() && isSpace(static_cast<std::uint8_t>(s[i]))) ++i;
  return s.substr(i);
}

Result<void> readPamHeader(Reader& r, Header& h) {
  std::string line;
  bool haveW = false, haveH = false, haveD = false, haveM = false;
  std::string tupleType;
  for (int lines = 0; r.line(line); ++lines) {
    if (lines > 1000) return fail(Errc::kParse, "the PAM header never ends (no ENDHDR)");
    line = trimmed(line);
    if (line.empty() || line[0] == '#') continue;
    if (line == "ENDHDR") {
      if (!haveW || !haveH || !haveD || !haveM) {
        return fail(Errc::kParse, "the PAM header lacks WIDTH, HEIGHT, DEPTH or MAXVAL");
      }
      return {};
    }
    const std::size_t space = line.find_first_of(" \t");
    const std::string key = line.substr(0, space);
    const std::string value = space == std::string::npos ? std::string() : trimmed(line.substr(space));
    const auto parse = [&](std::uint32_t& out, std::uint32_t max) {
      std::uint64_t v = 0;
      if (value.empty() || value.size() > 10) return false;
      for (char c : value) {
        if (c < '0' || c > '9') return false;
        v = v * 10 + static_cast<std::uint64_t>(c - '0');
      }
      if (v == 0 || v > max) return false;
      out = static_cast<std::uint32_t>(v);
      return true;
    };
    if (key == "WIDTH") {
      haveW = parse(h.width, kMaxSide);
      if (!haveW) return fail(Errc::kParse, fmt::format("PAM WIDTH '{}' is not 1 to {}", value, kMaxSide));
    } else if (key == "HEIGHT") {
      haveH = parse(h.height, kMaxSide);
      if (!haveH) return fail(Errc::kParse, fmt::format("PAM HEIGHT '{}' is not 1 to {}", value, kMaxSide));
    } else if (key == "DEPTH") {
      haveD = parse(h.depth, 4);
      if (!haveD) {
        return fail(Errc::kUnsupported, fmt::format("PAM DEPTH '{}' is not supported (1 to 4 channels)", value));
      }
    } else if (key == "MAXVAL") {
      haveM = parse(h.maxval, 65535);
      if (!haveM) return fail(Errc::kParse, fmt::format("PAM MAXVAL '{}' is not 1 to 65535", value));
    } else if (key == "TUPLTYPE") {
      tupleType += value;
    } else {
      return fail(Errc::kParse, fmt::format("'{}' is not a PAM header line", key));
    }
  }
  return fail(Errc::kParse, "the PAM header never ends (no ENDHDR)");
}

}  // namespace

bool looksLikeNetpbm(std::span<const std::uint8_t> bytes) {
  return bytes.size() >= 3 && bytes[0] == 'P' && bytes[1] >= '1' && bytes[1] <= '7' && isSpace(bytes[2]);
}

Result<Image> decodeNetpbm(std::span<const std::uint8_t> bytes) {
  if (!looksLikeNetpbm(bytes)) return fail(Errc::kParse, "this is not a Netpbm file (P1 to P7)");
  Header h;
  h.kind = static_cast<char>(bytes[1]);
  Reader r(bytes.subspan(2));
  if (h.kind == '7') {
    r.oneSpace();
    if (auto ok = readPamHeader(r, h); !ok) return std::unexpected(ok.error());
  } else {
    if (!r.number(h.width, kMaxSide) || !r.number(h.height, kMaxSide) || h.width == 0 || h.height == 0) {
      return fail(Errc::kParse, fmt::format("the header needs a width and a height of 1 to {} pixels", kMaxSide));
    }
    if (h.kind == '1' || h.kind == '4') {
      h.maxval = 1;
    } else if (!r.number(h.maxval, 65535) || h.maxval == 0) {
      return fail(Errc::kParse, "the header needs a maximum value of 1 to 65535");
    }
    h.depth = (h.kind == '3' || h.kind == '6') ? 3 : 1;
    const bool raw = h.kind >= '4';
    if (raw && !r.oneSpace()) return fail(Errc::kParse, "the header does not end with a blank before the pixels");
  }
  const bool wide = h.maxval > 255;
  const std::size_t samples = std::size_t{h.width} * h.height * h.depth;
  // Never allocate for samples that are not there: raw data must be complete, and plain data
  // needs at least one character per sample.
  const std::size_t rawBytes = h.kind == '4' ? std::size_t{(h.width + 7) / 8} * h.height : samples * (wide ? 2 : 1);
  if (h.kind >= '4' ? r.left() < rawBytes : r.left() < samples) {
    return fail(Errc::kParse, fmt::format("the file ends before its {} x {} pixels do", h.width, h.height));
  }
  Image image = Image::make(h.width, h.height, h.depth, wide ? ChannelType::kU16 : ChannelType::kU8);
  const auto store = [&](std::size_t index, std::uint32_t value) {
    if (wide) {
      const auto v = static_cast<std::uint16_t>((std::uint64_t{value} * 65535 + h.maxval / 2) / h.maxval);
      std::memcpy(image.pixels.data() + index * 2, &v, 2);
    } else {
      image.pixels[index] = static_cast<std::uint8_t>((value * 255 + h.maxval / 2) / h.maxval);
    }
  };
  if (h.kind == '1') {
    for (std::size_t i = 0; i < samples; ++i) {
      std::uint8_t b = 0;
      if (!r.bit(b)) return fail(Errc::kParse, fmt::format("the plain bitmap ends or breaks after {} pixels", i));
      image.pixels[i] = b ? 0 : 255;
    }
  } else if (h.kind == '4') {
    const std::uint8_t* p = r.here();
    const std::size_t rowBytes = (h.width + 7) / 8;
    for (std::uint32_t y = 0; y < h.height; ++y) {
      for (std::uint32_t x = 0; x < h.width; ++x) {
        const bool black = (p[y * rowBytes + x / 8] >> (7 - x % 8)) & 1;
        image.pixels[std::size_t{y} * h.width + x] = black ? 0 : 255;
      }
    }
  } else if (h.kind == '2' || h.kind == '3') {
    for (std::size_t i = 0; i < samples; ++i) {
      std::uint32_t v = 0;
      if (!r.number(v, h.maxval)) {
        return fail(Errc::kParse, fmt::format("sample {} is missing or over the maximum value {}", i, h.maxval));
      }
      store(i, v);
    }
  } else {
    const std::uint8_t* p = r.here();
    for (std::size_t i = 0; i < samples; ++i) {
      // A sample over maxval (seen in the wild with maxval 1) is taken as maxval, as other
      // decoders do.
      const std::uint32_t v = wide ? (std::uint32_t{p[2 * i]} << 8 | p[2 * i + 1]) : p[i];
      store(i, std::min(v, h.maxval));  // PAM BLACKANDWHITE is 0 black, 1 white: plain scaling (PBM is the inverse)
    }
  }
  return image;
}

Result<std::vector<std::uint8_t>> encodeNetpbm(const Image& image, bool pam) {
  if (image.empty() || image.channels < 1 || image.channels > 4 || image.type == ChannelType::kF32 ||
      image.pixels.size() < image.byteSize()) {
    return fail(Errc::kInvalidArgument, "Netpbm files hold 8- or 16-bit images of 1 to 4 channels");
  }
  const bool wide = image.type == ChannelType::kU16;
  const std::uint32_t maxval = wide ? 65535 : 255;
  std::string header;
  if (pam || image.channels == 2 || image.channels == 4) {
    static constexpr const char* kTuple[] = {"GRAYSCALE", "GRAYSCALE_ALPHA", "RGB", "RGB_ALPHA"};
    header = fmt::format("P7\nWIDTH {}\nHEIGHT {}\nDEPTH {}\nMAXVAL {}\nTUPLTYPE {}\nENDHDR\n", image.width,
                         image.height, image.channels, maxval, kTuple[image.channels - 1]);
  } else {
    header = fmt::format("P{}\n{} {}\n{}\n", image.channels == 1 ? 5 : 6, image.width, image.height, maxval);
  }
  std::vector<std::uint8_t> out(header.begin(), header.end());
  const std::size_t samples = std::size_t{image.width} * image.height * image.channels;
  out.reserve(out.size() + samples * (wide ? 2 : 1));
  for (std::size_t i = 0; i < samples; ++i) {
    if (wide) {
      std::uint16_t v = 0;
      std::memcpy(&v, image.pixels.data() + i * 2, 2);
      out.push_back(static_cast<std::uint8_t>(v >> 8));
      out.push_back(static_cast<std::uint8_t>(v));
    } else {
      out.push_back(image.pixels[i]);
    }
  }
  return out;
}

}  // namespace basalt::media
