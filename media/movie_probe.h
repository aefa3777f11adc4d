#pragma once

/// \file
/// \brief A quick look into a movie file without playing it (GStreamer's discoverer): can this
/// machine demux and decode it, and what is in it. For `basalt check` and the show loader's
/// checks; bounded in time, so a file that hangs a demuxer cannot hang the check.

#include <chrono>
#include <filesystem>

#include "media/movie_player.h"
#include "runtime/error.h"

namespace basalt::media {

/// \brief Reads `file`'s streams: size, frame rate, pixel aspect, duration, codec, audio.
/// Errors say what is wrong with the file (not a movie, no video stream, no decoder installed
/// for its codec, corrupt, timed out) and name it. Thread-safe; blocks up to `timeout`.
[[nodiscard]] Result<MovieInfo> probeMovie(const std::filesystem::path& file,
                                           std::chrono::milliseconds timeout = std::chrono::seconds(5));

}  // namespace basalt::media
