#pragma once

/// \file
/// \brief What `basalt run` plays shows with: every content reader, media stream and dial box
/// backend of this build, put together once where the program starts and handed down to the
/// show loader and the director (no process-wide registry).

#include "kiosk/show/show_loader.h"

namespace basalt::kiosk {

/// \brief The factories of this build: LAVA scripts, scenes, models and movies as items; movie
/// and camera textures; hid, replay and serial dial boxes (the synthetic one is built into the
/// loader); and the script interpreter as the control server's command runner.
[[nodiscard]] ShowFactories showFactories();

}  // namespace basalt::kiosk
