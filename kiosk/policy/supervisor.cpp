// Supervision through libsystemd: sd_notify for the service manager, sd_journal_sendv for logs.

#include "kiosk/policy/supervisor.h"

#include <sys/stat.h>
#include <sys/uio.h>
#include <systemd/sd-daemon.h>
#include <systemd/sd-journal.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>

#include <fmt/format.h>

#include "runtime/log.h"

namespace basalt::kiosk {

BASALT_LOG_CATEGORY(Supervision, "kiosk");

Supervisor::Supervisor(bool notifying, std::optional<Nanos> watchdog) : notifying_(notifying), watchdog_(watchdog) {}

std::unique_ptr<Supervisor> Supervisor::fromEnvironment() {
  const char* socket = std::getenv("NOTIFY_SOCKET");
  const bool notifying = socket && *socket;
  std::optional<Nanos> watchdog;
  std::uint64_t usec = 0;
  if (sd_watchdog_enabled(0, &usec) > 0 && usec > 0) watchdog = std::chrono::microseconds(usec);
  auto s = std::unique_ptr<Supervisor>(new Supervisor(notifying, watchdog));
  if (notifying) {
    log::info(kLogSupervision, "service manager: notifying {}{}", socket,
              watchdog ? fmt::format(", watchdog every {:.1f} s", toSeconds(*watchdog)) : std::string());
  }
  return s;
}

void Supervisor::notify(const std::string& message) {
  if (!notifying_) return;
  if (const int rc = sd_notify(0, message.c_str()); rc < 0) {
    static log::Once once;
    if (once.first()) {
      const char* socket = std::getenv("NOTIFY_SOCKET");
      log::warn(kLogSupervision,
                "cannot notify the service manager at $NOTIFY_SOCKET={}: {}{}; the show goes on without "
                "readiness or watchdog messages",
                socket ? socket : "", std::strerror(-rc),
                rc == -ENAMETOOLONG ? " (a socket path holds at most 107 bytes)" : "");
    }
  }
}

void Supervisor::status(std::string_view text) {
  if (text == status_) return;
  status_ = std::string(text);
  notify("STATUS=" + status_);
}

void Supervisor::reloading() {
  notify(fmt::format("RELOADING=1\nMONOTONIC_USEC={}",
                     std::chrono::duration_cast<std::chrono::microseconds>(wall_.now()).count()));
}

void Supervisor::reloaded(std::string_view text) {
  status_ = std::string(text);
  notify("READY=1\nSTATUS=" + status_);
}

void Supervisor::stopping() { notify("STOPPING=1\nSTATUS=stopping"); }

void Supervisor::afterPresent(const FrameContext& /*frame*/) {
  if (!notifying_) return;
  const Nanos now = wall_.now();
  if (!ready_) {
    ready_ = true;
    lastPing_ = now;
    // The first frame is on screen: the service is up.
    notify(status_.empty() ? std::string("READY=1") : "READY=1\nSTATUS=" + status_);
    return;
  }
  (void)pingIfDue();
}

void Supervisor::whileHolding() {
  // Before the first frame there is nothing to hold, and systemd waits for READY=1 anyway.
  if (!notifying_ || !ready_) return;
  if (pingIfDue()) ++holdingPings_;
}

bool Supervisor::pingIfDue() {
  const Nanos now = wall_.now();
  if (!watchdog_ || now - lastPing_ < *watchdog_ / 2) return false;
  lastPing_ = now;
  ++pings_;
  if (const int rc = sd_notify(0, "WATCHDOG=1"); rc < 0) {
    static log::Once once;
    if (once.first()) log::warn(kLogSupervision, "cannot ping the watchdog: {}", std::strerror(-rc));
  }
  return true;
}

bool stderrIsJournal() {
  const char* stream = std::getenv("JOURNAL_STREAM");
  if (!stream || !*stream) return false;
  unsigned long long device = 0;
  unsigned long long inode = 0;
  if (std::sscanf(stream, "%llu:%llu", &device, &inode) != 2) return false;
  struct stat st{};
  if (::fstat(STDERR_FILENO, &st) != 0) return false;
  return st.st_dev == device && st.st_ino == inode;
}

namespace {

int priorityOf(log::Level level) {
  switch (level) {
    case log::Level::kTrace:
    case log::Level::kDebug: return 7;  // LOG_DEBUG
    case log::Level::kInfo: return 6;   // LOG_INFO
    case log::Level::kWarn: return 4;   // LOG_WARNING
    case log::Level::kError: return 3;  // LOG_ERR
    case log::Level::kOff: break;
  }
  return 6;
}

class JournalSink final : public log::Sink {
 public:
  explicit JournalSink(std::string_view show) : show_(fmt::format("BASALT_SHOW={}", show)) {}
  void write(const log::Record& record) override {
    const std::string message = fmt::format("MESSAGE={}: {}", record.category, record.message);
    const std::string priority = fmt::format("PRIORITY={}", priorityOf(record.level));
    const std::string category = fmt::format("BASALT_CATEGORY={}", record.category);
    const std::string level = fmt::format("BASALT_LEVEL={}", log::levelName(record.level));
    const std::string_view identifier = "SYSLOG_IDENTIFIER=basalt";
    const auto field = [](std::string_view s) {
      return iovec{const_cast<char*>(s.data()), s.size()};  // NOLINT: iovec takes a non-const pointer
    };
    iovec fields[] = {field(message), field(priority), field(identifier), field(category), field(level), field(show_)};
    if (sd_journal_sendv(fields, static_cast<int>(std::size(fields))) < 0) {
      // The journal is gone (stopped, socket removed): keep the line on stderr.
      fmt::print(stderr, "basalt: {}: {}: {}\n", record.category, log::levelName(record.level), record.message);
    }
  }

 private:
  std::string show_;
};

}  // namespace

void logToJournal(std::string_view showName) {
  static std::once_flag once;
  std::call_once(once, [showName] {
    log::addSink(std::make_shared<JournalSink>(showName));
    log::setStderrEnabled(false);
  });
}

}  // namespace basalt::kiosk
