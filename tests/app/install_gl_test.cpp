// Basalt installed as a technician installs it: `cmake --install` into a staging root outside the
// build folder (DESTDIR) places every file where systemd, udev and man look for it; systemd
// accepts the service user, the folders and the unit as installed; and the installed program
// plays a show with a JPEG texture through the installed OpenImageIO module, never the build
// folder's.
// Example failures: the module installed where the program does not look, so that every JPEG
// texture is "not installed" once the build folder is gone; the installed program quietly loading
// the build folder's module (it works until the build folder goes); a sysusers.d or tmpfiles.d
// line systemd rejects; an install rule that misses the unit, the udev rule or the shows.

#include <gtest/gtest.h>

#include <stdlib.h>  // mkdtemp
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <regex>
#include <sstream>

#include "media/image_io.h"
#include "support/kiosk_process.h"
#include "support/process.h"
#include "support/test_paths.h"

namespace basalt {
namespace {

namespace fs = std::filesystem;

// The colours of the two halves of the test's JPEG (left, right), as the test writes them.
constexpr std::uint8_t kLeft[3] = {200, 40, 30};
constexpr std::uint8_t kRight[3] = {30, 60, 210};
constexpr std::uint32_t kWidth = 64, kHeight = 48;

std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// A staging root in the temporary folder, outside the build folder, removed at the end.
class StagedInstall : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "basalt-install-XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    root_ = pattern;
    const fs::path build = fs::weakly_canonical(test::binaryDir());
    ASSERT_NE(root_.string().rfind(build.string(), 0), 0u) << "the staging root must be outside " << build;
    const auto installed = test::run({BASALT_CMAKE_COMMAND, "--install", test::binaryDir().string()},
                                     {{"DESTDIR", root_.string()}}, std::chrono::seconds(120));
    ASSERT_EQ(installed.exitCode, 0) << installed.output;
    prefix_ = root_ / fs::path(BASALT_INSTALL_PREFIX).relative_path();
  }
  void TearDown() override {
    std::error_code ec;
    if (!root_.empty()) fs::remove_all(root_, ec);
  }
  /// Where GNUInstallDirs puts the module: LIBDIR/basalt (lib/<multiarch>/basalt under /usr).
  [[nodiscard]] fs::path stagedModule() const { return prefix_ / BASALT_INSTALL_LIBDIR / "basalt/libbasalt_oiio.so"; }

  /// Writes a show whose scene's background is a JPEG of two colours, made with GStreamer's own
  /// encoder; false (with `why`) where gst-launch-1.0 is missing.
  bool writeJpegShow(const fs::path& dir, std::string& why) {
    const std::string launch = test::onPath("gst-launch-1.0");
    if (launch.empty()) {
      why = "gst-launch-1.0 is not installed (gstreamer1.0-tools, scripts/packages-test.txt)";
      return false;
    }
    fs::create_directories(dir);
    std::string rgb;
    for (std::uint32_t y = 0; y < kHeight; ++y) {
      for (std::uint32_t x = 0; x < kWidth; ++x) {
        const std::uint8_t* c = x < kWidth / 2 ? kLeft : kRight;
        rgb.append(reinterpret_cast<const char*>(c), 3);
      }
    }
    std::ofstream(dir / "picture.rgb", std::ios::binary) << rgb;
    const auto made =
        test::run({launch, "-q", "filesrc", "location=" + (dir / "picture.rgb").string(),
                   "blocksize=" + std::to_string(rgb.size()), "!", "rawvideoparse", "width=" + std::to_string(kWidth),
                   "height=" + std::to_string(kHeight), "format=rgb", "framerate=1/1", "!", "videoconvert", "!",
                   "jpegenc", "quality=95", "!", "filesink", "location=" + (dir / "picture.jpg").string()});
    if (made.exitCode != 0 || !fs::exists(dir / "picture.jpg")) {
      why = "gst-launch-1.0 could not write the JPEG: " + made.output;
      return false;
    }
    fs::remove(dir / "picture.rgb");
    std::ofstream(dir / "picture.sce") << "background picture.jpg\n";
    std::ofstream(dir / "show.toml") << "[show]\nname = \"JPEG texture\"\nentry = \"picture.sce\"\n\n"
                                        "[output]\nkind = \"headless\"\nsize = \""
                                     << kWidth << "x" << kHeight << "\"\n";
    return true;
  }

