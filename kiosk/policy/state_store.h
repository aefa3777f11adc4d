#pragma once

/// \file
/// \brief Crash recovery: where the show was (mode, item, position) is saved atomically to a
/// small file, so that after a crash, a kill or a power cut the show resumes where it was. A
/// damaged or foreign state file is ignored with a warning.

#include <condition_variable>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "kiosk/policy/kiosk_policy.h"
#include "runtime/error.h"

namespace basalt::kiosk {

/// \brief The folder state is kept in when none is given: $STATE_DIRECTORY (systemd's
/// StateDirectory=), else $XDG_STATE_HOME/basalt, else ~/.local/state/basalt.
std::filesystem::path defaultStateFolder();

/// \brief Encodes and decodes the state file (text, one field a line, with a checksum).
std::string encodeState(const std::string& showId, const ResumePoint& point);
[[nodiscard]] Result<ResumePoint> decodeState(std::string_view text, const std::string& showId);

/// \brief Saves the resume point of one show.
///
/// Threading: save() is called from the frame loop and never blocks on the disk: it hands the
/// point to a writer thread (the newest point wins), which writes a temporary file, syncs it and
/// renames it over the old one. `mutex_` guards the hand-over.
class StateStore {
 public:
  /// \brief A store for `showId` (the manifest's path and name) in `folder`, created if needed.
  static Result<std::unique_ptr<StateStore>> open(const std::filesystem::path& folder, std::string showId);
  ~StateStore();
  StateStore(const StateStore&) = delete;
  StateStore& operator=(const StateStore&) = delete;

  /// \brief The saved point, or nothing (first run, or a damaged file: a warning says which).
  [[nodiscard]] std::optional<ResumePoint> load() const;
  /// \brief Queues `point` for writing.
  void save(const ResumePoint& point);
  /// \brief Waits until everything queued is on disk.
  void flush();
  [[nodiscard]] const std::filesystem::path& file() const { return file_; }
  /// \brief Writes that failed (a full disk): the show goes on.
  [[nodiscard]] std::uint64_t failures() const;

 private:
  StateStore(std::filesystem::path file, std::string showId);
  void writerLoop();
  Result<void> writeNow(const std::string& text);

  std::filesystem::path file_;
  std::string showId_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::optional<ResumePoint> pending_;  // guarded by mutex_
  bool writing_ = false;                // guarded by mutex_
  bool stop_ = false;                   // guarded by mutex_
  std::uint64_t failures_ = 0;          // guarded by mutex_
  std::thread writer_;
};

}  // namespace basalt::kiosk
