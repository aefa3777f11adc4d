#include "kiosk/lock/lock_protocol.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>

#include <fmt/format.h>

#include "runtime/show/show.h"

namespace basalt::kiosk {

static_assert(std::endian::native == std::endian::little, "the frame-lock encoding assumes a little-endian host");

namespace {

constexpr std::array<char, 4> kMagic{'B', 'L', 'C', 'K'};
constexpr std::uint8_t kVersion = 4;

class Writer {
 public:
  explicit Writer(LockBuffer& out) : out_(out) {}
  void header(LockMessageKind kind) {
    std::memcpy(out_.data(), kMagic.data(), kMagic.size());
    out_[4] = std::byte{kVersion};
    out_[5] = static_cast<std::byte>(kind);
    out_[6] = std::byte{0};
    out_[7] = std::byte{0};
    at_ = kLockHeaderBytes;
  }
  template <typename T>
  void put(T value) {
    std::memcpy(out_.data() + at_, &value, sizeof value);
    at_ += sizeof value;
  }
  void put(const Vec3& v) {
    put(v.x);
    put(v.y);
    put(v.z);
  }
  void put(const Mat4& m) {
    for (float f : m.m) put(f);
  }
  void bytes(const char* data, std::size_t n) {
    std::memcpy(out_.data() + at_, data, n);
    at_ += n;
  }
  /// `text` (at most `field` bytes), NUL-padded to `field`.
  void padded(std::string_view text, std::size_t field) {
    const std::size_t n = std::min(text.size(), field);
    if (n > 0) std::memcpy(out_.data() + at_, text.data(), n);  // an empty view's data may be null
    std::memset(out_.data() + at_ + n, 0, field - n);
    at_ += field;
  }
  [[nodiscard]] std::size_t size() const { return at_; }

 private:
  LockBuffer& out_;
  std::size_t at_ = 0;
};

class Reader {
 public:
  explicit Reader(std::span<const std::byte> in) : in_(in), at_(kLockHeaderBytes) {}
  template <typename T>
  T get() {
    T value;
    std::memcpy(&value, in_.data() + at_, sizeof value);
    at_ += sizeof value;
    if constexpr (std::is_floating_point_v<T>) {
      if (!std::isfinite(value)) finite_ = false;
    }
    return value;
  }
  Vec3 vec3() {
    Vec3 v;
    v.x = get<float>();
    v.y = get<float>();
    v.z = get<float>();
    return v;
  }
  Mat4 mat4() {
    Mat4 m;
    for (float& f : m.m) f = get<float>();
    return m;
  }
  void bytes(char* data, std::size_t n) {
    std::memcpy(data, in_.data() + at_, n);
    at_ += n;
  }
  /// A text of `length` bytes in a NUL-padded field of `field`: false when the length is beyond
  /// the field, the padding is not zero or the text holds a NUL or a line break.
  bool padded(std::size_t length, std::size_t field, std::string& text) {
    const auto* begin = reinterpret_cast<const char*>(in_.data() + at_);
    at_ += field;
    if (length > field) return false;
    text.assign(begin, length);
    if (std::any_of(begin + length, begin + field, [](char c) { return c != '\0'; })) return false;
    return text.find_first_of(std::string_view("\0\n\r", 3)) == std::string::npos;
  }
  [[nodiscard]] bool finite() const { return finite_; }