  /// The staged `basalt run` on `show`, with no variable pointing it at a module, its log at debug
  /// for the media category (it names the module it loads).
  test::ProcessResult runStaged(const fs::path& show, const fs::path& snapshot) {
    return test::run({"/usr/bin/env", "-u", "BASALT_MODULE_DIR", "-u", "LD_LIBRARY_PATH", "BASALT_LOG=media=debug",
                      (prefix_ / "bin/basalt").string(), "run", show.string(), "--headless", "--frames", "10",
                      "--no-resume", "--state-dir", (root_ / "state").string(), "--snapshot", snapshot.string()},
                     {}, std::chrono::seconds(120));
  }

  fs::path root_;
  fs::path prefix_;
};

TEST_F(StagedInstall, PlacesEveryFileWhereTheSystemLooks) {
  for (const fs::path& file :
       {fs::path("bin/basalt"), fs::path(BASALT_INSTALL_LIBDIR) / "basalt/libbasalt_oiio.so",
        fs::path("lib/systemd/system/basalt.service"), fs::path("lib/udev/rules.d/70-basalt.rules"),
        fs::path("lib/sysusers.d/basalt.conf"), fs::path("lib/tmpfiles.d/basalt.conf"),
        fs::path("share/basalt/systemd/network-online.conf"), fs::path("share/basalt/shows/README.md"),
        fs::path("share/basalt/shows/default/show.toml"), fs::path("share/basalt/shows/cube-cave/display.cave"),
        fs::path("share/basalt/shows/video-wall/clips/loop.webm"), fs::path("share/man/man1/basalt.1"),
        fs::path("share/doc/basalt/copyright"), fs::path("share/doc/basalt/README.md")}) {
    EXPECT_TRUE(fs::is_regular_file(prefix_ / file)) << prefix_ / file;
  }
  EXPECT_EQ(::access((prefix_ / "bin/basalt").c_str(), X_OK), 0) << "the program is executable";
  EXPECT_EQ(read(prefix_ / "lib/systemd/system/basalt.service"),
            read(test::sourceDir() / "configs/systemd/basalt.service"));
  EXPECT_NE(
      read(prefix_ / "lib/systemd/system/basalt.service").find("\nExecStart=" BASALT_INSTALL_PREFIX "/bin/basalt "),
      std::string::npos)
      << "the unit starts the program where it is installed";
}

// systemd's own tools, pointed at the staging root: the user and groups are made, the folders
// created with their owners, and the unit verifies with the installed program in ExecStart.
TEST_F(StagedInstall, SystemdAcceptsTheUserTheFoldersAndTheUnit) {
  if (::access("/usr/bin/systemd-sysusers", X_OK) != 0) GTEST_SKIP() << "systemd-sysusers is not installed";
  if (std::string(BASALT_INSTALL_PREFIX) != "/usr") GTEST_SKIP() << "systemd reads these files under /usr only";
  fs::create_directories(root_ / "etc");
  const auto users = test::run({"/usr/bin/systemd-sysusers", "--root=" + root_.string(), "basalt.conf"});
  ASSERT_EQ(users.exitCode, 0) << users.output;
  EXPECT_EQ(users.output.find("basalt.conf:"), std::string::npos)
      << "a line systemd-sysusers warns about: " << users.output;
  const std::string passwd = read(root_ / "etc/passwd");
  EXPECT_TRUE(std::regex_search(passwd, std::regex("(^|\n)basalt:x:[0-9]+:[0-9]+:[^\n]*:/var/lib/basalt:"))) << passwd;
  const std::string group = read(root_ / "etc/group");
  EXPECT_TRUE(std::regex_search(group, std::regex("(^|\n)basalt:x:"))) << group;
  for (const char* name : {"video", "render", "input", "dialout", "audio"}) {
    const std::regex member(std::string("(^|\n)") + name + ":x:[0-9]+:([^\n]*,)?basalt(,|\n)");
    EXPECT_TRUE(std::regex_search(group, member)) << "basalt is not in group " << name << ":\n" << group;
  }

  const auto folders = test::run({"/usr/bin/systemd-tmpfiles", "--root=" + root_.string(), "--create", "basalt.conf"});
  ASSERT_EQ(folders.exitCode, 0) << folders.output;
  EXPECT_TRUE(fs::is_directory(root_ / "srv/basalt")) << folders.output;
  EXPECT_TRUE(fs::is_directory(root_ / "etc/basalt")) << folders.output;
  EXPECT_EQ(fs::status(root_ / "etc/basalt").permissions() & fs::perms::all,
            fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec)
      << "the token's folder is 0750";

  // The installed unit with its ExecStart on the staged program (systemd-analyze checks that it
  // exists) and the staged manual page for its Documentation= (checked with man).
  std::string unit = read(prefix_ / "lib/systemd/system/basalt.service");
  unit = std::regex_replace(unit, std::regex(BASALT_INSTALL_PREFIX "/bin/basalt"), (prefix_ / "bin/basalt").string());
  fs::create_directories(root_ / "verify");
  std::ofstream(root_ / "verify/basalt.service") << unit;
  const auto verify = test::run({"/usr/bin/systemd-analyze", "verify", (root_ / "verify/basalt.service").string()},
                                {{"MANPATH", (prefix_ / "share/man").string()}});
  EXPECT_EQ(verify.exitCode, 0) << verify.output;
  EXPECT_EQ(verify.output.find("basalt.service:"), std::string::npos) << "a line systemd ignores: " << verify.output;
}

