#pragma once

/// \file
/// \brief Traces' camera video in Matroska: media's TraceVideoWriter and TraceVideoReader behind
/// sim's trace seams. sim/ may not depend on media/ (the dependency graph runs the other way
/// round through kiosk/), so the kiosk makes these factories and hands them to the TraceRecorder
/// (`basalt record`) and the ReplayProvider (`basalt run --replay`, show manifests, `basalt
/// devices --replay`). `.bvraw` traces are still read (sim's own reader takes them first).

#include "sim/trace_video.h"

namespace basalt::kiosk {

/// \brief Writes each camera of a trace as `NAME.mkv`: the frames as the device gave them (raw
/// YUV or MJPEG, never re-encoded; see media::TraceVideoWriter for the few rearranged layouts),
/// timestamps since the trace's start to the microsecond.
sim::TraceVideoWriterFactory matroskaTraceWriterFactory();

/// \brief Opens `.mkv` trace videos with media's reader; the frame rate a replay needs for
/// looping is taken from the first two frames' timestamps.
sim::TraceVideoReaderFactory matroskaTraceReaderFactory();

}  // namespace basalt::kiosk
