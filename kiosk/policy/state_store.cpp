#include "kiosk/policy/state_store.h"

#include <fcntl.h>
#include <unistd.h>

#include <charconv>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <fmt/std.h>

#include "runtime/log.h"
#include "runtime/unique_fd.h"

namespace basalt::kiosk {

BASALT_LOG_CATEGORY(State, "kiosk");

namespace {

constexpr std::string_view kMagic = "basalt-state 1";

/// FNV-1a, 64 bits: enough to tell a torn or edited file from a good one.
std::uint64_t checksum(std::string_view text) {
  std::uint64_t h = 1469598103934665603ULL;
  for (const char c : text) {
    h ^= static_cast<unsigned char>(c);
    h *= 1099511628211ULL;
  }
  return h;
}

std::optional<KioskMode> modeFromName(std::string_view name) {
  for (const KioskMode m : {KioskMode::kClosed, KioskMode::kAttract, KioskMode::kActive}) {
    if (kioskModeName(m) == name) return m;
  }
  return std::nullopt;
}

}  // namespace

std::filesystem::path defaultStateFolder() {
  if (const char* dir = std::getenv("STATE_DIRECTORY"); dir && *dir) {
    // systemd may list several folders separated by ':'; the first is ours.
    const std::string_view all(dir);
    return std::filesystem::path(std::string(all.substr(0, all.find(':'))));
  }
  if (const char* xdg = std::getenv("XDG_STATE_HOME"); xdg && *xdg) return std::filesystem::path(xdg) / "basalt";
  if (const char* home = std::getenv("HOME"); home && *home) {
    return std::filesystem::path(home) / ".local" / "state" / "basalt";
  }
  return "/var/lib/basalt";
}

std::string encodeState(const std::string& showId, const ResumePoint& point) {
  std::string body = fmt::format("{}\nshow={}\nmode={}\nindex={}\nitem={}\nposition_ns={}\n", kMagic, showId,
                                 kioskModeName(point.mode), point.index, point.item, point.position.count());
  return body + fmt::format("checksum={:016x}\n", checksum(body));
}

Result<ResumePoint> decodeState(std::string_view text, const std::string& showId) {
  const auto bad = [](std::string_view why) { return fail(Errc::kParse, std::string(why)); };
  const auto sumAt = text.rfind("checksum=");
  if (!text.starts_with(kMagic) || sumAt == std::string_view::npos) return bad("not a Basalt state file");
  // The checksum line is the last line, and covers everything before it.
  if (text.substr(sumAt + 9) != fmt::format("{:016x}\n", checksum(text.substr(0, sumAt)))) {
    return bad("its checksum does not match (a torn write or an edit)");
  }
  ResumePoint p;
  bool sameShow = false;
  bool haveMode = false;
  std::string_view rest = text.substr(kMagic.size() + 1, sumAt - kMagic.size() - 1);
  while (!rest.empty()) {
    const auto nl = rest.find('\n');
    const std::string_view line = rest.substr(0, nl);
    rest = nl == std::string_view::npos ? std::string_view{} : rest.substr(nl + 1);
    const auto eq = line.find('=');
    if (eq == std::string_view::npos) continue;
    const std::string_view key = line.substr(0, eq);
    const std::string_view value = line.substr(eq + 1);
    if (key == "show") {
      sameShow = value == showId;
    } else if (key == "mode") {
      auto m = modeFromName(value);
      if (!m) return bad("it names no mode");
      p.mode = *m;
      haveMode = true;
    } else if (key == "index") {
      std::from_chars(value.data(), value.data() + value.size(), p.index);
    } else if (key == "item") {
      p.item = std::string(value);
    } else if (key == "position_ns") {
      std::int64_t ns = 0;
      std::from_chars(value.data(), value.data() + value.size(), ns);
      p.position = Nanos{ns < 0 ? 0 : ns};
    }
  }
  if (!haveMode) return bad("it names no mode");
  if (!sameShow) return fail(Errc::kNotFound, "it belongs to another show");
  return p;
}

StateStore::StateStore(std::filesystem::path file, std::string showId)
    : file_(std::move(file)), showId_(std::move(showId)) {
  writer_ = std::thread([this] { writerLoop(); });
}

StateStore::~StateStore() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  changed_.notify_all();
  writer_.join();
}

