// What `basalt devices` says about a V4L2 node or a hidraw node the show's user may not open:
// the reason from open()/access(), and the udev rule in configs/ that grants access. The nodes are
// made in a temporary folder with mode 0000 and checked by a child process that runs as nobody
// (when the test runs as root, which may open anything), so no real device and no root-owned
// /dev node is needed.
// Example failures: a permission problem reported as "not a V4L2 device" and dropped from the
// list; a hint that names no rule file, so the operator does not know what to install.

#include <gtest/gtest.h>

#include <fcntl.h>
#include <grp.h>
#include <pwd.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include "devices/hid/hid_backend.h"
#include "devices/v4l2/v4l2_camera.h"

namespace basalt::devices {
namespace {

constexpr std::string_view kRuleFile = "configs/udev/70-basalt.rules";

/// A folder with a file `name` of mode 0000, removed again at the end.
class LockedNode {
 public:
  explicit LockedNode(const std::string& name)
      : folder_(std::filesystem::temp_directory_path() / ("basalt-perm-" + std::to_string(::getpid()))),
        node_(folder_ / name) {
    std::filesystem::remove_all(folder_);
    std::filesystem::create_directories(folder_);
    ::chmod(folder_.c_str(), 0755);  // nobody must reach the node to be refused by its mode
    std::ofstream(node_).put('\0');
    ::chmod(node_.c_str(), 0);
  }
  ~LockedNode() { std::filesystem::remove_all(folder_); }
  LockedNode(const LockedNode&) = delete;
  LockedNode& operator=(const LockedNode&) = delete;
  [[nodiscard]] const std::filesystem::path& folder() const { return folder_; }
  [[nodiscard]] std::string node() const { return node_.string(); }

 private:
  std::filesystem::path folder_;
  std::filesystem::path node_;
};

/// Runs `check` as an unprivileged user and returns what it printed; as root it forks and drops
/// to nobody first. Sets `skip` when the user cannot be changed.
std::string runUnprivileged(const std::function<std::string()>& check, std::string& skip) {
  if (::geteuid() != 0) return check();
  const passwd* nobody = ::getpwnam("nobody");
  if (!nobody) {
    skip = "running as root and there is no user 'nobody' to drop to";
    return {};
  }
  int fds[2];
  if (::pipe(fds) != 0) {
    skip = std::string("pipe: ") + std::strerror(errno);
    return {};
  }
  const pid_t child = ::fork();
  if (child == 0) {
    ::close(fds[0]);
    std::string out;
    if (::setgroups(0, nullptr) != 0 || ::setresgid(nobody->pw_gid, nobody->pw_gid, nobody->pw_gid) != 0 ||
        ::setresuid(nobody->pw_uid, nobody->pw_uid, nobody->pw_uid) != 0) {
      out = std::string("SKIP cannot become nobody: ") + std::strerror(errno);
    } else {
      out = check();
    }
    (void)!::write(fds[1], out.data(), out.size());
    ::_exit(0);
  }
  ::close(fds[1]);
  std::string out;
  char buf[512];
  for (ssize_t n; (n = ::read(fds[0], buf, sizeof buf)) > 0;) out.append(buf, static_cast<std::size_t>(n));
  ::close(fds[0]);
  int status = 0;
  ::waitpid(child, &status, 0);
  if (out.starts_with("SKIP ")) {
    skip = out.substr(5);
    return {};
  }
  return out;
}

// Makes sure a video node the user may not open is listed as found-but-not-openable with the
// reason and the udev rule, not skipped as "not a capture device".
TEST(PermissionHints, V4l2NodeTheUserCannotOpenNamesTheUdevRule) {
  LockedNode locked("video7");
  std::string skip;
  const std::string problem = runUnprivileged(
      [&] {
        V4l2Provider provider(locked.folder());
        const auto candidates = provider.enumerate();
        if (candidates.size() != 1) return "candidates: " + std::to_string(candidates.size());
        return candidates[0].info.path + "\n" + candidates[0].problem;
      },
      skip);
  if (!skip.empty()) GTEST_SKIP() << skip;
  EXPECT_NE(problem.find(locked.node()), std::string::npos) << problem;
  EXPECT_NE(problem.find("Permission denied"), std::string::npos) << problem;
  EXPECT_NE(problem.find(kRuleFile), std::string::npos) << problem;
  EXPECT_NE(problem.find("'video' group"), std::string::npos) << problem;
}

// Makes sure a hidraw node the user may not read and write says so and how to install the rule.
TEST(PermissionHints, HidrawNodeTheUserCannotOpenNamesTheUdevRule) {
  LockedNode locked("hidraw3");
  std::string skip;
  const std::string problem = runUnprivileged([&] { return hidrawAccessProblem(locked.node()); }, skip);
  if (!skip.empty()) GTEST_SKIP() << skip;
  EXPECT_NE(problem.find("Permission denied"), std::string::npos) << problem;
  EXPECT_NE(problem.find(kRuleFile), std::string::npos) << problem;
  EXPECT_NE(problem.find("udevadm control --reload"), std::string::npos) << problem;
  EXPECT_NE(problem.find("replug"), std::string::npos) << problem;
  // The same node opened by its owner (mode 0600): no problem. A node that is not there is no
  // permission problem and gets no rule hint.
  ::chmod(locked.node().c_str(), 0600);
  EXPECT_EQ(hidrawAccessProblem(locked.node()), "");
  const std::string gone = hidrawAccessProblem((locked.folder() / "hidraw9").string());
  EXPECT_NE(gone.find("No such file"), std::string::npos) << gone;
  EXPECT_EQ(gone.find(kRuleFile), std::string::npos) << gone;
}

}  // namespace
}  // namespace basalt::devices
