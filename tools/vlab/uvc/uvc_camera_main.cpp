// basalt-vlab-uvc-camera: the virtual lab's webcam, a UVC 1.1 camera emulated in user space
// (uvc_camera.h) and plugged into a machine's USB:
//
//   basalt-vlab-uvc-camera --usbredir SOCKET [--connect-timeout S] [--control FILE] [--unplugged]
//   basalt-vlab-uvc-camera --vhci [CONTROLLER] [--control FILE] [--unplugged]
//
// --usbredir connects to qemu's usb-redir chardev socket (-chardev socket,server=on with
// -device usb-redir on an emulated xHCI): the camera appears on the guest's PCI USB controller,
// as a real webcam would. --vhci attaches it to a port of the kernel's vhci_hcd on the machine
// it runs on (default controller /sys/devices/platform/vhci_hcd.0; needs root and the vhci-hcd
// module).
//
// --control FILE: the camera watches FILE (inotify on its folder); writing "unplug" or "plug"
// into it (a new file, or renamed into place) pulls or puts back the camera's cable. The camera
// deletes FILE once it acted and writes FILE.state: "plugged", "unplugged" or "error: why".
// --unplugged starts with the cable out. SIGTERM or SIGINT unplug and end it.
//
// Output: one line per event on stdout ("plugged: ...", "unplugged: ..."), problems on stderr.
// Exit status: 0 when stopped by a signal or when the host side (qemu) went away, 1 when it
// cannot plug in (no socket within the time-out, no vhci_hcd) or the link failed, 2 usage.

#include <poll.h>
#include <signal.h>
#include <sys/inotify.h>
#include <sys/signalfd.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <thread>

#include <fmt/format.h>

#include "runtime/clock.h"
#include "runtime/unique_fd.h"
#include "tools/vlab/uvc/usbip.h"
#include "tools/vlab/uvc/usbredir.h"
#include "tools/vlab/uvc/uvc_camera.h"

namespace {

namespace fs = std::filesystem;
using namespace basalt;
using namespace basalt::sim::vlab;

struct Options {
  std::string usbredir;
  bool vhci = false;
  std::string vhciController = VhciAttachment::kDefaultController;
  std::string control;
  double connectTimeout = 30;
  bool unplugged = false;
};

int usage() {
  std::fputs(
      "usage: basalt-vlab-uvc-camera (--usbredir SOCKET [--connect-timeout S] | --vhci [CONTROLLER])\n"
      "                              [--control FILE] [--unplugged]\n",
      stderr);
  return 2;
}

void say(const std::string& line) {
  std::fputs((line + "\n").c_str(), stdout);
  std::fflush(stdout);
}
void complain(const std::string& line) { std::fputs(("basalt-vlab-uvc-camera: " + line + "\n").c_str(), stderr); }

// Connects to qemu's usb-redir socket, waiting for qemu to make it.
Result<UniqueFd> connectSocket(const std::string& path, double timeoutSeconds) {
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  if (path.size() >= sizeof addr.sun_path) {
    return failf(Errc::kInvalidArgument, "the socket path {} is longer than {} bytes", path, sizeof addr.sun_path - 1);
  }
  std::memcpy(addr.sun_path, path.c_str(), path.size() + 1);
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeoutSeconds);
  int lastError = 0;
  do {
    UniqueFd fd(::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0));
    if (!fd) return fail(Errc::kIo, systemErrorText("socket", errno));
    if (::connect(fd.get(), reinterpret_cast<const sockaddr*>(&addr), sizeof addr) == 0) return fd;
    lastError = errno;
    if (lastError != ENOENT && lastError != ECONNREFUSED && lastError != EAGAIN) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  } while (std::chrono::steady_clock::now() < end);
  return fail(Errc::kUnavailable, fmt::format("cannot connect to qemu's usb-redir socket {} within {} s: {}", path,
                                              timeoutSeconds, std::strerror(lastError)));
}

// The camera's cable: plugged into vhci_hcd or into qemu, or not.
class Cable {
 public:
  Cable(UvcCamera& camera, const Clock& clock, const Options& options)
      : camera_(camera), clock_(clock), options_(options) {}

  [[nodiscard]] bool plugged() const { return link() != nullptr; }
  [[nodiscard]] UsbLink* link() const {
    if (vhci_) return &vhci_->link();
    return redir_.get();
  }

  Result<std::string> plug() {
    if (plugged()) return std::string("already plugged");
    camera_.reset();
    if (options_.vhci) {
      auto attached = VhciAttachment::attach(camera_, clock_, options_.vhciController);
      if (!attached) return std::unexpected(attached.error());
      vhci_.emplace(std::move(*attached));
      return fmt::format("{} on port {} of {}", camera_.describe(), vhci_->port(), options_.vhciController);
    }
    auto fd = connectSocket(options_.usbredir, options_.connectTimeout);
    if (!fd) return std::unexpected(fd.error());
    redir_ = std::make_unique<UsbredirLink>(std::move(*fd), camera_, clock_);
    if (auto started = redir_->start(); !started) {
      redir_.reset();
      return std::unexpected(started.error());
    }
    return fmt::format("{} through qemu's usb-redir at {}", camera_.describe(), options_.usbredir);
  }

  void unplug() {
    vhci_.reset();   // detaches the port
    redir_.reset();  // closing the socket detaches the device in qemu
    camera_.reset();
  }

 private:
  UvcCamera& camera_;
  const Clock& clock_;
  const Options& options_;
  std::optional<VhciAttachment> vhci_;
  std::unique_ptr<UsbredirLink> redir_;
};

