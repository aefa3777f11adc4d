#include "runtime/formats/text.h"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>

#include <fmt/format.h>

namespace basalt::formats {

// ---- Diagnostics ------------------------------------------------------------------------------

Diagnostics::Diagnostics(std::string file, std::uint32_t cap, bool log)
    : file_(std::move(file)), cap_(cap), log_(log) {}

std::string Diagnostics::where(std::uint32_t line, std::uint32_t column) const {
  if (line == 0) return file_;
  if (column == 0) return fmt::format("{}:{}", file_, line);
  return fmt::format("{}:{}:{}", file_, line, column);
}

void Diagnostics::add(Diagnostic d) {
  if (kept_.size() >= cap_) {
    ++dropped_;
    return;
  }
  if (log_) log::warn(kLogFormats, "{}", d.describe());
  kept_.push_back(std::move(d));
}

void Diagnostics::warn(std::uint32_t line, std::uint32_t column, std::string message) {
  add({where(line, column), std::move(message)});
}

void Diagnostics::ignored(std::string_view keyword, std::uint32_t line) {
  for (Ignored& i : ignored_) {
    if (i.keyword == keyword) {
      ++i.count;
      return;
    }
  }
  if (ignored_.size() >= 64) return;  // a file of random keywords says enough with 64
  ignored_.push_back({std::string(keyword), 1, line});
}

std::vector<Diagnostic> Diagnostics::finish() {
  if (!ignored_.empty()) {
    std::string list;
    for (const Ignored& i : ignored_) {
      if (!list.empty()) list += ", ";
      list += fmt::format("'{}' ({}x, first on line {})", i.keyword, i.count, i.firstLine);
    }
    ignored_.clear();
    const bool wasFull = kept_.size() >= cap_;
    if (wasFull) --dropped_;  // the summary always gets a place
    Diagnostic d{file_, "statements Basalt does not use were ignored: " + list};
    if (log_) log::warn(kLogFormats, "{}", d.describe());
    kept_.push_back(std::move(d));
  }
  if (dropped_ > 0) {
    Diagnostic d{file_, fmt::format("{} more warnings were not listed", dropped_)};
    if (log_) log::warn(kLogFormats, "{}", d.describe());
    kept_.push_back(std::move(d));
    dropped_ = 0;
  }
  return std::move(kept_);
}

// ---- Files and text ---------------------------------------------------------------------------

Result<std::string> readFileBytes(const std::filesystem::path& path, std::uint64_t maxBytes) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) {
    return fail(Errc::kNotFound, "no such file; check the name and the folder", path.string());
  }
  if (std::filesystem::is_directory(status)) {
    return fail(Errc::kInvalidArgument, "this is a folder, not a file", path.string());
  }
  struct FileCloser {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  std::unique_ptr<std::FILE, FileCloser> file(std::fopen(path.c_str(), "rb"));
  if (!file) {
    const int err = errno;
    return fail(err == EACCES ? Errc::kPermissionDenied : Errc::kIo, systemErrorText("cannot open the file", err),
                path.string());
  }
  std::string bytes;
  // Read in chunks rather than trusting the size reported before reading (pipes, growing files).
  constexpr std::size_t kChunk = std::size_t{1} << 20;
  const auto size = std::filesystem::file_size(path, ec);
  if (!ec && size > maxBytes) {
    return fail(Errc::kResourceExhausted,
                fmt::format("the file has {} bytes, more than the limit of {} bytes", size, maxBytes), path.string());
  }
  if (!ec) bytes.reserve(static_cast<std::size_t>(size));
  for (;;) {
    const std::size_t old = bytes.size();
    if (old >= maxBytes && old > 0) {
      return fail(Errc::kResourceExhausted, fmt::format("the file is larger than the limit of {} bytes", maxBytes),
                  path.string());
    }
    bytes.resize(old + kChunk);
    const std::size_t got = std::fread(bytes.data() + old, 1, kChunk, file.get());
    bytes.resize(old + got);
    if (got < kChunk) break;
  }
  if (std::ferror(file.get())) {
    return fail(Errc::kIo, "reading the file failed", path.string());
  }
  if (bytes.size() > maxBytes) {
    return fail(Errc::kResourceExhausted, fmt::format("the file is larger than the limit of {} bytes", maxBytes),
                path.string());
  }
  return bytes;
}

