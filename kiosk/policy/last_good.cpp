#include "kiosk/policy/last_good.h"

#include <fcntl.h>
#include <stdio.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <fstream>
#include <sstream>
#include <vector>

#include <fmt/chrono.h>
#include <fmt/format.h>
#include <fmt/std.h>

#include "runtime/unique_fd.h"

namespace basalt::kiosk {

namespace fs = std::filesystem;

namespace {

constexpr std::string_view kMagic = "basalt-last-good 1";
constexpr std::string_view kInfoFile = ".basalt-last-good";

/// FNV-1a, 64 bits, to tell two shows' folders apart.
std::uint64_t hashOf(std::string_view text) {
  std::uint64_t h = 1469598103934665603ULL;
  for (const char c : text) {
    h ^= static_cast<unsigned char>(c);
    h *= 1099511628211ULL;
  }
  return h;
}

fs::path absoluteOf(const fs::path& p) {
  std::error_code ec;
  fs::path a = fs::weakly_canonical(p, ec);
  return ec ? fs::absolute(p) : a;
}

bool inside(const fs::path& child, const fs::path& parent) {
  const auto [end, _] = std::mismatch(parent.begin(), parent.end(), child.begin(), child.end());
  return end == parent.end();
}

struct ShowFile {
  fs::path relative;
  std::uintmax_t size = 0;
  std::int64_t mtimeNs = 0;
};

/// The show folder's regular files (sorted), without the state folder; `total`: their bytes.
Result<std::vector<ShowFile>> listShow(const fs::path& showFolder, const fs::path& stateFolder, std::uintmax_t& total) {
  std::vector<ShowFile> files;
  std::error_code ec;
  const fs::path stateAbsolute = absoluteOf(stateFolder);
  fs::recursive_directory_iterator it(showFolder, ec);
  if (ec) return fail(Errc::kIo, fmt::format("cannot read the show folder {}: {}", showFolder, ec.message()));
  total = 0;
  for (; it != fs::recursive_directory_iterator(); it.increment(ec)) {
    if (ec) return fail(Errc::kIo, fmt::format("cannot read the show folder {}: {}", showFolder, ec.message()));
    const fs::path path = it->path();
    if (it->is_directory(ec)) {
      if (inside(absoluteOf(path), stateAbsolute)) it.disable_recursion_pending();
      continue;
    }
    if (!it->is_regular_file(ec)) continue;
    ShowFile f;
    f.relative = path.lexically_relative(showFolder);
    f.size = it->file_size(ec);
    const auto mtime = it->last_write_time(ec);
    f.mtimeNs = std::chrono::duration_cast<std::chrono::nanoseconds>(mtime.time_since_epoch()).count();
    total += f.size;
    files.push_back(std::move(f));
  }
  std::sort(files.begin(), files.end(), [](const ShowFile& a, const ShowFile& b) { return a.relative < b.relative; });
  return files;
}

/// One line per file: what a copy was made from, to tell whether the show changed since.
std::string signatureOf(const std::vector<ShowFile>& files) {
  std::string out;
  for (const ShowFile& f : files) out += fmt::format("file={} {} {}\n", f.size, f.mtimeNs, f.relative.string());
  return out;
}

std::string readText(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return {};
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

/// The value of `key=` in the info file, or "".
std::string field(std::string_view info, std::string_view key) {
  const std::string prefix = fmt::format("\n{}=", key);
  const auto at = info.find(prefix);
  if (at == std::string_view::npos) return {};
  const auto start = at + prefix.size();
  return std::string(info.substr(start, info.find('\n', start) - start));
}

Result<void> writeFile(const fs::path& file, std::string_view text) {
  UniqueFd fd(::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644));
  if (!fd) return fail(Errc::kIo, systemErrorText(fmt::format("creating {}", file), errno));
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd.get(), text.data() + done, text.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      return fail(Errc::kIo, systemErrorText(fmt::format("writing {}", file), errno));
    }
    done += static_cast<std::size_t>(n);
  }
  if (::fsync(fd.get()) != 0) return fail(Errc::kIo, systemErrorText(fmt::format("syncing {}", file), errno));
  return {};
}

void syncFolder(const fs::path& folder) {
  UniqueFd fd(::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (fd) ::fsync(fd.get());
}

}  // namespace