TEST_F(StagedInstall, InstalledProgramPlaysAJpegTextureThroughTheInstalledModule) {
  std::string why;
  if (!test::headlessEglWorks(why)) GTEST_SKIP() << "no headless EGL here: " << why;
  const fs::path show = root_ / "srv/basalt/show";
  if (!writeJpegShow(show, why)) GTEST_SKIP() << why;
  const fs::path snapshot = root_ / "snapshot.pam";
  const auto played = runStaged(show / "show.toml", snapshot);
  ASSERT_EQ(played.exitCode, 0) << played.output;
  EXPECT_EQ(played.output.find("not installed"), std::string::npos) << played.output;
  // The module loaded is the staged one (fmt writes paths in quotes).
  EXPECT_NE(played.output.find("loaded the OpenImageIO module from \"" + stagedModule().string() + "\""),
            std::string::npos)
      << played.output;

  // The picture: the JPEG's two halves fill the output (away from the seam, where JPEG's chroma
  // blurs them).
  auto image = media::readImage(snapshot);
  ASSERT_TRUE(image) << image.error().describe();
  ASSERT_EQ(image->width, kWidth);
  ASSERT_EQ(image->height, kHeight);
  const auto near = [&](std::uint32_t x, std::uint32_t y, const std::uint8_t* want) {
    for (std::uint32_t c = 0; c < 3; ++c) {
      if (std::abs(int{image->at(x, y, c)} - int{want[c]}) > 8) return false;
    }
    return true;
  };
  for (const std::uint32_t y : {2u, kHeight / 2, kHeight - 3}) {
    for (const std::uint32_t x : {2u, kWidth / 4}) EXPECT_TRUE(near(x, y, kLeft)) << "left half at " << x << "," << y;
    for (const std::uint32_t x : {kWidth * 3 / 4, kWidth - 3}) {
      EXPECT_TRUE(near(x, y, kRight)) << "right half at " << x << "," << y;
    }
  }
}

// The staged program with its module taken away must say so: it must not find the build
// folder's module instead (which would hide a module installed in the wrong place).
TEST_F(StagedInstall, InstalledProgramNeverLoadsTheBuildFoldersModule) {
  std::string why;
  if (!test::headlessEglWorks(why)) GTEST_SKIP() << "no headless EGL here: " << why;
  ASSERT_TRUE(fs::exists(test::binaryDir() / "libbasalt_oiio.so")) << "the build folder has its module";
  const fs::path show = root_ / "srv/basalt/show";
  if (!writeJpegShow(show, why)) GTEST_SKIP() << why;
  ASSERT_TRUE(fs::remove(stagedModule()));
  const auto played = runStaged(show / "show.toml", root_ / "snapshot.pam");
  EXPECT_NE(played.output.find("libbasalt_oiio.so is not installed"), std::string::npos) << played.output;
  EXPECT_EQ(played.output.find("loaded the OpenImageIO module"), std::string::npos) << played.output;
}

