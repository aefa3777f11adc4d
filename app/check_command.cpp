#include "app/check_command.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/std.h>

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

}  // namespace

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
    const auto it = std::find_if(fileCheckers().begin(), fileCheckers().end(),
                                 [&](const FileChecker& c) { return c.extension == ext; });
    if (it == fileCheckers().end()) {
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
