#include "runtime/log.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <mutex>
#include <string>

namespace basalt::log {
namespace {

// One lock for the category registry and the sinks: logging is rare and off the hot path.
struct Logger {
  std::mutex mutex;
  std::vector<Category*> categories;                  // guarded by mutex
  std::map<std::string, Level, std::less<>> pending;  // spec levels by name; guarded by mutex
  Level defaultLevel = Level::kInfo;                  // guarded by mutex
  std::vector<std::shared_ptr<Sink>> sinks;           // guarded by mutex
  bool stderrEnabled = true;                          // guarded by mutex
  bool envApplied = false;                            // guarded by mutex
};

Logger& logger() {
  static Logger* instance = new Logger;  // never destroyed: categories outlive static teardown
  return *instance;
}

bool parseLevel(std::string_view text, Level& out) {
  static constexpr std::pair<std::string_view, Level> kNames[] = {
      {"trace", Level::kTrace},  {"debug", Level::kDebug}, {"info", Level::kInfo}, {"warn", Level::kWarn},
      {"warning", Level::kWarn}, {"error", Level::kError}, {"off", Level::kOff},   {"none", Level::kOff}};
  for (const auto& [name, level] : kNames) {
    if (name == text) {
      out = level;
      return true;
    }
  }
  return false;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

Level levelFor(Logger& l, std::string_view name) {
  auto it = l.pending.find(name);
  return it != l.pending.end() ? it->second : l.defaultLevel;
}

bool configureLocked(Logger& l, std::string_view spec) {
  bool ok = true;
  while (!spec.empty()) {
    const auto comma = spec.find(',');
    std::string_view item = trim(spec.substr(0, comma));
    spec = comma == std::string_view::npos ? std::string_view{} : spec.substr(comma + 1);
    if (item.empty()) continue;
    const auto eq = item.find('=');
    Level level{};
    if (eq == std::string_view::npos) {
      if (!parseLevel(item, level)) {
        ok = false;
        continue;
      }
      l.defaultLevel = level;
      l.pending.clear();
      continue;
    }
    const std::string_view name = trim(item.substr(0, eq));
    if (!parseLevel(trim(item.substr(eq + 1)), level)) {
      ok = false;
      continue;
    }
    if (name == "*") {
      l.defaultLevel = level;
      l.pending.clear();
    } else {
      l.pending[std::string(name)] = level;
    }
  }
  for (Category* c : l.categories) c->setThreshold(levelFor(l, c->name()));
  return ok;
}

void applyEnvironmentLocked(Logger& l) {
  if (l.envApplied) return;
  l.envApplied = true;
  if (const char* spec = std::getenv("BASALT_LOG")) configureLocked(l, spec);
}

}  // namespace

std::string_view levelName(Level level) {
  switch (level) {
    case Level::kTrace: return "trace";
    case Level::kDebug: return "debug";
    case Level::kInfo: return "info";
    case Level::kWarn: return "warning";
    case Level::kError: return "error";
    case Level::kOff: return "off";
  }
  return "?";
}

Category::Category(std::string_view name) : name_(name), threshold_(Level::kInfo) {
  Logger& l = logger();
  std::lock_guard lock(l.mutex);
  applyEnvironmentLocked(l);
  l.categories.push_back(this);
  threshold_.store(levelFor(l, name_), std::memory_order_relaxed);
}

void addSink(std::shared_ptr<Sink> sink) {
  Logger& l = logger();
  std::lock_guard lock(l.mutex);
  l.sinks.push_back(std::move(sink));
}

void removeSink(const std::shared_ptr<Sink>& sink) {
  Logger& l = logger();
  std::lock_guard lock(l.mutex);
  std::erase(l.sinks, sink);
}

void setStderrEnabled(bool enabled) {
  Logger& l = logger();
  std::lock_guard lock(l.mutex);
  l.stderrEnabled = enabled;
}

bool configure(std::string_view spec) {
  Logger& l = logger();
  std::lock_guard lock(l.mutex);
  l.envApplied = true;
  return configureLocked(l, spec);
}

void write(const Category& category, Level level, std::string message) {
  Record record{std::chrono::system_clock::now(), level, category.name(), std::move(message)};
  Logger& l = logger();
  std::lock_guard lock(l.mutex);
  if (l.stderrEnabled) {
    // "basalt: render: warning: text"; info lines carry no level word.
    if (level == Level::kInfo) {
      fmt::print(stderr, "basalt: {}: {}\n", record.category, record.message);
    } else {
      fmt::print(stderr, "basalt: {}: {}: {}\n", record.category, levelName(level), record.message);
    }
    std::fflush(stderr);
  }
  for (const auto& sink : l.sinks) sink->write(record);
}

RingSink::RingSink(std::size_t capacity) : capacity_(std::max<std::size_t>(capacity, 1)) {
  records_.reserve(capacity_);
}

void RingSink::write(const Record& record) {
  while (busy_.test_and_set(std::memory_order_acquire)) {
  }
  if (records_.size() < capacity_) {
    records_.push_back(record);
  } else {
    records_[next_] = record;
  }
  next_ = (next_ + 1) % capacity_;
  busy_.clear(std::memory_order_release);
}

std::vector<Record> RingSink::snapshot(Level minimum) const {
  while (busy_.test_and_set(std::memory_order_acquire)) {
  }
  std::vector<Record> out;
  out.reserve(records_.size());
  const std::size_t n = records_.size();
  const std::size_t start = n < capacity_ ? 0 : next_;
  for (std::size_t i = 0; i < n; ++i) {
    const Record& r = records_[(start + i) % n];
    if (r.level >= minimum) out.push_back(r);
  }
  busy_.clear(std::memory_order_release);
  return out;
}

}  // namespace basalt::log
