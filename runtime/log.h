#pragma once

/// \file
/// \brief Logging with categories and levels, to pluggable sinks (stderr by default; the kiosk
/// adds journald; the status server reads the ring of recent records).
///
/// Threading: every function here may be called from any thread. Formatting allocates, so the
/// frame loop logs only on change (state transitions, errors), never per frame.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

namespace basalt::log {

enum class Level : std::uint8_t { kTrace, kDebug, kInfo, kWarn, kError, kOff };

/// \brief "trace", "debug", "info", "warning", "error", "off".
std::string_view levelName(Level level);

/// \brief A named source of log records with its own threshold.
///
/// Categories are created once, at namespace scope, with `BASALT_LOG_CATEGORY`. Their thresholds
/// come from `BASALT_LOG` (see ENV_VARS.md) and may be changed at run time.
class Category {
 public:
  explicit Category(std::string_view name);
  Category(const Category&) = delete;
  Category& operator=(const Category&) = delete;

  [[nodiscard]] std::string_view name() const { return name_; }
  [[nodiscard]] bool enabled(Level level) const { return level >= threshold_.load(std::memory_order_relaxed); }
  void setThreshold(Level level) { threshold_.store(level, std::memory_order_relaxed); }

 private:
  std::string_view name_;
  std::atomic<Level> threshold_;  // relaxed atomic: a stale read only delays a level change
};

/// \brief One log line as sinks receive it.
struct Record {
  std::chrono::system_clock::time_point wallTime;
  Level level;
  std::string_view category;
  std::string message;
};

/// \brief Receives records. Called with the logger's lock held: implementations must not log.
class Sink {
 public:
  virtual ~Sink() = default;
  virtual void write(const Record& record) = 0;
};

/// \brief Adds a sink; records go to every sink added. Ownership is shared with the caller.
void addSink(std::shared_ptr<Sink> sink);
void removeSink(const std::shared_ptr<Sink>& sink);
/// \brief Turns the default stderr sink on or off (the journald sink replaces it under systemd).
void setStderrEnabled(bool enabled);

/// \brief Applies a `BASALT_LOG`-style spec: "info", "render=debug,devices=trace", "*=warning".
/// Unknown category names are kept and applied when that category is created.
/// \return false when the spec has a level name that does not exist.
bool configure(std::string_view spec);

/// \brief Writes a record (already checked against the threshold by the helpers below).
void write(const Category& category, Level level, std::string message);

/// \brief Keeps the last N records in memory for the status server ("log tail", "last errors").
class RingSink final : public Sink {
 public:
  explicit RingSink(std::size_t capacity);
  void write(const Record& record) override;
  /// \brief The records in order, oldest first, at or above `minimum`.
  [[nodiscard]] std::vector<Record> snapshot(Level minimum = Level::kTrace) const;

 private:
  std::size_t capacity_;
  std::vector<Record> records_;  // guarded by busy_
  std::size_t next_ = 0;
  mutable std::atomic_flag busy_ = ATOMIC_FLAG_INIT;  // spin guard between write and snapshot
};

template <typename... Args>
void trace(const Category& c, fmt::format_string<Args...> f, Args&&... args) {
  if (c.enabled(Level::kTrace)) write(c, Level::kTrace, fmt::format(f, std::forward<Args>(args)...));
}
template <typename... Args>
void debug(const Category& c, fmt::format_string<Args...> f, Args&&... args) {
  if (c.enabled(Level::kDebug)) write(c, Level::kDebug, fmt::format(f, std::forward<Args>(args)...));
}
template <typename... Args>
void info(const Category& c, fmt::format_string<Args...> f, Args&&... args) {
  if (c.enabled(Level::kInfo)) write(c, Level::kInfo, fmt::format(f, std::forward<Args>(args)...));
}
template <typename... Args>
void warn(const Category& c, fmt::format_string<Args...> f, Args&&... args) {
  if (c.enabled(Level::kWarn)) write(c, Level::kWarn, fmt::format(f, std::forward<Args>(args)...));
}
template <typename... Args>
void error(const Category& c, fmt::format_string<Args...> f, Args&&... args) {
  if (c.enabled(Level::kError)) write(c, Level::kError, fmt::format(f, std::forward<Args>(args)...));
}

/// \brief A flag for "say this once": `static log::Once once; if (once.first()) log::warn(...)`.
class Once {
 public:
  /// \brief True exactly once, for the first caller, from any thread.
  bool first() { return !done_.exchange(true, std::memory_order_relaxed); }
  void reset() { done_.store(false, std::memory_order_relaxed); }

 private:
  std::atomic<bool> done_{false};
};

}  // namespace basalt::log

/// Defines a log category object `kLog<Name>` at namespace scope: BASALT_LOG_CATEGORY(Render, "render").
#define BASALT_LOG_CATEGORY(Ident, name) \
  inline ::basalt::log::Category kLog##Ident { name }