fs::path lastGoodFolder(const fs::path& stateFolder, const fs::path& manifestFile) {
  const std::string id = absoluteOf(manifestFile).string();
  const fs::path folder = absoluteOf(manifestFile).parent_path();
  std::string name;
  for (const char c : folder.filename().string()) {
    name += (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_') ? c : '-';
  }
  if (name.empty()) name = "show";
  return stateFolder / "last-good" / fmt::format("{}-{:08x}", name.substr(0, 40), hashOf(id) & 0xffffffffU);
}

Result<KeptCopy> keepLastGood(const fs::path& stateFolder, const fs::path& manifestFile, const fs::path& showFolder) {
  const fs::path target = lastGoodFolder(stateFolder, manifestFile);
  std::uintmax_t total = 0;
  auto files = listShow(showFolder, stateFolder, total);
  if (!files) return std::unexpected(files.error());
  if (total > kLastGoodMaxBytes) {
    return fail(Errc::kUnsupported, fmt::format("the show folder {} holds {} MiB, more than the {} MiB kept as its "
                                                "last good copy",
                                                showFolder, total >> 20, kLastGoodMaxBytes >> 20));
  }
  const std::string relativeManifest = absoluteOf(manifestFile).lexically_relative(absoluteOf(showFolder)).string();
  const std::string signature = signatureOf(*files);
  const std::string old = readText(target / kInfoFile);
  if (!old.empty() && old.find("\n" + signature) != std::string::npos && field(old, "manifest") == relativeManifest &&
      fs::exists(target / relativeManifest)) {
    return KeptCopy::kUnchanged;
  }

  // Copy beside the old copy, then swap it in with one rename.
  std::error_code ec;
  const fs::path parent = target.parent_path();
  fs::create_directories(parent, ec);
  if (ec) return fail(Errc::kIo, fmt::format("cannot create {}: {}", parent, ec.message()));
  const fs::path temporary = parent / fmt::format(".{}.partial-{}", target.filename().string(), ::getpid());
  fs::remove_all(temporary, ec);
  fs::create_directories(temporary, ec);
  if (ec) return fail(Errc::kIo, fmt::format("cannot create {}: {}", temporary, ec.message()));
  const auto failed = [&](std::string why) {
    std::error_code ignored;
    fs::remove_all(temporary, ignored);
    return fail(Errc::kIo, std::move(why));
  };
  for (const ShowFile& f : *files) {
    const fs::path to = temporary / f.relative;
    fs::create_directories(to.parent_path(), ec);
    if (!ec) fs::copy_file(showFolder / f.relative, to, fs::copy_options::overwrite_existing, ec);
    if (ec) return failed(fmt::format("cannot copy {}: {}", showFolder / f.relative, ec.message()));
    // The copy keeps the show's times, so that an unchanged show is recognised next time.
    fs::last_write_time(to, fs::file_time_type(std::chrono::nanoseconds(f.mtimeNs)), ec);
    ec.clear();
  }
  const std::string savedAt =
      fmt::format("{:%Y-%m-%dT%H:%M:%SZ}", std::chrono::floor<std::chrono::seconds>(std::chrono::system_clock::now()));
  const std::string info = fmt::format("{}\nshow={}\nmanifest={}\nsaved={}\n{}", kMagic,
                                       absoluteOf(manifestFile).string(), relativeManifest, savedAt, signature);
  if (auto r = writeFile(temporary / kInfoFile, info); !r) return failed(r.error().describe());
  // Sync every copied file before the swap: the copy must be whole when its name appears.
  for (const ShowFile& f : *files) {
    UniqueFd fd(::open((temporary / f.relative).c_str(), O_RDONLY | O_CLOEXEC));
    if (fd) ::fsync(fd.get());
  }
  if (fs::exists(target)) {
    if (::renameat2(AT_FDCWD, temporary.c_str(), AT_FDCWD, target.c_str(), RENAME_EXCHANGE) != 0) {
      return failed(systemErrorText(fmt::format("swapping in {}", target), errno));
    }
    fs::remove_all(temporary, ec);  // now the old copy
  } else if (::rename(temporary.c_str(), target.c_str()) != 0) {
    return failed(systemErrorText(fmt::format("renaming {} to {}", temporary, target), errno));
  }
  syncFolder(parent);
  return KeptCopy::kWritten;
}

std::optional<LastGoodCopy> findLastGood(const fs::path& stateFolder, const fs::path& manifestFile) {
  const fs::path folder = lastGoodFolder(stateFolder, manifestFile);
  const std::string info = readText(folder / kInfoFile);
  if (!info.starts_with(kMagic)) return std::nullopt;
  const std::string relative = field(info, "manifest");
  if (relative.empty() || !fs::is_regular_file(folder / relative)) return std::nullopt;
  return LastGoodCopy{folder / relative, field(info, "saved")};
}

}  // namespace basalt::kiosk