Result<std::unique_ptr<StateStore>> StateStore::open(const std::filesystem::path& folder, std::string showId) {
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (ec || ::access(folder.c_str(), W_OK) != 0) {
    return fail(Errc::kPermissionDenied,
                fmt::format("cannot keep the show's state in {}: {}; give another folder with --state-dir (under "
                            "systemd, StateDirectory=basalt provides one)",
                            folder, ec ? ec.message() : std::strerror(errno)));
  }
  // One file per show, named after it, so two shows on one machine never resume each other.
  std::string name;
  for (const char c : showId.substr(showId.rfind('/') == std::string::npos ? 0 : showId.rfind('/') + 1)) {
    name += (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_') ? c : '-';
  }
  const auto file = folder / fmt::format("{}-{:08x}.state", name.substr(0, 40), checksum(showId) & 0xffffffffU);
  return std::unique_ptr<StateStore>(new StateStore(file, std::move(showId)));
}

std::optional<ResumePoint> StateStore::load() const {
  std::ifstream in(file_, std::ios::binary);
  if (!in) return std::nullopt;
  std::ostringstream text;
  text << in.rdbuf();
  const std::string content = text.str();
  if (content.size() > std::size_t{64} * 1024) {
    log::warn(kLogState, "ignoring the saved state {}: it is too large; the show starts from the beginning", file_);
    return std::nullopt;
  }
  auto point = decodeState(content, showId_);
  if (!point) {
    log::warn(kLogState, "ignoring the saved state {}: {}; the show starts from the beginning", file_,
              point.error().message());
    return std::nullopt;
  }
  return *point;
}

void StateStore::save(const ResumePoint& point) {
  {
    std::lock_guard lock(mutex_);
    pending_ = point;
  }
  changed_.notify_one();
}

void StateStore::flush() {
  std::unique_lock lock(mutex_);
  changed_.notify_one();
  changed_.wait(lock, [this] { return !pending_ && !writing_; });
}

std::uint64_t StateStore::failures() const {
  std::lock_guard lock(mutex_);
  return failures_;
}

Result<void> StateStore::writeNow(const std::string& text) {
  const std::filesystem::path temporary = file_.string() + ".partial.tmp";
  UniqueFd fd(::open(temporary.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644));
  if (!fd) return fail(Errc::kIo, systemErrorText(fmt::format("creating {}", temporary), errno));
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd.get(), text.data() + done, text.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      return fail(Errc::kIo, systemErrorText(fmt::format("writing {}", temporary), errno));
    }
    done += static_cast<std::size_t>(n);
  }
  if (::fsync(fd.get()) != 0) return fail(Errc::kIo, systemErrorText(fmt::format("syncing {}", temporary), errno));
  fd.reset();
  if (::rename(temporary.c_str(), file_.c_str()) != 0) {
    return fail(Errc::kIo, systemErrorText(fmt::format("renaming {} to {}", temporary, file_), errno));
  }
  // The rename itself must survive a power cut: sync the folder.
  UniqueFd folder(::open(file_.parent_path().c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (folder) ::fsync(folder.get());
  return {};
}

void StateStore::writerLoop() {
  std::unique_lock lock(mutex_);
  for (;;) {
    changed_.wait(lock, [this] { return stop_ || pending_; });
    if (!pending_) {
      if (stop_) return;
      continue;
    }
    const ResumePoint point = *pending_;
    pending_.reset();
    writing_ = true;
    lock.unlock();
    const auto written = writeNow(encodeState(showId_, point));
    lock.lock();
    writing_ = false;
    if (!written) {
      ++failures_;
      if (failures_ == 1) {
        log::warn(kLogState, "cannot save the show's state: {}; after a restart it will start from the beginning",
                  written.error().describe());
      }
    }
    changed_.notify_all();
  }
}

}  // namespace basalt::kiosk
