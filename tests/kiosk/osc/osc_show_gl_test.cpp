// OSC into and out of a real `basalt run`: liblo's own oscsend drives the show on loopback (a
// quarter turn and a whole turn of the cube, the next item, a LAVA script command) and the
// picture and /health say what happened; liblo's oscdump listens where [[osc.send]] points and
// hears the item start, the device states and the figures at their rate. Then hostile input:
// malformed and huge packets, wrong types and a flood over UDP and TCP, while the show keeps its
// frames and counts what it refused.
// Example failures: a rotate that arrives but never reaches the frame loop; a quarter turn that
// turns by a quarter of a degree; the item's name missing from /item; figures at the poll's
// rate rather than the manifest's; a packet of random bytes that crashes the node.

#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <regex>
#include <sstream>
#include <thread>

#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "media/image_io.h"
#include "runtime/unique_fd.h"
#include "support/kiosk_process.h"
#include "support/process.h"
#include "support/test_paths.h"

namespace basalt {
namespace {

using namespace std::chrono_literals;

/// A UDP port free on loopback now (for oscdump to listen on).
std::uint16_t freeUdpPort() {
  UniqueFd fd(::socket(AF_INET, SOCK_DGRAM, 0));
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::bind(fd.get(), reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) return 0;
  socklen_t len = sizeof a;
  ::getsockname(fd.get(), reinterpret_cast<sockaddr*>(&a), &len);
  return ntohs(a.sin_port);
}

std::string showManifest(std::uint16_t dumpPort, double rate) {
  return fmt::format(R"(
[show]
name = "OSC test"
entry = "default"
fps = 30

[output]
kind = "headless"
size = "160x120"

[devices.dials]
kind = "dial_box"
backend = "synthetic"

[[kiosk.playlist]]
name = "first"
entry = "default"
duration = "1h"

[[kiosk.playlist]]
name = "second"
entry = "default"
duration = "1h"

[status]
listen = "127.0.0.1:0"
requests_per_second = 20

[osc]
listen = "127.0.0.1:0"

[[osc.bind]]
address = "/basalt/spin"
action = "rotate_y"

[[osc.bind]]
address = "/basalt/next"
action = "next"

[[osc.bind]]
address = "/basalt/do"
action = "command"
command = "$1"
types = "s"

[[osc.send]]
to = "127.0.0.1:{}"
figures = ["fps", "frames"]
rate = {}
)",
                     dumpPort, rate);
}

struct Picture {
  Image image;
  bool ok = false;
};

/// The show is tested with the tools a show controller's integrator would use.
class OscShow : public testing::Test {
 protected:
  void SetUp() override {
    std::string why;
    if (!test::headlessEglWorks(why)) GTEST_SKIP() << "no headless EGL here: " << why;
    oscsend_ = test::onPath("oscsend");
    oscdump_ = test::onPath("oscdump");
    if (oscsend_.empty() || oscdump_.empty()) GTEST_SKIP() << "liblo-tools (oscsend, oscdump) is not installed";
    dumpPort_ = freeUdpPort();
    ASSERT_NE(dumpPort_, 0);
    dump_ = std::make_unique<test::Process>(test::Process::start({oscdump_, "-L", std::to_string(dumpPort_)}));
    ASSERT_TRUE(dump_->started());
    std::this_thread::sleep_for(200ms);  // oscdump binds before the show sends
    dir_ = test::writeShow(std::string("osc-") + testing::UnitTest::GetInstance()->current_test_info()->name(),
                           showManifest(dumpPort_, 4));
    show_ = test::RunningShow::start({(dir_ / "show.toml").string(), "--realtime", "--no-resume"}, {}, why);
    ASSERT_TRUE(show_) << why;
    ASSERT_TRUE(show_->process().waitForOutput("basalt: osc: udp+tcp 127.0.0.1:", 10s))
        << show_->process().outputSoFar();
    show_->process().waitForOutput("\n", 1s);
    const std::regex line(R"(basalt: osc: udp\+tcp 127\.0\.0\.1:([0-9]+))");
    std::smatch m;
    const std::string out = show_->process().outputSoFar();
    ASSERT_TRUE(std::regex_search(out, m, line)) << out;
    oscPort_ = static_cast<std::uint16_t>(std::stoi(m[1]));
  }

