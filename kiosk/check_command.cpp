#include "kiosk/check_command.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/std.h>

#include "kiosk/check_formats.h"
#include "kiosk/check_mdl.h"
#include "kiosk/commands.h"
#include "kiosk/manifest.h"
#include "kiosk/options.h"
#include "kiosk/readers.h"
#include "media/image_io.h"
#include "media/movie_probe.h"
#include "runtime/script/interpreter.h"
#include "sim/providers.h"

namespace basalt::kiosk {

namespace {

/// How long `basalt check` (and a reload's checks) give one movie file.
constexpr std::chrono::seconds kMovieProbeTimeout{5};

/// A show manifest: every section and every file it names (kiosk/check_manifest.cpp prints
/// the problems and a summary line).
CheckResult checkToml(const std::filesystem::path& file) {
  CheckResult result;
  result.errors = checkManifestFile(file, stdout) == 0 ? 0 : 1;
  result.items = 1;
  return result;
}

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

std::string lowerExtension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

std::string knownKinds() {
  std::string s;
  for (std::size_t i = 0; i < std::size(kCheckers); ++i) {
    s += fmt::format("{}{} ({})", i ? ", " : "", kCheckers[i].extension, kCheckers[i].what);
  }
  return s;
}

}  // namespace

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

std::string_view checkUsage() {
  return R"(Usage: basalt check FILE...

Finds every error in the files of a show without running anything, and prints each as
`file:line: error: what is wrong`. The kind of file is told by its extension:
  .toml   show manifest: its outputs, views, entry, media, devices and bindings,
          textures, kiosk policy and status server; every file it names must exist
          inside the show folder and parse
  .mdl    LAVA script (the commands of 'basalt help script'): unknown commands and
          values (with a "did you mean"), wrong forms, unbalanced loops, files that are
          missing or outside the script's folder, parts the start-up cube does not have
  .sce    scene: every statement, and every model and terrain it imports
  .obj    Wavefront OBJ model (plain or Extended), with its material libraries
  .off    OFF model
  .cave   cave file: its settings, and the cave geometry model it names (facets flat,
          convex, the facet and side it names present)

Options:
  -h, --help    this text

Exit status: 0 when no file has errors, 1 when one has (or cannot be read), 2 for usage errors.
)";
}

int checkMain(std::span<const std::string_view> args) {
  registerContentReaders();
  auto parsed = parseOptions("check", args, {{"--help|-h"}});
  if (!parsed) return usageError(parsed.error().describe());
  std::vector<std::filesystem::path> files;
  for (const ParsedOption& o : *parsed) {
    if (o.name == "--help") {
      fmt::print("{}", checkUsage());
      return 0;
    }
    if (o.name.empty()) files.emplace_back(o.value);
  }
  if (files.empty()) return usageError("basalt check needs a file to check; see 'basalt check --help'");
  std::vector<const FileChecker*> checkers;
  for (const auto& file : files) {
    const std::string ext = lowerExtension(file);
    const auto it = std::find_if(std::begin(kCheckers), std::end(kCheckers),
                                 [&](const FileChecker& c) { return c.extension == ext; });
    if (it == std::end(kCheckers)) {
      return usageError(fmt::format("basalt check does not know '{}' files ({}); it checks {}",
                                    ext.empty() ? std::string("extension-less") : ext, file.string(), knownKinds()));
    }
    checkers.push_back(&*it);
  }
  bool anyErrors = false;
  for (std::size_t i = 0; i < files.size(); ++i) {
    const CheckResult r = checkers[i]->check(files[i]);
    anyErrors = anyErrors || r.errors > 0;
    std::fflush(stdout);
    if (r.errors == 0 && r.warnings == 0) {
      fmt::print("basalt: {}: no errors ({} {} checked)\n", files[i].string(), r.items, checkers[i]->items);
    } else {
      fmt::print("basalt: {}: {} {}, {} {}\n", files[i].string(), r.errors, r.errors == 1 ? "error" : "errors",
                 r.warnings, r.warnings == 1 ? "warning" : "warnings");
    }
  }
  std::fflush(stdout);
  return anyErrors ? 1 : 0;
}

}  // namespace basalt::kiosk