// Makes sure the Debian package CPack builds holds the installed files and depends on what runs
// Basalt only: the libraries the program and its module link (dpkg-shlibdeps), Mesa's drivers and
// the GStreamer plugins it opens at run time, and nothing of the build or the tests.
// Example failures: a -dev package or a test tool in Depends (a kiosk pulls in compilers); the
// module's OpenImageIO missing from Depends (dpkg-shlibdeps not run on it); the package without
// its module or unit.
TEST(DebianPackage, HoldsTheInstalledFilesAndDependsOnRuntimePackagesOnly) {
  if (::access("/usr/bin/dpkg-shlibdeps", X_OK) != 0) GTEST_SKIP() << "dpkg-shlibdeps is not installed (dpkg-dev)";
  const fs::path out = test::scratchDir("debian-package");
  const auto packed = test::run({BASALT_CPACK_COMMAND, "-G", "DEB", "--config",
                                 (test::binaryDir() / "CPackConfig.cmake").string(), "-B", out.string()},
                                {}, std::chrono::seconds(300));
  ASSERT_EQ(packed.exitCode, 0) << packed.output;
  fs::path deb;
  for (const auto& entry : fs::directory_iterator(out)) {
    if (entry.path().extension() == ".deb") deb = entry.path();
  }
  ASSERT_FALSE(deb.empty()) << packed.output;

  const auto depends = test::run({"/usr/bin/dpkg-deb", "--field", deb.string(), "Depends"});
  ASSERT_EQ(depends.exitCode, 0) << depends.output;
  std::vector<std::string> names;
  std::istringstream list(depends.output);
  for (std::string item; std::getline(list, item, ',');) {
    const auto start = item.find_first_not_of(" \n");
    const auto end = item.find_first_of(" (\n", start);
    if (start != std::string::npos) names.push_back(item.substr(start, end - start));
  }
  const auto has = [&](const std::string& prefix) {
    return std::any_of(names.begin(), names.end(), [&](const std::string& n) { return n.starts_with(prefix); });
  };
  for (const char* wanted :
       {"libopenimageio", "libgstreamer1.0-0", "libegl1", "libgles2", "libgbm1", "libzmq5", "libcamera0",
        "libhidapi-hidraw0", "libusb-1.0-0", "libsystemd0", "libegl-mesa0", "libgl1-mesa-dri",
        "gstreamer1.0-plugins-good", "gstreamer1.0-plugins-ugly", "gstreamer1.0-libav", "gstreamer1.0-alsa"}) {
    EXPECT_TRUE(has(wanted)) << wanted << " missing from Depends: " << depends.output;
  }
  for (const std::string& name : names) {
    EXPECT_FALSE(name.ends_with("-dev")) << name << " in Depends: " << depends.output;
    for (const char* testOnly : {"clang", "qemu", "chromium", "xvfb", "libgtest", "gstreamer1.0-tools", "cmake"}) {
      EXPECT_FALSE(name.starts_with(testOnly)) << name << " in Depends: " << depends.output;
    }
  }

  const auto contents = test::run({"/usr/bin/dpkg-deb", "--contents", deb.string()});
  ASSERT_EQ(contents.exitCode, 0) << contents.output;
  for (const std::string& file :
       {std::string("./usr/bin/basalt"), "./usr/" + std::string(BASALT_INSTALL_LIBDIR) + "/basalt/libbasalt_oiio.so",
        std::string("./usr/lib/systemd/system/basalt.service"), std::string("./usr/lib/sysusers.d/basalt.conf"),
        std::string("./usr/lib/tmpfiles.d/basalt.conf"), std::string("./usr/lib/udev/rules.d/70-basalt.rules"),
        std::string("./usr/share/man/man1/basalt.1"), std::string("./usr/share/basalt/shows/default/show.toml")}) {
    EXPECT_NE(contents.output.find(" " + file + "\n"), std::string::npos) << file << " is not in the package";
  }
  const auto scripts = test::run({"/usr/bin/dpkg-deb", "--info", deb.string()});
  EXPECT_NE(scripts.output.find(" postinst "), std::string::npos) << scripts.output;
  fs::remove_all(out);
}

}  // namespace
}  // namespace basalt
