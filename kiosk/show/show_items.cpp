#include "kiosk/show/show_items.h"

#include <algorithm>

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

/// The factory for a kind of entry that is not built in; null for the built-in ones.
const ItemFactory* factoryFor(EntryKind kind, const ItemFactories& factories) {
  switch (kind) {
    case EntryKind::kScript: return &factories.script;
    case EntryKind::kScene: return &factories.scene;
    case EntryKind::kModel: return &factories.model;
    case EntryKind::kMovie: return &factories.movie;
    case EntryKind::kBuiltinDefault:
    case EntryKind::kBuiltinBlack: break;
  }
  return nullptr;
}

}  // namespace

Result<std::unique_ptr<ItemPlayer>> prepareItem(const EntrySpec& entry, const Manifest& show,
                                                const ItemFactories& factories) {
  if (const ItemFactory* factory = factoryFor(entry.kind, factories); factory && *factory) {
    return (*factory)(entry, show);
  }
  switch (entry.kind) {
    case EntryKind::kBuiltinDefault: return std::make_unique<DefaultItem>();
    case EntryKind::kBuiltinBlack: return std::make_unique<BlackItem>();
    default: break;
  }
  return fail(Errc::kUnsupported,
              fmt::format("cannot play {} '{}': {}", entryKindName(entry.kind), entry.text, missingReader(entry.kind)),
              fmt::format("{}:{}", show.file.string(), entry.line));
}

Result<std::string> runScriptCommand(const CommandRunner& runner, std::string_view command,
                                     const CommandTarget& target) {
  if (!runner) {
    return fail(Errc::kUnsupported, "this build has no LAVA script interpreter to run the command");
  }
  return runner(command, target);
}

}  // namespace basalt::kiosk