namespace {

void appendUtf8(std::string& out, std::uint32_t cp) {
  if (cp < 0x80) {
    out.push_back(static_cast<char>(cp));
  } else if (cp < 0x800) {
    out.push_back(static_cast<char>(0xC0 | (cp >> 6)));
    out.push_back(static_cast<char>(0x80 | (cp & 0x3F)));
  } else if (cp < 0x10000) {
    out.push_back(static_cast<char>(0xE0 | (cp >> 12)));
    out.push_back(static_cast<char>(0x80 | ((cp >> 6) & 0x3F)));
    out.push_back(static_cast<char>(0x80 | (cp & 0x3F)));
  } else {
    out.push_back(static_cast<char>(0xF0 | (cp >> 18)));
    out.push_back(static_cast<char>(0x80 | ((cp >> 12) & 0x3F)));
    out.push_back(static_cast<char>(0x80 | ((cp >> 6) & 0x3F)));
    out.push_back(static_cast<char>(0x80 | (cp & 0x3F)));
  }
}

/// Decodes UTF-16 (big- or little-endian) to UTF-8; unpaired surrogates become U+FFFD.
std::string decodeUtf16(std::string_view bytes, bool bigEndian) {
  std::string out;
  out.reserve(bytes.size() / 2);
  const auto unit = [&](std::size_t i) -> std::uint32_t {
    const auto a = static_cast<unsigned char>(bytes[i]);
    const auto b = static_cast<unsigned char>(bytes[i + 1]);
    return bigEndian ? (std::uint32_t{a} << 8 | b) : (std::uint32_t{b} << 8 | a);
  };
  std::size_t i = 0;
  while (i + 1 < bytes.size()) {
    std::uint32_t cp = unit(i);
    i += 2;
    if (cp >= 0xD800 && cp <= 0xDBFF) {
      if (i + 1 < bytes.size()) {
        const std::uint32_t low = unit(i);
        if (low >= 0xDC00 && low <= 0xDFFF) {
          cp = 0x10000 + ((cp - 0xD800) << 10) + (low - 0xDC00);
          i += 2;
        } else {
          cp = 0xFFFD;
        }
      } else {
        cp = 0xFFFD;
      }
    } else if (cp >= 0xDC00 && cp <= 0xDFFF) {
      cp = 0xFFFD;
    }
    appendUtf8(out, cp);
  }
  return out;
}

}  // namespace

Result<std::string> decodeText(std::string bytes, Diagnostics& diagnostics) {
  const auto byte = [&](std::size_t i) { return static_cast<unsigned char>(bytes[i]); };
  if (bytes.size() >= 3 && byte(0) == 0xEF && byte(1) == 0xBB && byte(2) == 0xBF) {
    bytes.erase(0, 3);
  }
  std::optional<bool> utf16BigEndian;
  if (bytes.size() >= 2 && byte(0) == 0xFE && byte(1) == 0xFF) {
    utf16BigEndian = true;
  } else if (bytes.size() >= 2 && byte(0) == 0xFF && byte(1) == 0xFE) {
    utf16BigEndian = false;
  } else if (bytes.size() >= 4 && bytes.size() % 2 == 0) {
    // No BOM: ASCII text in UTF-16 has a zero in every other byte.
    if (byte(0) == 0 && byte(1) != 0 && byte(2) == 0 && byte(3) != 0) utf16BigEndian = true;
    if (byte(0) != 0 && byte(1) == 0 && byte(2) != 0 && byte(3) == 0) utf16BigEndian = false;
  }
  if (utf16BigEndian) {
    const bool hasBom = (byte(0) == 0xFE && byte(1) == 0xFF) || (byte(0) == 0xFF && byte(1) == 0xFE);
    std::string text = decodeUtf16(std::string_view(bytes).substr(hasBom ? 2 : 0), *utf16BigEndian);
    diagnostics.warn(0, 0,
                     fmt::format("the file is UTF-16 ({}); it was decoded, but save it as UTF-8 for other tools",
                                 *utf16BigEndian ? "big-endian" : "little-endian"));
    bytes = std::move(text);
  }
  if (const std::size_t offset = bytes.find('\0'); offset != std::string::npos) {
    const auto line =
        static_cast<std::uint32_t>(std::count(bytes.begin(), bytes.begin() + static_cast<long>(offset), '\n') + 1);
    const std::size_t lineStart = bytes.rfind('\n', offset == 0 ? 0 : offset - 1);
    const auto column =
        static_cast<std::uint32_t>(offset - (lineStart == std::string::npos || offset == 0 ? 0 : lineStart + 1) + 1);
    return parseError(diagnostics.where(line, column),
                      "this is not a text file (it has a zero byte here); check that the right file was named");
  }
  return bytes;
}

// ---- Numbers ----------------------------------------------------------------------------------

