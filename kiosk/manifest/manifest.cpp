// The show manifest reader: show.toml through toml++ (a maintained TOML 1.0 parser, used here
// and nowhere else, with exceptions off), validated section by section. Every problem becomes a
// Diagnostic with the line it is on; reading goes on after an error so that one run of
// `basalt check` reports them all.

#include "kiosk/manifest/manifest.h"

#define TOML_EXCEPTIONS 0  // NOLINT(bugprone-macro-parentheses): toml++ configuration
#include <toml++/toml.h>

#include <arpa/inet.h>
#include <netinet/in.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <tuple>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <fmt/std.h>

#include "devices/midi/midi_decoder.h"
#include "kiosk/manifest/time_zone.h"
#include "runtime/frame.h"
#include "sim/hid_recording.h"
#include "sim/midi_file.h"

namespace basalt::kiosk {

// ---- Diagnostics ----------------------------------------------------------------------------

std::string Diagnostic::format() const {
  std::string where = file.string();
  if (line > 0) where += fmt::format(":{}", line);
  switch (severity) {
    case Severity::kError: return fmt::format("{}: {}", where, message);
    case Severity::kWarning: return fmt::format("{}: warning: {}", where, message);
    case Severity::kNote: return fmt::format("{}: note: {}", where, message);
  }
  return where + ": " + message;
}

void Diagnostics::error(const std::filesystem::path& file, int line, std::string message) {
  items_.push_back({Severity::kError, file, line, std::move(message)});
}
void Diagnostics::warning(const std::filesystem::path& file, int line, std::string message) {
  items_.push_back({Severity::kWarning, file, line, std::move(message)});
}
void Diagnostics::note(const std::filesystem::path& file, int line, std::string message) {
  items_.push_back({Severity::kNote, file, line, std::move(message)});
}

std::size_t Diagnostics::errorCount() const {
  return static_cast<std::size_t>(
      std::count_if(items_.begin(), items_.end(), [](const Diagnostic& d) { return d.severity == Severity::kError; }));
}

std::string Diagnostics::format() const {
  std::string out;
  for (const Diagnostic& d : items_) out += d.format() + "\n";
  return out;
}

// ---- Names ----------------------------------------------------------------------------------

std::string_view outputKindName(OutputKind kind) {
  switch (kind) {
    case OutputKind::kAuto: return "auto";
    case OutputKind::kHeadless: return "headless";
    case OutputKind::kKms: return "kms";
    case OutputKind::kWindow: return "window";
  }
  return "?";
}

std::string_view entryKindName(EntryKind kind) {
  switch (kind) {
    case EntryKind::kBuiltinDefault: return "the default show";
    case EntryKind::kBuiltinBlack: return "black";
    case EntryKind::kScript: return "script";
    case EntryKind::kScene: return "scene";
    case EntryKind::kModel: return "model";
    case EntryKind::kMovie: return "movie";
  }
  return "?";
}

std::string_view mediaKindName(MediaKind kind) {
  switch (kind) {
    case MediaKind::kMovie: return "movie";
    case MediaKind::kImage: return "image";
    case MediaKind::kCamera: return "camera";
  }
  return "?";
}

std::string_view deviceKindName(DeviceKind kind) {
  switch (kind) {
    case DeviceKind::kDialBox: return "dial_box";
    case DeviceKind::kCamera: return "camera";
    case DeviceKind::kTracker: return "tracker";
  }
  return "device";
}

std::string_view deviceBackendName(DeviceBackend backend) {
  switch (backend) {
    case DeviceBackend::kHid: return "hid";
    case DeviceBackend::kV4l2: return "v4l2";
    case DeviceBackend::kLibcamera: return "libcamera";
    case DeviceBackend::kReplay: return "replay";
    case DeviceBackend::kSynthetic: return "synthetic";
    case DeviceBackend::kSerial: return "serial";
    case DeviceBackend::kMidi: return "midi";
    case DeviceBackend::kOsc: return "osc";
  }
  return "?";
}

std::string_view outsideHoursName(OutsideHours outside) {
  switch (outside) {
    case OutsideHours::kStandby: return "standby";
    case OutsideHours::kBlack: return "black";
    case OutsideHours::kDisplayOff: return "display_off";
  }
  return "?";
}

namespace {
bool loopbackHost(std::string_view host) { return host == "localhost" || host == "::1" || host.starts_with("127."); }
}  // namespace

bool StatusSpec::loopbackOnly() const { return loopbackHost(host); }

bool OscSpec::loopbackOnly() const { return loopbackHost(host); }

Result<std::string> readLockKey(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) return failf(Errc::kNotFound, "cannot read the frame-lock key file {}", file.string());
  std::ostringstream text;
  text << in.rdbuf();
  std::string key = text.str();
  const auto first = key.find_first_not_of(" \t\r\n");
  const auto last = key.find_last_not_of(" \t\r\n");
  key = first == std::string::npos ? std::string() : key.substr(first, last - first + 1);
  if (key.size() < kLockKeyMinChars) {
    return failf(Errc::kInvalidArgument,
                 "the frame-lock key file {} holds {} characters, fewer than {}; make it with: openssl rand -hex 32 "
                 "> {}",
                 file.string(), key.size(), kLockKeyMinChars, file.string());
  }
  return key;
}

bool isAddress(std::string_view text) {
  const std::string s(text);
  in_addr v4{};
  in6_addr v6{};
  return ::inet_pton(AF_INET, s.c_str(), &v4) == 1 || ::inet_pton(AF_INET6, s.c_str(), &v6) == 1;
}

bool LockSpec::loopbackOnly() const { return loopbackHost(role == LockRole::kFollower ? leader : listen); }

Manifest Manifest::builtinDefault() {
  Manifest m;
  m.name = "default show";
  m.entry = {EntryKind::kBuiltinDefault, "default", {}, 0, EntryView::kDefault};
  return m;
}

const DeviceSpec* Manifest::findDevice(std::string_view deviceName) const {
  for (const DeviceSpec& d : devices) {
    if (d.name == deviceName) return &d;
  }
  return nullptr;
}

const MediaSpec* Manifest::findMedia(std::string_view mediaName) const {
  for (const MediaSpec& m : media) {
    if (m.name == mediaName) return &m;
  }
  return nullptr;
}

// ---- Values ---------------------------------------------------------------------------------

namespace {

bool parseUnsigned(std::string_view text, int& out) {
  if (text.empty()) return false;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), out);
  return ec == std::errc{} && end == text.data() + text.size() && out >= 0;
}

std::string lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

}  // namespace

Result<Nanos> parseDuration(std::string_view text) {
  const auto bad = [&] {
    return fail(Errc::kInvalidArgument,
                fmt::format("'{}' is not a duration; write it like 90s, 5m, 1h30m, 250ms or 2d", text));
  };
  if (text.empty()) return bad();
  double total = 0;
  std::string_view rest = text;
  while (!rest.empty()) {
    double value = 0;
    const auto [end, ec] = std::from_chars(rest.data(), rest.data() + rest.size(), value);
    if (ec != std::errc{} || !std::isfinite(value) || value < 0) return bad();
    rest.remove_prefix(static_cast<std::size_t>(end - rest.data()));
    double unit = 1;
    if (rest.starts_with("ms")) {
      unit = 1e-3;
      rest.remove_prefix(2);
    } else if (rest.starts_with("s")) {
      rest.remove_prefix(1);
    } else if (rest.starts_with("m")) {
      unit = 60;
      rest.remove_prefix(1);
    } else if (rest.starts_with("h")) {
      unit = 3600;
      rest.remove_prefix(1);
    } else if (rest.starts_with("d")) {
      unit = 86400;
      rest.remove_prefix(1);
    } else if (!rest.empty() || text.find_first_not_of("0123456789.") != std::string_view::npos) {
      return bad();
    }
    total += value * unit;
  }
  if (total > 365.0 * 86400) return fail(Errc::kInvalidArgument, fmt::format("duration '{}' is over a year", text));
  return fromSeconds(total);
}

Result<TimeRange> parseTimeRange(std::string_view text) {
  const auto bad = [&] {
    return fail(Errc::kInvalidArgument,
                fmt::format("'{}' is not a range of hours; write it like 09:00-17:30 (24-hour clock)", text));
  };
  const auto dash = text.find('-');
  if (dash == std::string_view::npos) return bad();
  const auto clock = [](std::string_view t, int& minutes) {
    while (!t.empty() && t.front() == ' ') t.remove_prefix(1);
    while (!t.empty() && t.back() == ' ') t.remove_suffix(1);
    const auto colon = t.find(':');
    int h = 0;
    int m = 0;
    if (colon == std::string_view::npos || !parseUnsigned(t.substr(0, colon), h) ||
        !parseUnsigned(t.substr(colon + 1), m) || t.size() - colon - 1 != 2 || h > 24 || m > 59 ||
        (h == 24 && m != 0)) {
      return false;
    }
    minutes = h * 60 + m;
    return true;
  };
  TimeRange r;
  if (!clock(text.substr(0, dash), r.begin) || !clock(text.substr(dash + 1), r.end)) return bad();
  if (r.begin == 1440) return bad();
  if (r.end <= r.begin) {
    return fail(Errc::kInvalidArgument,
                fmt::format("'{}' ends before it begins; a range cannot cross midnight: split it into "
                            "two days (e.g. 22:00-24:00 and 00:00-02:00)",
                            text));
  }
  return r;
}

Result<Date> parseDate(std::string_view text) {
  int y = 0;
  int m = 0;
  int d = 0;
  const bool shape = text.size() == 10 && text[4] == '-' && text[7] == '-' && parseUnsigned(text.substr(0, 4), y) &&
                     parseUnsigned(text.substr(5, 2), m) && parseUnsigned(text.substr(8, 2), d);
  if (!shape || m < 1 || m > 12 || d < 1) {
    return fail(Errc::kInvalidArgument, fmt::format("'{}' is not a date; write it like 2026-12-24", text));
  }
  int cy = 0;
  unsigned cm = 0;
  unsigned cd = 0;
  civilFromDays(daysFromCivil(y, static_cast<unsigned>(m), static_cast<unsigned>(d)), cy, cm, cd);
  if (cy != y || cm != static_cast<unsigned>(m) || cd != static_cast<unsigned>(d)) {
    return fail(Errc::kInvalidArgument, fmt::format("{} is not a day of the calendar", text));
  }
  return Date{y, static_cast<unsigned>(m), static_cast<unsigned>(d)};
}

Result<ModeRequest> parseMode(std::string_view text) {
  const auto bad = [&] {
    return fail(Errc::kInvalidArgument,
                fmt::format("'{}' is not a mode; write WIDTHxHEIGHT or WIDTHxHEIGHT@HZ, e.g. 1920x1080@60", text));
  };
  ModeRequest mode;
  std::string_view size = text;
  if (const auto at = text.find('@'); at != std::string_view::npos) {
    size = text.substr(0, at);
    const std::string_view hz = text.substr(at + 1);
    const auto [end, ec] = std::from_chars(hz.data(), hz.data() + hz.size(), mode.refresh);
    if (ec != std::errc{} || end != hz.data() + hz.size() || !(mode.refresh > 0 && mode.refresh < 1000)) return bad();
  }
  const auto x = size.find_first_of("xX");
  int w = 0;
  int h = 0;
  if (x == std::string_view::npos || !parseUnsigned(size.substr(0, x), w) || !parseUnsigned(size.substr(x + 1), h) ||
      w < 1 || h < 1 || w > 16384 || h > 16384) {
    return bad();
  }
  mode.width = static_cast<std::uint32_t>(w);
  mode.height = static_cast<std::uint32_t>(h);
  return mode;
}

Result<std::filesystem::path> confinePath(const std::filesystem::path& folder, std::string_view text) {
  if (text.empty()) return fail(Errc::kInvalidArgument, "an empty path");
  std::error_code ec;
  const std::filesystem::path root = std::filesystem::weakly_canonical(folder, ec);
  if (ec) {
    return fail(Errc::kNotFound, fmt::format("the show folder {} cannot be read: {}", folder.string(), ec.message()));
  }
  const std::filesystem::path given(text);
  const std::filesystem::path joined = given.is_absolute() ? given : root / given;
  std::filesystem::path resolved = std::filesystem::weakly_canonical(joined, ec);
  if (ec) return fail(Errc::kNotFound, fmt::format("'{}' cannot be resolved: {}", text, ec.message()));
  const auto [r, p] = std::mismatch(root.begin(), root.end(), resolved.begin(), resolved.end());
  if (r != root.end()) {
    return fail(Errc::kPermissionDenied,
                fmt::format("'{}' leaves the show folder {}; put it inside the folder (symbolic links are "
                            "followed)",
                            text, root.string()));
  }
  return resolved;
}

// ---- The reader -----------------------------------------------------------------------------

