#include "kiosk/manifest/check_formats.h"

#include <algorithm>
#include <cctype>
#include <string>

#include <fmt/format.h>

#include "media/image_io.h"
#include "runtime/formats/cave.h"
#include "runtime/formats/model.h"
#include "runtime/formats/scene.h"

namespace basalt::kiosk {

namespace {

/// What one format's reader found: problems with their "file:line:column" and a count.
struct Findings {
  std::vector<Diagnostic> problems;
  std::size_t items = 0;
};

/// Splits "file:line:column", "file:line" or "file" into the file and the line; the column goes
/// in front of the message.
Diagnostic fromWhere(Severity severity, const std::string& where, std::string message,
                     const std::filesystem::path& fallback) {
  std::string file = where;
  // Up to two trailing numbers: "...:line:column" or "...:line".
  int last = -1;
  int beforeLast = -1;
  for (int i = 0; i < 2; ++i) {
    const std::size_t colon = file.rfind(':');
    if (colon == std::string::npos || colon + 1 == file.size()) break;
    const std::string tail = file.substr(colon + 1);
    if (!std::all_of(tail.begin(), tail.end(), [](unsigned char c) { return std::isdigit(c) != 0; })) break;
    beforeLast = last;
    last = std::stoi(tail);
    file.resize(colon);
  }
  if (file.empty()) file = fallback.string();
  // Read from the end: with two numbers, `last` is the line and `beforeLast` the column.
  const int line = last < 0 ? 0 : last;
  if (beforeLast >= 0) message = fmt::format("column {}: {}", beforeLast, message);
  return {severity, file, line, std::move(message)};
}

void addWarnings(Findings& f, const std::vector<formats::Diagnostic>& warnings, const std::filesystem::path& file) {
  for (const formats::Diagnostic& w : warnings)
    f.problems.push_back(fromWhere(Severity::kWarning, w.where, w.message, file));
}

void addError(Findings& f, const Error& error, const std::filesystem::path& file) {
  f.problems.push_back(fromWhere(Severity::kError, error.where(), error.message(), file));
}

formats::LoadOptions quietOptions() {
  formats::LoadOptions options;
  options.logWarnings = false;  // the checker prints them itself
  options.decodeImage = [](const std::filesystem::path& path) { return media::readImage(path); };
  return options;
}

Findings findModel(const std::filesystem::path& file) {
  Findings f;
  auto model = formats::loadModel(file, quietOptions());
  if (!model) {
    addError(f, model.error(), file);
    return f;
  }
  addWarnings(f, model->warnings, file);
  f.items = formats::countModel(*model).objects;
  return f;
}

Findings findScene(const std::filesystem::path& file) {
  Findings f;
  auto scene = formats::loadScene(file, quietOptions());
  if (!scene) {
    addError(f, scene.error(), file);
    return f;
  }
  addWarnings(f, scene->warnings, file);
  f.items = scene->description.sources.size();
  if (f.items > 0 && scene->models.empty() && scene->terrains.empty()) {
    f.problems.push_back(
        {Severity::kError, file, 0, fmt::format("nothing to show: none of its {} imports could be loaded", f.items)});
  }
  return f;
}

/// `facing`: also whether the facets face the viewer as written (a whole cave file). A manifest
/// asks that per facet view, knowing the view's `winding` (checkCaveFacing).
Findings findCave(const std::filesystem::path& file, bool facing) {
  Findings f;
  auto cave = formats::loadCave(file, nullptr, quietOptions());
  if (!cave) {
    addError(f, cave.error(), file);
    return f;
  }
  addWarnings(f, cave->warnings, file);
  if (facing && cave->geometry) {
    if (auto problem = formats::caveFacingProblem(*cave->geometry, formats::FacetWinding::kInward)) {
      addWarnings(f, {*problem}, file);
    }
  }
  f.items = cave->geometry ? cave->geometry->facets.size() : 0;
  return f;
}

CheckResult result(Findings f) {
  CheckResult r;
  r.diagnostics = std::move(f.problems);
  r.items = f.items;
  return r;
}

}  // namespace

CheckResult checkSceneFile(const std::filesystem::path& file) { return result(findScene(file)); }
CheckResult checkModelFile(const std::filesystem::path& file) { return result(findModel(file)); }
CheckResult checkCaveFile(const std::filesystem::path& file) { return result(findCave(file, true)); }

std::vector<Diagnostic> checkSceneContent(const std::filesystem::path& file) { return findScene(file).problems; }
std::vector<Diagnostic> checkModelContent(const std::filesystem::path& file) { return findModel(file).problems; }
std::vector<Diagnostic> checkCaveContent(const std::filesystem::path& file) { return findCave(file, false).problems; }

std::vector<Diagnostic> checkCaveFacing(const std::filesystem::path& cave, formats::FacetWinding winding,
                                        std::string_view view) {
  auto loaded = formats::loadCave(cave, nullptr, quietOptions());
  // A cave that does not load is reported by its content check.
  if (!loaded || !loaded->geometry) return {};
  auto problem = formats::caveFacingProblem(*loaded->geometry, winding);
  if (!problem) return {};
  problem->message = fmt::format("facet view '{}': {}", view, problem->message);
  Findings f;
  addWarnings(f, {*problem}, cave);
  return f.problems;
}

}  // namespace basalt::kiosk
