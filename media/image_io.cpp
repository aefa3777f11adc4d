// Image files: PNG snapshots through libpng, everything else through OpenImageIO.
//
// Serves: snapshots (the default PNG, and any format OIIO writes, chosen by the extension) and
// image textures. OIIO lives in a module loaded on first use (oiio_module.h says why); PNG
// writing, on the start-up path of every headless run, needs only libpng.
// Configuration: BASALT_MODULE_DIR names the folder of the OIIO module (ENV_VARS.md).

#include "media/image_io.h"

#include <dlfcn.h>
#include <png.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <system_error>
#include <vector>

#include <fmt/format.h>
#include <fmt/std.h>

#include "media/netpbm.h"
#include "media/oiio_module.h"
#include "media/sun_raster.h"
#include "runtime/log.h"

namespace basalt::media {

BASALT_LOG_CATEGORY(Media, "media");

namespace {

constexpr const char* kModuleName = "libbasalt_oiio.so";

std::string lowerExtension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

/// Where the OIIO module is looked for, in order: BASALT_MODULE_DIR; beside the executable (the
/// build folder's `basalt`); the install folder relative to the executable (an installed tree
/// also works when staged under another root, DESTDIR or a package's); the install folder as
/// configured; the build folder, for programs that run from inside it (the tests) only. An
/// installed or copied `basalt` never loads a build folder's module, which may be stale or gone.
std::vector<std::filesystem::path> moduleSearchPath() {
  std::vector<std::filesystem::path> dirs;
  if (const char* env = std::getenv("BASALT_MODULE_DIR"); env && *env) dirs.emplace_back(env);
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    dirs.push_back(exe.parent_path());
    dirs.push_back((exe.parent_path() / BASALT_MODULE_RELATIVE_DIR).lexically_normal());
  }
  dirs.emplace_back(BASALT_MODULE_INSTALL_DIR);
  if (!ec) {
    // /proc/self/exe has its links resolved: compare with the build folder's resolved path.
    const std::filesystem::path build = std::filesystem::weakly_canonical(BASALT_MODULE_BUILD_DIR, ec);
    if (!ec && std::mismatch(build.begin(), build.end(), exe.begin(), exe.end()).first == build.end()) {
      dirs.push_back(build);
    }
  }
  return dirs;
}

struct OiioModule {
  std::once_flag once;
  const BasaltOiioApi* api = nullptr;
  std::string error;
};

OiioModule& oiioModule() {
  static OiioModule module;
  return module;
}

Result<const BasaltOiioApi*> oiio() {
  OiioModule& m = oiioModule();
  std::call_once(m.once, [&m] {
    std::string tried;
    for (const auto& dir : moduleSearchPath()) {
      const std::filesystem::path candidate = dir / kModuleName;
      std::error_code ec;
      if (!std::filesystem::exists(candidate, ec)) {
        tried += fmt::format(" {}", candidate);
        continue;
      }
      void* handle = ::dlopen(candidate.c_str(), RTLD_NOW | RTLD_LOCAL);
      if (!handle) {
        m.error = fmt::format("cannot load {}: {}", candidate, ::dlerror());
        return;
      }
      auto entry = reinterpret_cast<BasaltOiioApiFn>(::dlsym(handle, "basalt_oiio_api"));
      const BasaltOiioApi* api = entry ? entry() : nullptr;
      if (!api || api->version != kBasaltOiioApiVersion) {
        m.error = fmt::format("{} is not a matching Basalt OIIO module; rebuild Basalt", candidate);
        return;
      }
      log::debug(kLogMedia, "loaded the OpenImageIO module from {}", candidate);
      m.api = api;
      return;
    }
    m.error = fmt::format(
        "the OpenImageIO module {} is not installed (looked for{}); install Basalt with its module "
        "(cmake --install, or the package) or set BASALT_MODULE_DIR",
        kModuleName, tried);
  });
  if (!m.api) return fail(Errc::kUnavailable, m.error);
  return m.api;
}

/// Writes to a temporary name in the target's folder (so the rename is atomic), then renames.
template <typename WriteFn>
Result<void> writeAtomically(const std::filesystem::path& path, WriteFn&& write) {
  const std::filesystem::path folder = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (ec) {
    return fail(Errc::kIo, fmt::format("cannot create folder {}: {}; choose a writable folder", folder, ec.message()),
                path.string());
  }
  // The temporary keeps the extension, since writers choose the format by it.
  const std::filesystem::path temporary =
      folder / fmt::format(".{}.{}.partial{}", path.stem().string(), ::getpid(), path.extension().string());
  if (auto r = write(temporary); !r) {
    std::filesystem::remove(temporary, ec);
    return std::unexpected(r.error().at(path.string()));
  }
  std::filesystem::rename(temporary, path, ec);
  if (ec) {
    const std::string why = ec.message();  // before remove() reuses ec
    std::filesystem::remove(temporary, ec);
    return fail(Errc::kIo, fmt::format("cannot move the image into place: {}", why), path.string());
  }
  return {};
}

png_image pngHeaderFor(const Image& image) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  png.width = image.width;
  png.height = image.height;
  switch (image.channels) {
    case 1: png.format = PNG_FORMAT_GRAY; break;
    case 2: png.format = PNG_FORMAT_GA; break;
    case 3: png.format = PNG_FORMAT_RGB; break;
    default: png.format = PNG_FORMAT_RGBA; break;
  }
  return png;
}