namespace {

/// A place in a manifest that toml++ must not be given, with what is wrong there.
struct TextProblem {
  int line = 0;
  int column = 0;  // in characters, 1-based
  std::string what;
};

/// Checks that `text` is UTF-8 (RFC 3629: no overlong forms, no surrogates, nothing above
/// U+10FFFF, no sequence cut short). Returns the first bad byte's place.
std::optional<TextProblem> invalidUtf8(std::string_view text) {
  int line = 1;
  int column = 1;
  std::size_t i = 0;
  while (i < text.size()) {
    const auto b = static_cast<unsigned char>(text[i]);
    if (b < 0x80) {
      if (b == '\n') {
        ++line;
        column = 1;
      } else {
        ++column;
      }
      ++i;
      continue;
    }
    // The sequence's length and the range its second byte must fall in (the narrower ranges
    // rule out overlong forms, surrogates and code points above U+10FFFF).
    std::size_t length = 0;
    unsigned char low = 0x80;
    unsigned char high = 0xBF;
    if (b >= 0xC2 && b <= 0xDF) {
      length = 2;
    } else if (b >= 0xE0 && b <= 0xEF) {
      length = 3;
      if (b == 0xE0) low = 0xA0;
      if (b == 0xED) high = 0x9F;
    } else if (b >= 0xF0 && b <= 0xF4) {
      length = 4;
      if (b == 0xF0) low = 0x90;
      if (b == 0xF4) high = 0x8F;
    } else {
      return TextProblem{line, column,
                         fmt::format("byte 0x{:02X} cannot start a UTF-8 character{}", b,
                                     b >= 0x80 && b <= 0xBF ? " (a continuation byte without a lead byte)" : "")};
    }
    for (std::size_t k = 1; k < length; ++k) {
      if (i + k >= text.size()) {
        return TextProblem{
            line, column,
            fmt::format("the file ends inside a UTF-8 character (byte 0x{:02X} needs {} more)", b, length - k)};
      }
      const auto c = static_cast<unsigned char>(text[i + k]);
      const unsigned char lo = k == 1 ? low : 0x80;
      const unsigned char hi = k == 1 ? high : 0xBF;
      if (c < lo || c > hi) {
        return TextProblem{line, column,
                           fmt::format("byte 0x{:02X} after 0x{:02X} is not part of a valid UTF-8 character", c, b)};
      }
    }
    i += length;
    ++column;
  }
  return std::nullopt;
}

/// Where a manifest has a non-ASCII character that TOML does not allow, or that the TOML reader
/// Basalt builds with (toml++ 3.3) cannot look at safely. toml++ 3.3's test for non-ASCII
/// whitespace reaches `unreachable` (undefined behaviour) for U+00A1..U+0499 (Latin-1, Greek,
/// Cyrillic), U+2C5E..U+3057 and U+FB26..U+FEFE, and toml++ applies that test to every
/// character it reads outside a string or comment: while skipping whitespace, and while reading
/// a bare key, number, date or boolean up to its end. So such characters may reach toml++ only
/// where it reads them as the content of a string or a comment:
/// - a quote starts a string only where TOML allows one (a key at the start of a line, after
///   `[`, `{`, `.` in a key, `,` or `=`); elsewhere (`8'...`, `'a''b'`) toml++ reads it as part
///   of a token or refuses it, and what follows is outside any string;
/// - a value that is not a string, array or inline table (a number, date, boolean, inf, nan, or
///   a bad token) is read by toml++ up to a value terminator (whitespace, `,`, `]`, `}`, `#`),
///   so a quote, `=`, `[` or `{` inside it (`8='...'`) opens nothing;
/// Also, with a `what` of its own, two places where toml++ 3.3 reads on without checking and
/// assumes (`__builtin_assume` under clang, undefined behaviour when false) what it expects: a
/// table header whose `[` is not followed by a key, a quote or `]` (`[#`, `[=`, `[[[`, `[` at the
/// end of a line), and a `}` inside an array (toml++ reads it as the start of a value).
/// - inside a multi-line basic string, not right after a backslash, nor first after a
///   line-ending backslash (toml++ tests those for whitespace).
std::optional<TextProblem> misplacedNonAscii(std::string_view text) {
  enum class In { kCode, kComment, kBasic, kLiteral, kMultiBasic, kMultiLiteral };
  enum class Open { kHeader, kArray, kInlineTable };
  In in = In::kCode;
  int line = 1;
  std::size_t lineStart = 0;
  std::vector<Open> open;  // brackets and braces open in code, innermost last
  bool keyContext = true;  // a key may come next (rather than a value)
  char previous = '\n';    // the last character of code that is not a space, tab or comment
  bool bareValue = false;  // inside a value toml++ reads up to a value terminator
  const auto spot = [&](std::size_t at) {
    int column = 1;
    for (std::size_t i = lineStart; i < at; ++i) column += (static_cast<unsigned char>(text[i]) & 0xC0) != 0x80;
    return TextProblem{line, column, "a non-ASCII character outside quotes or a comment"};
  };
  const auto quotes = [&](std::size_t at, char q) {
    std::size_t n = 0;
    while (at + n < text.size() && text[at + n] == q) ++n;
    return n;
  };
  const auto stringMayStart = [&] {
    switch (previous) {
      case '=':
      case ',':
      case '{':
      case '[': return true;        // '[': a table header's key or an array's first value
      case '.': return keyContext;  // a dotted key; after a digit, a number goes on
      case '\n': return true;       // a key at the start of a line
      default: return false;
    }
  };
  std::size_t i = text.starts_with("\xEF\xBB\xBF") ? 3 : 0;
  while (i < text.size()) {
    const char c = text[i];
    const bool high = (static_cast<unsigned char>(c) & 0x80) != 0;
    if (c == '\n') {
      ++line;
      lineStart = i + 1;
      bareValue = false;
      if (in != In::kMultiBasic && in != In::kMultiLiteral) {
        in = In::kCode;
        // A new line at the top level starts a key; inside an array, values go on.
        if (open.empty() || open.back() != Open::kArray) {
          open.clear();
          keyContext = true;
          previous = '\n';
        }
      }
      ++i;
      continue;
    }
    switch (in) {
      case In::kCode:
        if (high) return spot(i);
        if (c == ' ' || c == '\t' || c == '\r') {
          bareValue = false;
          break;
        }
        if (bareValue && c != ',' && c != ']' && c != '}' && c != '#') {
          previous = c;  // still the bare value
          break;
        }
        bareValue = false;
        if (c == '#') {
          in = In::kComment;
          break;
        }
        if (c == '"' || c == '\'') {
          if (!stringMayStart()) {
            previous = c;             // part of a bad token: what follows is code
            bareValue = !keyContext;  // and a bad value goes on up to a value terminator
            break;
          }
          const bool multi = quotes(i, c) >= 3;
          in = c == '"' ? (multi ? In::kMultiBasic : In::kBasic) : (multi ? In::kMultiLiteral : In::kLiteral);
          previous = c;
          i += multi ? 3 : 1;
          continue;
        }
        if (c == '[') {
          // `[` at the start of a line opens a table header, and `[[` an array-of-tables header.
          const bool header = keyContext && (open.empty() || (open.back() == Open::kHeader && previous == '['));
          if (header) {
            std::size_t next = i + 1;
            while (next < text.size() && (text[next] == ' ' || text[next] == '\t')) ++next;
            const char k = next < text.size() ? text[next] : ']';
            const bool keyStarts = std::isalnum(static_cast<unsigned char>(k)) != 0 || k == '_' || k == '-' ||
                                   k == '"' || k == '\'' || k == ']' || (k == '[' && next == i + 1 && open.empty());
            if (!keyStarts) {
              TextProblem problem = spot(next);
              problem.what = "a table header without a key after its '['";
              return problem;
            }
          }
          open.push_back(header ? Open::kHeader : Open::kArray);
          keyContext = open.back() == Open::kHeader;
        } else if (c == '{') {
          open.push_back(Open::kInlineTable);
          keyContext = true;
        } else if (c == ']' || c == '}') {
          if (c == '}' && !open.empty() && open.back() == Open::kArray) {
            TextProblem problem = spot(i);
            problem.what = "an array closed by '}'";
            return problem;
          }
          if (!open.empty()) open.pop_back();
          keyContext = false;
        } else if (c == '=') {
          keyContext = false;
        } else if (c == ',') {
          keyContext = !open.empty() && open.back() == Open::kInlineTable;
        } else if (!keyContext) {
          bareValue = true;  // a number, date, boolean, inf or nan starts
        }
        previous = c;
        break;
      case In::kComment: break;
      case In::kBasic:
        if (c == '\\') {
          i += 2;
          continue;
        }
        if (c == '"') in = In::kCode;
        break;
      case In::kLiteral:
        if (c == '\'') in = In::kCode;
        break;
      case In::kMultiBasic:
      case In::kMultiLiteral: {
        const char q = in == In::kMultiBasic ? '"' : '\'';
        if (in == In::kMultiBasic && c == '\\') {
          std::size_t next = i + 1;
          if (next < text.size() && (static_cast<unsigned char>(text[next]) & 0x80) != 0) return spot(next);
          if (next < text.size() &&
              (text[next] == ' ' || text[next] == '\t' || text[next] == '\r' || text[next] == '\n')) {
            while (next < text.size() &&
                   (text[next] == ' ' || text[next] == '\t' || text[next] == '\r' || text[next] == '\n')) {
              if (text[next] == '\n') {
                ++line;
                lineStart = next + 1;
              }
              ++next;
            }
            if (next < text.size() && (static_cast<unsigned char>(text[next]) & 0x80) != 0) return spot(next);
            i = next;
          } else {
            i = next + 1;
          }
          continue;
        }
        if (c == q) {
          const std::size_t n = quotes(i, q);
          if (n >= 3) in = In::kCode;  // up to two more quotes belong to the string
          i += n;
          continue;
        }
        break;
      }
    }
    ++i;
  }
  return std::nullopt;
}

// LAVA's dial table has a default action for dials 0 to 7.
constexpr std::uint16_t kLavaDials = 8;

const std::set<std::string, std::less<>> kScriptExtensions{".mdl"};
const std::set<std::string, std::less<>> kSceneExtensions{".sce"};
const std::set<std::string, std::less<>> kModelExtensions{".obj", ".off"};
const std::set<std::string, std::less<>> kMovieExtensions{".mkv",  ".mp4", ".mov", ".webm", ".avi", ".mpg",
                                                          ".mpeg", ".m1v", ".m2v", ".ogv",  ".ts",  ".m4v"};
const std::set<std::string, std::less<>> kImageExtensions{".png", ".jpg", ".jpeg", ".tif", ".tiff", ".exr", ".ppm",
                                                          ".pgm", ".pnm", ".tga",  ".bmp", ".hdr",  ".webp"};

std::string extensionOf(const std::filesystem::path& p) { return lower(p.extension().string()); }

std::string typeName(const toml::node& node) {
  switch (node.type()) {
    case toml::node_type::table: return "a table";
    case toml::node_type::array: return "an array";
    case toml::node_type::string: return "a string";
    case toml::node_type::integer: return "an integer";
    case toml::node_type::floating_point: return "a number";
    case toml::node_type::boolean: return "true or false";
    case toml::node_type::date: return "a date";
    case toml::node_type::time: return "a time";
    case toml::node_type::date_time: return "a date and time";
    case toml::node_type::none: return "nothing";
  }
  return "a value";
}

int lineOf(const toml::node& node) { return static_cast<int>(node.source().begin.line); }

/// Levenshtein distance, for "did you mean".
std::size_t editDistance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

std::string joinNames(std::initializer_list<std::string_view> names) {
  std::string out;
  std::size_t i = 0;
  for (const std::string_view n : names) {
    if (i > 0) out += i + 1 == names.size() ? " or " : ", ";
    out += n;
    ++i;
  }
  return out;
}

template <typename Enum>
struct NamedValue {
  std::string_view name;
  Enum value;
};

class Reader {
 public:
  Reader(const std::filesystem::path& file, Diagnostics& diagnostics, const ReadOptions& options)
      : diags_(diagnostics), options_(options) {
    std::error_code ec;
    file_ = std::filesystem::absolute(file, ec);
    if (ec) file_ = file;
    folder_ = file_.parent_path();
    shown_ = file;
  }

  std::optional<Manifest> read() {
    std::string text;
    if (!load(text)) return std::nullopt;
    return readText(text);
  }

  std::optional<Manifest> readText(std::string_view text) {
    const std::size_t errorsBefore = diags_.errorCount();
    if (text.size() > kMaxManifestBytes) {
      diags_.error(
          shown_, 0,
          fmt::format("the manifest is {} bytes; a show.toml is at most {} bytes", text.size(), kMaxManifestBytes));
      return std::nullopt;
    }
    // toml++ is given only valid UTF-8, and non-ASCII characters only where it reads them as
    // string or comment content (see misplacedNonAscii).
    if (const auto bad = invalidUtf8(text)) {
      diags_.error(shown_, bad->line,
                   fmt::format("not valid UTF-8 at column {}: {}; save the manifest as UTF-8", bad->column, bad->what));
      return std::nullopt;
    }
    if (const auto bad = misplacedNonAscii(text)) {
      if (!bad->what.starts_with("a non-ASCII")) {
        diags_.error(shown_, bad->line, fmt::format("not valid TOML: {} (column {})", bad->what, bad->column));
      } else {
        diags_.error(shown_, bad->line,
                     fmt::format("not valid TOML: a non-ASCII character at column {} outside quotes or a comment (or "
                                 "right after a backslash in a \"\"\" string); put text in quotes",
                                 bad->column));
      }
      return std::nullopt;
    }
    toml::parse_result parsed = toml::parse(text, file_.string());
    if (!parsed) {
      const toml::parse_error& e = parsed.error();
      diags_.error(shown_, static_cast<int>(e.source().begin.line),
                   fmt::format("not valid TOML: {} (column {})", e.description(), e.source().begin.column));
      return std::nullopt;
    }
    const toml::table& root = parsed.table();
    manifest_.file = file_;
    std::error_code ec;
    manifest_.folder = std::filesystem::weakly_canonical(folder_, ec);
    if (ec) manifest_.folder = folder_;
    manifest_.name = manifest_.folder.filename().string();
    manifest_.entry = {EntryKind::kBuiltinDefault, "default", {}, 0, EntryView::kDefault};

    checkKeys(root, "",
              {"show", "output", "views", "viewer", "media", "devices", "bindings", "textures", "kiosk", "status",
               "input", "lock", "osc"});
    if (const toml::table* t = table(root, "show", "")) readShow(*t);
    if (const toml::table* t = table(root, "output", "")) readOutput(*t);
    readViews(root);
    if (const toml::table* t = table(root, "devices", "")) readDevices(*t);
    if (const toml::table* t = table(root, "viewer", "")) readViewer(*t);
    if (const toml::table* t = table(root, "media", "")) readMedia(*t);
    readBindings(root);
    if (const toml::table* t = table(root, "textures", "")) readTextures(*t);
    checkMediaShown();
    if (const toml::table* t = table(root, "kiosk", "")) readKiosk(*t);
    if (const toml::table* t = table(root, "status", "")) readStatus(*t);
    if (const toml::table* t = table(root, "input", "")) readInput(*t);
    if (const toml::table* t = table(root, "lock", "")) readLock(*t);
    if (const toml::table* t = table(root, "osc", "")) readOsc(*t);
    for (const DeviceSpec& d : manifest_.devices) {
      if (d.kind == DeviceKind::kTracker && d.backend == DeviceBackend::kOsc && !manifest_.osc.enabled) {
        error(d.line, fmt::format("devices.{}: an osc tracker takes /tracker/{} messages from the show's OSC input; "
                                  "add an [osc] table (listen = \"127.0.0.1:9000\")",
                                  d.name, d.match.name.empty() ? d.name : d.match.name));
      }
    }

    // By line, keeping the order of problems found on the same line.
    std::vector<std::size_t> order(diagsOwn_.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [this](std::size_t a, std::size_t b) {
      return diagsOwn_[a].line != diagsOwn_[b].line ? diagsOwn_[a].line < diagsOwn_[b].line : a < b;
    });
    for (const std::size_t i : order) diags_.add(std::move(diagsOwn_[i]));
    for (Diagnostic& d : diagsReferenced_) diags_.add(std::move(d));
    if (diags_.errorCount() > errorsBefore) return std::nullopt;
    return std::move(manifest_);
  }

 private:
  // ---- reporting ----
  void error(int line, std::string message) {
    diagsOwn_.push_back({Severity::kError, shown_, line, std::move(message)});
  }
  void warning(int line, std::string message) {
    diagsOwn_.push_back({Severity::kWarning, shown_, line, std::move(message)});
  }
  void note(int line, std::string message) { diagsOwn_.push_back({Severity::kNote, shown_, line, std::move(message)}); }

  static std::string key(std::string_view path, std::string_view name) {
    return path.empty() ? std::string(name) : fmt::format("{}.{}", path, name);
  }

