// The content checks: one checker per kind of file `basalt check` reads, and the checks a
// manifest runs on each file it names (images, scripts, scenes, models, movies, traces). The
// show loader and `basalt check` share them, so a show that passes the check loads.

#include "kiosk/manifest/content_check.h"

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/std.h>

#include "kiosk/manifest/check_formats.h"
#include "kiosk/manifest/check_mdl.h"
#include "kiosk/manifest/manifest.h"
#include "media/image_io.h"
#include "media/movie_probe.h"
#include "runtime/script/interpreter.h"
#include "sim/providers.h"

namespace basalt::kiosk {

namespace {

/// How long `basalt check` (and a reload's checks) give one movie file.
constexpr std::chrono::seconds kMovieProbeTimeout{5};

/// A show manifest: every section and every file it names (kiosk/manifest/check_manifest.cpp).
CheckResult checkToml(const std::filesystem::path& file) { return checkManifestFile(file); }

// One line per kind of file; the checker lives in its own file.
constexpr FileChecker kCheckers[] = {
    {".toml", "show manifest", "manifests", checkToml}, {".mdl", "LAVA script", "commands", checkMdl},
    {".sce", "scene", "imports", checkSceneFile},       {".obj", "Wavefront OBJ model", "objects", checkModelFile},
    {".off", "OFF model", "objects", checkModelFile},   {".cave", "cave file", "facets", checkCaveFile},
};

/// Images a manifest names (textures, fallbacks) must decode.
std::vector<Diagnostic> checkImageContent(const std::filesystem::path& file) {
  std::vector<Diagnostic> out;
  auto image = media::readImage(file);
  if (!image) {
    out.push_back({Severity::kError, file, 0, fmt::format("cannot be read as an image: {}", image.error().message())});
  } else if (image->empty()) {
    out.push_back({Severity::kError, file, 0, "the image is empty (0 pixels)"});
  }
  return out;
}

/// A script a manifest names: what `basalt check SCRIPT.mdl` finds, as the manifest's problems.
std::vector<Diagnostic> checkScriptContent(const std::filesystem::path& file) {
  std::vector<Diagnostic> out;
  auto interpreter = script::Interpreter::load(file);
  if (!interpreter) {
    out.push_back({Severity::kError, file, 0, interpreter.error().message()});
    return out;
  }
  const script::Program& program = interpreter->program();
  const std::filesystem::path folder = file.parent_path().empty() ? "." : file.parent_path();
  std::vector<script::Diagnostic> found = program.diagnostics;
  for (script::Diagnostic& d : checkScriptStatically(program, folder)) found.push_back(std::move(d));
  script::sortByLine(found);
  for (const script::Diagnostic& d : found) {
    const Severity severity = d.severity == script::Severity::kError     ? Severity::kError
                              : d.severity == script::Severity::kWarning ? Severity::kWarning
                                                                         : Severity::kNote;
    out.push_back({severity, file, static_cast<int>(d.line), d.message});
  }
  return out;
}

/// A movie a manifest names (a media file or an item): GStreamer must be able to read it.
std::vector<Diagnostic> checkMovieContent(const std::filesystem::path& file) {
  std::vector<Diagnostic> out;
  auto info = media::probeMovie(file, kMovieProbeTimeout);
  if (!info) {
    out.push_back({Severity::kError, file, 0, info.error().message()});
  } else if (info->duration <= Nanos{0}) {
    out.push_back({Severity::kWarning, file, 0,
                   "its length is unknown (a stream without an index): it plays, but cannot be resumed or seeked"});
  }
  return out;
}

/// A replay trace a manifest names: its trace.toml and every recording in it must read, and
/// each recorded dial box must decode (what the replay backend opens).
std::vector<Diagnostic> checkTraceContent(const std::filesystem::path& folder) {
  std::vector<Diagnostic> out;
  const auto report = [&](const Error& e, const std::filesystem::path& fallback) {
    // The trace reader's errors carry "file:line"; keep it as the diagnostic's place.
    std::filesystem::path file = fallback;
    int line = 0;
    const std::string& where = e.where();
    if (const auto colon = where.rfind(':'); colon != std::string::npos && colon + 1 < where.size() &&
                                             std::all_of(where.begin() + static_cast<std::ptrdiff_t>(colon) + 1,
                                                         where.end(), [](char c) { return c >= '0' && c <= '9'; })) {
      file = where.substr(0, colon);
      line = std::stoi(where.substr(colon + 1));
    } else if (!where.empty()) {
      file = where;
    }
    out.push_back({Severity::kError, file, line, e.message()});
  };
  sim::ReplayProvider replay;
  if (auto r = replay.addTrace(folder); !r) {
    report(r.error(), folder / "trace.toml");
    return out;
  }
  std::size_t devices = 0;
  for (const devices::DeviceCandidate& c : replay.enumerate()) {
    ++devices;
    if (!c.problem.empty()) {
      out.push_back({Severity::kError, c.info.path.empty() ? folder : std::filesystem::path(c.info.path), 0,
                     fmt::format("recorded {} cannot be replayed: {}", c.info.name, c.problem)});
    }
  }
  if (devices == 0) {
    out.push_back(
        {Severity::kWarning, folder / "trace.toml", 0, "the trace records no device: its replay device stays absent"});
  }
  return out;
}

}  // namespace

std::size_t CheckResult::errors() const {
  return static_cast<std::size_t>(std::count_if(diagnostics.begin(), diagnostics.end(),
                                                [](const Diagnostic& d) { return d.severity == Severity::kError; }));
}

std::size_t CheckResult::warnings() const {
  return static_cast<std::size_t>(std::count_if(diagnostics.begin(), diagnostics.end(),
                                                [](const Diagnostic& d) { return d.severity == Severity::kWarning; }));
}

std::string_view severityName(Severity severity) {
  switch (severity) {
    case Severity::kError: return "error";
    case Severity::kWarning: return "warning";
    case Severity::kNote: return "note";
  }
  return "error";
}

std::string formatCheckDiagnostic(const Diagnostic& d) {
  return fmt::format("{}{}: {}: {}", d.file.string(), d.line > 0 ? fmt::format(":{}", d.line) : std::string(),
                     severityName(d.severity), d.message);
}

std::span<const FileChecker> fileCheckers() { return kCheckers; }

const std::map<std::string, ContentChecker, std::less<>>& contentCheckers() {
  static const std::map<std::string, ContentChecker, std::less<>> checkers{
      {".png", checkImageContent},  {".jpg", checkImageContent},  {".jpeg", checkImageContent},
      {".tif", checkImageContent},  {".tiff", checkImageContent}, {".exr", checkImageContent},
      {".ppm", checkImageContent},  {".pgm", checkImageContent},  {".pnm", checkImageContent},
      {".tga", checkImageContent},  {".bmp", checkImageContent},  {".hdr", checkImageContent},
      {".mdl", checkScriptContent}, {".sce", checkSceneContent},  {".obj", checkModelContent},
      {".off", checkModelContent},  {".cave", checkCaveContent},  {".trace", checkTraceContent},
      {".mkv", checkMovieContent},  {".mp4", checkMovieContent},  {".mov", checkMovieContent},
      {".webm", checkMovieContent}, {".avi", checkMovieContent},  {".mpg", checkMovieContent},
      {".mpeg", checkMovieContent}, {".m1v", checkMovieContent},  {".m2v", checkMovieContent},
      {".ogv", checkMovieContent},  {".ts", checkMovieContent},   {".m4v", checkMovieContent},
  };
  return checkers;
}

}  // namespace basalt::kiosk