Result<void> writePng(const std::filesystem::path& path, const Image& image) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  png.width = image.width;
  png.height = image.height;
  switch (image.channels) {
    case 1: png.format = PNG_FORMAT_GRAY; break;
    case 2: png.format = PNG_FORMAT_GA; break;
    case 3: png.format = PNG_FORMAT_RGB; break;
    default: png.format = PNG_FORMAT_RGBA; break;
  }
  if (!png_image_write_to_file(&png, path.c_str(), 0, image.pixels.data(), static_cast<png_int_32>(image.rowBytes()),
                               nullptr)) {
    const std::string message = png.message;
    png_image_free(&png);
    return fail(Errc::kIo, fmt::format("cannot write the PNG: {}", message));
  }
  return {};
}

/// Reads a whole image file for Basalt's own codecs (capped: 1 GiB is far beyond any texture).
Result<std::vector<std::uint8_t>> readAll(const std::filesystem::path& path) {
  constexpr std::uintmax_t kMaxBytes = std::uintmax_t{1} << 30;
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec) return fail(Errc::kIo, fmt::format("cannot read the file: {}", ec.message()), path.string());
  if (size > kMaxBytes) return fail(Errc::kResourceExhausted, "the image file is larger than 1 GiB", path.string());
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(size));
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (!file) return fail(Errc::kIo, systemErrorText("cannot open the file", errno), path.string());
  const std::size_t got = std::fread(bytes.data(), 1, bytes.size(), file);
  std::fclose(file);
  bytes.resize(got);
  return bytes;
}

/// The first bytes of a file, to recognise formats Basalt decodes itself.
std::vector<std::uint8_t> readHead(const std::filesystem::path& path) {
  std::vector<std::uint8_t> head(8);
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (!file) return {};
  head.resize(std::fread(head.data(), 1, head.size(), file));
  std::fclose(file);
  return head;
}

Result<void> writeBytes(const std::filesystem::path& path, const std::vector<std::uint8_t>& bytes) {
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (!file) return fail(Errc::kIo, systemErrorText("cannot create the file", errno));
  const bool ok = std::fwrite(bytes.data(), 1, bytes.size(), file) == bytes.size();
  const bool closed = std::fclose(file) == 0;
  if (!ok || !closed) return fail(Errc::kIo, "cannot write the image (is the disk full?)");
  return {};
}

}  // namespace

Result<std::vector<std::uint8_t>> encodePng(const Image& image) {
  if (image.type != ChannelType::kU8 || image.channels < 1 || image.channels > 4 || image.empty()) {
    return fail(Errc::kInvalidArgument, "only non-empty 8-bit images with 1 to 4 channels are encoded as PNG");
  }
  png_image png = pngHeaderFor(image);
  png_alloc_size_t size = 0;
  const auto stride = static_cast<png_int_32>(image.rowBytes());
  if (!png_image_write_to_memory(&png, nullptr, &size, 0, image.pixels.data(), stride, nullptr)) {
    const std::string message = png.message;
    png_image_free(&png);
    return fail(Errc::kIo, fmt::format("cannot encode the PNG: {}", message));
  }
  std::vector<std::uint8_t> bytes(size);
  png = pngHeaderFor(image);
  if (!png_image_write_to_memory(&png, bytes.data(), &size, 0, image.pixels.data(), stride, nullptr)) {
    const std::string message = png.message;
    png_image_free(&png);
    return fail(Errc::kIo, fmt::format("cannot encode the PNG: {}", message));
  }
  bytes.resize(size);
  return bytes;
}

