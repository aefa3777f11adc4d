#include "kiosk/lock_protocol.h"

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
constexpr std::uint8_t kVersion = 2;

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
  }
  return "unknown";
}

std::size_t sizeOf(LockMessageKind kind) {
  switch (kind) {
    case LockMessageKind::kFrame: return kFrameMessageBytes;
    case LockMessageKind::kPresent: return kPresentMessageBytes;
    case LockMessageKind::kReady: return kReadyMessageBytes;
    case LockMessageKind::kBye: return kByeMessageBytes;
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

}  // namespace basalt::kiosk
