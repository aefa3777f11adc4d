#pragma once

/// \file
/// \brief Plugs Basalt's content readers into the kiosk's seams (kiosk/show/show_items.h): LAVA
/// scripts (.mdl), scenes (.sce) and models (.obj, .off) as show items, and the script
/// interpreter as the control server's command runner.

#include <string>
#include <string_view>

#include "kiosk/show/show_items.h"

namespace basalt::kiosk {

/// \brief Registers the script, scene and model item factories and the command runner. Call
/// once where the program starts, before the first show loads (runShow, checkMain, tests).
/// Movies are not registered: a movie item still fails with a message that says so.
void registerContentReaders();

/// \brief The control server's command runner: one line of LAVA script run on the target's
/// Show. Returns what happened (the command and any notes) or why it could not run.
[[nodiscard]] Result<std::string> runControlCommand(std::string_view command, const CommandTarget& target);

}  // namespace basalt::kiosk
