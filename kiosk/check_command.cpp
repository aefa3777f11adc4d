#include "kiosk/check_command.h"

#include <algorithm>
#include <cctype>
#include <cstdio>

#include <fmt/format.h>
#include <fmt/std.h>

#include "kiosk/commands.h"
#include "kiosk/options.h"
#include "media/image_io.h"

namespace basalt::kiosk {

namespace {

/// Images a manifest names (textures, fallbacks) must decode.
std::vector<Diagnostic> checkImage(const std::filesystem::path& file) {
  std::vector<Diagnostic> out;
  auto image = media::readImage(file);
  if (!image) {
    out.push_back({Severity::kError, file, 0, fmt::format("cannot be read as an image: {}", image.error().message())});
  } else if (image->empty()) {
    out.push_back({Severity::kError, file, 0, "the image is empty (0 pixels)"});
  }
  return out;
}

/// The checkers for whole files given to `basalt check`, by extension.
struct CommandChecker {
  std::string_view extension;
  int (*check)(const std::filesystem::path& file, std::FILE* out);
};

constexpr CommandChecker kCommandCheckers[] = {
    {".toml", checkManifestFile},
};

std::string lowerExtension(const std::filesystem::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

}  // namespace

const std::map<std::string, FileChecker, std::less<>>& fileCheckers() {
  static const std::map<std::string, FileChecker, std::less<>> checkers{
      {".png", checkImage},  {".jpg", checkImage}, {".jpeg", checkImage}, {".tif", checkImage},
      {".tiff", checkImage}, {".exr", checkImage}, {".ppm", checkImage},  {".pgm", checkImage},
      {".pnm", checkImage},  {".tga", checkImage}, {".bmp", checkImage},  {".hdr", checkImage},
  };
  return checkers;
}

std::string_view checkUsage() {
  return R"(Usage: basalt check FILE...

Checks show files without playing them and prints every problem as 'file:line: what is wrong'.
  show.toml   a show manifest: its outputs, views, entry, media, devices and bindings,
              textures, kiosk policy and status server; every file it names must exist inside
              the show folder and parse.

Exit status: 0 when every file is good (warnings and notes allowed), 1 when any has an error,
2 for usage errors.
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
    files.emplace_back(o.value);
  }
  if (files.empty()) return usageError("'basalt check' needs a file to check; see 'basalt check --help'");
  int status = 0;
  for (const auto& file : files) {
    const std::string ext = lowerExtension(file);
    const auto* checker = std::find_if(std::begin(kCommandCheckers), std::end(kCommandCheckers),
                                       [&](const CommandChecker& c) { return c.extension == ext; });
    if (checker == std::end(kCommandCheckers)) {
      fmt::print(stderr, "{}: basalt check does not know {} files; it checks show manifests (.toml)\n", file.string(),
                 ext.empty() ? "extension-less" : ext);
      status = 1;
      continue;
    }
    status = std::max(status, checker->check(file, stdout));
  }
  return status;
}

}  // namespace basalt::kiosk