namespace {

/// `image` with its alpha channel (the last of 2 or 4) removed; 1 and 3 channels unchanged.
Image withoutAlpha(const Image& image) {
  if (image.channels != 2 && image.channels != 4) return image;
  Image out = image;
  out.channels = image.channels - 1;
  const std::size_t sample = channelBytes(image.type);
  const std::size_t pixels = std::size_t{image.width} * image.height;
  out.pixels.resize(pixels * out.channels * sample);
  for (std::size_t i = 0; i < pixels; ++i) {
    std::memcpy(out.pixels.data() + i * out.channels * sample, image.pixels.data() + i * image.channels * sample,
                out.channels * sample);
  }
  return out;
}

}  // namespace

Result<void> writeImage(const std::filesystem::path& path, const Image& image) {
  if (image.empty() || image.channels < 1 || image.channels > 4 || image.pixels.size() < image.byteSize()) {
    return fail(Errc::kInvalidArgument, "the image to write is empty or malformed", path.string());
  }
  const std::string ext = lowerExtension(path);
  if (ext == ".png" && image.type == ChannelType::kU8) {
    return writeAtomically(path, [&](const std::filesystem::path& tmp) { return writePng(tmp, image); });
  }
  if (const int depth = sunRasterDepthFor(ext, image.channels); depth != 0) {
    auto bytes = encodeSunRaster(image, depth);
    if (!bytes) return std::unexpected(bytes.error().at(path.string()));
    return writeAtomically(path, [&](const std::filesystem::path& tmp) { return writeBytes(tmp, *bytes); });
  }
  if (ext == ".ppm" || ext == ".pgm" || ext == ".pnm") {
    // PPM and PGM hold no alpha: a frame from the screen is opaque, so its alpha is dropped
    // (.pam keeps it). A grey image in a .ppm is written as PGM, which every PNM reader takes.
    auto bytes = encodeNetpbm(withoutAlpha(image), false);
    if (!bytes) return std::unexpected(bytes.error().at(path.string()));
    return writeAtomically(path, [&](const std::filesystem::path& tmp) { return writeBytes(tmp, *bytes); });
  }
  if (ext == ".pam") {
    auto bytes = encodeNetpbm(image, true);
    if (!bytes) return std::unexpected(bytes.error().at(path.string()));
    return writeAtomically(path, [&](const std::filesystem::path& tmp) { return writeBytes(tmp, *bytes); });
  }
  auto api = oiio();
  if (!api) return std::unexpected(api.error().at(path.string()));
  return writeAtomically(path, [&](const std::filesystem::path& tmp) -> Result<void> {
    std::array<char, 512> error{};
    if ((*api)->write(tmp.c_str(), image.pixels.data(), image.width, image.height, image.channels,
                      static_cast<std::uint32_t>(channelBytes(image.type)), error.data(), error.size()) != 0) {
      return fail(Errc::kIo, fmt::format("cannot write the image: {}; use .png, .jpg, .tif or .exr", error.data()));
    }
    return {};
  });
}

Result<Image> readImage(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    return fail(Errc::kNotFound, "no such image file", path.string());
  }
  // Formats Basalt decodes itself are recognised by their first bytes, whatever the name says.
  const std::vector<std::uint8_t> head = readHead(path);
  const bool sun = head.size() >= 4 && (std::uint32_t{head[0]} << 24 | std::uint32_t{head[1]} << 16 |
                                        std::uint32_t{head[2]} << 8 | head[3]) == kSunRasterMagic;
  if (sun || looksLikeNetpbm(head)) {
    auto bytes = readAll(path);
    if (!bytes) return std::unexpected(bytes.error());
    auto image = sun ? decodeSunRaster(*bytes) : decodeNetpbm(*bytes);
    if (!image) {
      return fail(image.error().code(), fmt::format("cannot read the image: {}", image.error().message()),
                  path.string());
    }
    return image;
  }
  auto api = oiio();
  if (!api) return std::unexpected(api.error().at(path.string()));
  Image image;
  BasaltOiioImage out{};
  out.context = &image;
  out.allocate = [](void* context, std::uint32_t w, std::uint32_t h, std::uint32_t c, std::uint32_t bytes) {
    auto* img = static_cast<Image*>(context);
    *img = Image::make(w, h, c, bytes == 2 ? ChannelType::kU16 : ChannelType::kU8);
    return img->pixels.data();
  };
  std::array<char, 512> error{};
  if ((*api)->read(path.c_str(), &out, error.data(), error.size()) != 0) {
    return fail(Errc::kParse, fmt::format("cannot read the image: {}", error.data()), path.string());
  }
  return image;
}

}  // namespace basalt::media
