// Trace folders: trace.toml (a small TOML subset that Basalt writes and reads: `key = value`
// with strings, numbers and booleans, `[[device]]` tables, comments), hid-recorder files for
// dial boxes and trace videos for cameras. File names in trace.toml may not leave the folder.

#include "sim/trace.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

#include <fmt/chrono.h>
#include <fmt/format.h>

#include "devices/midi/midi_decoder.h"
#include "sim/hid_comments.h"
#include "sim/hid_recording.h"
#include "sim/midi_file.h"
#include "sim/raw_video.h"

namespace basalt::sim {

namespace {

std::string quote(std::string_view s) {
  std::string out = "\"";
  for (char c : s) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\t': out += "\\t"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          out += fmt::format("\\u{:04x}", static_cast<unsigned>(c));
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

std::string hexBytes(const std::vector<std::uint8_t>& bytes) {
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    if (i) out += " ";
    out += fmt::format("{:02x}", bytes[i]);
  }
  return out;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

struct Value {
  enum class Type : std::uint8_t { kString, kNumber, kBool } type = Type::kString;
  std::string text;
  double number = 0;
  bool boolean = false;
};

/// Parses the value after '=' (and an optional trailing comment); false with `why` on error.
bool parseValue(std::string_view s, Value& v, std::string& why) {
  s = trim(s);
  if (s.empty()) {
    why = "a value is missing after '='";
    return false;
  }
  std::string_view rest;
  if (s.front() == '"') {
    v.type = Value::Type::kString;
    std::size_t i = 1;
    for (; i < s.size() && s[i] != '"'; ++i) {
      if (s[i] == '\\' && i + 1 < s.size()) {
        const char e = s[++i];
        switch (e) {
          case 'n': v.text += '\n'; break;
          case 't': v.text += '\t'; break;
          case '"': v.text += '"'; break;
          case '\\': v.text += '\\'; break;
          case 'u': {
            unsigned code = 0;
            if (i + 4 >= s.size() || std::from_chars(s.data() + i + 1, s.data() + i + 5, code, 16).ec != std::errc{}) {
              why = "a \\u escape needs four hexadecimal digits";
              return false;
            }
            v.text += static_cast<char>(code < 0x80 ? code : '?');
            i += 4;
            break;
          }
          default: why = fmt::format("unknown escape '\\{}'", e); return false;
        }
      } else {
        v.text += s[i];
      }
    }
    if (i >= s.size()) {
      why = "a string is not closed with '\"'";
      return false;
    }
    rest = trim(s.substr(i + 1));
  } else {
    const auto hash = s.find('#');
    const std::string_view word = trim(s.substr(0, hash));
    rest = hash == std::string_view::npos ? std::string_view{} : s.substr(hash);
    if (word == "true" || word == "false") {
      v.type = Value::Type::kBool;
      v.boolean = word == "true";
    } else {
      v.type = Value::Type::kNumber;
      const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), v.number);
      if (ec != std::errc{} || end != word.data() + word.size() || !std::isfinite(v.number)) {
        why = fmt::format("'{}' is not a string, number or true/false", word);
        return false;
      }
    }
  }
  if (!rest.empty() && rest.front() != '#') {
    why = fmt::format("unexpected '{}' after the value", rest.substr(0, 20));
    return false;
  }
  return true;
}

bool parseHexList(std::string_view s, std::vector<std::uint8_t>& out) {
  out.clear();
  std::size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && s[i] == ' ') ++i;
    if (i >= s.size()) break;
    unsigned v = 0;
    const auto [end, ec] = std::from_chars(s.data() + i, s.data() + std::min(s.size(), i + 2), v, 16);
    if (ec != std::errc{} || end != s.data() + std::min(s.size(), i + 2)) return false;
    if (out.size() >= 65536) return false;
    out.push_back(static_cast<std::uint8_t>(v));
    i += 2;
  }
  return true;
}

PixelFormat formatByName(std::string_view name) {
  for (int f = 1; f <= static_cast<int>(PixelFormat::kMjpeg); ++f) {
    if (pixelFormatName(static_cast<PixelFormat>(f)) == name) return static_cast<PixelFormat>(f);
  }
  return PixelFormat::kUnknown;
}

}  // namespace

