#pragma once

/// \file
/// \brief Basalt's content readers as the kiosk's factories (ItemFactories in
/// kiosk/show/show_items.h): LAVA scripts (.mdl), scenes (.sce) and models (.obj, .off) as show
/// items, and the script interpreter as the control server's command runner. The program puts
/// them into its ShowFactories where it starts (app/show_factories.cpp).

#include <string>
#include <string_view>

#include "kiosk/show/show_items.h"

namespace basalt::kiosk {

/// \brief The item factory for LAVA scripts (EntryKind::kScript): parses the script and reads
/// ahead every model and image it loads, so that stepping it never waits for a disk.
[[nodiscard]] Result<std::unique_ptr<ItemPlayer>> makeScriptItem(const EntrySpec& entry, const Manifest& manifest);

/// \brief The item factory for scenes (EntryKind::kScene): the scene, its imports and images.
[[nodiscard]] Result<std::unique_ptr<ItemPlayer>> makeSceneItem(const EntrySpec& entry, const Manifest& manifest);

/// \brief The item factory for models (EntryKind::kModel): shown as LAVA shows a loaded object.
[[nodiscard]] Result<std::unique_ptr<ItemPlayer>> makeModelItem(const EntrySpec& entry, const Manifest& manifest);

/// \brief The control server's command runner: one line of LAVA script run on the target's
/// Show. Returns what happened (the command and any notes) or why it could not run.
[[nodiscard]] Result<std::string> runControlCommand(std::string_view command, const CommandTarget& target);

}  // namespace basalt::kiosk
