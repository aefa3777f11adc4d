// `basalt check show.toml`: the manifest checker. Reads the manifest as `basalt run` does, with
// every referenced file's own checker, and returns all problems and its verdict on the show.

#include <set>
#include <utility>

#include <fmt/format.h>
#include <fmt/std.h>

#include "kiosk/manifest/check_formats.h"
#include "kiosk/manifest/content_check.h"
#include "kiosk/manifest/manifest.h"

namespace basalt::kiosk {

CheckResult checkManifestFile(const std::filesystem::path& file) {
  Diagnostics diagnostics;
  ReadOptions options;
  options.fileCheckers = &contentCheckers();
  const auto manifest = readManifest(file, diagnostics, options);
  CheckResult result;
  result.diagnostics = diagnostics.items();
  result.items = 1;
  if (manifest) {
    // Whether each facet view sees its facets' fronts: said once per cave file and winding, for
    // the first view that shows it that way.
    std::set<std::pair<std::filesystem::path, formats::FacetWinding>> facing;
    for (const ViewSpec& v : manifest->views) {
      if (v.kind != ViewKind::kFacet || v.cave.empty() || !facing.emplace(v.cave, v.winding).second) continue;
      for (Diagnostic& d : checkCaveFacing(v.cave, v.winding, v.name)) result.diagnostics.push_back(std::move(d));
    }
  }
  if (!manifest && result.errors() == 0) {
    // Not expected (the reader says why it gives up), but a manifest that is not read is never "ok".
    result.diagnostics.push_back({Severity::kError, file, 0, "the manifest could not be read"});
  }
  if (const std::size_t errors = result.errors(); errors > 0 || !manifest) {
    result.verdict = fmt::format("its last good copy plays until {} fixed", errors == 1 ? "it is" : "they are");
    return result;
  }
  result.verdict = fmt::format(
      "ok: '{}' plays {} with {} device{}, {} media, {} binding{}", manifest->name,
      manifest->entry.kind == EntryKind::kBuiltinDefault ? std::string("the default show") : manifest->entry.text,
      manifest->devices.size(), manifest->devices.size() == 1 ? "" : "s", manifest->media.size(),
      manifest->bindings.size(), manifest->bindings.size() == 1 ? "" : "s");
  if (const OscSpec& osc = manifest->osc; osc.enabled) {
    // Said only where there is OSC, so that the line of every other show stays as it was.
    result.verdict +=
        fmt::format("; OSC on {}:{} with {} binding{} and {} destination{}", osc.host, osc.port, osc.bindings.size(),
                    osc.bindings.size() == 1 ? "" : "s", osc.send.size(), osc.send.size() == 1 ? "" : "s");
  }
  return result;
}

}  // namespace basalt::kiosk