bool scanFloat(std::string_view text, float& value, std::size_t& used) {
  std::size_t start = 0;
  if (!text.empty() && text[0] == '+') {
    // from_chars takes no '+'; a second sign after it is no number.
    if (text.size() < 2 || text[1] == '-' || text[1] == '+') return false;
    start = 1;
  }
  const char* first = text.data() + start;
  const char* last = text.data() + text.size();
  auto [ptr, ec] = std::from_chars(first, last, value, std::chars_format::general);
  if (ec == std::errc::result_out_of_range) {
    // Denormal-small values come back as out of range in libstdc++: they are zero for us.
    double wide = 0;
    auto [ptr2, ec2] = std::from_chars(first, last, wide, std::chars_format::general);
    if (ec2 == std::errc() && std::fabs(wide) < 1.0) {
      value = 0.0f;
      used = static_cast<std::size_t>(ptr2 - text.data());
      return true;
    }
    return false;
  }
  if (ec != std::errc()) return false;
  used = static_cast<std::size_t>(ptr - text.data());
  return true;
}

bool parseFloat(std::string_view token, float& value) {
  std::size_t used = 0;
  return scanFloat(token, value, used) && used == token.size();
}

bool parseInt(std::string_view token, std::int64_t& value) {
  std::size_t start = token.size() > 1 && token[0] == '+' && token[1] != '-' ? 1 : 0;
  const char* first = token.data() + start;
  const char* last = token.data() + token.size();
  auto [ptr, ec] = std::from_chars(first, last, value);
  return ec == std::errc() && ptr == last && first != last;
}

// ---- Strings ----------------------------------------------------------------------------------

std::string_view trim(std::string_view text) {
  while (!text.empty() && (isBlank(text.front()) || text.front() == '\r')) text.remove_prefix(1);
  while (!text.empty() && (isBlank(text.back()) || text.back() == '\r')) text.remove_suffix(1);
  return text;
}

std::vector<std::string_view> splitBlanks(std::string_view text) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < text.size()) {
    while (i < text.size() && (isBlank(text[i]) || text[i] == '\r')) ++i;
    const std::size_t start = i;
    while (i < text.size() && !isBlank(text[i]) && text[i] != '\r') ++i;
    if (i > start) out.push_back(text.substr(start, i - start));
  }
  return out;
}

std::string normaliseName(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (std::string_view token : splitBlanks(text)) {
    if (!out.empty()) out.push_back(' ');
    out.append(token);
  }
  return out;
}

std::string lowerAscii(std::string_view text) {
  std::string out(text);
  for (char& c : out) {
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  }
  return out;
}

bool splitStatementItems(std::string_view line, std::vector<StatementItem>& items, std::size_t& errorAt) {
  items.clear();
  std::size_t i = 0;
  const auto blank = [&](std::size_t k) { return isBlank(line[k]) || line[k] == '\r'; };
  while (i < line.size()) {
    while (i < line.size() && blank(i)) ++i;
    if (i >= line.size()) break;
    StatementItem item;
    item.offset = i;
    const std::size_t start = i;
    while (i < line.size() && !blank(i) && line[i] != '[') ++i;
    item.name = line.substr(start, i - start);
    // A '[' may follow after blanks ("bgcolor [0,0,0]").
    std::size_t j = i;
    while (j < line.size() && blank(j)) ++j;
    if (j < line.size() && line[j] == '[') {
      const std::size_t close = line.find(']', j + 1);
      if (close == std::string_view::npos) {
        errorAt = j;
        return false;
      }
      item.bracketed = true;
      item.argsOffset = j + 1;
      std::size_t k = j + 1;
      while (k < close) {
        while (k < close && (blank(k) || line[k] == ',')) ++k;
        const std::size_t argStart = k;
        while (k < close && !blank(k) && line[k] != ',') ++k;
        if (k > argStart) item.args.push_back(line.substr(argStart, k - argStart));
      }
      i = close + 1;
    }
    items.push_back(item);
  }
  return true;
}

bool isObjDataStatement(std::string_view line) {
  std::size_t i = 0;
  while (i < line.size() && isBlank(line[i])) ++i;
  std::size_t end = i;
  while (end < line.size() && !isBlank(line[end])) ++end;
  const std::string_view key = line.substr(i, end - i);
  static constexpr std::string_view kData[] = {"v", "vt",   "vn",    "vc",   "vp",   "f",    "fo",  "l",
                                               "p", "curv", "curv2", "surf", "parm", "trim", "hole"};
  for (std::string_view k : kData) {
    if (k == key) return true;
  }
  return false;
}

// ---- Lines ------------------------------------------------------------------------------------