std::string formatTraceToml(const TraceInfo& info) {
  std::string out = "# A Basalt trace: replay it with the replay backend (see sim/README.md, \"Traces\").\n";
  out += "format = 1\n";
  out += fmt::format("recorded = {}\n", quote(info.recorded));
  out += fmt::format("host = {}\n", quote(info.host));
  out += fmt::format("basalt = {}\n", quote(info.basalt));
  out += fmt::format("fps = {}\n", info.fps);
  out += fmt::format("seconds = {:.6f}\n", info.seconds);
  for (const TraceDevice& d : info.devices) {
    out += "\n[[device]]\n";
    out += fmt::format("name = {}\n", quote(d.name));
    out += fmt::format("kind = {}\n", quote(d.kind == devices::DeviceKind::kDialBox   ? "dial box"
                                            : d.kind == devices::DeviceKind::kTracker ? "tracker"
                                                                                      : "video source"));
    out += fmt::format("file = {}\n", quote(d.file));
    out += fmt::format("device = {}\n", quote(d.info.name));
    out += fmt::format("backend = {}\n", quote(d.info.backend));
    out += fmt::format("bus = {}\n", quote(d.info.bus));
    out += fmt::format("vendor = \"{:04x}\"\n", d.info.vendor);
    out += fmt::format("product = \"{:04x}\"\n", d.info.product);
    out += fmt::format("path = {}\n", quote(d.info.path));
    if (!d.info.serial.empty()) out += fmt::format("serial = {}\n", quote(d.info.serial));
    if (d.kind != devices::DeviceKind::kVideoSource) {
      out += fmt::format("descriptor = \"{}\"\n", hexBytes(d.descriptor));
    } else {
      out += fmt::format("format = {}\n", quote(pixelFormatName(d.mode.format)));
      out += fmt::format("width = {}\nheight = {}\n", d.mode.width, d.mode.height);
      out += fmt::format("video_fps = {}\n", d.mode.fps);
    }
  }
  return out;
}

