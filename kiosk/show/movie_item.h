#pragma once

/// \file
/// \brief A movie as a show item: the whole screen shows it, letterboxed at its aspect, over
/// black. It loops gaplessly while the item is to loop (an item with a duration, or alone in
/// its list) and otherwise ends at its last frame, so that the playlist moves on.

#include <cstdint>
#include <memory>

#include "kiosk/manifest/manifest.h"
#include "kiosk/show/show_items.h"
#include "render/output.h"
#include "render/stream_texture.h"

namespace basalt::kiosk {

/// \brief Where a picture of `picture` pixels (already corrected for pixel aspect) sits on an
/// output of `output` pixels: as large as fits, centred, black bars on the two other sides.
[[nodiscard]] render::PictureRect letterbox(double pictureWidth, double pictureHeight, render::Size output);

/// \brief The item factory for movies (EntryKind::kMovie). Runs on the show loader's thread:
/// opens the file and waits (bounded) for its first frame, so that a file GStreamer cannot play
/// is reported with its manifest line when the show loads, not when the item comes up.
[[nodiscard]] Result<std::unique_ptr<ItemPlayer>> makeMovieItem(const EntrySpec& entry, const Manifest& show);

}  // namespace basalt::kiosk