std::optional<std::string_view> LineReader::next() {
  if (pos_ >= text_.size()) return std::nullopt;
  number_ = nextNumber_;
  joined_.clear();
  bool continued = false;
  for (;;) {
    const std::size_t start = pos_;
    std::size_t end = start;
    while (end < text_.size() && text_[end] != '\n' && text_[end] != '\r') ++end;
    std::string_view line = text_.substr(start, end - start);
    // Step over the line end: "\r\n", "\n" or a lone "\r".
    pos_ = end;
    if (pos_ < text_.size()) {
      if (text_[pos_] == '\r' && pos_ + 1 < text_.size() && text_[pos_ + 1] == '\n') {
        pos_ += 2;
      } else {
        pos_ += 1;
      }
    }
    ++nextNumber_;
    std::string_view content = line;
    while (!content.empty() && isBlank(content.back())) content.remove_suffix(1);
    const bool continues = continuation_ == Continuation::kObjData && !content.empty() && content.back() == '\\' &&
                           pos_ < text_.size() && isObjDataStatement(continued ? std::string_view(joined_) : line);
    if (!continues && !continued) return line;
    if (continues) content.remove_suffix(1);
    joined_.append(continues ? content : line);
    if (continues) {
      joined_.push_back(' ');
      continued = true;
      continue;
    }
    return std::string_view(joined_);
  }
}

// ---- Paths ------------------------------------------------------------------------------------

namespace {

bool isRegularFile(const std::filesystem::path& p) {
  std::error_code ec;
  return std::filesystem::is_regular_file(p, ec);
}

std::optional<std::filesystem::path> caseInsensitiveMatch(const std::filesystem::path& folder,
                                                          const std::string& name) {
  std::error_code ec;
  const std::string wanted = lowerAscii(name);
  std::filesystem::directory_iterator it(folder, ec);
  if (ec) return std::nullopt;
  std::size_t looked = 0;
  for (const auto& entry : it) {
    if (++looked > 10000) break;  // a huge folder is not worth scanning for a guess
    if (lowerAscii(entry.path().filename().string()) == wanted && isRegularFile(entry.path())) return entry.path();
  }
  return std::nullopt;
}

}  // namespace

ResolvedPath resolveReferencedFile(std::string_view name, const std::filesystem::path& base,
                                   const std::vector<std::filesystem::path>& searchPaths) {
  std::string cleaned(trim(name));
  if (cleaned.size() >= 2 && cleaned.front() == '"' && cleaned.back() == '"') {
    cleaned = cleaned.substr(1, cleaned.size() - 2);
  }
  std::replace(cleaned.begin(), cleaned.end(), '\\', '/');
  // "a//b" is "a/b" on Linux; lexically_normal() leaves a name of slashes alone ("//"), so a
  // written-back reference would read as a different path.
  cleaned.erase(std::unique(cleaned.begin(), cleaned.end(), [](char a, char b) { return a == '/' && b == '/'; }),
                cleaned.end());
  // "C:/textures/wood.jpg" from another machine: only the last component can mean anything here.
  const bool windowsAbsolute = cleaned.size() >= 3 && cleaned[1] == ':' && cleaned[2] == '/' &&
                               ((cleaned[0] >= 'A' && cleaned[0] <= 'Z') || (cleaned[0] >= 'a' && cleaned[0] <= 'z'));
  const std::filesystem::path named(windowsAbsolute ? cleaned.substr(2) : cleaned);
  const std::filesystem::path direct = (named.is_absolute() ? named : base / named).lexically_normal();
  if (!windowsAbsolute && isRegularFile(direct)) return {direct, true};
  const std::filesystem::path leaf = named.filename();
  if (!leaf.empty()) {
    if (isRegularFile(base / leaf)) return {(base / leaf).lexically_normal(), true};
    for (const auto& folder : searchPaths) {
      if (!named.is_absolute() && isRegularFile(folder / named)) return {(folder / named).lexically_normal(), true};
      if (isRegularFile(folder / leaf)) return {(folder / leaf).lexically_normal(), true};
    }
    // Names written on Windows often differ in case from the files: look in the named folder,
    // then beside the referring file.
    const std::filesystem::path namedFolder = direct.parent_path();
    if (auto match = caseInsensitiveMatch(namedFolder, leaf.string())) return {match->lexically_normal(), true};
    if (namedFolder != base.lexically_normal()) {
      if (auto match = caseInsensitiveMatch(base, leaf.string())) return {match->lexically_normal(), true};
    }
  }
  return {direct, false};
}

std::string relativeReference(const std::filesystem::path& target, const std::filesystem::path& folder) {
  if (target.empty()) return {};
  std::error_code ec;
  const std::filesystem::path absoluteTarget = std::filesystem::absolute(target, ec).lexically_normal();
  const std::filesystem::path absoluteFolder = std::filesystem::absolute(folder, ec).lexically_normal();
  std::filesystem::path rel = absoluteTarget.lexically_relative(absoluteFolder);
  if (rel.empty()) rel = absoluteTarget;
  return rel.generic_string();
}

}  // namespace basalt::formats
