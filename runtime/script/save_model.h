#pragma once

/// \file
/// \brief LAVA's Save Model (manual §8): "save everything so that the exact same image will be
/// seen when reloaded". The Show is written as an `.mdl` script of the commands in the command
/// table; run on a fresh show it gives the same Show state and so, bit for bit, the same picture.

#include <string>

#include "runtime/script/interpreter.h"
#include "runtime/show/show.h"

namespace basalt::script {

/// \brief The Show as a script: the object (`load_color_cube` or `load_object`), the textures
/// on parts, every global attribute, each part's own attributes (which win over global ones),
/// every global-only setting (lights, depth cue, clipping, view, motion, matrices, ...), and the
/// part selection. Numbers are written so that they read back exactly.
///
/// Not written, because no script command sets them: fog, the earth-sky and background images
/// (scene files set those); a comment in the output says so when they differ from the defaults.
std::string saveModel(const runtime::Show& show, const ObjectSource& object);

}  // namespace basalt::script