  bool load(std::string& text) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(file_, ec)) {
      diags_.error(shown_, 0, "no such manifest; give the path of a show.toml (see configs/ for examples)");
      return false;
    }
    const auto size = std::filesystem::file_size(file_, ec);
    if (ec || size > kMaxManifestBytes) {
      diags_.error(shown_, 0,
                   fmt::format("the manifest is {} bytes; a show.toml is at most {} bytes", size, kMaxManifestBytes));
      return false;
    }
    std::ifstream in(file_, std::ios::binary);
    std::ostringstream content;
    content << in.rdbuf();
    if (!in && !in.eof()) {
      diags_.error(shown_, 0, "cannot read the manifest; check its permissions");
      return false;
    }
    text = content.str();
    return true;
  }

  /// Reports keys of `t` not in `allowed`, suggesting the nearest allowed key.
  void checkKeys(const toml::table& t, std::string_view path, std::initializer_list<std::string_view> allowed) {
    for (auto&& [k, v] : t) {
      const std::string_view name = k.str();
      if (std::find(allowed.begin(), allowed.end(), name) != allowed.end()) continue;
      std::string_view best;
      std::size_t bestDistance = 3;
      for (const std::string_view a : allowed) {
        const std::size_t d = editDistance(name, a);
        if (d < bestDistance) {
          bestDistance = d;
          best = a;
        }
      }
      const int line = lineOf(v) > 0 ? lineOf(v) : static_cast<int>(k.source().begin.line);
      if (!best.empty()) {
        error(line, fmt::format("{}: unknown key; did you mean '{}'?", key(path, name), best));
      } else {
        error(line, fmt::format("{}: unknown key; {} takes {}", key(path, name), path.empty() ? "a manifest" : path,
                                joinNames(allowed)));
      }
    }
  }

  const toml::table* table(const toml::table& parent, std::string_view name, std::string_view path) {
    const toml::node* node = parent.get(name);
    if (!node) return nullptr;
    if (const toml::table* t = node->as_table()) return t;
    error(lineOf(*node),
          fmt::format("{}: must be a table ([{}]), not {}", key(path, name), key(path, name), typeName(*node)));
    return nullptr;
  }

  std::optional<std::string> string(const toml::table& t, std::string_view name, std::string_view path) {
    const toml::node* node = t.get(name);
    if (!node) return std::nullopt;
    if (const auto* s = node->as_string()) return s->get();
    error(lineOf(*node), fmt::format("{}: must be a string, not {}", key(path, name), typeName(*node)));
    return std::nullopt;
  }

  std::optional<bool> boolean(const toml::table& t, std::string_view name, std::string_view path) {
    const toml::node* node = t.get(name);
    if (!node) return std::nullopt;
    if (const auto* b = node->as_boolean()) return b->get();
    error(lineOf(*node), fmt::format("{}: must be true or false, not {}", key(path, name), typeName(*node)));
    return std::nullopt;
  }

  std::optional<double> number(const toml::table& t, std::string_view name, std::string_view path, double min,
                               double max) {
    const toml::node* node = t.get(name);
    if (!node) return std::nullopt;
    double value = 0;
    if (const auto* i = node->as_integer()) {
      value = static_cast<double>(i->get());
    } else if (const auto* f = node->as_floating_point()) {
      value = f->get();
    } else {
      error(lineOf(*node), fmt::format("{}: must be a number, not {}", key(path, name), typeName(*node)));
      return std::nullopt;
    }
    if (!std::isfinite(value) || value < min || value > max) {
      error(lineOf(*node), fmt::format("{}: {} is out of range; use {} to {}", key(path, name), value, min, max));
      return std::nullopt;
    }
    return value;
  }

  std::optional<std::int64_t> integer(const toml::table& t, std::string_view name, std::string_view path,
                                      std::int64_t min, std::int64_t max) {
    const toml::node* node = t.get(name);
    if (!node) return std::nullopt;
    const auto* i = node->as_integer();
    if (!i) {
      error(lineOf(*node), fmt::format("{}: must be a whole number, not {}", key(path, name), typeName(*node)));
      return std::nullopt;
    }
    if (i->get() < min || i->get() > max) {
      error(lineOf(*node), fmt::format("{}: {} is out of range; use {} to {}", key(path, name), i->get(), min, max));
      return std::nullopt;
    }
    return i->get();
  }

  template <typename Enum>
  std::optional<Enum> choice(const toml::table& t, std::string_view name, std::string_view path,
                             std::initializer_list<NamedValue<Enum>> values) {
    const toml::node* node = t.get(name);
    if (!node) return std::nullopt;
    auto text = string(t, name, path);
    if (!text) return std::nullopt;
    for (const auto& v : values) {
      if (v.name == *text) return v.value;
    }
    std::string names;
    std::size_t i = 0;
    for (const auto& v : values) {
      if (i > 0) names += i + 1 == values.size() ? " or " : ", ";
      names += v.name;
      ++i;
    }
    std::string_view best;
    std::size_t bestDistance = 3;
    for (const auto& v : values) {
      if (const std::size_t d = editDistance(*text, v.name); d < bestDistance) bestDistance = d, best = v.name;
    }
    error(lineOf(*node), fmt::format("{}: '{}' is not one of {}{}", key(path, name), *text, names,
                                     best.empty() ? std::string() : fmt::format("; did you mean '{}'?", best)));
    return std::nullopt;
  }

  std::optional<Nanos> duration(const toml::table& t, std::string_view name, std::string_view path) {
    const toml::node* node = t.get(name);
    if (!node) return std::nullopt;
    if (node->is_integer() || node->is_floating_point()) {
      auto seconds = number(t, name, path, 0, 365.0 * 86400);
      if (!seconds) return std::nullopt;
      return fromSeconds(*seconds);
    }
    auto text = string(t, name, path);
    if (!text) return std::nullopt;
    auto d = parseDuration(*text);
    if (!d) {
      error(lineOf(*node), fmt::format("{}: {}", key(path, name), d.error().message()));
      return std::nullopt;
    }
    return *d;
  }

  /// A path in the manifest: resolved, confined, and checked to exist.
  /// `wantFolder`: true a folder, false a regular file, nullopt either.
  std::optional<std::filesystem::path> filePath(const toml::node& node, std::string_view text, std::string_view what,
                                                std::optional<bool> wantFolder = false) {
    auto resolved = confinePath(folder_, text);
    if (!resolved) {
      error(lineOf(node), fmt::format("{}: {}", what, resolved.error().message()));
      return std::nullopt;
    }
    std::error_code ec;
    const auto status = std::filesystem::status(*resolved, ec);
    if (!std::filesystem::exists(status)) {
      error(lineOf(node), fmt::format("{}: '{}' does not exist (looked for {})", what, text, resolved->string()));
      return std::nullopt;
    }
    if (wantFolder == true && !std::filesystem::is_directory(status)) {
      error(lineOf(node), fmt::format("{}: '{}' must be a folder", what, text));
      return std::nullopt;
    }
    if (wantFolder == false && !std::filesystem::is_regular_file(status)) {
      error(lineOf(node), fmt::format("{}: '{}' is not a regular file", what, text));
      return std::nullopt;
    }
    return *resolved;
  }

  /// Runs the checker for the file's extension, once per file.
  /// `kind` is the checker's key when the name does not tell it (a trace folder: ".trace").
  void checkContents(const std::filesystem::path& path, int line, std::string_view what, std::string kind = {}) {
    if (!checked_.insert(path.string()).second) return;
    const std::string ext = kind.empty() ? extensionOf(path) : std::move(kind);
    if (options_.fileCheckers) {
      if (auto it = options_.fileCheckers->find(ext); it != options_.fileCheckers->end()) {
        for (Diagnostic& d : it->second(path)) {
          if (d.line == 0 && d.file == path) {
            // A problem with the file as a whole (a movie that cannot play, an image that does
            // not decode): reported at the manifest line that names it.
            std::error_code ec;
            const std::filesystem::path canonicalFolder = std::filesystem::weakly_canonical(folder_, ec);
            std::string name = path.lexically_relative(ec ? folder_ : canonicalFolder).generic_string();
            if (name.empty() || name.starts_with("..")) name = path.filename().string();
            d = {d.severity, shown_, line, fmt::format("{}: {}: {}", what, name, d.message)};
          }
          diagsReferenced_.push_back(std::move(d));
        }
        return;
      }
    }
    note(line, fmt::format("{}: '{}' exists; its contents are not checked (this build has no {} reader)", what,
                           path.filename().string(), ext));
  }

  std::optional<EntrySpec> entry(const toml::node& node, std::string_view what, bool allowMovie = true) {
    const auto* s = node.as_string();
    if (!s) {
      error(lineOf(node), fmt::format("{}: must be a file name or \"default\", not {}", what, typeName(node)));
      return std::nullopt;
    }
    EntrySpec e;
    e.text = s->get();
    e.line = lineOf(node);
    if (e.text == "default") {
      e.kind = EntryKind::kBuiltinDefault;
      return e;
    }
    if (e.text == "black") {
      e.kind = EntryKind::kBuiltinBlack;
      return e;
    }
    const std::string ext = extensionOf(e.text);
    if (kScriptExtensions.contains(ext)) {
      e.kind = EntryKind::kScript;
    } else if (kSceneExtensions.contains(ext)) {
      e.kind = EntryKind::kScene;
    } else if (kModelExtensions.contains(ext)) {
      e.kind = EntryKind::kModel;
    } else if (allowMovie && kMovieExtensions.contains(ext)) {
      e.kind = EntryKind::kMovie;
    } else {
      error(e.line, fmt::format("{}: '{}' is not something a show plays; use a LAVA script (.mdl), a scene "
                                "(.sce), a model (.obj, .off){}, \"default\" or \"black\"",
                                what, e.text, allowMovie ? ", a movie (.mkv, .mp4, ...)" : ""));
      return std::nullopt;
    }
    auto path = filePath(node, e.text, what);
    if (!path) return std::nullopt;
    e.path = *path;
    checkContents(e.path, e.line, what);
    return e;
  }

  /// `view = "scene" | "fit"` beside an entry: how its world is framed.
  void entryView(const toml::table& t, const std::string& path, EntrySpec& e) {
    const auto view = choice<EntryView>(t, "view", path, {{"scene", EntryView::kScene}, {"fit", EntryView::kFit}});
    if (!view) return;
    if (e.kind != EntryKind::kScene && e.kind != EntryKind::kModel) {
      error(lineOf(*t.get("view")),
            fmt::format("{}.view: only a scene (.sce) or a model (.obj, .off) can be framed; {} is drawn as "
                        "LAVA draws it",
                        path, e.text));
      return;
    }
    e.view = *view;
  }

  // ---- [show] ----
  void readShow(const toml::table& t) {
    checkKeys(t, "show", {"name", "entry", "fps", "view"});
    if (auto name = string(t, "name", "show")) {
      if (name->empty()) {
        error(lineOf(*t.get("name")), "show.name: must not be empty");
      } else {
        manifest_.name = *name;
      }
    }
    if (auto fps = number(t, "fps", "show", 1, 1000)) manifest_.fps = *fps;
    if (const toml::node* n = t.get("entry")) {
      if (auto e = entry(*n, "show.entry")) {
        manifest_.entry = *e;
        entryView(t, "show", manifest_.entry);
      }
    } else {
      note(lineOf(t), "show.entry: not given; the show plays the built-in default show");
    }
  }

  // ---- [output] ----
  void readOutput(const toml::table& t) {
    OutputSpec& o = manifest_.output;
    o.line = lineOf(t);
    checkKeys(t, "output", {"kind", "size", "device", "connector", "mode", "fullscreen"});
    if (auto kind = choice<OutputKind>(t, "kind", "output",
                                       {{"auto", OutputKind::kAuto},
                                        {"headless", OutputKind::kHeadless},
                                        {"kms", OutputKind::kKms},
                                        {"window", OutputKind::kWindow}})) {
      o.kind = *kind;
    }
    if (auto size = string(t, "size", "output")) {
      auto mode = parseMode(*size);
      if (!mode || mode->refresh != 0) {
        error(lineOf(*t.get("size")),
              fmt::format("output.size: '{}' is not a size; write WIDTHxHEIGHT, e.g. 1280x720", *size));
      } else {
        o.width = mode->width;
        o.height = mode->height;
      }
    }
    if (auto device = string(t, "device", "output")) {
      if (!device->starts_with("/dev/dri/card")) {
        error(lineOf(*t.get("device")),
              fmt::format("output.device: '{}' is not a DRM device; use /dev/dri/cardN", *device));
      } else {
        o.device = *device;
      }
    }
    if (auto connector = string(t, "connector", "output")) o.connector = *connector;
    if (auto modeText = string(t, "mode", "output")) {
      auto mode = parseMode(*modeText);
      if (!mode) {
        error(lineOf(*t.get("mode")), fmt::format("output.mode: {}", mode.error().message()));
      } else {
        o.mode = *mode;
      }
    }
    if (auto fullscreen = boolean(t, "fullscreen", "output")) o.fullscreen = *fullscreen;
    const bool kmsOnly = !o.device.empty() || !o.connector.empty() || o.mode;
    if (kmsOnly && (o.kind == OutputKind::kHeadless || o.kind == OutputKind::kWindow)) {
      warning(o.line, fmt::format("output: device, connector and mode apply to the kms output only; kind is '{}'",
                                  outputKindName(o.kind)));
    }
  }

  // ---- [[views]] ----
  void readViews(const toml::table& root) {
    const toml::node* node = root.get("views");
    if (!node) return;
    const toml::array* views = node->as_array();
    if (!views) {
      error(lineOf(*node), "views: must be an array of tables ([[views]])");
      return;
    }
    std::set<std::string, std::less<>> names;
    std::size_t index = 0;
    for (const toml::node& item : *views) {
      const std::string path = fmt::format("views[{}]", index++);
      const toml::table* t = item.as_table();
      if (!t) {
        error(lineOf(item), fmt::format("{}: must be a table", path));
        continue;
      }
      ViewSpec v;
      v.line = lineOf(*t);
      checkKeys(*t, path,
                {"name", "kind", "cave", "facet", "eye", "viewport", "stereo", "eye_spacing", "projection", "winding",
                 "of", "from", "display_at", "display_scale"});
      v.name = string(*t, "name", path).value_or(fmt::format("view {}", index));
      if (!names.insert(v.name).second)
        error(v.line, fmt::format("{}: a view named '{}' already exists", path, v.name));
      if (auto kind = choice<ViewKind>(*t, "kind", path,
                                       {{"plain", ViewKind::kPlain},
                                        {"facet", ViewKind::kFacet},
                                        {"stereo", ViewKind::kStereo},
                                        {"aids", ViewKind::kAids}})) {
        v.kind = *kind;
      }
      if (const toml::node* cave = t->get("cave")) {
        if (const auto* s = cave->as_string()) {
          if (extensionOf(s->get()) != ".cave") {
            error(lineOf(*cave), fmt::format("{}.cave: '{}' is not a cave file (.cave)", path, s->get()));
          } else if (auto p = filePath(*cave, s->get(), path + ".cave")) {
            v.cave = *p;
            checkContents(*p, lineOf(*cave), path + ".cave");
          }
        } else {
          error(lineOf(*cave), fmt::format("{}.cave: must be a file name", path));
        }
      }
      if (auto facet = integer(*t, "facet", path, 0, 255)) {
        v.facet = static_cast<std::uint32_t>(*facet);
        v.facetGiven = true;
      }
      if (auto stereo = choice<ViewSpec::Stereo>(*t, "stereo", path,
                                                 {{"show", ViewSpec::Stereo::kShow},
                                                  {"off", ViewSpec::Stereo::kOff},
                                                  {"anaglyph", ViewSpec::Stereo::kAnaglyph},
                                                  {"side_by_side", ViewSpec::Stereo::kSideBySide},
                                                  {"top_bottom", ViewSpec::Stereo::kTopBottom}})) {
        v.stereo = *stereo;
      }
      if (auto spacing = number(*t, "eye_spacing", path, 0.0, 10.0)) v.eyeSpacing = static_cast<float>(*spacing);
      if (auto projection = choice<bool>(*t, "projection", path, {{"rear", true}, {"front", false}})) {
        v.rearProjection = *projection;
      }
      if (auto winding = choice<formats::FacetWinding>(*t, "winding", path,
                                                       {{"inward", formats::FacetWinding::kInward},
                                                        {"outward", formats::FacetWinding::kOutward},
                                                        {"auto", formats::FacetWinding::kAuto}})) {
        v.winding = *winding;
      }
      if (v.kind != ViewKind::kFacet && t->get("winding")) {
        warning(v.line, fmt::format("{}: winding applies to facet views only", path));
      }
      if (auto eye = choice<Eye>(*t, "eye", path, {{"left", Eye::kLeft}, {"right", Eye::kRight}})) v.eye = *eye;
      if (const toml::node* vp = t->get("viewport")) readViewport(*vp, path, v);
      if (v.kind == ViewKind::kFacet && v.cave.empty() && !t->get("cave")) {
        error(v.line, fmt::format("{}: a facet view needs cave = \"display.cave\"", path));
      }
      if (v.kind != ViewKind::kStereo && t->get("eye")) {
        warning(v.line, fmt::format("{}: eye applies to stereo views only", path));
      }
      if (auto of = string(*t, "of", path)) v.of = *of;
      if (const toml::node* from = t->get("from")) readFrom(*from, path, v);
      if (const toml::node* at = t->get("display_at")) readDisplayAt(*at, path, v);
      if (auto scale = number(*t, "display_scale", path, 1e-6, 1e6)) v.displayScale = static_cast<float>(*scale);
      if (v.kind != ViewKind::kFacet && v.kind != ViewKind::kAids &&
          (t->get("display_at") || t->get("display_scale"))) {
        warning(v.line, fmt::format("{}: display_at and display_scale apply to facet and aids views only", path));
      }
      if (v.kind != ViewKind::kAids && (t->get("of") || t->get("from"))) {
        warning(v.line, fmt::format("{}: of and from apply to aids views only", path));
      }
      manifest_.views.push_back(std::move(v));
    }
    // An aids view shows a facet view's set-up: the one it names, or the first.
    for (const ViewSpec& v : manifest_.views) {
      if (v.kind != ViewKind::kAids) continue;
      const auto facetView = std::find_if(manifest_.views.begin(), manifest_.views.end(), [&](const ViewSpec& o) {
        return o.kind == ViewKind::kFacet && (v.of.empty() || o.name == v.of);
      });
      if (facetView != manifest_.views.end()) continue;
      if (v.of.empty()) {
        error(v.line, fmt::format("views: the aids view '{}' needs a facet view to show; add one with kind = \"facet\"",
                                  v.name));
      } else {
        error(v.line, fmt::format("views: the aids view '{}' names '{}', which is not a facet view", v.name, v.of));
      }
    }
  }

  // ---- [viewer] ----
  void readViewer(const toml::table& t) {
    ViewerSpec& v = manifest_.viewer;
    v.line = lineOf(t);
    checkKeys(t, "viewer",
              {"position", "tracker", "smoothing", "time_constant_ms", "min_cutoff", "beta", "tracker_offset",
               "tracker_scale"});
    if (const toml::node* position = t.get("position")) {
      if (auto p = point(*position)) {
        v.position = *p;
      } else {
        error(lineOf(*position), "viewer.position: must be a point [x, y, z] in the display geometry's units");
      }
    }
    if (auto tracker = string(t, "tracker", "viewer")) {
      const DeviceSpec* d = manifest_.findDevice(*tracker);
      if (!d) {
        error(lineOf(*t.get("tracker")),
              fmt::format("viewer.tracker: no device '{}' in [devices]; add one with kind = \"tracker\"", *tracker));
      } else if (d->kind != DeviceKind::kTracker) {
        error(lineOf(*t.get("tracker")),
              fmt::format("viewer.tracker: '{}' is a {}, not a tracker", *tracker, deviceKindName(d->kind)));
      } else {
        v.tracker = *tracker;
      }
    }
    using Kind = runtime::HeadSmoothing::Kind;
    if (auto kind =
            choice<Kind>(t, "smoothing", "viewer",
                         {{"one_euro", Kind::kOneEuro}, {"exponential", Kind::kExponential}, {"off", Kind::kOff}})) {
      v.smoothing.kind = *kind;
    }
    if (auto ms = number(t, "time_constant_ms", "viewer", 0, 10000)) {
      v.smoothing.timeConstant = Nanos{static_cast<std::int64_t>(*ms * 1e6)};
    }
    if (auto cutoff = number(t, "min_cutoff", "viewer", 0.001, 1000)) v.smoothing.minCutoff = *cutoff;
    if (auto beta = number(t, "beta", "viewer", 0, 1e6)) v.smoothing.beta = *beta;
    const bool euroKeys = t.get("min_cutoff") || t.get("beta");
    if (t.get("time_constant_ms") && v.smoothing.kind != Kind::kExponential) {
      warning(lineOf(*t.get("time_constant_ms")),
              "viewer.time_constant_ms: only smoothing = \"exponential\" has a time constant; this is ignored");
    }
    if (euroKeys && v.smoothing.kind != Kind::kOneEuro) {
      warning(v.line, "viewer: min_cutoff and beta apply to smoothing = \"one_euro\" only; they are ignored");
    }
    if (const toml::node* offset = t.get("tracker_offset")) {
      if (auto p = point(*offset)) {
        v.trackerOffset = *p;
      } else {
        error(lineOf(*offset), "viewer.tracker_offset: must be a point [x, y, z] in the display geometry's units");
      }
    }
    if (auto scale = number(t, "tracker_scale", "viewer", 1e-6, 1e6)) v.trackerScale = static_cast<float>(*scale);
    if (v.tracker.empty()) {
      for (const char* key :
           {"smoothing", "time_constant_ms", "min_cutoff", "beta", "tracker_offset", "tracker_scale"}) {
        if (t.get(key)) {
          warning(lineOf(*t.get(key)), fmt::format("viewer.{}: applies to a tracked viewer; there is no tracker", key));
        }
      }
    }
    const bool facets =
        std::ranges::any_of(manifest_.views, [](const ViewSpec& s) { return s.kind == ViewKind::kFacet; });
    if (!facets) warning(v.line, "viewer: only facet views draw from the viewer; this show has none");
  }

  /// An array of three finite numbers within a million of zero.
  static std::optional<std::array<float, 3>> point(const toml::node& node) {
    const toml::array* a = node.as_array();
    if (!a || a->size() != 3) return std::nullopt;
    std::array<float, 3> values{};
    for (std::size_t i = 0; i < 3; ++i) {
      const toml::node* element = a->get(i);
      const auto n = element ? element->value<double>() : std::nullopt;
      if (!n || !std::isfinite(*n) || std::abs(*n) > 1e6) return std::nullopt;
      values[i] = static_cast<float>(*n);
    }
    return values;
  }

  void readFrom(const toml::node& node, const std::string& path, ViewSpec& v) {
    const auto values = point(node);
    if (!values || ((*values)[0] == 0 && (*values)[1] == 0 && (*values)[2] == 0)) {
      error(lineOf(node), fmt::format("{}.from: must be a direction [x, y, z] in the cave's axes, not all zero", path));
      return;
    }
    v.from = *values;
  }

  void readDisplayAt(const toml::node& node, const std::string& path, ViewSpec& v) {
    const auto values = point(node);
    if (!values) {
      error(lineOf(node), fmt::format("{}.display_at: must be a position [x, y, z] in scene units", path));
      return;
    }
    v.displayAt = *values;
  }

  void readViewport(const toml::node& node, const std::string& path, ViewSpec& v) {
    const toml::array* a = node.as_array();
    std::array<std::uint32_t, 4> values{};
    bool ok = a && a->size() == 4;
    for (std::size_t i = 0; ok && i < 4; ++i) {
      const toml::node* element = a->get(i);
      const auto* n = element ? element->as_integer() : nullptr;
      ok = n && n->get() >= 0 && n->get() <= 16384;
      if (ok) values[i] = static_cast<std::uint32_t>(n->get());
    }
    if (!ok || values[2] == 0 || values[3] == 0) {
      error(lineOf(node), fmt::format("{}.viewport: must be [x, y, width, height] in pixels", path));
      return;
    }
    const OutputSpec& o = manifest_.output;
    if (o.width > 0 && (values[0] + values[2] > o.width || values[1] + values[3] > o.height)) {
      error(lineOf(node), fmt::format("{}.viewport: [{}, {}, {}, {}] does not fit the {}x{} output", path, values[0],
                                      values[1], values[2], values[3], o.width, o.height));
      return;
    }
    v.viewport = values;
  }

  /// Why a hid-recorder file cannot be replayed as a dial box, or nothing.
  static std::optional<std::string> checkHidRecording(const std::filesystem::path& file) {
    if (sim::isMidiFilePath(file)) {
      auto midi = sim::readMidiFile(file);
      if (!midi) return fmt::format("is not a Standard MIDI File: {}", midi.error().message());
      return std::nullopt;
    }
    auto recording = sim::readHidRecording(file);
    if (!recording) return fmt::format("is not a hid-recorder file: {}", recording.error().message());
    if (recording->devices.empty()) return std::string("records no device (no R: or E: lines)");
    return std::nullopt;
  }

  // ---- [devices.NAME] ----
  void readDevices(const toml::table& devices) {
    for (auto&& [k, node] : devices) {
      const std::string name(k.str());
      const std::string path = "devices." + name;
      const toml::table* t = node.as_table();
      if (!t) {
        error(lineOf(node), fmt::format("{}: must be a table ([{}])", path, path));
        continue;
      }
      DeviceSpec d;
      d.name = name;
      d.line = lineOf(*t);
      checkKeys(*t, path,
                {"kind", "backend", "match", "trace", "script", "loop", "required", "size", "gain", "acceleration",
                 "mirror", "faults", "format", "midi", "motion", "radius", "period", "rate", "centre"});
      const auto kind = choice<DeviceKind>(
          *t, "kind", path,
          {{"dial_box", DeviceKind::kDialBox}, {"camera", DeviceKind::kCamera}, {"tracker", DeviceKind::kTracker}});
      if (!t->get("kind")) {
        error(d.line, fmt::format("{}: needs kind = \"dial_box\", \"camera\" or \"tracker\"", path));
      }
      if (kind) d.kind = *kind;
      const auto backend = choice<DeviceBackend>(*t, "backend", path,
                                                 {{"hid", DeviceBackend::kHid},
                                                  {"serial", DeviceBackend::kSerial},
                                                  {"midi", DeviceBackend::kMidi},
                                                  {"osc", DeviceBackend::kOsc},
                                                  {"v4l2", DeviceBackend::kV4l2},
                                                  {"libcamera", DeviceBackend::kLibcamera},
                                                  {"replay", DeviceBackend::kReplay},
                                                  {"synthetic", DeviceBackend::kSynthetic}});
      if (!t->get("backend")) {
        error(d.line, fmt::format("{}: needs backend = \"hid\", \"serial\", \"midi\", \"osc\", \"v4l2\", "
                                  "\"libcamera\", \"replay\" or \"synthetic\"",
                                  path));
      }
      if (backend) d.backend = *backend;
      if (kind && backend) {
        const bool dialBackend = *backend == DeviceBackend::kHid || *backend == DeviceBackend::kReplay ||
                                 *backend == DeviceBackend::kSynthetic || *backend == DeviceBackend::kSerial ||
                                 *backend == DeviceBackend::kMidi;
        const bool cameraBackend = *backend != DeviceBackend::kHid && *backend != DeviceBackend::kSerial &&
                                   *backend != DeviceBackend::kMidi && *backend != DeviceBackend::kOsc;
        const bool trackerBackend = *backend == DeviceBackend::kHid || *backend == DeviceBackend::kReplay ||
                                    *backend == DeviceBackend::kSynthetic || *backend == DeviceBackend::kOsc;
        if ((*kind == DeviceKind::kDialBox && !dialBackend) || (*kind == DeviceKind::kCamera && !cameraBackend) ||
            (*kind == DeviceKind::kTracker && !trackerBackend)) {
          error(lineOf(*t->get("backend")),
                fmt::format("{}: a {} cannot use the {} backend; a dial_box uses hid, serial, midi, replay or "
                            "synthetic, a camera v4l2, libcamera, replay or synthetic, a tracker hid, osc, replay "
                            "or synthetic",
                            path, deviceKindName(*kind), deviceBackendName(*backend)));
        }
      }
      if (const toml::table* m = table(*t, "match", path)) readMatch(*m, path + ".match", d);
      if (d.backend == DeviceBackend::kSerial && d.match.path.empty() && d.kind == DeviceKind::kDialBox) {
        error(d.line,
              fmt::format("{}: the serial backend needs the port: match = {{ path = \"/dev/ttyUSB0\" }}", path));
      }
      if (const toml::node* trace = t->get("trace")) {
        if (const auto* s = trace->as_string()) {
          // A NAME.trace folder from 'basalt record', or (dial boxes) a file from hid-tools'
          // hid-recorder, recorded on any machine.
          if (auto p = filePath(*trace, s->get(), path + ".trace", std::nullopt)) {
            std::error_code ec;
            if (std::filesystem::is_regular_file(*p, ec)) {
              if (d.kind == DeviceKind::kCamera) {
                error(lineOf(*trace), fmt::format("{}.trace: '{}' is a file; a camera replays a NAME.trace folder "
                                                  "(record one with 'basalt record')",
                                                  path, s->get()));
              } else if (auto bad = checkHidRecording(*p)) {
                error(lineOf(*trace), fmt::format("{}.trace: '{}' {}", path, s->get(), *bad));
              } else {
                d.trace = *p;
              }
            } else if (!std::filesystem::is_regular_file(*p / "trace.toml", ec)) {
              error(lineOf(*trace), fmt::format("{}.trace: '{}' has no trace.toml; record one with 'basalt record', "
                                                "or name a hid-recorder file",
                                                path, s->get()));
            } else {
              d.trace = *p;
              checkContents(*p, lineOf(*trace), path + ".trace", ".trace");
            }
          }
        } else {
          error(lineOf(*trace),
                fmt::format("{}.trace: must be the name of a NAME.trace folder or a hid-recorder file", path));
        }
      }
      if (d.backend == DeviceBackend::kReplay && !t->get("trace")) {
        error(d.line, fmt::format("{}: the replay backend needs trace = \"NAME.trace\"", path));
      }
      if (d.backend != DeviceBackend::kReplay && t->get("trace")) {
        warning(lineOf(*t->get("trace")), fmt::format("{}.trace: only the replay backend reads a trace", path));
      }
      if (const toml::node* midi = t->get("midi")) readMidiOptions(*midi, path, d);
      if (const toml::node* script = t->get("script")) readSyntheticScript(*script, path, d);
      if (t->get("script") && d.backend != DeviceBackend::kSynthetic) {
        warning(lineOf(*t->get("script")), fmt::format("{}.script: only the synthetic backend plays a script", path));
      }
      if (auto loop = boolean(*t, "loop", path)) d.loop = *loop;
      if (auto required = boolean(*t, "required", path)) d.required = *required;
      if (auto size = string(*t, "size", path)) {
        auto mode = parseMode(*size);
        if (!mode || mode->refresh != 0) {
          error(lineOf(*t->get("size")), fmt::format("{}.size: '{}' is not WIDTHxHEIGHT", path, *size));
        } else if (d.kind != DeviceKind::kCamera) {
          warning(lineOf(*t->get("size")), fmt::format("{}.size: only cameras have a size", path));
        } else {
          d.width = mode->width;
          d.height = mode->height;
        }
      }
      if (auto mirror = boolean(*t, "mirror", path)) {
        d.mirror = *mirror;
        if (d.kind != DeviceKind::kCamera) {
          warning(lineOf(*t->get("mirror")), fmt::format("{}.mirror: only cameras mirror; this is ignored", path));
        }
      }
      if (auto format = string(*t, "format", path)) {
        bool known = false;
        for (int i = 1; i <= static_cast<int>(PixelFormat::kMjpeg); ++i) {
          known = known || pixelFormatName(static_cast<PixelFormat>(i)) == *format;
        }
        if (!known) {
          error(lineOf(*t->get("format")),
                fmt::format("{}.format: '{}' is not one of RGBA, BGRA, RGB, GRAY8, I420, YV12, NV12, NV21, YUYV, "
                            "UYVY, MJPEG",
                            path, *format));
        } else if (d.kind != DeviceKind::kCamera) {
          warning(lineOf(*t->get("format")), fmt::format("{}.format: only cameras have a format", path));
        } else {
          d.format = *format;
        }
      }
      if (const toml::node* faults = t->get("faults")) {
        if (d.kind != DeviceKind::kCamera || d.backend != DeviceBackend::kSynthetic) {
          warning(lineOf(*faults), fmt::format("{}.faults: only synthetic cameras play faults; this is ignored", path));
        }
        readSyntheticFaults(*faults, path, d);
      }
      if (auto gain = number(*t, "gain", path, -1e6, 1e6)) d.gain = *gain;
      if (auto acceleration = number(*t, "acceleration", path, 0, 1e3)) d.acceleration = *acceleration;
      for (const char* key : {"gain", "acceleration"}) {
        if (t->get(key) && d.kind != DeviceKind::kDialBox) {
          warning(lineOf(*t->get(key)), fmt::format("{}.{}: only dial boxes have one; this is ignored", path, key));
        }
      }
      readTrackerMotion(*t, path, d);
      manifest_.devices.push_back(std::move(d));
    }
  }

  /// `midi = { profile = "xtouch-mini-mc", encoding = "sign_magnitude", channel = 1, dials = [16, 17],
  /// buttons = [...], notes = [...], nrpn = [...], high_resolution = false, echo = false }`: the midi
  /// backend's options, checked here as the backend will read them.
  void readMidiOptions(const toml::node& node, const std::string& path, DeviceSpec& d) {
    const std::string mp = path + ".midi";
    const toml::table* m = node.as_table();
    if (!m) {
      error(lineOf(node), fmt::format("{}: must be a table: midi = {{ profile = \"xtouch-mini-mc\" }}", mp));
      return;
    }
    if (d.backend != DeviceBackend::kMidi) {
      warning(lineOf(node), fmt::format("{}: only the midi backend reads it; this is ignored", mp));
      return;
    }
    checkKeys(*m, mp,
              {"profile", "encoding", "channel", "dials", "buttons", "notes", "nrpn", "high_resolution", "echo"});
    std::map<std::string, std::string> options;
    for (const char* key : {"profile", "encoding"}) {
      if (auto v = string(*m, key, mp)) options[key] = *v;
    }
    if (auto channel = integer(*m, "channel", mp, 1, 16)) options["channel"] = std::to_string(*channel);
    for (const char* key : {"dials", "buttons", "notes", "nrpn"}) {
      const toml::node* list = m->get(key);
      if (!list) continue;
      const toml::array* a = list->as_array();
      std::string text;
      bool ok = a != nullptr;
      if (a) {
        for (const toml::node& item : *a) {
          const auto* n = item.as_integer();
          ok = ok && n && n->get() >= 0 && n->get() <= 16383;
          if (!ok) break;
          if (!text.empty()) text += ',';
          text += std::to_string(n->get());
        }
      }
      if (!ok || text.empty()) {
        error(lineOf(*list), fmt::format("{}.{}: must be a list of numbers: {} = [16, 17, 18]", mp, key, key));
        continue;
      }
      options[key] = text;
    }
    for (const char* key : {"high_resolution", "echo"}) {
      if (auto v = boolean(*m, key, mp)) options[key] = *v ? "true" : "false";
    }
    // The backend's own check, so that `basalt check` names what the device would refuse.
    if (auto profile = devices::midiProfileFromOptions(d.match.name, options); !profile) {
      error(lineOf(node), fmt::format("{}: {}", mp, profile.error().message()));
      return;
    }
    d.midi = std::move(options);
  }

  void readTrackerMotion(const toml::table& t, const std::string& path, DeviceSpec& d) {
    TrackerMotion& m = d.motion;
    if (auto shape = choice<TrackerMotion::Shape>(t, "motion", path,
                                                  {{"circle", TrackerMotion::Shape::kCircle},
                                                   {"line", TrackerMotion::Shape::kLine},
                                                   {"figure_eight", TrackerMotion::Shape::kFigureEight}})) {
      m.shape = *shape;
    }
    if (auto radius = number(t, "radius", path, 0, 100)) m.radius = static_cast<float>(*radius);
    if (auto period = number(t, "period", path, 0.01, 3600)) m.period = *period;
    if (auto rate = integer(t, "rate", path, 1, 2000)) m.rate = static_cast<std::uint32_t>(*rate);
    if (const toml::node* centre = t.get("centre")) {
      if (auto p = point(*centre)) {
        m.centre = *p;
      } else {
        error(lineOf(*centre), fmt::format("{}.centre: must be a point [x, y, z] in metres", path));
      }
    }
    for (const char* key : {"motion", "radius", "period", "rate", "centre"}) {
      if (t.get(key) && (d.kind != DeviceKind::kTracker || d.backend != DeviceBackend::kSynthetic)) {
        warning(lineOf(*t.get(key)),
                fmt::format("{}.{}: only synthetic trackers move by themselves; this is ignored", path, key));
      }
    }
  }

  void readMatch(const toml::table& m, const std::string& path, DeviceSpec& d) {
    checkKeys(m, path, {"usb", "name", "path", "serial"});
    if (auto usb = string(m, "usb", path)) {
      // "077d:0410": vendor and product in hexadecimal, as lsusb prints them.
      unsigned vendor = 0;
      unsigned product = 0;
      const auto colon = usb->find(':');
      const auto hex = [](std::string_view s, unsigned& out) {
        const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), out, 16);
        return ec == std::errc{} && end == s.data() + s.size() && s.size() == 4;
      };
      if (colon == std::string::npos || !hex(std::string_view(*usb).substr(0, colon), vendor) ||
          !hex(std::string_view(*usb).substr(colon + 1), product)) {
        error(lineOf(*m.get("usb")),
              fmt::format("{}.usb: '{}' is not VVVV:PPPP (vendor and product in hexadecimal, as lsusb prints them)",
                          path, *usb));
      } else {
        d.match.vendor = static_cast<std::uint16_t>(vendor);
        d.match.product = static_cast<std::uint16_t>(product);
      }
    }
    if (auto name = string(m, "name", path)) d.match.name = *name;
    if (auto p = string(m, "path", path)) {
      if (d.backend == DeviceBackend::kMidi && !p->starts_with("seq:")) {
        error(lineOf(*m.get("path")),
              fmt::format("{}.path: '{}': a MIDI port's path is seq:CLIENT:PORT (aconnect -l lists them); match a "
                          "controller by name = \"X-TOUCH MINI\" to survive replugging",
                          path, *p));
      } else if (d.backend != DeviceBackend::kMidi && !p->starts_with("/dev/") && !p->starts_with("usb:")) {
        error(lineOf(*m.get("path")), fmt::format("{}.path: '{}' is neither a /dev node nor a usb: path", path, *p));
      } else {
        d.match.path = *p;
      }
    }
    if (auto serial = string(m, "serial", path)) d.match.serial = *serial;
    if (auto p = string(m, "path", path); p && d.backend == DeviceBackend::kSerial && !p->starts_with("/dev/")) {
      error(lineOf(*m.get("path")), fmt::format("{}.path: '{}': the serial backend needs a /dev node", path, *p));
    }
    if (d.backend == DeviceBackend::kSynthetic || d.backend == DeviceBackend::kReplay) {
      warning(lineOf(m), fmt::format("{}: the {} backend matches no hardware; this is ignored", path,
                                     deviceBackendName(d.backend)));
    }
  }

  void readSyntheticFaults(const toml::node& node, const std::string& path, DeviceSpec& d) {
    const toml::array* a = node.as_array();
    if (!a) {
      error(lineOf(node), fmt::format("{}.faults: must be an array of {{ at = \"2s\", fault = \"unplug\" }}", path));
      return;
    }
    Nanos last{0};
    std::size_t i = 0;
    for (const toml::node& item : *a) {
      const std::string ip = fmt::format("{}.faults[{}]", path, i++);
      const toml::table* t = item.as_table();
      if (!t) {
        error(lineOf(item), fmt::format("{}: must be {{ at = \"2s\", fault = \"unplug\" }}", ip));
        continue;
      }
      checkKeys(*t, ip, {"at", "fault", "for"});
      SyntheticFault f;
      if (auto at = duration(*t, "at", ip)) {
        if (*at < last) error(lineOf(*t), fmt::format("{}: times must not go backwards", ip));
        f.at = last = *at;
      } else if (!t->get("at")) {
        error(lineOf(*t), fmt::format("{}: needs at = \"TIME\" after the camera opens", ip));
      }
      const auto kind = choice<SyntheticFault::Kind>(*t, "fault", ip,
                                                     {{"unplug", SyntheticFault::Kind::kUnplug},
                                                      {"signal_lost", SyntheticFault::Kind::kSignalLost},
                                                      {"stall", SyntheticFault::Kind::kStall},
                                                      {"corrupt", SyntheticFault::Kind::kCorrupt}});
      if (!t->get("fault")) {
        error(lineOf(*t), fmt::format("{}: needs fault = \"unplug\", \"signal_lost\", \"stall\" or \"corrupt\"", ip));
      }
      if (kind) f.kind = *kind;
      if (auto length = duration(*t, "for", ip)) f.duration = *length;
      if (kind && *kind == SyntheticFault::Kind::kCorrupt && d.format != "MJPEG") {
        error(lineOf(*t), fmt::format("{}: only MJPEG frames can be corrupt (format = \"MJPEG\")", ip));
      }
      if (kind && (*kind == SyntheticFault::Kind::kSignalLost || *kind == SyntheticFault::Kind::kStall) &&
          !t->get("for")) {
        error(lineOf(*t), fmt::format("{}: needs for = \"TIME\" (how long it lasts)", ip));
      }
      d.faults.push_back(f);
    }
  }

  void readSyntheticScript(const toml::node& node, const std::string& path, DeviceSpec& d) {
    const toml::array* a = node.as_array();
    if (!a) {
      error(lineOf(node),
            fmt::format("{}.script: must be an array of {{ at = \"1s\", dial = 0, turns = 0.25 }}", path));
      return;
    }
    Nanos last{0};
    std::size_t i = 0;
    for (const toml::node& item : *a) {
      const std::string ip = fmt::format("{}.script[{}]", path, i++);
      const toml::table* t = item.as_table();
      if (!t) {
        error(lineOf(item), fmt::format("{}: must be {{ at = \"1s\", dial = 0, turns = 0.25 }}", ip));
        continue;
      }
      checkKeys(*t, ip, {"at", "dial", "turns", "button", "pressed", "shuttle", "position"});
      SyntheticInput in;
      const auto at = duration(*t, "at", ip);
      if (!t->get("at")) error(lineOf(*t), fmt::format("{}: needs at = \"TIME\" after the device opens", ip));
      if (at) in.at = *at;
      if (at && *at < last) error(lineOf(*t), fmt::format("{}: times must not go backwards", ip));
      if (at) last = *at;
      const bool dial = t->get("dial") != nullptr;
      const bool button = t->get("button") != nullptr;
      const bool shuttle = t->get("shuttle") != nullptr;
      if (int{dial} + int{button} + int{shuttle} != 1) {
        error(lineOf(*t), fmt::format("{}: give one of dial = N with turns, button = N with pressed, or shuttle = N "
                                      "with position",
                                      ip));
        continue;
      }
      in.button = button;
      in.shuttle = shuttle;
      if (shuttle) {
        // A shuttle ring held off-centre (-1..1, full deflection at the ends) until the next one.
        if (auto index = integer(*t, "shuttle", ip, 0, 7)) in.index = static_cast<std::uint16_t>(*index);
        if (auto position = number(*t, "position", ip, -1, 1)) in.value = *position;
        if (!t->get("position")) {
          error(lineOf(*t), fmt::format("{}: needs position = N (-1 to 1; 0 lets the ring go)", ip));
        }
      } else if (dial) {
        if (auto index = integer(*t, "dial", ip, 0, 7)) in.index = static_cast<std::uint16_t>(*index);
        if (auto turns = number(*t, "turns", ip, -100, 100)) in.value = *turns;
        if (!t->get("turns")) error(lineOf(*t), fmt::format("{}: needs turns = N (fractions of a full turn)", ip));
      } else {
        if (auto index = integer(*t, "button", ip, 0, 31)) in.index = static_cast<std::uint16_t>(*index);
        in.value = boolean(*t, "pressed", ip).value_or(true) ? 1 : 0;
      }
      d.script.push_back(in);
    }
  }

  // ---- [media.NAME] ----
  void readMedia(const toml::table& media) {
    for (auto&& [k, node] : media) {
      const std::string name(k.str());
      const std::string path = "media." + name;
      const toml::table* t = node.as_table();
      if (!t) {
        error(lineOf(node), fmt::format("{}: must be a table ([{}])", path, path));
        continue;
      }
      MediaSpec m;
      m.name = name;
      m.line = lineOf(*t);
      checkKeys(*t, path, {"kind", "file", "device", "loop", "audio", "on_loss"});
      const auto kind = choice<MediaKind>(
          *t, "kind", path,
          {{"movie", MediaKind::kMovie}, {"image", MediaKind::kImage}, {"camera", MediaKind::kCamera}});
      if (!t->get("kind")) error(m.line, fmt::format("{}: needs kind = \"movie\", \"image\" or \"camera\"", path));
      if (kind) m.kind = *kind;
      if (auto loop = boolean(*t, "loop", path)) m.loop = *loop;
      if (auto audio = boolean(*t, "audio", path)) m.audio = *audio;
      if (kind == MediaKind::kCamera) {
        if (t->get("file"))
          error(lineOf(*t->get("file")), fmt::format("{}: a camera has no file; name its device", path));
        if (auto device = string(*t, "device", path)) {
          const DeviceSpec* d = manifest_.findDevice(*device);
          if (!d) {
            error(lineOf(*t->get("device")), fmt::format("{}.device: no device '{}' in [devices]", path, *device));
          } else if (d->kind != DeviceKind::kCamera) {
            error(lineOf(*t->get("device")),
                  fmt::format("{}.device: '{}' is a {}, not a camera", path, *device, deviceKindName(d->kind)));
          } else {
            m.device = *device;
          }
        } else if (!t->get("device")) {
          error(m.line, fmt::format("{}: a camera needs device = \"NAME\" from [devices]", path));
        }
        if (auto loss = string(*t, "on_loss", path)) readCameraLoss(*loss, lineOf(*t->get("on_loss")), path, m);
      } else if (kind) {
        if (t->get("device")) warning(lineOf(*t->get("device")), fmt::format("{}.device: only cameras have one", path));
        if (t->get("on_loss")) {
          warning(lineOf(*t->get("on_loss")), fmt::format("{}.on_loss: only cameras are lost; this is ignored", path));
        }
        if (const toml::node* file = t->get("file")) {
          if (const auto* s = file->as_string()) {
            const auto& extensions = *kind == MediaKind::kMovie ? kMovieExtensions : kImageExtensions;
            if (!extensions.contains(extensionOf(s->get()))) {
              error(lineOf(*file), fmt::format("{}.file: '{}' is not {} file this show can play", path, s->get(),
                                               *kind == MediaKind::kMovie ? "a movie" : "an image"));
            } else if (auto p = filePath(*file, s->get(), path + ".file")) {
              m.file = *p;
              checkContents(*p, lineOf(*file), path + ".file");
            }
          } else {
            error(lineOf(*file), fmt::format("{}.file: must be a file name", path));
          }
        } else {
          error(m.line, fmt::format("{}: needs file = \"NAME\"", path));
        }
      }
      manifest_.media.push_back(std::move(m));
    }
  }

  /// A movie or camera that no texture shows is never played or opened: say so.
  void checkMediaShown() {
    for (const MediaSpec& m : manifest_.media) {
      if (m.kind == MediaKind::kImage) continue;
      const bool shown =
          std::ranges::any_of(manifest_.textures, [&](const TextureSpec& t) { return t.source == m.name; });
      if (shown) continue;
      warning(m.line, fmt::format("media.{}: no texture shows it, so the {} is never {}; add [textures.NAME] with "
                                  "source = \"{}\"",
                                  m.name, m.kind == MediaKind::kMovie ? "movie" : "camera",
                                  m.kind == MediaKind::kMovie ? "played" : "opened", m.name));
    }
  }

  /// `on_loss`: "fallback", "last_frame", "test_pattern" or a colour "#RRGGBB".
  void readCameraLoss(const std::string& text, int line, const std::string& path, MediaSpec& m) {
    if (text == "fallback") {
      m.onLoss = CameraLoss::kFallbackImage;
    } else if (text == "last_frame") {
      m.onLoss = CameraLoss::kLastFrame;
    } else if (text == "test_pattern") {
      m.onLoss = CameraLoss::kTestPattern;
    } else {
      unsigned rgb = 0;
      const bool hex = text.size() == 7 && text[0] == '#' &&
                       std::from_chars(text.data() + 1, text.data() + 7, rgb, 16).ptr == text.data() + 7;
      if (!hex) {
        error(line, fmt::format("{}.on_loss: '{}' is not one of fallback, last_frame, test_pattern or a colour "
                                "\"#RRGGBB\"",
                                path, text));
        return;
      }
      m.onLoss = CameraLoss::kColour;
      m.lossColour = {static_cast<std::uint8_t>(rgb >> 16), static_cast<std::uint8_t>(rgb >> 8),
                      static_cast<std::uint8_t>(rgb)};
    }
  }

  // ---- [[bindings]] ----
  void readBindings(const toml::table& root) {
    const toml::node* node = root.get("bindings");
    if (!node) return;
    const toml::array* bindings = node->as_array();
    if (!bindings) {
      error(lineOf(*node), "bindings: must be an array of tables ([[bindings]])");
      return;
    }
    std::set<std::tuple<std::string, bool, int>> seen;
    std::size_t index = 0;
    for (const toml::node& item : *bindings) {
      const std::string path = fmt::format("bindings[{}]", index++);
      const toml::table* t = item.as_table();
      if (!t) {
        error(lineOf(item), fmt::format("{}: must be a table", path));
        continue;
      }
      BindingSpec b;
      b.line = lineOf(*t);
      checkKeys(*t, path, {"device", "dial", "button", "action", "gain", "acceleration", "invert"});
      auto device = string(*t, "device", path);
      if (!t->get("device")) error(b.line, fmt::format("{}: needs device = \"NAME\" from [devices]", path));
      const DeviceSpec* d = device ? manifest_.findDevice(*device) : nullptr;
      if (device && !d) {
        error(lineOf(*t->get("device")), fmt::format("{}.device: no device '{}' in [devices]", path, *device));
      } else if (d && d->kind != DeviceKind::kDialBox) {
        error(lineOf(*t->get("device")), fmt::format("{}.device: '{}' is a {}; only dial boxes have dials and buttons",
                                                     path, *device, deviceKindName(d->kind)));
        d = nullptr;
      }
      if (device) b.device = *device;
      const bool dial = t->get("dial") != nullptr;
      const bool button = t->get("button") != nullptr;
      if (dial == button) {
        error(b.line, fmt::format("{}: give either dial = N or button = N", path));
        continue;
      }
      b.button = button;
      // A synthetic box has LAVA's 8 dials and 32 buttons; others are checked when they open.
      const bool synthetic = d && d->backend == DeviceBackend::kSynthetic;
      const std::int64_t maxIndex =
          button ? 31 : (synthetic ? 7 : static_cast<std::int64_t>(runtime::kMaxBoundDials) - 1);
      if (auto i = integer(*t, button ? "button" : "dial", path, 0, maxIndex)) b.index = static_cast<std::uint16_t>(*i);
      // A dial of LAVA's table may keep its action and change only its gain or acceleration.
      b.actionGiven = t->get("action") != nullptr;
      if (!b.actionGiven && (button || b.index >= kLavaDials)) {
        error(b.line, fmt::format("{}: needs action = \"...\"{}", path,
                                  button ? "" : " (only dials 0 to 7 have a default action, LAVA's)"));
      }
      if (dial) {
        if (auto action = choice<runtime::Action>(*t, "action", path,
                                                  {{"none", runtime::Action::kNone},
                                                   {"rotate_x", runtime::Action::kRotateX},
                                                   {"rotate_y", runtime::Action::kRotateY},
                                                   {"rotate_z", runtime::Action::kRotateZ},
                                                   {"scale", runtime::Action::kScale},
                                                   {"translate_x", runtime::Action::kTranslateX},
                                                   {"translate_y", runtime::Action::kTranslateY},
                                                   {"translate_z", runtime::Action::kTranslateZ},
                                                   {"walk", runtime::Action::kWalk},
                                                   {"strafe", runtime::Action::kStrafe},
                                                   {"rise", runtime::Action::kRise},
                                                   {"turn", runtime::Action::kTurn},
                                                   {"tilt", runtime::Action::kTilt}})) {
          b.action = *action;
          b.gain = defaultGain(*action);
        }
        if (!b.actionGiven && b.index < kLavaDials) {
          b.action = runtime::Bindings::lavaDefaults().dial(b.index).action;
          b.gain = defaultGain(b.action);
        }
        if (auto gain = number(*t, "gain", path, -1e6, 1e6)) {
          b.gain = *gain;
          b.gainGiven = true;
        }
        if (auto acceleration = number(*t, "acceleration", path, 0, 1e3)) b.acceleration = acceleration;
        if (auto invert = boolean(*t, "invert", path)) b.invert = *invert;
        if (b.action == runtime::Action::kNone && (t->get("gain") || t->get("acceleration") || t->get("invert"))) {
          warning(b.line, fmt::format("{}: dial {} does nothing, so its gain, acceleration and invert do nothing", path,
                                      b.index));
        }
      } else {
        if (auto action = choice<KioskAction>(*t, "action", path,
                                              {{"none", KioskAction::kNone},
                                               {"next", KioskAction::kNextItem},
                                               {"previous", KioskAction::kPreviousItem},
                                               {"reset_view", KioskAction::kResetView}})) {
          b.kioskAction = *action;
        }
        for (const char* key : {"gain", "acceleration", "invert"}) {
          if (t->get(key)) warning(lineOf(*t->get(key)), fmt::format("{}.{}: buttons have no {}", path, key, key));
        }
      }
      if (!seen.insert({b.device, b.button, b.index}).second) {
        error(b.line,
              fmt::format("{}: {} {} of '{}' is already bound", path, b.button ? "button" : "dial", b.index, b.device));
      }
      manifest_.bindings.push_back(std::move(b));
    }
  }

  static double defaultGain(runtime::Action action) {
    switch (action) {
      case runtime::Action::kRotateX:
      case runtime::Action::kRotateY:
      case runtime::Action::kRotateZ: return 360;
      case runtime::Action::kScale:
      case runtime::Action::kTranslateX:
      case runtime::Action::kTranslateY:
      case runtime::Action::kTranslateZ: return 1;
      // The walk-through viewer: a turn of the dial walks 2 scene units or turns a quarter.
      case runtime::Action::kWalk:
      case runtime::Action::kStrafe:
      case runtime::Action::kRise: return 2;
      case runtime::Action::kTurn:
      case runtime::Action::kTilt: return 90;
      case runtime::Action::kNone:
      case runtime::Action::kMoveZoomX:  // the Zoom dials are `basalt run --zoom-dials`, not manifests
      case runtime::Action::kMoveZoomY: return 0;
    }
    return 0;
  }

  // ---- [textures.NAME] ----
  std::optional<std::filesystem::path> imageFile(const toml::table& t, std::string_view name, const std::string& path) {
    const toml::node* node = t.get(name);
    if (!node) return std::nullopt;
    const auto* s = node->as_string();
    if (!s) {
      error(lineOf(*node), fmt::format("{}.{}: must be an image file name", path, name));
      return std::nullopt;
    }
    if (!kImageExtensions.contains(extensionOf(s->get()))) {
      error(lineOf(*node),
            fmt::format("{}.{}: '{}' is not an image (.png, .jpg, .tif, .exr, ...)", path, name, s->get()));
      return std::nullopt;
    }
    auto p = filePath(*node, s->get(), fmt::format("{}.{}", path, name));
    if (p) checkContents(*p, lineOf(*node), fmt::format("{}.{}", path, name));
    return p;
  }

  void readTextures(const toml::table& textures) {
    for (auto&& [k, node] : textures) {
      const std::string name(k.str());
      const std::string path = "textures." + name;
      const toml::table* t = node.as_table();
      if (!t) {
        error(lineOf(node), fmt::format("{}: must be a table ([{}])", path, path));
        continue;
      }
      TextureSpec x;
      x.name = name;
      x.line = lineOf(*t);
      checkKeys(*t, path, {"source", "file", "fallback"});
      if (auto source = string(*t, "source", path)) {
        if (!manifest_.findMedia(*source)) {
          error(lineOf(*t->get("source")), fmt::format("{}.source: no media '{}' in [media]", path, *source));
        } else {
          x.source = *source;
        }
      }
      if (auto file = imageFile(*t, "file", path)) x.file = *file;
      if (auto fallback = imageFile(*t, "fallback", path)) x.fallback = *fallback;
      const bool hasSource = t->get("source") != nullptr;
      const bool hasFile = t->get("file") != nullptr;
      if (hasSource == hasFile) {
        error(x.line, fmt::format("{}: give either source = \"MEDIA\" (a movie, camera or image from [media]) or "
                                  "file = \"IMAGE\"",
                                  path));
      }
      if (hasSource && !t->get("fallback")) {
        const MediaSpec* m = manifest_.findMedia(x.source);
        if (m && m->kind != MediaKind::kImage) {
          warning(x.line,
                  fmt::format("{}: no fallback image; while '{}' is not live the texture shows black", path, x.source));
        }
      }
      manifest_.textures.push_back(std::move(x));
    }
  }

  // ---- [kiosk] ----
  std::vector<PlaylistItem> readItems(const toml::node& node, const std::string& path) {
    std::vector<PlaylistItem> items;
    const toml::array* a = node.as_array();
    if (!a) {
      error(lineOf(node), fmt::format("{}: must be an array of {{ entry = \"...\", duration = \"5m\" }}", path));
      return items;
    }
    std::size_t i = 0;
    for (const toml::node& n : *a) {
      const std::string ip = fmt::format("{}[{}]", path, i++);
      const toml::table* t = n.as_table();
      if (!t) {
        error(lineOf(n), fmt::format("{}: must be {{ entry = \"...\", duration = \"5m\" }}", ip));
        continue;
      }
      checkKeys(*t, ip, {"entry", "duration", "name", "view"});
      PlaylistItem item;
      item.line = lineOf(*t);
      const toml::node* e = t->get("entry");
      if (!e) {
        error(item.line, fmt::format("{}: needs entry = \"FILE\" (or \"default\")", ip));
        continue;
      }
      auto spec = entry(*e, ip + ".entry");
      if (!spec) continue;
      item.entry = *spec;
      entryView(*t, ip, item.entry);
      item.name = string(*t, "name", ip).value_or(spec->path.empty() ? spec->text : spec->path.filename().string());
      if (auto d = duration(*t, "duration", ip)) item.duration = *d;
      if (t->get("duration") && item.duration < std::chrono::seconds(1)) {
        error(lineOf(*t->get("duration")), fmt::format("{}.duration: an item plays at least one second", ip));
      }
      items.push_back(std::move(item));
    }
    if (items.size() > 1) {
      for (std::size_t k = 0; k < items.size(); ++k) {
        const PlaylistItem& item = items[k];
        const bool endsByItself = item.entry.kind == EntryKind::kScript || item.entry.kind == EntryKind::kMovie;
        if (item.duration == Nanos{0} && !endsByItself) {
          error(item.line, fmt::format("{}[{}]: {} never ends by itself; give it a duration so the list moves on", path,
                                       k, item.name));
        }
      }
    }
    return items;
  }

  void readKiosk(const toml::table& t) {
    KioskSpec& k = manifest_.kiosk;
    k.line = lineOf(t);
    checkKeys(t, "kiosk", {"schedule", "attract", "playlist", "resume"});
    if (auto resume = boolean(t, "resume", "kiosk")) k.resume = *resume;
    if (const toml::table* s = table(t, "schedule", "kiosk")) readSchedule(*s);
    if (const toml::table* a = table(t, "attract", "kiosk")) {
      k.attract.present = true;
      k.attract.line = lineOf(*a);
      checkKeys(*a, "kiosk.attract", {"items", "idle_timeout"});
      if (const toml::node* items = a->get("items")) k.attract.items = readItems(*items, "kiosk.attract.items");
      if (k.attract.items.empty()) {
        error(k.attract.line, "kiosk.attract: needs items = [ { entry = \"attract.mdl\", duration = \"30s\" } ]");
      }
      if (auto idle = duration(*a, "idle_timeout", "kiosk.attract")) {
        if (*idle < std::chrono::seconds(5)) {
          error(lineOf(*a->get("idle_timeout")), "kiosk.attract.idle_timeout: at least 5 seconds");
        } else {
          k.attract.idleTimeout = *idle;
        }
      }
    }
    if (const toml::node* playlist = t.get("playlist")) {
      k.playlist = readItems(*playlist, "kiosk.playlist");
      if (k.playlist.empty() && playlist->is_array()) error(lineOf(*playlist), "kiosk.playlist: has no items");
    }
  }

  std::optional<std::vector<TimeRange>> hours(const toml::node& node, const std::string& path) {
    std::vector<TimeRange> ranges;
    std::vector<std::pair<std::string, int>> texts;
    if (const auto* s = node.as_string()) {
      if (s->get() == "closed") return ranges;
      texts.emplace_back(s->get(), lineOf(node));
    } else if (const auto* a = node.as_array()) {
      for (const toml::node& n : *a) {
        const auto* item = n.as_string();
        if (!item) {
          error(lineOf(n), fmt::format("{}: each range is a string like \"09:00-17:00\"", path));
          return std::nullopt;
        }
        texts.emplace_back(item->get(), lineOf(n) > 0 ? lineOf(n) : lineOf(node));
      }
    } else {
      error(lineOf(node), fmt::format("{}: must be \"09:00-17:00\", a list of such ranges, or \"closed\"", path));
      return std::nullopt;
    }
    for (const auto& [text, line] : texts) {
      auto r = parseTimeRange(text);
      if (!r) {
        error(line, fmt::format("{}: {}", path, r.error().message()));
        return std::nullopt;
      }
      ranges.push_back(*r);
    }
    std::sort(ranges.begin(), ranges.end(), [](const TimeRange& a, const TimeRange& b) { return a.begin < b.begin; });
    for (std::size_t i = 1; i < ranges.size(); ++i) {
      if (ranges[i].begin < ranges[i - 1].end) {
        error(lineOf(node), fmt::format("{}: ranges overlap; merge them into one", path));
        return std::nullopt;
      }
    }
    return ranges;
  }

  void readSchedule(const toml::table& t) {
    static constexpr std::string_view kDays[] = {"monday", "tuesday",  "wednesday", "thursday",
                                                 "friday", "saturday", "sunday"};
    ScheduleSpec& s = manifest_.kiosk.schedule;
    s.present = true;
    s.line = lineOf(t);
    checkKeys(t, "kiosk.schedule",
              {"timezone", "outside", "standby", "daily", "monday", "tuesday", "wednesday", "thursday", "friday",
               "saturday", "sunday", "exceptions"});
    if (auto tz = string(t, "timezone", "kiosk.schedule")) {
      if (auto zone = TimeZone::load(*tz); !zone) {
        error(lineOf(*t.get("timezone")), fmt::format("kiosk.schedule.timezone: {}", zone.error().message()));
      } else {
        s.timezone = *tz;
      }
    } else if (!t.get("timezone")) {
      warning(s.line, "kiosk.schedule: no timezone; opening hours are read in UTC (set timezone = \"Europe/Paris\")");
    }
    bool anyDay = false;
    if (const toml::node* daily = t.get("daily")) {
      if (auto h = hours(*daily, "kiosk.schedule.daily")) {
        for (auto& day : s.week) day = *h;
      }
      anyDay = true;
    }
    for (std::size_t d = 0; d < 7; ++d) {
      if (const toml::node* n = t.get(kDays[d])) {
        if (auto h = hours(*n, fmt::format("kiosk.schedule.{}", kDays[d]))) s.week[d] = *h;
        anyDay = true;
      }
    }
    if (!anyDay) {
      error(s.line, "kiosk.schedule: no opening hours; add daily = \"10:00-18:00\" or monday = ... sunday = ...");
    }
    if (auto outside = choice<OutsideHours>(t, "outside", "kiosk.schedule",
                                            {{"standby", OutsideHours::kStandby},
                                             {"black", OutsideHours::kBlack},
                                             {"display_off", OutsideHours::kDisplayOff}})) {
      s.outside = *outside;
    }
    if (const toml::node* standby = t.get("standby")) {
      if (auto e = entry(*standby, "kiosk.schedule.standby")) s.standby = *e;
      if (s.outside != OutsideHours::kStandby) {
        warning(lineOf(*standby), "kiosk.schedule.standby: only shown when outside = \"standby\"");
      }
    } else if (s.outside == OutsideHours::kStandby) {
      error(lineOf(*t.get("outside")), "kiosk.schedule: outside = \"standby\" needs standby = \"FILE\"");
    }
    if (const toml::node* ex = t.get("exceptions")) readExceptions(*ex);
  }

  void readExceptions(const toml::node& node) {
    const toml::array* a = node.as_array();
    if (!a) {
      error(lineOf(node), "kiosk.schedule.exceptions: must be an array of tables ([[kiosk.schedule.exceptions]])");
      return;
    }
    std::set<Date> dates;
    std::size_t i = 0;
    for (const toml::node& n : *a) {
      const std::string path = fmt::format("kiosk.schedule.exceptions[{}]", i++);
      const toml::table* t = n.as_table();
      if (!t) {
        error(lineOf(n), fmt::format("{}: must be a table with date and hours", path));
        continue;
      }
      checkKeys(*t, path, {"date", "hours", "note"});
      ExceptionDay day;
      day.line = lineOf(*t);
      const toml::node* date = t->get("date");
      if (!date) {
        error(day.line, fmt::format("{}: needs date = 2026-12-25", path));
        continue;
      }
      if (const auto* d = date->as_date()) {
        const toml::date v = d->get();
        auto parsed = parseDate(fmt::format("{:04}-{:02}-{:02}", v.year, v.month, v.day));
        if (!parsed) {
          error(lineOf(*date), fmt::format("{}.date: {}", path, parsed.error().message()));
          continue;
        }
        day.date = *parsed;
      } else if (const auto* s = date->as_string()) {
        auto parsed = parseDate(s->get());
        if (!parsed) {
          error(lineOf(*date), fmt::format("{}.date: {}", path, parsed.error().message()));
          continue;
        }
        day.date = *parsed;
      } else {
        error(lineOf(*date), fmt::format("{}.date: must be a date like 2026-12-25", path));
        continue;
      }
      if (!dates.insert(day.date).second) {
        error(day.line,
              fmt::format("{}: {:04}-{:02}-{:02} is listed twice", path, day.date.year, day.date.month, day.date.day));
      }
      if (const toml::node* h = t->get("hours")) {
        if (auto ranges = hours(*h, path + ".hours")) day.hours = *ranges;
      } else {
        error(day.line, fmt::format("{}: needs hours = \"closed\" or \"10:00-14:00\"", path));
      }
      day.note = string(*t, "note", path).value_or("");
      manifest_.kiosk.schedule.exceptions.push_back(std::move(day));
    }
  }

  // ---- [input] ----
  void readInput(const toml::table& t) {
    InputSpec& in = manifest_.input;
    in.line = lineOf(t);
    checkKeys(t, "input", {"evdev", "keyboards", "pointers", "names"});
    if (auto mode = choice<EvdevMode>(t, "evdev", "input",
                                      {{"auto", EvdevMode::kAuto}, {"on", EvdevMode::kOn}, {"off", EvdevMode::kOff}})) {
      in.evdev = *mode;
    }
    if (auto keyboards = boolean(t, "keyboards", "input")) in.keyboards = *keyboards;
    if (auto pointers = boolean(t, "pointers", "input")) in.pointers = *pointers;
    if (const toml::node* names = t.get("names")) {
      const toml::array* a = names->as_array();
      if (!a) {
        error(lineOf(*names), "input.names: must be an array of device names, e.g. [\"Dell KB216\"]");
      } else {
        for (const toml::node& item : *a) {
          const auto* name = item.as_string();
          if (!name || name->get().empty()) {
            error(lineOf(item), "input.names: each entry must be a device name (a non-empty string)");
          } else {
            in.names.push_back(name->get());
          }
        }
      }
    }
    if (!in.keyboards && !in.pointers && in.evdev != EvdevMode::kOff) {
      warning(in.line,
              "input: keyboards and pointers are both false: no keyboard or mouse is read (say evdev = "
              "\"off\" instead)");
    }
    if (in.evdev == EvdevMode::kOn && manifest_.output.kind == OutputKind::kWindow) {
      warning(t.get("evdev") ? lineOf(*t.get("evdev")) : in.line,
              "input.evdev: 'on' with the window output reads every key twice (the window delivers them too)");
    }
  }

  // ---- [lock] ----
  void readLock(const toml::table& t) {
    LockSpec& l = manifest_.lock;
    l.line = lineOf(t);
    checkKeys(t, "lock",
              {"role", "node", "leader", "listen", "port", "followers", "join_timeout_ms", "timeout_ms", "drop_after",
               "leader_timeout_ms", "clock", "key_file", "max_followers", "max_frame_jump"});
    if (auto role =
            choice<LockRole>(t, "role", "lock", {{"leader", LockRole::kLeader}, {"follower", LockRole::kFollower}})) {
      l.role = *role;
    } else if (!t.get("role")) {
      error(l.line, "lock: needs role = \"leader\" or \"follower\"");
    }
    if (auto node = string(t, "node", "lock")) {
      if (node->empty() || node->size() > 32) {
        error(lineOf(*t.get("node")), "lock.node: a name of 1 to 32 characters, unique in the group");
      } else {
        l.node = *node;
      }
    }
    if (auto leader = string(t, "leader", "lock")) l.leader = *leader;
    if (auto listen = string(t, "listen", "lock")) {
      if (isAddress(*listen)) {
        l.listen = *listen;
      } else {
        error(lineOf(*t.get("listen")),
              fmt::format("lock.listen: '{}' is not an IP address; name one of this node's addresses (the one "
                          "facing the followers), or \"0.0.0.0\" for every interface",
                          *listen));
      }
    }
    if (auto port = integer(t, "port", "lock", 1, 65533)) l.port = static_cast<int>(*port);
    if (auto n = integer(t, "followers", "lock", 0, 256)) l.followers = static_cast<int>(*n);
    if (auto ms = integer(t, "join_timeout_ms", "lock", 0, 600000)) l.joinTimeoutMs = static_cast<int>(*ms);
    if (auto ms = integer(t, "timeout_ms", "lock", 1, 10000)) l.timeoutMs = static_cast<int>(*ms);
    if (auto n = integer(t, "drop_after", "lock", 1, 10000)) l.dropAfter = static_cast<int>(*n);
    if (auto ms = integer(t, "leader_timeout_ms", "lock", 10, 600000)) l.leaderTimeoutMs = static_cast<int>(*ms);
    if (auto clock = boolean(t, "clock", "lock")) l.clock = *clock;
    if (auto n = integer(t, "max_followers", "lock", 1, 256)) l.maxFollowers = static_cast<int>(*n);
    if (auto n = integer(t, "max_frame_jump", "lock", 1, 1000000)) l.maxFrameJump = static_cast<int>(*n);
    if (l.followers > l.maxFollowers) {
      error(lineOf(*t.get("followers")),
            fmt::format("lock.followers: {} is more than max_followers ({}); raise max_followers", l.followers,
                        l.maxFollowers));
    }
    if (auto keyFile = string(t, "key_file", "lock")) readLockKeyFile(*keyFile, lineOf(*t.get("key_file")));
    if (l.role != LockRole::kOff && l.keyFile.empty() && !l.loopbackOnly()) {
      warning(t.get("listen") ? lineOf(*t.get("listen")) : l.line,
              fmt::format("lock: {} '{}' without key_file: the frame lock is unauthenticated, and anything that "
                          "reaches the port can freeze or steer the show; give every node the same key_file "
                          "(make it with: openssl rand -hex 32 > lock.key; chmod 600 lock.key)",
                          l.role == LockRole::kFollower ? "the leader at" : "listening on",
                          l.role == LockRole::kFollower ? l.leader : l.listen));
    }
    if (l.role == LockRole::kFollower && l.leader.empty()) {
      error(l.line, "lock: a follower needs leader = \"ADDRESS\" (the leader's IP address or host name)");
    }
    if (l.role == LockRole::kLeader && t.get("leader")) {
      warning(lineOf(*t.get("leader")), "lock.leader: ignored on the leader (it listens on lock.listen)");
    }
    if (l.role == LockRole::kFollower && (t.get("followers") || t.get("timeout_ms") || t.get("drop_after"))) {
      warning(l.line, "lock: followers, timeout_ms and drop_after are the leader's; a follower ignores them");
    }
  }

  /// `lock.key_file`: a credential, so it may live outside the show folder; checked for being
  /// there, long enough and readable only by its owner.
  void readLockKeyFile(std::string_view file, int line) {
    std::filesystem::path p(file);
    if (p.is_relative()) p = folder_ / p;
    manifest_.lock.keyFile = p;
    std::error_code ec;
    if (!std::filesystem::is_regular_file(p, ec)) {
      warning(line, fmt::format("lock.key_file: '{}' does not exist yet; the lock does not start until it does (make "
                                "it with: openssl rand -hex 32 > {}; chmod 600 {})",
                                file, p.string(), p.string()));
      return;
    }
    using std::filesystem::perms;
    const perms mode = std::filesystem::status(p, ec).permissions();
    if (!ec && (mode & (perms::group_all | perms::others_all)) != perms::none) {
      warning(line, fmt::format("lock.key_file: '{}' is readable by other users; make it the service's only (chmod "
                                "600 {})",
                                file, p.string()));
    }
    if (auto key = readLockKey(p); !key) error(line, fmt::format("lock.key_file: {}", key.error().message()));
  }

  // ---- [osc] ----
  /// "HOST:PORT" or "[V6]:PORT" into its parts; an empty string, or why it is not one.
  static std::string splitHostPort(std::string_view text, std::string& host, int& port) {
    std::string_view h = text;
    std::string_view p;
    if (text.starts_with('[')) {
      const auto close = text.find(']');
      if (close == std::string_view::npos || close + 1 >= text.size() || text[close + 1] != ':') {
        return fmt::format("'{}' is not [ADDRESS]:PORT", text);
      }
      h = text.substr(1, close - 1);
      p = text.substr(close + 2);
    } else if (const auto colon = text.rfind(':'); colon != std::string_view::npos) {
      h = text.substr(0, colon);
      p = text.substr(colon + 1);
    } else {
      return fmt::format("'{}' needs a port: ADDRESS:PORT", text);
    }
    if (!parseUnsigned(p, port) || port < 0 || port > 65535) return fmt::format("port '{}' is not 0 to 65535", p);
    if (h.empty()) return fmt::format("'{}' needs an address before the port", text);
    host = std::string(h);
    return {};
  }

  static bool numericAddress(const std::string& text) {
    in6_addr v6{};
    in_addr v4{};
    return ::inet_pton(AF_INET, text.c_str(), &v4) == 1 || ::inet_pton(AF_INET6, text.c_str(), &v6) == 1;
  }

  void readOsc(const toml::table& t) {
    OscSpec& o = manifest_.osc;
    o.enabled = true;
    o.line = lineOf(t);
    o.messagesPerSecond = manifest_.status.requestsPerSecond;  // the same limit as the HTTP controls
    checkKeys(t, "osc", {"enabled", "listen", "protocols", "allow", "messages_per_second", "bind", "send"});
    if (auto enabled = boolean(t, "enabled", "osc")) o.enabled = *enabled;
    if (auto listen = string(t, "listen", "osc")) {
      int port = 0;
      if (auto why = splitHostPort(*listen, o.host, port); !why.empty()) {
        error(lineOf(*t.get("listen")), fmt::format("osc.listen: {}; e.g. 127.0.0.1:9000", why));
      } else if (!numericAddress(o.host) && o.host != "localhost") {
        error(lineOf(*t.get("listen")),
              fmt::format("osc.listen: '{}' is not an address of this machine (127.0.0.1, 0.0.0.0, ::, ...)", o.host));
      } else {
        o.port = static_cast<std::uint16_t>(port);
      }
    }
    if (const toml::node* node = t.get("protocols")) {
      const toml::array* a = node->as_array();
      if (!a || a->empty()) {
        error(lineOf(*node), "osc.protocols: must be a list of \"udp\" and \"tcp\"");
      } else {
        o.udp = o.tcp = false;
        for (const toml::node& p : *a) {
          const auto* name = p.as_string();
          if (name && name->get() == "udp") {
            o.udp = true;
          } else if (name && name->get() == "tcp") {
            o.tcp = true;
          } else {
            error(lineOf(p), "osc.protocols: each is \"udp\" or \"tcp\"");
          }
        }
      }
    }
    if (const toml::node* node = t.get("allow")) {
      const toml::array* a = node->as_array();
      if (!a) {
        error(lineOf(*node), "osc.allow: must be a list of senders' addresses, e.g. [\"127.0.0.1\", \"10.0.0.5\"]");
      } else {
        for (const toml::node& p : *a) {
          const auto* address = p.as_string();
          if (!address || !numericAddress(address->get())) {
            error(lineOf(p), fmt::format("osc.allow: '{}' is not an IPv4 or IPv6 address",
                                         address ? address->get() : std::string(typeName(p))));
            continue;
          }
          o.allow.push_back(address->get());
        }
      }
    }
    if (auto rate = number(t, "messages_per_second", "osc", 1, 10000)) o.messagesPerSecond = *rate;
    if (o.enabled && !o.loopbackOnly() && o.allow.empty()) {
      warning(t.get("listen") ? lineOf(*t.get("listen")) : o.line,
              fmt::format("osc.listen: '{}' lets any machine that reaches port {} drive the show; list the senders "
                          "in osc.allow",
                          o.host, o.port));
    }
    if (const toml::node* node = t.get("bind")) {
      const toml::array* a = node->as_array();
      if (!a) {
        error(lineOf(*node), "osc.bind: must be an array of tables ([[osc.bind]])");
      } else {
        std::set<std::string> seen;
        std::size_t index = 0;
        for (const toml::node& item : *a) {
          const std::string path = fmt::format("osc.bind[{}]", index++);
          const toml::table* b = item.as_table();
          if (!b) {
            error(lineOf(item), fmt::format("{}: must be a table", path));
            continue;
          }
          if (auto spec = readOscBinding(*b, path)) {
            if (!seen.insert(spec->address).second) {
              error(spec->line, fmt::format("{}.address: '{}' is already bound", path, spec->address));
              continue;
            }
            o.bindings.push_back(std::move(*spec));
          }
        }
      }
    }
    if (const toml::node* node = t.get("send")) {
      const toml::array* a = node->as_array();
      if (!a) {
        error(lineOf(*node), "osc.send: must be an array of tables ([[osc.send]])");
      } else {
        std::size_t index = 0;
        for (const toml::node& item : *a) {
          const std::string path = fmt::format("osc.send[{}]", index++);
          const toml::table* d = item.as_table();
          if (!d) {
            error(lineOf(item), fmt::format("{}: must be a table", path));
            continue;
          }
          if (auto spec = readOscSend(*d, path)) o.send.push_back(std::move(*spec));
        }
      }
    }
  }

  /// Why `address` cannot be an OSC method's address, or "".
  static std::string oscAddressProblem(std::string_view address) {
    if (!address.starts_with('/')) return "must start with '/'";
    if (address.size() > kOscMaxAddressBytes) return fmt::format("is longer than {} bytes", kOscMaxAddressBytes);
    if (address.ends_with('/')) return "must not end with '/'";
    for (const char c : address) {
      if (c <= ' ' || c > '~' || c == '#' || c == ',')
        return "may hold only printable characters, no space, '#' or ','";
      if (std::string_view("?*[]{}").find(c) != std::string_view::npos) {
        return fmt::format("holds '{}', which OSC keeps for patterns a sender matches against", c);
      }
    }
    if (address.find("//") != std::string_view::npos) return "has an empty part ('//')";
    return {};
  }

  std::optional<std::array<double, 2>> pair(const toml::table& t, std::string_view name, const std::string& path) {
    const toml::node* node = t.get(name);
    if (!node) return std::nullopt;
    const toml::array* a = node->as_array();
    std::array<double, 2> out{};
    if (a && a->size() == 2) {
      for (std::size_t i = 0; i < 2; ++i) {
        const toml::node& v = (*a)[i];
        if (const auto* n = v.as_integer()) {
          out[i] = static_cast<double>(n->get());
        } else if (const auto* f = v.as_floating_point(); f && std::isfinite(f->get())) {
          out[i] = f->get();
        } else {
          a = nullptr;
          break;
        }
      }
    } else {
      a = nullptr;
    }
    if (!a) {
      error(lineOf(*node), fmt::format("{}.{}: must be two numbers, [LOW, HIGH]", path, name));
      return std::nullopt;
    }
    return out;
  }

  std::optional<OscBindingSpec> readOscBinding(const toml::table& t, const std::string& path) {
    OscBindingSpec b;
    b.line = lineOf(t);
    checkKeys(t, path, {"address", "action", "command", "types", "input", "range", "mode"});
    bool ok = true;
    if (auto address = string(t, "address", path)) {
      if (auto why = oscAddressProblem(*address); !why.empty()) {
        error(lineOf(*t.get("address")), fmt::format("{}.address: '{}' {}", path, *address, why));
        ok = false;
      } else if (address->starts_with("/tracker/")) {
        error(lineOf(*t.get("address")),
              fmt::format("{}.address: '{}': addresses under /tracker/ are kept for tracker devices", path, *address));
        ok = false;
      }
      b.address = *address;
    } else {
      if (!t.get("address")) error(b.line, fmt::format("{}: needs address = \"/...\"", path));
      ok = false;
    }
    const toml::node* actionNode = t.get("action");
    auto action = string(t, "action", path);
    if (!action) {
      if (!actionNode) error(b.line, fmt::format("{}: needs action = \"...\"", path));
      return std::nullopt;
    }
    static constexpr std::array<std::pair<std::string_view, OscDo>, 5> kControls{{{"next", OscDo::kNext},
                                                                                  {"previous", OscDo::kPrevious},
                                                                                  {"reload", OscDo::kReload},
                                                                                  {"reset_view", OscDo::kResetView},
                                                                                  {"command", OscDo::kCommand}}};
    bool known = false;
    for (const auto& [name, what] : kControls) {
      if (*action == name) b.what = what, known = true;
    }
    if (!known) {
      const auto dial = runtime::actionByName(*action);
      if (dial && *dial != runtime::Action::kNone && *dial != runtime::Action::kMoveZoomX &&
          *dial != runtime::Action::kMoveZoomY) {
        b.what = OscDo::kDial;
        b.action = *dial;
        known = true;
      }
    }
    if (!known) {
      static constexpr std::array<std::string_view, 18> kNames{
          "rotate_x", "rotate_y", "rotate_z", "scale", "translate_x", "translate_y", "translate_z", "walk",    "strafe",
          "rise",     "turn",     "tilt",     "next",  "previous",    "reload",      "reset_view",  "command", ""};
      std::string_view best;
      std::size_t bestDistance = 3;
      for (const std::string_view n : kNames) {
        if (n.empty()) continue;
        if (const std::size_t d = editDistance(*action, n); d < bestDistance) bestDistance = d, best = n;
      }
      error(lineOf(*actionNode),
            fmt::format("{}.action: unknown action '{}'{}; OSC bindings take rotate_x, rotate_y, rotate_z, scale, "
                        "translate_x, translate_y, translate_z, walk, strafe, rise, turn, tilt, next, previous, "
                        "reload, reset_view or command",
                        path, *action, best.empty() ? std::string() : fmt::format(" (did you mean '{}'?)", best)));
      return std::nullopt;
    }
    // The command and its placeholders $1..$8.
    std::size_t highest = 0;
    std::set<std::size_t> used;
    if (auto command = string(t, "command", path)) {
      if (b.what != OscDo::kCommand) {
        error(lineOf(*t.get("command")), fmt::format("{}.command: only action = \"command\" runs a command", path));
        ok = false;
      }
      b.command = *command;
      for (std::size_t i = 0; i + 1 < command->size(); ++i) {
        if ((*command)[i] == '$' && std::isdigit(static_cast<unsigned char>((*command)[i + 1]))) {
          const std::size_t n = static_cast<std::size_t>((*command)[i + 1] - '0');
          if (n == 0 || n > kOscMaxArguments ||
              (i + 2 < command->size() && std::isdigit(static_cast<unsigned char>((*command)[i + 2])))) {
            error(lineOf(*t.get("command")),
                  fmt::format("{}.command: placeholders are $1 to ${}", path, kOscMaxArguments));
            ok = false;
            break;
          }
          used.insert(n);
          highest = std::max(highest, n);
        }
      }
      if (command->empty() || command->find('\n') != std::string::npos) {
        error(lineOf(*t.get("command")), fmt::format("{}.command: must be one LAVA script command", path));
        ok = false;
      }
      if (command->size() > 1024) {
        error(lineOf(*t.get("command")), fmt::format("{}.command: a command is at most 1024 bytes", path));
        ok = false;
      }
    } else if (b.what == OscDo::kCommand && !t.get("command")) {
      error(b.line, fmt::format("{}: action = \"command\" needs command = \"...\" (a LAVA script command; $1, $2 "
                                "... stand for the message's arguments)",
                                path));
      ok = false;
    }
    // The types, and their number against what the action takes.
    switch (b.what) {
      case OscDo::kDial: b.types = "f"; break;
      case OscDo::kCommand: b.types = std::string(highest, 'f'); break;
      default: b.types = ""; break;
    }
    const toml::node* typesNode = t.get("types");
    if (auto types = string(t, "types", path)) {
      b.types = *types;
      if (types->size() > kOscMaxArguments || types->find_first_not_of("fs") != std::string::npos) {
        error(lineOf(*typesNode), fmt::format("{}.types: '{}' must be at most {} of 'f' (a number) and 's' (a string)",
                                              path, *types, kOscMaxArguments));
        ok = false;
      }
    }
    const int typesLine = typesNode ? lineOf(*typesNode) : b.line;
    const std::string_view actionText = *action;
    if (b.what == OscDo::kDial && b.types != "f") {
      error(typesLine, fmt::format("{}: wrong arity: '{}' takes one number (types = \"f\"), not \"{}\"", path,
                                   actionText, b.types));
      ok = false;
    } else if ((b.what == OscDo::kNext || b.what == OscDo::kPrevious || b.what == OscDo::kReload ||
                b.what == OscDo::kResetView) &&
               !b.types.empty() && b.types != "f") {
      error(typesLine, fmt::format("{}: wrong arity: '{}' takes no argument, or one number (types = \"f\": a button, "
                                   "acting when it is 0.5 or more), not \"{}\"",
                                   path, actionText, b.types));
      ok = false;
    } else if (b.what == OscDo::kCommand && !b.types.empty()) {
      for (std::size_t n = 1; n <= b.types.size(); ++n) {
        if (!used.contains(n)) {
          error(typesLine, fmt::format("{}: wrong arity: types = \"{}\" gives {} arguments, but the command has no "
                                       "${}",
                                       path, b.types, b.types.size(), n));
          ok = false;
          break;
        }
      }
    }
    if (b.what == OscDo::kCommand && highest > b.types.size()) {
      error(typesLine, fmt::format("{}: wrong arity: the command uses ${}, but types = \"{}\" gives {} argument{}",
                                   path, highest, b.types, b.types.size(), b.types.size() == 1 ? "" : "s"));
      ok = false;
    }
    const bool numbers = b.types.find('f') != std::string::npos;
    if (auto input = pair(t, "input", path)) {
      if ((*input)[0] == (*input)[1]) {
        error(lineOf(*t.get("input")), fmt::format("{}.input: LOW and HIGH must differ", path));
        ok = false;
      }
      b.input = *input;
    }
    if (auto range = pair(t, "range", path)) b.range = *range;
    if (!numbers && (t.get("input") || t.get("range"))) {
      warning(lineOf(*t.get(t.get("input") ? "input" : "range")),
              fmt::format("{}: no argument is a number, so input and range scale nothing", path));
    }
    if (auto mode = choice<bool>(t, "mode", path, {{"relative", false}, {"absolute", true}})) {
      b.absolute = *mode;
      if (b.what != OscDo::kDial) {
        warning(lineOf(*t.get("mode")), fmt::format("{}.mode: only dial actions move by a change", path));
      }
    }
    if (b.what == OscDo::kDial && !b.range) b.range = std::array<double, 2>{0, defaultGain(b.action)};
    if (!ok) return std::nullopt;
    return b;
  }

  std::optional<OscSendSpec> readOscSend(const toml::table& t, const std::string& path) {
    OscSendSpec d;
    d.line = lineOf(t);
    checkKeys(t, path, {"to", "protocol", "prefix", "events", "figures", "rate"});
    bool ok = true;
    if (auto to = string(t, "to", path)) {
      int port = 0;
      if (auto why = splitHostPort(*to, d.host, port); !why.empty()) {
        error(lineOf(*t.get("to")), fmt::format("{}.to: {}; e.g. \"127.0.0.1:9001\"", path, why));
        ok = false;
      } else if (port == 0) {
        error(lineOf(*t.get("to")), fmt::format("{}.to: port 0 is no destination; give the port that listens", path));
        ok = false;
      } else {
        d.port = static_cast<std::uint16_t>(port);
      }
    } else {
      if (!t.get("to")) error(d.line, fmt::format("{}: needs to = \"HOST:PORT\"", path));
      ok = false;
    }
    if (auto tcp = choice<bool>(t, "protocol", path, {{"udp", false}, {"tcp", true}})) d.tcp = *tcp;
    if (auto prefix = string(t, "prefix", path)) {
      if (auto why = oscAddressProblem(*prefix); !why.empty()) {
        error(lineOf(*t.get("prefix")), fmt::format("{}.prefix: '{}' {}", path, *prefix, why));
        ok = false;
      }
      d.prefix = *prefix;
    }
    if (const toml::node* node = t.get("events")) {
      const toml::array* a = node->as_array();
      if (!a) {
        error(lineOf(*node), fmt::format("{}.events: must be a list of \"item\", \"devices\" and \"lock\"", path));
        ok = false;
      } else {
        d.item = d.devices = d.lock = false;
        for (const toml::node& e : *a) {
          const auto* name = e.as_string();
          const std::string text = name ? name->get() : std::string();
          if (text == "item") {
            d.item = true;
          } else if (text == "devices") {
            d.devices = true;
          } else if (text == "lock") {
            d.lock = true;
          } else {
            error(lineOf(e), fmt::format("{}.events: '{}' is not one of item, devices or lock", path, text));
            ok = false;
          }
        }
      }
    }
    if (const toml::node* node = t.get("figures")) {
      const toml::array* a = node->as_array();
      if (!a) {
        error(lineOf(*node), fmt::format("{}.figures: must be a list of names", path));
        ok = false;
      } else {
        for (const toml::node& e : *a) {
          const auto* name = e.as_string();
          const std::string text = name ? name->get() : std::string();
          if (std::ranges::find(kOscFigureNames, text) == kOscFigureNames.end()) {
            error(lineOf(e),
                  fmt::format("{}.figures: '{}' is not one of {}", path, text, fmt::join(kOscFigureNames, ", ")));
            ok = false;
            continue;
          }
          d.figures.push_back(text);
        }
      }
    }
    if (auto rate = number(t, "rate", path, 0.1, 60)) d.rate = *rate;
    if (t.get("rate") && d.figures.empty()) {
      warning(lineOf(*t.get("rate")), fmt::format("{}.rate: no figures to send at this rate", path));
    }
    if (!ok) return std::nullopt;
    return d;
  }

  // ---- [status] ----
  void readStatus(const toml::table& t) {
    StatusSpec& s = manifest_.status;
    s.enabled = true;
    s.line = lineOf(t);
    checkKeys(t, "status",
              {"enabled", "listen", "token", "token_file", "max_request_bytes", "requests_per_second", "read_token",
               "read_token_file", "snapshot"});
    if (auto enabled = boolean(t, "enabled", "status")) s.enabled = *enabled;
    if (auto listen = string(t, "listen", "status")) readListen(*listen, lineOf(*t.get("listen")));
    if (auto token = string(t, "token", "status")) {
      if (token->size() < 16) {
        error(lineOf(*t.get("token")), "status.token: at least 16 characters; make one with 'openssl rand -hex 16'");
      } else {
        s.token = *token;
        warning(lineOf(*t.get("token")),
                "status.token: a token written in show.toml travels with the show; prefer token_file");
      }
    }
    if (auto tokenFile = string(t, "token_file", "status")) {
      // A credential, not media: it may live outside the show folder (/etc/basalt, $CREDENTIALS_DIRECTORY).
      std::filesystem::path p(*tokenFile);
      if (p.is_relative()) p = folder_ / p;
      std::error_code ec;
      if (!std::filesystem::is_regular_file(p, ec)) {
        warning(lineOf(*t.get("token_file")),
                fmt::format("status.token_file: '{}' does not exist yet; controls stay off until it does (make it "
                            "with: openssl rand -hex 16 > {})",
                            *tokenFile, p.string()));
      }
      s.tokenFile = p;
      if (t.get("token")) error(lineOf(*t.get("token_file")), "status: give token or token_file, not both");
    }
    if (auto bytes = integer(t, "max_request_bytes", "status", 1024, 1 << 20)) {
      s.maxRequestBytes = static_cast<std::size_t>(*bytes);
    }
    if (auto rate = number(t, "requests_per_second", "status", 1, 1000)) s.requestsPerSecond = *rate;
    if (auto snapshot = boolean(t, "snapshot", "status")) s.snapshot = *snapshot;
    if (auto token = string(t, "read_token", "status")) {
      if (token->size() < 16) {
        error(lineOf(*t.get("read_token")),
              "status.read_token: at least 16 characters; make one with 'openssl rand -hex 16'");
      } else {
        s.readToken = *token;
      }
    }
    if (auto tokenFile = string(t, "read_token_file", "status")) {
      std::filesystem::path p(*tokenFile);
      if (p.is_relative()) p = folder_ / p;
      std::error_code ec;
      if (!std::filesystem::is_regular_file(p, ec)) {
        warning(lineOf(*t.get("read_token_file")),
                fmt::format("status.read_token_file: '{}' does not exist yet; other machines cannot read the status "
                            "until it does (make it with: openssl rand -hex 16 > {})",
                            *tokenFile, p.string()));
      }
      s.readTokenFile = p;
      if (t.get("read_token")) {
        error(lineOf(*t.get("read_token_file")), "status: give read_token or read_token_file, not both");
      }
    }
    if (s.loopbackOnly() && (t.get("read_token") || t.get("read_token_file"))) {
      const char* key = t.get("read_token") ? "read_token" : "read_token_file";
      warning(lineOf(*t.get(key)),
              fmt::format("status.{}: the server listens on {}, which only this machine reaches, and this machine "
                          "reads without a token; the token takes effect with a listen address other machines reach",
                          key, s.host));
    }
    if (s.enabled && !s.loopbackOnly() && s.token.empty() && s.tokenFile.empty()) {
      error(t.get("listen") ? lineOf(*t.get("listen")) : s.line,
            fmt::format("status.listen: '{}' opens the server beyond this machine; that needs token_file (controls "
                        "change the show)",
                        s.host));
    }
  }

  void readListen(std::string_view listen, int line) {
    StatusSpec& s = manifest_.status;
    std::string_view host = listen;
    std::string_view port;
    if (listen.starts_with('[')) {
      const auto close = listen.find(']');
      if (close == std::string_view::npos || close + 1 >= listen.size() || listen[close + 1] != ':') {
        error(line, fmt::format("status.listen: '{}' is not [ADDRESS]:PORT", listen));
        return;
      }
      host = listen.substr(1, close - 1);
      port = listen.substr(close + 2);
    } else if (const auto colon = listen.rfind(':'); colon != std::string_view::npos) {
      host = listen.substr(0, colon);
      port = listen.substr(colon + 1);
    } else {
      error(line, fmt::format("status.listen: '{}' needs a port: ADDRESS:PORT, e.g. 127.0.0.1:8180", listen));
      return;
    }
    int p = -1;
    if (!parseUnsigned(port, p) || p < 0 || p > 65535) {
      error(line, fmt::format("status.listen: port '{}' is not 0 to 65535", port));
      return;
    }
    if (host.empty()) {
      error(line, "status.listen: needs an address; 127.0.0.1 keeps the server on this machine");
      return;
    }
    s.host = std::string(host);
    s.port = static_cast<std::uint16_t>(p);
  }

  static constexpr std::uintmax_t kMaxManifestBytes = 1 << 20;

  Diagnostics& diags_;
  const ReadOptions& options_;
  std::filesystem::path file_;
  std::filesystem::path folder_;
  std::filesystem::path shown_;  // the manifest's name as the user gave it, for messages
  Manifest manifest_;
  std::vector<Diagnostic> diagsOwn_;
  std::vector<Diagnostic> diagsReferenced_;
  std::set<std::string> checked_;
};

}  // namespace

std::optional<Manifest> readManifest(const std::filesystem::path& file, Diagnostics& diagnostics,
                                     const ReadOptions& options) {
  return Reader(file, diagnostics, options).read();
}

std::optional<Manifest> readManifestText(std::string_view text, const std::filesystem::path& file,
                                         Diagnostics& diagnostics, const ReadOptions& options) {
  return Reader(file, diagnostics, options).readText(text);
}

}  // namespace basalt::kiosk
