// `basalt check show.toml`: the manifest checker. Reads the manifest as `basalt run` does, with
// every referenced file's own checker, and prints all problems, then one summary line.

#include <cstdio>

#include <fmt/format.h>
#include <fmt/std.h>

#include "kiosk/manifest/content_check.h"
#include "kiosk/manifest/manifest.h"

namespace basalt::kiosk {

int checkManifestFile(const std::filesystem::path& file, std::FILE* out) {
  Diagnostics diagnostics;
  ReadOptions options;
  options.fileCheckers = &contentCheckers();
  const auto manifest = readManifest(file, diagnostics, options);
  fmt::print(out, "{}", diagnostics.format());
  const std::size_t errors = diagnostics.errorCount();
  if (errors > 0 || !manifest) {
    fmt::print(out, "{}: {} problem{}; the show will not start until {} fixed\n", file.string(), errors,
               errors == 1 ? "" : "s", errors == 1 ? "it is" : "they are");
    std::fflush(out);
    return 1;
  }
  fmt::print(
      out, "{}: ok: '{}' plays {} with {} device{}, {} media, {} binding{}\n", file.string(), manifest->name,
      manifest->entry.kind == EntryKind::kBuiltinDefault ? std::string("the default show") : manifest->entry.text,
      manifest->devices.size(), manifest->devices.size() == 1 ? "" : "s", manifest->media.size(),
      manifest->bindings.size(), manifest->bindings.size() == 1 ? "" : "s");
  std::fflush(out);
  return 0;
}

}  // namespace basalt::kiosk