Result<TraceInfo> parseTraceToml(std::string_view text, std::string_view name) {
  TraceInfo info;
  TraceDevice* device = nullptr;
  int lineNo = 0;
  bool sawFormat = false;
  auto bad = [&](std::string what) { return fail(Errc::kParse, std::move(what), fmt::format("{}:{}", name, lineNo)); };
  std::size_t pos = 0;
  while (pos <= text.size()) {
    const std::size_t nl = text.find('\n', pos);
    const std::string_view line = trim(text.substr(pos, nl == std::string_view::npos ? text.size() - pos : nl - pos));
    pos = nl == std::string_view::npos ? text.size() + 1 : nl + 1;
    ++lineNo;
    if (line.empty() || line.front() == '#') continue;
    if (line == "[[device]]") {
      if (info.devices.size() >= 64) return bad("more than 64 devices");
      info.devices.emplace_back();
      device = &info.devices.back();
      continue;
    }
    if (line.front() == '[') return bad(fmt::format("unknown table '{}'; a trace has only [[device]] tables", line));
    const auto eq = line.find('=');
    if (eq == std::string_view::npos) return bad("expected 'key = value'");
    const std::string_view key = trim(line.substr(0, eq));
    Value v;
    std::string why;
    if (!parseValue(line.substr(eq + 1), v, why)) return bad(why);
    auto str = [&]() -> Result<std::string> {
      if (v.type != Value::Type::kString) return bad(fmt::format("{} must be a string", key));
      return v.text;
    };
    auto num = [&](double lo, double hi) -> Result<double> {
      if (v.type != Value::Type::kNumber || v.number < lo || v.number > hi) {
        return bad(fmt::format("{} must be a number from {} to {}", key, lo, hi));
      }
      return v.number;
    };
    auto hex16 = [&](std::uint16_t& out) -> Result<void> {
      auto s = str();
      if (!s) return std::unexpected(s.error());
      unsigned x = 0;
      const auto [end, ec] = std::from_chars(s->data(), s->data() + s->size(), x, 16);
      if (ec != std::errc{} || end != s->data() + s->size() || x > 0xffff) {
        return bad(fmt::format("{} must be 4 hexadecimal digits", key));
      }
      out = static_cast<std::uint16_t>(x);
      return {};
    };
    Result<void> r;
    if (!device) {
      if (key == "format") {
        auto n = num(1, 1);
        if (!n) return bad("this trace was written by a newer Basalt (format is not 1)");
        sawFormat = true;
      } else if (key == "recorded") {
        auto s = str();
        if (!s) return std::unexpected(s.error());
        info.recorded = *s;
      } else if (key == "host") {
        auto s = str();
        if (!s) return std::unexpected(s.error());
        info.host = *s;
      } else if (key == "basalt") {
        auto s = str();
        if (!s) return std::unexpected(s.error());
        info.basalt = *s;
      } else if (key == "fps") {
        auto n = num(0, 1000);
        if (!n) return std::unexpected(n.error());
        info.fps = *n;
      } else if (key == "seconds") {
        auto n = num(0, 1e9);
        if (!n) return std::unexpected(n.error());
        info.seconds = *n;
      }
      continue;
    }
    TraceDevice& d = *device;
    if (key == "name" || key == "file" || key == "device" || key == "backend" || key == "bus" || key == "path" ||
        key == "serial" || key == "kind" || key == "format" || key == "descriptor") {
      auto s = str();
      if (!s) return std::unexpected(s.error());
      if (key == "name") d.name = *s;
      if (key == "device") d.info.name = *s;
      if (key == "backend") d.info.backend = *s;
      if (key == "bus") d.info.bus = *s;
      if (key == "path") d.info.path = *s;
      if (key == "serial") d.info.serial = *s;
      if (key == "file") {
        if (s->empty() || s->find('/') != std::string::npos || s->find('\\') != std::string::npos || *s == "." ||
            *s == "..") {
          return bad(fmt::format("file '{}' must be a file name inside the trace folder", *s));
        }
        d.file = *s;
      }
      if (key == "kind") {
        if (*s == "dial box") {
          d.kind = devices::DeviceKind::kDialBox;
        } else if (*s == "video source") {
          d.kind = devices::DeviceKind::kVideoSource;
        } else if (*s == "tracker") {
          d.kind = devices::DeviceKind::kTracker;
        } else {
          return bad(fmt::format("kind '{}' is not \"dial box\", \"tracker\" or \"video source\"", *s));
        }
      }
      if (key == "format") {
        d.mode.format = formatByName(*s);
        if (d.mode.format == PixelFormat::kUnknown) return bad(fmt::format("unknown pixel format '{}'", *s));
      }
      if (key == "descriptor" && !parseHexList(*s, d.descriptor)) return bad("descriptor must be hexadecimal bytes");
    } else if (key == "vendor") {
      r = hex16(d.info.vendor);
    } else if (key == "product") {
      r = hex16(d.info.product);
    } else if (key == "width" || key == "height") {
      auto n = num(1, 16384);
      if (!n) return std::unexpected(n.error());
      (key == "width" ? d.mode.width : d.mode.height) = static_cast<std::uint32_t>(*n);
    } else if (key == "video_fps") {
      auto n = num(0, 1000);
      if (!n) return std::unexpected(n.error());
      d.mode.fps = *n;
    }
    if (!r) return std::unexpected(r.error());
  }
  lineNo = 0;
  if (!sawFormat) return fail(Errc::kParse, "'format = 1' is missing; is this a Basalt trace.toml?", std::string(name));
  for (const TraceDevice& d : info.devices) {
    if (d.name.empty() || d.file.empty()) {
      return fail(Errc::kParse, "every [[device]] needs a name and a file", std::string(name));
    }
  }
  return info;
}

Result<TraceInfo> readTrace(const std::filesystem::path& folder) {
  const std::filesystem::path file = folder / "trace.toml";
  std::ifstream in(file);
  if (!in) {
    return fail(Errc::kNotFound, "cannot read trace.toml; is this a trace folder made by 'basalt record'?",
                folder.string());
  }
  std::ostringstream text;
  text << in.rdbuf();
  auto info = parseTraceToml(text.str(), file.string());
  if (info) info->folder = folder;
  return info;
}

