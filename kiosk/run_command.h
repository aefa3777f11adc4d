#pragma once

/// \file
/// \brief `basalt run`: wires the show, the output, the renderer and the frame loop.

#include "kiosk/cli.h"

namespace basalt::kiosk {

/// \brief Plays a show as the options say; returns the process exit status (0, or 1 with a
/// message on stderr that says what failed and what to do).
int runShow(const RunOptions& options);

}  // namespace basalt::kiosk
