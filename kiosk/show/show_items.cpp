#include "kiosk/show/show_items.h"

#include <algorithm>
#include <array>
#include <mutex>

#include <fmt/format.h>

namespace basalt::kiosk {

namespace {

/// LAVA's start-up scene, resumed by running its motion forward.
class DefaultItem final : public ItemPlayer {
 public:
  Result<void> start(runtime::Show& show, Nanos position, double fps) override {
    show = runtime::Show::makeDefault();
    // The cube's motion is per frame; a resumed cube turns on from where it was. Capped at ten
    // minutes of frames so that resuming stays well within one frame's time.
    const auto frames = std::min<std::int64_t>(static_cast<std::int64_t>(toSeconds(position) * fps), 36000);
    for (std::int64_t i = 0; i < frames; ++i) show.advanceFrame();
    return {};
  }
};

/// Nothing on black.
class BlackItem final : public ItemPlayer {
 public:
  Result<void> start(runtime::Show& show, Nanos /*position*/, double /*fps*/) override {
    show = runtime::Show();
    return {};
  }
};

struct Registry {
  std::mutex mutex;
  std::array<ItemFactory, 6> factories;  // by EntryKind; guarded by mutex
  CommandRunner commands;                // guarded by mutex
};

Registry& registry() {
  static Registry r;
  return r;
}

std::string_view missingReader(EntryKind kind) {
  switch (kind) {
    case EntryKind::kScript: return "this build has no LAVA script interpreter";
    case EntryKind::kScene: return "this build has no .sce scene reader";
    case EntryKind::kModel: return "this build has no model reader";
    case EntryKind::kMovie:
      return "movies are not played as show items in this build yet; show the movie as a texture of a model "
             "or scene ([media] and [textures] in show.toml)";
    case EntryKind::kBuiltinDefault:
    case EntryKind::kBuiltinBlack: break;
  }
  return "this build cannot play it";
}

}  // namespace

void setItemFactory(EntryKind kind, ItemFactory factory) {
  Registry& r = registry();
  std::lock_guard lock(r.mutex);
  r.factories[static_cast<std::size_t>(kind)] = std::move(factory);
}

Result<std::unique_ptr<ItemPlayer>> prepareItem(const EntrySpec& entry, const Manifest& show) {
  ItemFactory factory;
  {
    Registry& r = registry();
    std::lock_guard lock(r.mutex);
    factory = r.factories[static_cast<std::size_t>(entry.kind)];
  }
  if (factory) return factory(entry, show);
  switch (entry.kind) {
    case EntryKind::kBuiltinDefault: return std::make_unique<DefaultItem>();
    case EntryKind::kBuiltinBlack: return std::make_unique<BlackItem>();
    default: break;
  }
  return fail(Errc::kUnsupported,
              fmt::format("cannot play {} '{}': {}", entryKindName(entry.kind), entry.text, missingReader(entry.kind)),
              fmt::format("{}:{}", show.file.string(), entry.line));
}

void setCommandRunner(CommandRunner runner) {
  Registry& r = registry();
  std::lock_guard lock(r.mutex);
  r.commands = std::move(runner);
}

Result<std::string> runScriptCommand(std::string_view command, const CommandTarget& target) {
  CommandRunner runner;
  {
    Registry& r = registry();
    std::lock_guard lock(r.mutex);
    runner = r.commands;
  }
  if (!runner) {
    return fail(Errc::kUnsupported, "this build has no LAVA script interpreter to run the command");
  }
  return runner(command, target);
}

}  // namespace basalt::kiosk