// TraceRecorder

namespace {

/// The mark a recording keeps in its folder while it runs, locked with flock: a folder whose
/// mark nobody holds was left by a recording that never finished.
constexpr std::string_view kMarkName = ".recording";

/// Whether a file in a trace folder is one a recording writes before trace.toml.
bool writtenWhileRecording(const std::filesystem::path& name) {
  const std::filesystem::path ext = name.extension();
  return name == kMarkName || ext == ".hid" || ext == ".mid" || ext == ".mkv" || ext == ".bvraw";
}

/// Opens (or creates) the mark and takes its lock; false in `busy` when another process holds it.
Result<UniqueFd> lockMark(const std::filesystem::path& mark, bool& busy) {
  busy = false;
  UniqueFd fd(::open(mark.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644));
  if (!fd) return fail(Errc::kIo, fmt::format("cannot create {}: {}", mark.string(), std::strerror(errno)));
  if (::flock(fd.get(), LOCK_EX | LOCK_NB) != 0) {
    busy = errno == EWOULDBLOCK;
    if (!busy) return fail(Errc::kIo, fmt::format("cannot lock {}: {}", mark.string(), std::strerror(errno)));
  }
  return fd;
}

/// What the mark says about the recording that holds it ("pid 1234 on kiosk-3").
std::string markText(const std::filesystem::path& mark) {
  std::ifstream in(mark);
  std::string line;
  std::getline(in, line);
  return line.size() > 200 ? line.substr(0, 200) : line;
}

}  // namespace

Result<std::unique_ptr<TraceRecorder>> TraceRecorder::create(const std::filesystem::path& folder, const Clock& clock,
                                                             Options options) {
  std::error_code ec;
  const std::filesystem::path mark = folder / kMarkName;
  const bool existed = std::filesystem::exists(folder, ec);
  std::vector<std::filesystem::path> leftOver;
  UniqueFd markFd;
  if (existed) {
    if (!std::filesystem::is_directory(folder, ec)) {
      return fail(Errc::kInvalidArgument, "this is a file, not a folder; record into a new folder", folder.string());
    }
    bool finished = false;
    std::vector<std::string> foreign;
    std::size_t seen = 0;
    for (std::filesystem::directory_iterator it(folder, ec), end; !ec && it != end && seen < 10000; it.increment(ec)) {
      ++seen;
      const std::filesystem::path name = it->path().filename();
      if (name == "trace.toml") {
        finished = true;
      } else if (it->is_regular_file(ec) && writtenWhileRecording(name)) {
        leftOver.push_back(name);
      } else {
        foreign.push_back(name.string());
      }
    }
    if (ec) return fail(Errc::kIo, "cannot list the trace folder: " + ec.message(), folder.string());
    std::sort(leftOver.begin(), leftOver.end());
    if (finished) {
      return fail(Errc::kInvalidArgument,
                  "this folder holds a finished trace (it has trace.toml); record into another folder, or remove "
                  "this one to record it again",
                  folder.string());
    }
    if (!foreign.empty()) {
      std::sort(foreign.begin(), foreign.end());
      std::string names;
      for (std::size_t i = 0; i < std::min<std::size_t>(foreign.size(), 3); ++i) names += (i ? ", " : "") + foreign[i];
      if (foreign.size() > 3) names += fmt::format(" and {} more", foreign.size() - 3);
      return fail(
          Errc::kInvalidArgument,
          fmt::format("this folder is not empty and is not a trace (it holds {}); record into a new folder", names),
          folder.string());
    }
    if (!leftOver.empty()) {
      // An unfinished trace: replaced, unless its recording is still running.
      bool busy = false;
      auto locked = lockMark(mark, busy);
      if (!locked) return std::unexpected(locked.error());
      if (busy) {
        const std::string who = markText(mark);
        return fail(Errc::kUnavailable,
                    fmt::format("another 'basalt record' is writing this trace now{}; wait for it to finish, or record "
                                "into another folder",
                                who.empty() ? std::string() : " (" + who + ")"),
                    folder.string());
      }
      markFd = std::move(*locked);
    }
  }
  std::filesystem::create_directories(folder, ec);
  if (ec) return fail(Errc::kIo, "cannot create the trace folder: " + ec.message(), folder.string());
  std::vector<std::string> replaced;
  for (const std::filesystem::path& name : leftOver) {
    if (name == kMarkName) continue;  // kept: it is this recording's mark now
    std::filesystem::remove(folder / name, ec);
    if (ec) {
      return fail(Errc::kIo,
                  fmt::format("cannot remove {} of an unfinished recording: {}", name.string(), ec.message()),
                  folder.string());
    }
    replaced.push_back(name.string());
  }
  if (!markFd) {
    bool busy = false;
    auto locked = lockMark(mark, busy);
    if (!locked) return std::unexpected(locked.error());
    if (busy) return fail(Errc::kUnavailable, "another 'basalt record' started writing this trace", folder.string());
    markFd = std::move(*locked);
  }
  char host[256] = {};
  ::gethostname(host, sizeof host - 1);
  const std::string text = fmt::format("pid {} on {}\n", ::getpid(), host);
  if (::ftruncate(markFd.get(), 0) != 0 || ::pwrite(markFd.get(), text.data(), text.size(), 0) < 0) {
    return fail(Errc::kIo, fmt::format("cannot write {}: {}", mark.string(), std::strerror(errno)));
  }
  if (!options.videoWriter) options.videoWriter = rawVideoWriterFactory();
  return std::unique_ptr<TraceRecorder>(
      new TraceRecorder(folder, clock, std::move(options), std::move(markFd), !existed, std::move(replaced)));
}

