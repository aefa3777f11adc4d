#pragma once

/// \file
/// \brief Tells a stream that the file it plays has changed on disk: inotify on the file's
/// folder, filtered by the file's name, so that a file replaced by rename (a new inode under the
/// same name), deleted, emptied or written again is noticed without reading it every frame.

#include <sys/types.h>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "runtime/error.h"
#include "runtime/unique_fd.h"

namespace basalt::kiosk {

/// \brief What identifies the content of a file: a rename puts another inode under the name, a
/// write in place changes its size or modification time.
struct FileIdentity {
  dev_t device = 0;
  ino_t inode = 0;
  off_t size = 0;
  std::int64_t modifiedNs = 0;
  bool operator==(const FileIdentity&) const = default;
};

/// \brief The identity of the regular file at `file` now; none when it is missing or not a
/// regular file.
[[nodiscard]] std::optional<FileIdentity> identify(const std::filesystem::path& file);

/// \brief What happened to a file between two looks, for a log line: "was deleted", "is
/// missing", "is back", "was emptied", "was replaced" (another inode under the name) or "was
/// written over (N bytes, M before)".
[[nodiscard]] std::string describeChange(const std::optional<FileIdentity>& before,
                                         const std::optional<FileIdentity>& now);

/// \brief What happened to the watched file since the last take().
enum class FileChange : std::uint8_t {
  kNone,      ///< nothing
  kWriting,   ///< written to (IN_MODIFY): more may follow; look once it has been quiet a while
  kSettled,   ///< closed after writing, created, moved in or out, deleted: look now
  kWatchLost  ///< the folder's watch is gone (the folder was deleted or moved): look now, and watch again later
};

/// \brief One file watched through inotify on its folder. Not thread-safe: one owner (the frame
/// loop's thread). take() never blocks: one non-blocking read() per call.
class FileWatch {
 public:
  /// \brief Watches `file`'s folder for IN_CLOSE_WRITE, IN_MOVED_TO, IN_MOVED_FROM, IN_CREATE,
  /// IN_DELETE and IN_MODIFY on the file's name. Fails when inotify is out of instances or
  /// watches, or the folder is missing: the caller then looks at the file on a back-off.
  [[nodiscard]] static Result<FileWatch> open(const std::filesystem::path& file);

  /// \brief The strongest change since the last call (kWatchLost > kSettled > kWriting).
  [[nodiscard]] FileChange take();

 private:
  FileWatch(UniqueFd fd, std::string name) : fd_(std::move(fd)), name_(std::move(name)) {}
  UniqueFd fd_;
  std::string name_;  // the file's name in its folder, as inotify reports it
};

}  // namespace basalt::kiosk