 private:
  std::span<const std::byte> in_;
  std::size_t at_;
  bool finite_ = true;
};

std::string_view kindName(LockMessageKind kind) {
  switch (kind) {
    case LockMessageKind::kFrame: return "frame";
    case LockMessageKind::kPresent: return "present";
    case LockMessageKind::kReady: return "ready";
    case LockMessageKind::kBye: return "bye";
    case LockMessageKind::kResend: return "resend";
    case LockMessageKind::kCommand: return "command";
  }
  return "unknown";
}

std::size_t sizeOf(LockMessageKind kind) {
  switch (kind) {
    case LockMessageKind::kFrame: return kFrameMessageBytes;
    case LockMessageKind::kPresent: return kPresentMessageBytes;
    case LockMessageKind::kReady: return kReadyMessageBytes;
    case LockMessageKind::kBye: return kByeMessageBytes;
    case LockMessageKind::kResend: return kResendMessageBytes;
    case LockMessageKind::kCommand: return kCommandMessageBytes;
  }
  return 0;
}

Result<void> expectKind(std::span<const std::byte> bytes, LockMessageKind want) {
  auto kind = peekKind(bytes);
  if (!kind) return std::unexpected(kind.error());
  if (*kind != want) {
    return failf(Errc::kParse, "frame-lock message: expected a '{}' message, got '{}'", kindName(want),
                 kindName(*kind));
  }
  return {};
}

Result<void> finiteOrFail(const Reader& r, LockMessageKind kind) {
  if (r.finite()) return {};
  return failf(Errc::kParse, "frame-lock message: the '{}' message holds a number that is not finite", kindName(kind));
}

}  // namespace

LockedShowState captureLockedState(const runtime::Show& show) {
  LockedShowState s;
  s.global = show.position().global;
  s.local = show.position().local;
  s.view = show.position().view;
  const runtime::Motion& m = show.motion();
  s.globalRotate = m.globalRotate;
  s.localRotate = m.localRotate;
  s.globalScale = m.globalScale;
  s.localScale = m.localScale;
  s.globalFreeRun = m.globalFreeRun;
  s.localFreeRun = m.localFreeRun;
  s.motionFramesLeft = m.framesLeft;
  const runtime::ViewSettings& v = show.view();
  s.viewCenter = v.center;
  s.viewScale = v.viewScale;
  s.zClipScale = v.zClipScale;
  s.perspective = v.perspective;
  s.viewerPosition = show.viewer().position;
  s.viewerRotation = show.viewer().rotation;
  s.eyeSpacing = show.viewer().eyeSpacing;
  s.head = show.head();
  return s;
}

void applyLockedState(const LockedShowState& s, runtime::Show& show) {
  show.position().global = s.global;
  show.position().local = s.local;
  show.position().view = s.view;
  runtime::Motion& m = show.motion();
  m.globalRotate = s.globalRotate;
  m.localRotate = s.localRotate;
  m.globalScale = s.globalScale;
  m.localScale = s.localScale;
  m.globalFreeRun = s.globalFreeRun;
  m.localFreeRun = s.localFreeRun;
  m.framesLeft = s.motionFramesLeft;
  runtime::ViewSettings& v = show.view();
  v.center = s.viewCenter;
  v.viewScale = s.viewScale;
  v.zClipScale = s.zClipScale;
  v.perspective = s.perspective;
  show.viewer().position = s.viewerPosition;
  show.viewer().rotation = s.viewerRotation;
  show.viewer().eyeSpacing = s.eyeSpacing;
  show.head() = s.head;
}

std::string ReadyMessage::nodeName() const {
  const auto end = std::find(node.begin(), node.end(), '\0');
  return {node.begin(), end};
}

std::string LockedProgramme::itemName() const {
  const auto end = std::find(item.begin(), item.end(), '\0');
  return {item.begin(), end};
}

void LockedProgramme::setItemName(std::string_view name) {
  item.fill('\0');
  std::copy_n(name.begin(), std::min(name.size(), item.size()), item.begin());
}

void ReadyMessage::setNodeName(std::string_view name) {
  node.fill('\0');
  std::copy_n(name.begin(), std::min(name.size(), node.size()), node.begin());
}

std::size_t encode(const FrameMessage& m, LockBuffer& out) {
  Writer w(out);
  w.header(LockMessageKind::kFrame);
  w.put(m.frame);
  w.put(m.showTimeNs);
  w.put(m.sentNs);
  const LockedShowState& s = m.state;
  w.put(s.global);
  w.put(s.local);
  w.put(s.view);
  w.put(s.globalRotate);
  w.put(s.localRotate);
  w.put(s.globalScale);
  w.put(s.localScale);
  w.put(static_cast<std::uint32_t>((s.globalFreeRun ? 1U : 0U) | (s.localFreeRun ? 2U : 0U)));
  w.put(s.motionFramesLeft);
  w.put(s.viewCenter);
  w.put(s.viewScale);
  w.put(s.zClipScale);
  w.put(s.perspective);
  w.put(s.viewerPosition);
  w.put(s.viewerRotation);
  w.put(s.eyeSpacing);
  const LockedProgramme& p = m.programme;
  w.put(static_cast<std::uint8_t>((p.present ? 1U : 0U) | (p.hasItem ? 2U : 0U)));
  w.put(p.mode);
  w.put(p.display);
  w.put(std::uint8_t{0});
  w.put(p.index);
  w.put(p.itemStartNs);
  w.put(p.mediaStartNs);
  w.put(p.reloads);
  w.put(std::uint32_t{0});
  w.bytes(p.item.data(), p.item.size());
  for (const std::int64_t pass : p.moviePassNs) w.put(pass);
  const LockedCommand& c = m.command;
  const bool carried = c.carried && c.text.size() <= kFrameCommandBytes;
  w.put(c.epoch);
  w.put(c.newest);
  w.put(c.base);
  w.put(static_cast<std::uint16_t>(carried ? c.text.size() : 0));
  w.put(static_cast<std::uint8_t>(carried ? 1U : 0U));
  w.put(std::uint8_t{0});
  w.padded(carried ? std::string_view(c.text) : std::string_view(), kFrameCommandBytes);
  w.put(m.movies.item);
  for (const std::int32_t shown : m.movies.textures) w.put(shown);
  w.put(m.session);
  const runtime::HeadPose& h = s.head;
  w.put(static_cast<std::uint32_t>(h.tracked ? 1U : 0U));
  w.put(h.position);
  w.put(h.right);
  w.put(static_cast<std::int64_t>(h.sampleTime.count()));
  return w.size();
}

std::size_t encode(const PresentMessage& m, LockBuffer& out) {
  Writer w(out);
  w.header(LockMessageKind::kPresent);
  w.put(m.frame);
  return w.size();
}

std::size_t encode(const ReadyMessage& m, LockBuffer& out) {
  Writer w(out);
  w.header(LockMessageKind::kReady);
  w.put(m.frame);
  w.put(m.skipped);
  w.put(m.clockOffsetNs);
  w.bytes(m.node.data(), m.node.size());
  return w.size();
}

std::size_t encode(const ByeMessage& m, LockBuffer& out) {
  Writer w(out);
  w.header(LockMessageKind::kBye);
  w.put(m.frame);
  return w.size();
}

std::size_t encode(const ResendMessage& m, LockBuffer& out) {
  Writer w(out);
  w.header(LockMessageKind::kResend);
  w.put(m.epoch);
  w.put(m.from);
  return w.size();
}

std::size_t encode(const CommandMessage& m, LockBuffer& out) {
  Writer w(out);
  w.header(LockMessageKind::kCommand);
  w.put(m.epoch);
  w.put(m.seq);
  w.put(static_cast<std::uint16_t>(std::min(m.text.size(), kCommandTextBytes)));
  w.put(static_cast<std::uint8_t>(m.earlierGone ? 1U : 0U));
  w.put(std::uint8_t{0});
  w.padded(m.text, kCommandTextBytes);
  return w.size();
}

Result<LockMessageKind> peekKind(std::span<const std::byte> bytes) {
  if (bytes.size() < kLockHeaderBytes) {
    return failf(Errc::kParse, "frame-lock message: {} bytes, shorter than the {}-byte header", bytes.size(),
                 kLockHeaderBytes);
  }
  if (std::memcmp(bytes.data(), kMagic.data(), kMagic.size()) != 0) {
    return fail(Errc::kParse, "frame-lock message: no 'BLCK' magic (is something else sending to this port?)");
  }
  if (const auto version = std::to_integer<std::uint8_t>(bytes[4]); version != kVersion) {
    return failf(Errc::kParse,
                 "frame-lock message: version {}, this basalt speaks version {} (run the same basalt on every node)",
                 version, kVersion);
  }
  const auto kind = static_cast<LockMessageKind>(std::to_integer<std::uint8_t>(bytes[5]));
  const std::size_t want = sizeOf(kind);
  if (want == 0) {
    return failf(Errc::kParse, "frame-lock message: unknown kind {}", std::to_integer<int>(bytes[5]));
  }
  if (bytes[6] != std::byte{0} || bytes[7] != std::byte{0}) {
    return fail(Errc::kParse, "frame-lock message: the header's reserved bytes are not zero");
  }
  if (bytes.size() != want) {
    return failf(Errc::kParse, "frame-lock message: a '{}' message is {} bytes, this one has {}{}", kindName(kind),
                 want, bytes.size(), bytes.size() < want ? " (truncated)" : "");
  }
  return kind;
}

Result<FrameMessage> decodeFrame(std::span<const std::byte> bytes) {
  if (auto r = expectKind(bytes, LockMessageKind::kFrame); !r) return std::unexpected(r.error());
  Reader r(bytes);
  FrameMessage m;
  m.frame = r.get<std::int64_t>();
  m.showTimeNs = r.get<std::int64_t>();
  m.sentNs = r.get<std::int64_t>();
  LockedShowState& s = m.state;
  s.global = r.mat4();
  s.local = r.mat4();
  s.view = r.mat4();
  s.globalRotate = r.vec3();
  s.localRotate = r.vec3();
  s.globalScale = r.get<float>();
  s.localScale = r.get<float>();
  const auto flags = r.get<std::uint32_t>();
  if (flags > 3) return fail(Errc::kParse, "frame-lock message: the 'frame' message's motion flags are unknown");
  s.globalFreeRun = (flags & 1U) != 0;
  s.localFreeRun = (flags & 2U) != 0;
  s.motionFramesLeft = r.get<std::int32_t>();
  s.viewCenter = r.vec3();
  s.viewScale = r.get<float>();
  s.zClipScale = r.get<float>();
  s.perspective = r.get<float>();
  s.viewerPosition = r.vec3();
  s.viewerRotation = r.vec3();
  s.eyeSpacing = r.get<float>();
  LockedProgramme& p = m.programme;
  const auto programmeFlags = r.get<std::uint8_t>();
  p.mode = r.get<std::uint8_t>();
  p.display = r.get<std::uint8_t>();
  const auto reserved = r.get<std::uint8_t>();
  p.index = r.get<std::uint32_t>();
  p.itemStartNs = r.get<std::int64_t>();
  p.mediaStartNs = r.get<std::int64_t>();
  p.reloads = r.get<std::uint32_t>();
  const auto reserved2 = r.get<std::uint32_t>();
  r.bytes(p.item.data(), p.item.size());
  for (std::int64_t& pass : p.moviePassNs) pass = r.get<std::int64_t>();
  if (std::any_of(p.moviePassNs.begin(), p.moviePassNs.end(), [](std::int64_t pass) { return pass < 0; })) {
    return fail(Errc::kParse, "frame-lock message: the 'frame' message's programme has a negative movie pass");
  }
  if (programmeFlags > 3 || reserved != 0 || reserved2 != 0) {
    return fail(Errc::kParse,
                "frame-lock message: the 'frame' message's programme flags or reserved bytes are unknown");
  }
  if (p.mode > 2 || p.display > 2) {
    return failf(Errc::kParse, "frame-lock message: programme mode {} or display {} is unknown", p.mode, p.display);
  }
  p.present = (programmeFlags & 1U) != 0;
  p.hasItem = (programmeFlags & 2U) != 0;
  LockedCommand& c = m.command;
  c.epoch = r.get<std::uint32_t>();
  c.newest = r.get<std::uint32_t>();
  c.base = r.get<std::uint32_t>();
  const auto length = r.get<std::uint16_t>();
  const auto commandFlags = r.get<std::uint8_t>();
  const auto reserved3 = r.get<std::uint8_t>();
  const bool textOk = r.padded(length, kFrameCommandBytes, c.text);
  if (commandFlags > 1 || reserved3 != 0) {
    return fail(Errc::kParse, "frame-lock message: the 'frame' message's command flags or reserved byte are unknown");
  }
  c.carried = commandFlags == 1;
  if (!textOk || (c.carried ? (length == 0 || c.newest == 0) : length != 0)) {
    return fail(Errc::kParse,
                "frame-lock message: the 'frame' message's command text is too long, not one line, not padded with "
                "zeros, or does not match its flag");
  }
  if (c.base > c.newest) {
    return failf(Errc::kParse, "frame-lock message: command base {} is beyond the newest command {}", c.base, c.newest);
  }
  LockedMovieFrames& movies = m.movies;
  movies.item = r.get<std::int32_t>();
  for (std::int32_t& shown : movies.textures) shown = r.get<std::int32_t>();
  m.session = r.get<std::uint32_t>();
  runtime::HeadPose& head = s.head;
  const auto headFlags = r.get<std::uint32_t>();
  head.position = r.vec3();
  head.right = r.vec3();
  head.sampleTime = Nanos{r.get<std::int64_t>()};
  if (headFlags > 1) return fail(Errc::kParse, "frame-lock message: the 'frame' message's head flags are unknown");
  head.tracked = headFlags == 1;
  if (movies.item < -1 ||
      std::any_of(movies.textures.begin(), movies.textures.end(), [](std::int32_t shown) { return shown < -1; })) {
    return fail(Errc::kParse, "frame-lock message: a movie frame below -1 (-1 means none)");
  }
  if (auto f = finiteOrFail(r, LockMessageKind::kFrame); !f) return std::unexpected(f.error());
  if (m.frame < 0) return failf(Errc::kParse, "frame-lock message: frame number {} is negative", m.frame);
  return m;
}

Result<PresentMessage> decodePresent(std::span<const std::byte> bytes) {
  if (auto r = expectKind(bytes, LockMessageKind::kPresent); !r) return std::unexpected(r.error());
  Reader r(bytes);
  PresentMessage m;
  m.frame = r.get<std::int64_t>();
  if (m.frame < 0) return failf(Errc::kParse, "frame-lock message: frame number {} is negative", m.frame);
  return m;
}

Result<ReadyMessage> decodeReady(std::span<const std::byte> bytes) {
  if (auto r = expectKind(bytes, LockMessageKind::kReady); !r) return std::unexpected(r.error());
  Reader r(bytes);
  ReadyMessage m;
  m.frame = r.get<std::int64_t>();
  m.skipped = r.get<std::int64_t>();
  m.clockOffsetNs = r.get<std::int64_t>();
  r.bytes(m.node.data(), m.node.size());
  if (m.frame < -1) return failf(Errc::kParse, "frame-lock message: frame number {} is below -1", m.frame);
  if (m.skipped < 0) return fail(Errc::kParse, "frame-lock message: a negative count of skipped frames");
  return m;
}

Result<ByeMessage> decodeBye(std::span<const std::byte> bytes) {
  if (auto r = expectKind(bytes, LockMessageKind::kBye); !r) return std::unexpected(r.error());
  Reader r(bytes);
  ByeMessage m;
  m.frame = r.get<std::int64_t>();
  return m;
}

Result<ResendMessage> decodeResend(std::span<const std::byte> bytes) {
  if (auto r = expectKind(bytes, LockMessageKind::kResend); !r) return std::unexpected(r.error());
  Reader r(bytes);
  ResendMessage m;
  m.epoch = r.get<std::uint32_t>();
  m.from = r.get<std::uint32_t>();
  if (m.from == 0) return fail(Errc::kParse, "frame-lock message: a 'resend' from command 0 (commands count from 1)");
  return m;
}

Result<CommandMessage> decodeCommand(std::span<const std::byte> bytes) {
  if (auto r = expectKind(bytes, LockMessageKind::kCommand); !r) return std::unexpected(r.error());
  Reader r(bytes);
  CommandMessage m;
  m.epoch = r.get<std::uint32_t>();
  m.seq = r.get<std::uint32_t>();
  const auto length = r.get<std::uint16_t>();
  const auto flags = r.get<std::uint8_t>();
  const auto reserved = r.get<std::uint8_t>();
  const bool textOk = r.padded(length, kCommandTextBytes, m.text);
  if (flags > 1 || reserved != 0) {
    return fail(Errc::kParse, "frame-lock message: the 'command' message's flags or reserved byte are unknown");
  }
  m.earlierGone = flags == 1;
  if (m.seq == 0) return fail(Errc::kParse, "frame-lock message: command number 0 (commands count from 1)");
  if (!textOk || length == 0) {
    return fail(Errc::kParse,
                "frame-lock message: the 'command' message's text is empty, too long, not one line or not padded "
                "with zeros");
  }
  return m;
}

void LockCommandLog::restart(std::uint32_t epoch) {
  epoch_ = epoch;
  newest_ = 0;
  base_ = 0;
  kept_.clear();
}

std::uint32_t LockCommandLog::add(std::string text) {
  kept_.push_back(std::move(text));
  if (kept_.size() > kKept) kept_.pop_front();
  return ++newest_;
}

const std::string* LockCommandLog::at(std::uint32_t seq) const {
  if (seq == 0 || seq > newest_ || seq < oldest()) return nullptr;
  return &kept_[kept_.size() - 1 - (newest_ - seq)];
}

}  // namespace basalt::kiosk