TraceRecorder::TraceRecorder(std::filesystem::path folder, const Clock& clock, Options options, UniqueFd mark,
                             bool madeFolder, std::vector<std::string> replaced)
    : folder_(std::move(folder)),
      clock_(clock),
      options_(std::move(options)),
      mark_(std::move(mark)),
      madeFolder_(madeFolder),
      replaced_(std::move(replaced)),
      start_(clock.now()) {
  info_.folder = folder_;
  info_.host = options_.host;
  info_.basalt = options_.basaltVersion;
  info_.fps = options_.fps;
  info_.recorded = fmt::format("{:%Y-%m-%dT%H:%M:%SZ}", std::chrono::floor<std::chrono::seconds>(clock.wallNow()));
  writer_ = std::thread([this] { writerLoop(); });
}

TraceRecorder::~TraceRecorder() {
  if (auto r = finish(); !r) return;  // a destructor cannot report: call finish() to see the error
}

void TraceRecorder::noteError(const Error& e) {
  if (!firstError_) firstError_ = e;
}

Result<void> TraceRecorder::addDialBox(DeviceId id, const std::string& name, const devices::DeviceInfo& info,
                                       const std::vector<std::uint8_t>& descriptor) {
  return addHidDevice(id, name, info, descriptor, devices::DeviceKind::kDialBox);
}

Result<void> TraceRecorder::addTracker(DeviceId id, const std::string& name, const devices::DeviceInfo& info,
                                       const std::vector<std::uint8_t>& descriptor) {
  return addHidDevice(id, name, info, descriptor, devices::DeviceKind::kTracker);
}

