#include "app/check_command.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/std.h>
#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "app/options.h"
#include "kiosk/manifest/content_check.h"

namespace basalt::kiosk {

namespace {

std::string lowerExtension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

std::string knownKinds() {
  std::string s;
  for (std::size_t i = 0; i < fileCheckers().size(); ++i) {
    s += fmt::format("{}{} ({})", i ? ", " : "", fileCheckers()[i].extension, fileCheckers()[i].what);
  }
  return s;
}

std::string plural(std::size_t n, std::string_view one, std::string_view many) {
  return fmt::format("{} {}", n, n == 1 ? one : many);
}

/// The diagnostics, then one line for the file whose counts are those of the lines above it.
void printText(const std::filesystem::path& file, const FileChecker& checker, const CheckResult& r) {
  for (const Diagnostic& d : r.diagnostics) fmt::print("{}\n", formatCheckDiagnostic(d));
  const std::size_t errors = r.errors();
  const std::size_t warnings = r.warnings();
  std::string line;
  if (errors > 0 || warnings > 0) {
    line = plural(errors, "error", "errors") + ", " + plural(warnings, "warning", "warnings");
    if (!r.verdict.empty()) line += "; " + r.verdict;
  } else if (!r.verdict.empty()) {
    line = r.verdict;
  } else {
    line = fmt::format("no errors ({} {} checked)", r.items, checker.items);
  }
  fmt::print("basalt: {}: {}\n", file.string(), line);
}

/// `basalt check --json`: every file's diagnostics and counts, and the totals, for CI.
std::string checkJson(const std::vector<std::filesystem::path>& files, const std::vector<const FileChecker*>& checkers,
                      const std::vector<CheckResult>& results) {
  nlohmann::ordered_json out;
  out["files"] = nlohmann::ordered_json::array();
  std::size_t errors = 0;
  std::size_t warnings = 0;
  for (std::size_t i = 0; i < results.size(); ++i) {
    const CheckResult& r = results[i];
    nlohmann::ordered_json file;
    file["file"] = files[i].string();
    file["kind"] = checkers[i]->what;
    file["errors"] = r.errors();
    file["warnings"] = r.warnings();
    file["items"] = r.items;
    file["items_are"] = checkers[i]->items;
    if (!r.verdict.empty()) file["verdict"] = r.verdict;
    file["diagnostics"] = nlohmann::ordered_json::array();
    for (const Diagnostic& d : r.diagnostics) {
      nlohmann::ordered_json item;
      item["file"] = d.file.string();
      item["line"] = d.line;
      item["severity"] = severityName(d.severity);
      item["message"] = d.message;
      file["diagnostics"].push_back(std::move(item));
    }
    errors += r.errors();
    warnings += r.warnings();
    out["files"].push_back(std::move(file));
  }
  out["errors"] = errors;
  out["warnings"] = warnings;
  // Paths and messages may hold bytes that are not UTF-8 (a file name, a line quoted from a
  // file): replaced, so that the document stays valid JSON.
  return out.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
}

}  // namespace

std::string_view checkUsage() {
  return R"(Usage: basalt check FILE...

Finds every error in the files of a show without running anything, and prints each as
`file:line: error: what is wrong` (warnings and notes alike). The kind of file is told by its extension:
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
          convex, the facet and side it names present, facing the viewer: a geometry
          wound outward is said once, with its lines and the fix)

Each file ends with one line that counts the errors and warnings printed above it.

Options:
  --json        print one JSON document instead, for CI: {"files": [{"file", "kind",
                "errors", "warnings", "items", "items_are", "verdict" (manifests),
                "diagnostics": [{"file", "line", "severity", "message"}, ...]}, ...],
                "errors", "warnings"}; "line" is 0 for the whole file, "severity" is
                "error", "warning" or "note"
  -h, --help    this text

Exit status: 0 when no file has errors, 1 when one has (or cannot be read), 2 for usage errors.
)";
}

int checkMain(std::span<const std::string_view> args) {
  auto parsed = parseOptions("check", args, {{"--help|-h"}, {"--json"}});
  if (!parsed) return usageError(parsed.error().describe());
  std::vector<std::filesystem::path> files;
  bool json = false;
  for (const ParsedOption& o : *parsed) {
    if (o.name == "--help") {
      fmt::print("{}", checkUsage());
      return 0;
    }
    if (o.name == "--json") json = true;
    if (o.name.empty()) files.emplace_back(o.value);
  }
  if (files.empty()) return usageError("basalt check needs a file to check; see 'basalt check --help'");
  std::vector<const FileChecker*> checkers;
  for (const auto& file : files) {
    const std::string ext = lowerExtension(file);
    const auto it = std::find_if(fileCheckers().begin(), fileCheckers().end(),
                                 [&](const FileChecker& c) { return c.extension == ext; });
    if (it == fileCheckers().end()) {
      return usageError(fmt::format("basalt check does not know '{}' files ({}); it checks {}",
                                    ext.empty() ? std::string("extension-less") : ext, file.string(), knownKinds()));
    }
    checkers.push_back(&*it);
  }
  std::vector<CheckResult> results;
  for (std::size_t i = 0; i < files.size(); ++i) {
    results.push_back(checkers[i]->check(files[i]));
    if (!json) printText(files[i], *checkers[i], results.back());
  }
  if (json) {
    fmt::print("{}\n", checkJson(files, checkers, results));
  } else if (results.size() > 1) {
    std::size_t errors = 0;
    std::size_t warnings = 0;
    for (const CheckResult& r : results) {
      errors += r.errors();
      warnings += r.warnings();
    }
    fmt::print("basalt: {} files: {}, {}\n", results.size(), plural(errors, "error", "errors"),
               plural(warnings, "warning", "warnings"));
  }
  std::fflush(stdout);
  const bool anyErrors =
      std::any_of(results.begin(), results.end(), [](const CheckResult& r) { return r.errors() > 0; });
  return anyErrors ? 1 : 0;
}

}  // namespace basalt::kiosk