void writeState(const std::string& control, const std::string& state) {
  if (control.empty()) return;
  const std::string tmp = control + ".state.tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << state << "\n";
  }
  std::error_code ec;
  fs::rename(tmp, control + ".state", ec);
}

// Reads and removes the control file; empty when there is none.
std::string takeRequest(const std::string& control) {
  std::ifstream in(control);
  if (!in) return {};
  std::stringstream text;
  text << in.rdbuf();
  std::error_code ec;
  fs::remove(control, ec);
  std::string request = text.str();
  while (!request.empty() && std::isspace(static_cast<unsigned char>(request.back()))) request.pop_back();
  return request;
}

}  // namespace

int main(int argc, char** argv) {
  Options opt;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool hasValue = i + 1 < argc;
    if (arg == "--usbredir" && hasValue) {
      opt.usbredir = argv[++i];
    } else if (arg == "--vhci") {
      opt.vhci = true;
      if (hasValue && argv[i + 1][0] == '/') opt.vhciController = argv[++i];
    } else if (arg == "--control" && hasValue) {
      opt.control = argv[++i];
    } else if (arg == "--connect-timeout" && hasValue) {
      char* end = nullptr;
      opt.connectTimeout = std::strtod(argv[++i], &end);
      if (*end != '\0' || opt.connectTimeout < 0) return usage();
    } else if (arg == "--unplugged") {
      opt.unplugged = true;
    } else {
      return usage();
    }
  }
  if (opt.vhci == !opt.usbredir.empty()) return usage();

  auto created = UvcCamera::create(UvcCameraConfig::labDefault());
  if (!created) {
    complain(created.error().describe());
    return 1;
  }
  UvcCamera camera = std::move(*created);
  SystemClock clock;

  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGHUP);
  ::sigprocmask(SIG_BLOCK, &signals, nullptr);
  ::signal(SIGPIPE, SIG_IGN);
  UniqueFd signalFd(::signalfd(-1, &signals, SFD_CLOEXEC | SFD_NONBLOCK));

  UniqueFd inotifyFd;
  if (!opt.control.empty()) {
    inotifyFd = UniqueFd(::inotify_init1(IN_CLOEXEC | IN_NONBLOCK));
    const fs::path folder =
        fs::path(opt.control).parent_path().empty() ? fs::path(".") : fs::path(opt.control).parent_path();
    if (!inotifyFd || ::inotify_add_watch(inotifyFd.get(), folder.c_str(), IN_CLOSE_WRITE | IN_MOVED_TO) < 0) {
      complain(systemErrorText("watching " + folder.string() + " for the control file", errno));
      return 1;
    }
    takeRequest(opt.control);  // a request left from before does not count
  }

  Cable cable(camera, clock, opt);
  if (!opt.unplugged) {
    auto plugged = cable.plug();
    if (!plugged) {
      complain("cannot plug the camera in: " + plugged.error().describe());
      writeState(opt.control, "error: " + plugged.error().describe());
      return 1;
    }
    say("plugged: " + *plugged);
  }
  writeState(opt.control, cable.plugged() ? "plugged" : "unplugged");

  int status = 0;
  for (;;) {
    pollfd fds[3] = {{signalFd.get(), POLLIN, 0}, {inotifyFd.get(), POLLIN, 0}, {-1, POLLIN, 0}};
    UsbLink* link = cable.link();
    if (link) fds[2].fd = link->fd();
    int timeoutMs = 1000;
    if (link) {
      const Nanos deadline = link->nextDeadline();
      if (deadline != Nanos::max()) {
        const auto wait = std::chrono::ceil<std::chrono::milliseconds>(deadline - clock.now()).count();
        timeoutMs = static_cast<int>(std::clamp<std::int64_t>(wait, 0, 1000));
      }
    }
    if (::poll(fds, 3, timeoutMs) < 0 && errno != EINTR) {
      complain(systemErrorText("poll", errno));
      status = 1;
      break;
    }
    if (fds[0].revents & POLLIN) {
      signalfd_siginfo info{};
      [[maybe_unused]] const ssize_t n = ::read(signalFd.get(), &info, sizeof info);
      say(fmt::format("stopping on signal {}", info.ssi_signo));
      break;
    }
    if (fds[1].revents & POLLIN) {
      char events[4096];
      while (::read(inotifyFd.get(), events, sizeof events) > 0) {
      }
      const std::string request = takeRequest(opt.control);
      if (request == "unplug") {
        cable.unplug();
        say("unplugged: on request");
        writeState(opt.control, "unplugged");
      } else if (request == "plug") {
        auto plugged = cable.plug();
        if (plugged) {
          say("plugged: " + *plugged);
          writeState(opt.control, "plugged");
        } else {
          complain("cannot plug the camera in: " + plugged.error().describe());
          writeState(opt.control, "error: " + plugged.error().describe());
        }
      } else if (!request.empty()) {
        complain("unknown request \"" + request + "\" in " + opt.control + " (plug or unplug)");
        writeState(opt.control, "error: unknown request " + request);
      }
      link = cable.link();
      if (!link) continue;
    }
    if (!link) continue;
    Result<void> served =
        (fds[2].revents & (POLLIN | POLLHUP | POLLERR)) ? link->onReadable() : link->serviceTransfers();
    if (!served) {
      if (served.error().code() == Errc::kDeviceLost && !opt.vhci) {
        say("the host side closed the connection (qemu quit): stopping");
        break;
      }
      complain("the link to the host failed: " + served.error().describe() + "; unplugging");
      cable.unplug();
      writeState(opt.control, "unplugged");
      if (!opt.vhci) {
        status = 1;
        break;
      }
    }
  }
  cable.unplug();
  writeState(opt.control, "unplugged");
  return status;
}