Result<void> TraceRecorder::addHidDevice(DeviceId id, const std::string& name, const devices::DeviceInfo& info,
                                         const std::vector<std::uint8_t>& descriptor, devices::DeviceKind kind) {
  std::lock_guard lock(mutex_);
  if (dials_.contains(id)) return {};
  TraceDevice d;
  d.name = name;
  d.kind = kind;
  d.info = info;
  d.file = name + ".hid";
  d.descriptor = descriptor;
  DialFile f;
  if (devices::isMidiDescriptor(descriptor)) {
    // A MIDI dial box records as a Standard MIDI File (aplaymidi plays it), written by finish().
    d.file = name + ".mid";
    f.out.open(folder_ / d.file, std::ios::binary | std::ios::trunc);
    if (!f.out) return fail(Errc::kIo, "cannot create the recording file", (folder_ / d.file).string());
    f.midi = true;
    f.messages.name = info.name;
    f.messages.descriptor = descriptor;
    f.index = info_.devices.size();
    info_.devices.push_back(std::move(d));
    dials_.emplace(id, std::move(f));
    return {};
  }
  f.out.open(folder_ / d.file, std::ios::binary | std::ios::trunc);
  if (!f.out) return fail(Errc::kIo, "cannot create the recording file", (folder_ / d.file).string());
  HidRecordedDevice header;
  header.name = info.name;
  header.phys = hidPhysicalPath(info);
  header.bus = info.bus == "usb" ? 3 : (info.bus == "bluetooth" ? 5 : 6);
  header.vendor = info.vendor;
  header.product = info.product;
  header.descriptor = descriptor;
  // As hid-recorder begins: the name, then the descriptor item by item, then the R: N: P: I:
  // lines; each report's E: line comes after a comment that decodes it.
  f.comments = HidComments::create(descriptor);
  f.out << "# " << info.name << "\n";
  f.out << "# Recorded by " << options_.basaltVersion << " (basalt record) from " << devices::describeDevice(info)
        << "\n";
  f.out << f.comments.descriptorLines();
  f.out << HidRecordingWriter::header(header, false);
  f.index = info_.devices.size();
  info_.devices.push_back(std::move(d));
  dials_.emplace(id, std::move(f));
  return {};
}

Result<void> TraceRecorder::addVideoSource(DeviceId id, const std::string& name, const devices::DeviceInfo& info,
                                           const devices::VideoMode& mode) {
  std::lock_guard lock(mutex_);
  if (videos_.contains(id)) return {};
  TraceDevice d;
  d.name = name;
  d.kind = devices::DeviceKind::kVideoSource;
  d.info = info;
  d.mode = mode;
  VideoFile f;
  auto writer = options_.videoWriter(folder_, name, mode, d.file);
  if (!writer) return std::unexpected(writer.error());
  f.writer = std::move(*writer);
  f.index = info_.devices.size();
  info_.devices.push_back(std::move(d));
  videos_.emplace(id, std::move(f));
  return {};
}

void TraceRecorder::onReport(DeviceId device, Nanos time, std::span<const std::uint8_t> report) {
  std::lock_guard lock(mutex_);
  if (stopping_) return;
  auto it = dials_.find(device);
  if (it == dials_.end()) return;
  if (it->second.midi) {
    it->second.messages.reports.push_back({time - start_, {report.begin(), report.end()}});
    ++reports_;
    lastTime_ = std::max(lastTime_, time - start_);
    return;
  }
  it->second.out << it->second.comments.reportLine(report) << HidRecordingWriter::reportLine(time - start_, report);
  if (!it->second.out)
    noteError(Error(Errc::kIo, "cannot write the recording (disk full?)", info_.devices[it->second.index].file));
  ++reports_;
  lastTime_ = std::max(lastTime_, time - start_);
}

void TraceRecorder::onFrame(DeviceId device, const FrameRef& frame) {
  {
    std::lock_guard lock(mutex_);
    if (stopping_ || !videos_.contains(device)) return;
    if (frames_.size() >= 8) {
      ++framesDropped_;
      return;
    }
    frames_.push_back({device, frame});
  }
  framesReady_.notify_one();
}

void TraceRecorder::writerLoop() {
  std::unique_lock lock(mutex_);
  for (;;) {
    framesReady_.wait(lock, [this] { return stopping_ || !frames_.empty(); });
    if (frames_.empty()) {
      framesDone_.notify_all();
      if (stopping_) return;
      continue;
    }
    PendingFrame p = std::move(frames_.front());
    frames_.pop_front();
    auto it = videos_.find(p.device);
    if (it == videos_.end()) continue;
    TraceVideoWriter* writer = it->second.writer.get();
    const Nanos pts = p.frame->pts - start_;
    lastTime_ = std::max(lastTime_, pts);
    writing_ = true;
    lock.unlock();  // write without holding the lock: device threads keep queueing
    auto r = writer->write(*p.frame, pts);
    p.frame.reset();
    lock.lock();
    writing_ = false;
    if (frames_.empty()) framesDone_.notify_all();
    if (r) {
      ++framesWritten_;
    } else {
      noteError(r.error());
    }
  }
}

