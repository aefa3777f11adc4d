#include "kiosk/show/file_watch.h"

#include <sys/inotify.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <string_view>

#include <fmt/format.h>

namespace basalt::kiosk {

std::optional<FileIdentity> identify(const std::filesystem::path& file) {
  struct stat st{};
  if (::stat(file.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return std::nullopt;
  return FileIdentity{st.st_dev, st.st_ino, st.st_size,
                      static_cast<std::int64_t>(st.st_mtim.tv_sec) * 1'000'000'000 + st.st_mtim.tv_nsec};
}

std::string describeChange(const std::optional<FileIdentity>& before, const std::optional<FileIdentity>& now) {
  if (!now) return before ? "was deleted" : "is missing";
  if (!before) return "is back";
  if (now->size == 0) return "was emptied";
  if (now->device != before->device || now->inode != before->inode) return "was replaced";
  return fmt::format("was written over ({} bytes, {} before)", now->size, before->size);
}

Result<FileWatch> FileWatch::open(const std::filesystem::path& file) {
  UniqueFd fd(::inotify_init1(IN_CLOEXEC | IN_NONBLOCK));
  if (!fd) {
    return fail(Errc::kUnavailable, fmt::format("inotify: {}", std::strerror(errno)), file.string());
  }
  const std::filesystem::path folder = file.parent_path().empty() ? "." : file.parent_path();
  constexpr std::uint32_t kMask = IN_CLOSE_WRITE | IN_MOVED_TO | IN_MOVED_FROM | IN_CREATE | IN_DELETE | IN_MODIFY;
  if (::inotify_add_watch(fd.get(), folder.c_str(), kMask) < 0) {
    return fail(Errc::kUnavailable, fmt::format("cannot watch its folder: {}", std::strerror(errno)), file.string());
  }
  return FileWatch(std::move(fd), file.filename().string());
}

FileChange FileWatch::take() {
  FileChange change = FileChange::kNone;
  const auto raise = [&change](FileChange c) { change = std::max(change, c); };
  alignas(inotify_event) std::array<char, 4096> buffer{};
  for (;;) {
    const ssize_t n = ::read(fd_.get(), buffer.data(), buffer.size());
    if (n <= 0) break;  // EAGAIN: nothing more
    for (ssize_t at = 0; at < n;) {
      inotify_event event{};
      std::memcpy(&event, buffer.data() + at, sizeof event);
      const char* name = buffer.data() + at + sizeof event;
      at += static_cast<ssize_t>(sizeof event + event.len);
      if ((event.mask & IN_Q_OVERFLOW) != 0) {
        raise(FileChange::kSettled);  // events were lost: look anyway
        continue;
      }
      if ((event.mask & IN_IGNORED) != 0) {
        raise(FileChange::kWatchLost);
        continue;
      }
      if (event.len == 0 || name_ != std::string_view(name, ::strnlen(name, event.len))) continue;
      const bool onlyWritten = (event.mask & static_cast<std::uint32_t>(IN_MODIFY)) == event.mask;
      raise(onlyWritten ? FileChange::kWriting : FileChange::kSettled);
    }
  }
  return change;
}

}  // namespace basalt::kiosk