  /// Sends with liblo's oscsend: `url` is "localhost PORT" over UDP or "osc.tcp://..." .
  void send(const std::vector<std::string>& message, bool tcp = false) {
    std::vector<std::string> argv{oscsend_};
    if (tcp) {
      argv.push_back(fmt::format("osc.tcp://127.0.0.1:{}", oscPort_));
    } else {
      argv.push_back("127.0.0.1");
      argv.push_back(std::to_string(oscPort_));
    }
    argv.insert(argv.end(), message.begin(), message.end());
    const auto r = test::run(argv, {}, 10s);
    ASSERT_EQ(r.exitCode, 0) << r.output;
  }

  nlohmann::json health() {
    const auto h = show_->get("/health");
    EXPECT_EQ(h.status, 200) << h.body;
    return nlohmann::json::parse(h.body, nullptr, false);
  }

  /// Waits until /health's `pointer` equals `value` (within 5 s).
  bool healthBecomes(const std::string& pointer, const nlohmann::json& value) {
    for (int i = 0; i < 50; ++i) {
      const auto h = health();
      if (!h.is_discarded() && h.contains(nlohmann::json::json_pointer(pointer)) &&
          h[nlohmann::json::json_pointer(pointer)] == value) {
        return true;
      }
      std::this_thread::sleep_for(100ms);
    }
    return false;
  }

  Picture snapshot(const std::string& name) {
    // The server reads the frame back at most once a second: wait past the last one.
    std::this_thread::sleep_for(1100ms);
    const auto s = show_->get("/snapshot.png");
    Picture p;
    if (s.status != 200) return p;
    const auto file = test::scratchDir("osc-snapshots") / (name + ".png");
    std::ofstream(file, std::ios::binary) << s.body;
    auto image = media::readImage(file);
    if (!image) return p;
    p.image = std::move(*image);
    p.ok = true;
    return p;
  }

  /// Pixels whose colour differs by more than `tolerance` in some channel.
  static std::size_t differing(const Image& a, const Image& b, int tolerance = 24) {
    std::size_t n = 0;
    for (std::uint32_t y = 0; y < a.height; ++y) {
      for (std::uint32_t x = 0; x < a.width; ++x) {
        for (std::uint32_t c = 0; c < 3; ++c) {
          if (std::abs(static_cast<int>(a.at(x, y, c)) - static_cast<int>(b.at(x, y, c))) > tolerance) {
            ++n;
            break;
          }
        }
      }
    }
    return n;
  }

  void TearDown() override {
    if (dump_) dump_->signal(SIGTERM);
  }