bool TraceRecorder::drain(std::chrono::milliseconds timeout) {
  std::unique_lock lock(mutex_);
  return framesDone_.wait_for(lock, timeout, [this] { return frames_.empty() && !writing_; });
}

void TraceRecorder::stopWriting() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  framesReady_.notify_all();
  if (writer_.joinable()) writer_.join();
}

Result<TraceInfo> TraceRecorder::finish() {
  {
    std::lock_guard lock(mutex_);
    if (discarded_) return fail(Errc::kInvalidArgument, "the recording was discarded", folder_.string());
    if (stopping_ && !writer_.joinable()) {
      if (firstError_) return std::unexpected(*firstError_);
      return info_;
    }
  }
  stopWriting();
  std::lock_guard lock(mutex_);
  for (auto& [id, f] : dials_) {
    if (f.midi) {
      const std::vector<std::uint8_t> smf = formatMidiFile(f.messages);
      f.out.write(reinterpret_cast<const char*>(smf.data()), static_cast<std::streamsize>(smf.size()));
    }
    f.out.flush();
    if (!f.out) noteError(Error(Errc::kIo, "cannot write the recording (disk full?)", info_.devices[f.index].file));
    f.out.close();
  }
  for (auto& [id, f] : videos_) {
    if (auto r = f.writer->finish(); !r) noteError(r.error());
  }
  info_.seconds = toSeconds(std::max(lastTime_, clock_.now() - start_));
  std::ofstream toml(folder_ / "trace.toml", std::ios::trunc);
  toml << formatTraceToml(info_);
  toml.close();
  if (!toml) noteError(Error(Errc::kIo, "cannot write trace.toml", folder_.string()));
  if (firstError_) return std::unexpected(*firstError_);
  // Finished: the mark goes, so that the folder reads as a finished trace.
  std::error_code ec;
  std::filesystem::remove(folder_ / kMarkName, ec);
  mark_.reset();
  return info_;
}

void TraceRecorder::discard() {
  const bool finishing = [&] {
    std::lock_guard lock(mutex_);
    return !stopping_;
  }();
  stopWriting();
  std::lock_guard lock(mutex_);
  if (discarded_) return;
  discarded_ = true;
  if (finishing) {
    // Close what is open before it is removed (a video writer's pipeline holds its file).
    for (auto& [id, f] : dials_) f.out.close();
    for (auto& [id, f] : videos_) {
      if (auto r = f.writer->finish(); !r) noteError(r.error());
    }
  }
  std::error_code ec;
  for (const TraceDevice& d : info_.devices) {
    if (!d.file.empty()) std::filesystem::remove(folder_ / d.file, ec);
  }
  std::filesystem::remove(folder_ / "trace.toml", ec);
  std::filesystem::remove(folder_ / kMarkName, ec);
  mark_.reset();
  // The folder goes too when this recording made it (remove() leaves a folder that is not empty).
  if (madeFolder_) std::filesystem::remove(folder_, ec);
}

std::uint64_t TraceRecorder::bytesWritten() const {
  std::vector<std::filesystem::path> files;
  {
    std::lock_guard lock(mutex_);
    for (const TraceDevice& d : info_.devices) files.push_back(folder_ / d.file);
  }
  std::uint64_t bytes = 0;
  for (const std::filesystem::path& f : files) {
    std::error_code ec;
    const auto size = std::filesystem::file_size(f, ec);
    if (!ec) bytes += size;
  }
  return bytes;
}

std::uint64_t TraceRecorder::reportsWritten() const {
  std::lock_guard lock(mutex_);
  return reports_;
}
std::uint64_t TraceRecorder::framesWritten() const {
  std::lock_guard lock(mutex_);
  return framesWritten_;
}
std::uint64_t TraceRecorder::framesDropped() const {
  std::lock_guard lock(mutex_);
  return framesDropped_;
}

}  // namespace basalt::sim