  std::string oscsend_, oscdump_;
  std::uint16_t dumpPort_ = 0;
  std::uint16_t oscPort_ = 0;
  std::unique_ptr<test::Process> dump_;
  std::filesystem::path dir_;
  std::unique_ptr<test::RunningShow> show_;
};

// Makes sure oscsend's messages reach the show through the frame loop: a LAVA command stops the
// default show's own motion; a quarter turn about Y changes the picture and three more quarters
// bring it back (a whole turn: the colour cube's faces all differ, so only 360 degrees matches);
// the next item plays. Each control is logged as HTTP controls are.
TEST_F(OscShow, OscsendTurnsTheCubeMovesOnAndRunsACommand) {
  send({"/basalt/do", "s", "motion.stop"});
  ASSERT_TRUE(healthBecomes("/osc/acted", 1)) << health().dump();
  const Picture before = snapshot("before");
  ASSERT_TRUE(before.ok);
  send({"/basalt/spin", "f", "0.25"});  // a quarter of a turn: 90 degrees
  ASSERT_TRUE(healthBecomes("/osc/acted", 2));
  const Picture quarter = snapshot("quarter");
  ASSERT_TRUE(quarter.ok);
  EXPECT_GT(differing(before.image, quarter.image), 500u) << "a quarter turn shows other faces";
  send({"/basalt/spin", "f", "0.75"}, true);  // over TCP: the rest of the turn
  ASSERT_TRUE(healthBecomes("/osc/acted", 3));
  const Picture whole = snapshot("whole");
  ASSERT_TRUE(whole.ok);
  EXPECT_LT(differing(before.image, whole.image), 40u)
      << "a whole turn is where it started (edges may differ by rounding)";

  EXPECT_EQ(health()["show"]["item"], "first");
  send({"/basalt/next"});
  EXPECT_TRUE(healthBecomes("/show/item", "second")) << health().dump();
  const std::string out = show_->process().outputWithin(500ms);
  EXPECT_NE(out.find("control OSC /basalt/do from 127.0.0.1: ran: motion.stop"), std::string::npos) << out;
  EXPECT_NE(out.find("control OSC /basalt/spin from 127.0.0.1: rotate_y 90"), std::string::npos) << out;
  EXPECT_NE(out.find("control OSC /basalt/spin from 127.0.0.1: rotate_y 270"), std::string::npos) << out;
  EXPECT_NE(out.find("control OSC /basalt/next from 127.0.0.1: open, playing: 'second' (2/2)"), std::string::npos)
      << out;
}

// A tracker fed over OSC (the /tracker/NAME convention): oscsend's positions reach the
// `kind = "tracker"`, `backend = "osc"` device through the OSC input, the device goes live in
// /health, its samples are counted in /metrics, and the facet view follows the head: the same
// display seen from two head positions gives two pictures.
// Example failures: /tracker/ messages counted unmatched (no tracker wired to the OSC input);
// the tracker never opens; the samples arrive but the frustum stays at the display's centre.
TEST(OscTracker, OscsendMovesTheTrackedViewersFrustum) {
  std::string why;
  if (!test::headlessEglWorks(why)) GTEST_SKIP() << "no headless EGL here: " << why;
  const std::string oscsend = test::onPath("oscsend");
  if (oscsend.empty()) GTEST_SKIP() << "liblo-tools (oscsend) is not installed";
  const auto dir = test::writeShow("osc-tracker", R"(
[show]
name = "OSC tracker"
entry = "display.obj"
fps = 30

[output]
kind = "headless"
size = "160x120"

[[views]]
name = "front"
kind = "facet"
cave = "display.cave"
facet = 5

[devices.head]
kind = "tracker"
backend = "osc"

[viewer]
tracker = "head"
smoothing = "off"

[status]
listen = "127.0.0.1:0"

[osc]
listen = "127.0.0.1:0"
)");
  for (const char* file : {"display.cave", "display.obj"}) {
    std::filesystem::copy_file(test::sourceDir() / "configs/shows/cube-cave" / file, dir / file,
                               std::filesystem::copy_options::overwrite_existing);
  }
  auto show = test::RunningShow::start({(dir / "show.toml").string(), "--realtime", "--no-resume"}, {}, why);
  ASSERT_TRUE(show) << why;
  ASSERT_TRUE(show->process().waitForOutput("basalt: osc: udp+tcp 127.0.0.1:", 10s)) << show->process().outputSoFar();
  show->process().waitForOutput("\n", 1s);
  std::smatch m;
  const std::string out = show->process().outputSoFar();
  ASSERT_TRUE(std::regex_search(out, m, std::regex(R"(basalt: osc: udp\+tcp 127\.0\.0\.1:([0-9]+))"))) << out;
  const std::string port = m[1];
  const auto sendHead = [&](const char* x, const char* y, const char* z) {
    const auto r = test::run({oscsend, "127.0.0.1", port, "/tracker/head", "ffffff", x, y, z, "0", "0", "0"}, {}, 10s);
    ASSERT_EQ(r.exitCode, 0) << r.output;
  };
  const auto headState = [&] {
    const auto h = nlohmann::json::parse(show->get("/health").body, nullptr, false);
    if (h.is_discarded()) return std::string();
    for (const auto& d : h["devices"]) {
      if (d["name"] == "head") return d["state"].get<std::string>();
    }
    return std::string();
  };
  const auto picture = [&](const std::string& name) {
    std::this_thread::sleep_for(1100ms);  // one read-back a second
    const auto s = show->get("/snapshot.png");
    const auto file = test::scratchDir("osc-tracker-" + name) / "snapshot.png";
    std::ofstream(file, std::ios::binary) << s.body;
    return media::readImage(file);
  };
  // Sent for a while, so that the device manager's next try finds it speaking and opens it.
  std::string state;
  for (int i = 0; i < 60 && state != "live"; ++i) {
    sendHead("0.6", "0", "0");
    std::this_thread::sleep_for(100ms);
    state = headState();
  }
  ASSERT_EQ(state, "live") << show->get("/health").body;
  for (int i = 0; i < 5; ++i) sendHead("0.6", "0", "0");
  auto right = picture("right");
  for (int i = 0; i < 5; ++i) sendHead("0.6", "0", "0");
  auto again = picture("again");
  for (int i = 0; i < 5; ++i) sendHead("-0.6", "0.3", "0");
  auto left = picture("left");
  ASSERT_TRUE(right && again && left);
  const auto differing = [](const Image& a, const Image& b) {
    std::size_t n = 0;
    for (std::size_t i = 0; i < a.pixels.size() && i < b.pixels.size(); ++i) n += a.pixels[i] != b.pixels[i];
    return n;
  };
  EXPECT_EQ(differing(*right, *again), 0u) << "the same head, the same picture (nothing else moves)";
  EXPECT_GT(differing(*right, *left), right->pixels.size() / 50) << "the facet's frustum follows the head";
  const std::string metrics = show->get("/metrics").body;
  std::smatch samples;
  ASSERT_TRUE(
      std::regex_search(metrics, samples, std::regex(R"(basalt_tracker_samples_total\{tracker="head"\} ([0-9]+))")))
      << metrics;
  EXPECT_GE(std::stoi(samples[1]), 10) << metrics;
}

/// NTP time of an oscdump line ("eeb44aba.01bb2788 /basalt/fps f 30.9") in seconds.
double dumpTime(const std::string& line) {
  const auto dot = line.find('.');
  const auto space = line.find(' ');
  if (dot == std::string::npos || space == std::string::npos || dot > space) return -1;
  const double seconds = static_cast<double>(std::stoul(line.substr(0, dot), nullptr, 16));
  const double fraction = static_cast<double>(std::stoul(line.substr(dot + 1, space - dot - 1), nullptr, 16));
  return seconds + fraction / 4294967296.0;
}

// Makes sure a show controller listening with oscdump hears the node: the item started (with
// its name, place and list length) at the start and after next, the dial box's state, and the
// figures at the manifest's rate (4 a second). Example failure: /item sent without the name, or
// fps sent at 20 Hz.
TEST_F(OscShow, OscdumpHearsTheItemsTheDeviceAndTheFiguresAtTheirRate) {
  std::this_thread::sleep_for(3s);
  send({"/basalt/next"});
  ASSERT_TRUE(healthBecomes("/show/item", "second"));
  std::this_thread::sleep_for(500ms);
  const std::string heard = dump_->outputWithin(300ms);
  EXPECT_NE(heard.find("/basalt/item sii \"first\" 1 2"), std::string::npos) << heard;
  EXPECT_NE(heard.find("/basalt/item sii \"second\" 2 2"), std::string::npos) << heard;
  EXPECT_NE(heard.find("/basalt/device ss \"dials\" \"live\""), std::string::npos) << heard;
  std::vector<double> fpsTimes;
  std::vector<double> fpsValues;
  std::istringstream lines(heard);
  for (std::string line; std::getline(lines, line);) {
    if (line.find(" /basalt/fps f ") == std::string::npos) continue;
    fpsTimes.push_back(dumpTime(line));
    fpsValues.push_back(std::stod(line.substr(line.rfind(' ') + 1)));
  }
  ASSERT_GE(fpsTimes.size(), 8u) << heard;
  // Figures every 1/4 s: the mean gap over the run, and no gap far from it.
  const double mean = (fpsTimes.back() - fpsTimes.front()) / static_cast<double>(fpsTimes.size() - 1);
  EXPECT_NEAR(mean, 0.25, 0.03) << heard;
  EXPECT_NEAR(fpsValues.back(), 30, 3) << "the show runs at its 30 fps: " << heard;
}

void sendUdp(std::uint16_t port, const std::vector<std::byte>& bytes) {
  UniqueFd fd(::socket(AF_INET, SOCK_DGRAM, 0));
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(port);
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  (void)::sendto(fd.get(), bytes.data(), bytes.size(), 0, reinterpret_cast<sockaddr*>(&a), sizeof a);
}

std::vector<std::byte> oscString(std::string_view address, std::string_view tags) {
  std::vector<std::byte> out;
  for (const std::string_view part : {address, tags}) {
    for (const char c : part) out.push_back(static_cast<std::byte>(c));
    out.push_back(std::byte{0});
    while (out.size() % 4 != 0) out.push_back(std::byte{0});
  }
  return out;
}

// Makes sure hostile input changes nothing and stops nothing: random bytes, a datagram of 60 KB,
// a TCP frame announcing 1 MB, a string where a number belongs and a flood of 5,000 messages a
// second from one sender. The show keeps drawing (frames go on, no late frames from OSC), the
// node answers, and every refusal is counted.
TEST_F(OscShow, HostileInputIsCountedAndTheShowKeepsItsFrames) {
  send({"/basalt/do", "s", "motion.stop"});
  ASSERT_TRUE(healthBecomes("/osc/acted", 1));
  const auto start = health();
  const std::int64_t framesBefore = start["frames"]["total"].get<std::int64_t>();
  // Malformed: random bytes of every length up to 512, and a bundle cut short.
  std::uint32_t x = 99;
  for (int i = 0; i < 200; ++i) {
    std::vector<std::byte> noise(static_cast<std::size_t>(4 + (i * 4) % 512));
    for (std::byte& b : noise) {
      x = x * 1664525 + 1013904223;
      b = static_cast<std::byte>(x >> 24);
    }
    sendUdp(oscPort_, noise);
  }
  // Huge: a 60 KB datagram.
  sendUdp(oscPort_, std::vector<std::byte>(60000, std::byte{'/'}));
  // TCP: a frame announcing 1 MB; the connection is closed and counted.
  {
    UniqueFd fd(::socket(AF_INET, SOCK_STREAM, 0));
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(oscPort_);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ASSERT_EQ(::connect(fd.get(), reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
    const unsigned char header[4] = {0x00, 0x10, 0x00, 0x00};
    ASSERT_EQ(::write(fd.get(), header, 4), 4);
    std::this_thread::sleep_for(300ms);
    char b = 0;
    EXPECT_EQ(::read(fd.get(), &b, 1), 0) << "the server closed the connection";
  }
  // Wrong types (counted every time, logged once).
  for (int i = 0; i < 5; ++i) send({"/basalt/spin", "s", "fast"});
  // A flood: 5,000 "/basalt/spin ,s" and "/nowhere" datagrams over a second.
  const auto wrong = oscString("/nowhere", ",");
  for (int i = 0; i < 5000; ++i) {
    sendUdp(oscPort_, wrong);
    if (i % 50 == 49) std::this_thread::sleep_for(10ms);
  }
  std::this_thread::sleep_for(1s);
  const auto after = health();
  ASSERT_FALSE(after.is_discarded());
  const auto& osc = after["osc"];
  EXPECT_GE(osc["refused"]["malformed"].get<std::int64_t>(), 150) << osc.dump();
  EXPECT_GE(osc["refused"]["wrong_types"].get<std::int64_t>(), 5) << osc.dump();
  EXPECT_GE(osc["refused"]["rate_limited"].get<std::int64_t>(), 4000) << osc.dump();
  EXPECT_EQ(osc["acted"], 1) << "nothing hostile acted: " << osc.dump();
  const std::int64_t frames = after["frames"]["total"].get<std::int64_t>() - framesBefore;
  EXPECT_GT(frames, 30) << "the show kept drawing: " << after["frames"].dump();
  const std::string out = show_->process().outputWithin(300ms);
  std::size_t said = 0;
  for (std::size_t at = out.find("OSC /basalt/spin ,s from"); at != std::string::npos;
       at = out.find("OSC /basalt/spin ,s from", at + 1)) {
    ++said;
  }
  EXPECT_EQ(said, 1u) << "said once: " << out;
  // And the node still takes a good message.
  std::this_thread::sleep_for(2s);  // the sender's bucket fills again
  send({"/basalt/next"});
  EXPECT_TRUE(healthBecomes("/show/item", "second")) << health().dump();
  const auto metrics = show_->get("/metrics");
  EXPECT_EQ(test::metric(metrics.body, "basalt_osc_messages_total{outcome=\"wrong_types\"}"),
            osc["refused"]["wrong_types"].get<double>())
      << metrics.body;
}

}  // namespace
}  // namespace basalt
