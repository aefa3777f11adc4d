// The status and control server of a real `basalt run`, over real HTTP: what /health, /metrics,
// /snapshot.png, /log.txt and / serve; controls with no token, a wrong token and the right one;
// malformed, oversized and too frequent requests; a second Basalt on the same port; and the
// status page as a desktop's and a phone's browser show it (headless Chromium), its fields read
// from the DOM and its screenshots checked.
// Example failures: /health without the device that is down; a Prometheus line the scraper
// rejects; a control that runs without a token; a malformed request that crashes or hangs the
// server; a page that stays empty because its script failed.

#include <gtest/gtest.h>
#include <httplib.h>

#include <signal.h>
#include <unistd.h>

#include <fstream>
#include <regex>
#include <sstream>
#include <tuple>

#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "media/image_io.h"
#include "runtime/formats/cave.h"
#include "support/kiosk_process.h"
#include "support/polyhedra.h"
#include "support/test_paths.h"

namespace basalt {
namespace {

constexpr const char* kToken = "0123456789abcdef0123456789abcdef";

std::string showManifest(bool withToken) {
  std::string m = R"(
[show]
name = "Status test"
entry = "default"
fps = 30

[output]
kind = "headless"
size = "160x120"

[devices.dials]
kind = "dial_box"
backend = "synthetic"
script = [ { at = "0.2s", dial = 1, turns = 0.05 } ]

[devices.knob]
kind = "dial_box"
backend = "hid"
match = { usb = "077d:0410" }

[devices.cam]
kind = "camera"
backend = "synthetic"
size = "64x48"

[media.live]
kind = "camera"
device = "cam"

[textures.camera]
source = "live"

[[kiosk.playlist]]
name = "first"
entry = "default"
duration = "1h"

[[kiosk.playlist]]
name = "second"
entry = "black"
duration = "1h"

[status]
listen = "127.0.0.1:0"
requests_per_second = 20
max_request_bytes = 2048
)";
  if (withToken) m += "token_file = \"token\"\n";
  return m;
}

class StatusServer : public testing::Test {
 protected:
  void SetUp() override { start(true); }
  void start(bool withToken) {
    std::string why;
    if (!test::headlessEglWorks(why)) GTEST_SKIP() << "no headless EGL here: " << why;
    dir_ = test::writeShow(std::string("status-") + testing::UnitTest::GetInstance()->current_test_info()->name(),
                           showManifest(withToken));
    std::ofstream(dir_ / "token") << kToken << "\n";
    show_ = test::RunningShow::start({(dir_ / "show.toml").string(), "--realtime", "--no-resume"}, {}, why);
    ASSERT_TRUE(show_) << why;
  }
  std::filesystem::path dir_;
  std::unique_ptr<test::RunningShow> show_;
};

/// The object in `list` whose "name" is `name`, or null.
nlohmann::json named(const nlohmann::json& list, const std::string& name) {
  for (const auto& item : list) {
    if (item.value("name", "") == name) return item;
  }
  return nullptr;
}

TEST_F(StatusServer, HealthReportsTheShowItsFramesAndItsDevices) {
  ::usleep(400000);  // a few frames, and the synthetic dial's first turn
  const auto h = show_->get("/health");
  ASSERT_EQ(h.status, 200) << h.body;
  EXPECT_EQ(h.headers.at("Content-Type"), "application/json");
  ASSERT_TRUE(nlohmann::json::accept(h.body)) << h.body;
  const auto health = nlohmann::json::parse(h.body);
  EXPECT_EQ(health["show"]["name"], "Status test") << h.body;
  EXPECT_EQ(health["state"], "degraded") << "the knob is absent: " << h.body;
  EXPECT_EQ(health["show"]["item"], "first") << h.body;
  EXPECT_EQ(health["show"]["mode"], "active") << h.body;
  const auto dials = named(health["devices"], "dials");
  ASSERT_TRUE(dials.is_object()) << h.body;
  EXPECT_EQ(dials["kind"], "dial_box");
  EXPECT_EQ(dials["backend"], "synthetic");
  EXPECT_EQ(dials["state"], "live");
  const auto knob = named(health["devices"], "knob");
  ASSERT_TRUE(knob.is_object()) << h.body;
  EXPECT_EQ(knob["backend"], "hid");
  EXPECT_EQ(knob["state"], "absent");
  EXPECT_NE(knob["message"].get<std::string>().find("no hid 077d:0410 is plugged in"), std::string::npos)
      << "the reason: " << h.body;
  EXPECT_TRUE(health["frames"]["frame_time_ms"]["p50"].is_number()) << h.body;
  EXPECT_GT(health["frames"]["total"].get<std::int64_t>(), 0) << "frames were drawn: " << h.body;
  EXPECT_TRUE(health["last_errors"].is_array()) << h.body;
  EXPECT_TRUE(health["uptime_seconds"].is_number()) << h.body;
  // Each device says since when it is in its state (ISO 8601), and frames have a rate.
  const std::regex iso(R"re([0-9]{4}-[0-9]{2}-[0-9]{2}T[0-9:.]+Z)re");
  EXPECT_TRUE(std::regex_match(dials["since"].get<std::string>(), iso)) << h.body;
  EXPECT_TRUE(std::regex_match(knob["since"].get<std::string>(), iso)) << h.body;
  EXPECT_GT(health["frames"]["per_second"].get<double>(), 0.0) << h.body;
  // The camera's stream plays, and the camera's row says so (its state is its stream's).
  ASSERT_EQ(health["streams"].size(), 1u) << h.body;
  EXPECT_EQ(health["streams"][0]["name"], "live");
  EXPECT_EQ(health["streams"][0]["kind"], "camera");
  EXPECT_EQ(health["streams"][0]["state"], "playing");
  const auto cam = named(health["devices"], "cam");
  ASSERT_TRUE(cam.is_object()) << h.body;
  EXPECT_EQ(cam["kind"], "camera");
  EXPECT_EQ(cam["backend"], "synthetic");
  EXPECT_EQ(cam["state"], "live");
  EXPECT_TRUE(cam["message"].get<std::string>().starts_with("shown by texture 'camera': ")) << h.body;
}

TEST_F(StatusServer, MetricsAreValidPrometheusText) {
  ::usleep(300000);
  const auto m = show_->get("/metrics");
  ASSERT_EQ(m.status, 200);
  EXPECT_EQ(m.headers.at("Content-Type"), "text/plain; version=0.0.4; charset=utf-8");
  const std::regex sample(
      R"(^[a-zA-Z_:][a-zA-Z0-9_:]*(\{([a-zA-Z_][a-zA-Z0-9_]*="([^"\\]|\\.)*",?)*\})? -?[0-9.e+-]+$)");
  const std::regex comment(R"(^# (HELP|TYPE) [a-zA-Z_:][a-zA-Z0-9_:]* .+$)");
  std::istringstream lines(m.body);
  std::string line;
  int samples = 0;
  while (std::getline(lines, line)) {
    if (line.starts_with("#")) {
      EXPECT_TRUE(std::regex_match(line, comment)) << line;
    } else {
      EXPECT_TRUE(std::regex_match(line, sample)) << line;
      ++samples;
    }
  }
  EXPECT_GT(samples, 20);
  EXPECT_GT(test::metric(m.body, "basalt_frames_total").value_or(0), 0);
  EXPECT_EQ(test::metric(m.body, "basalt_device_up{device=\"dials\"}"), 1.0) << m.body;
  EXPECT_EQ(test::metric(m.body, "basalt_device_state{device=\"dials\"}"), 2.0) << "2: live; " << m.body;
  EXPECT_EQ(test::metric(m.body, "basalt_device_up{device=\"knob\"}"), 0.0) << m.body;
  EXPECT_EQ(test::metric(m.body, "basalt_device_state{device=\"knob\"}"), 0.0) << "0: absent; " << m.body;
  EXPECT_EQ(test::metric(m.body, "basalt_device_info{device=\"knob\",kind=\"dial_box\",backend=\"hid\"}"), 1.0);
  EXPECT_EQ(test::metric(m.body, "basalt_kiosk_mode{mode=\"active\"}"), 1.0);
  EXPECT_EQ(test::metric(m.body, "basalt_up"), 1.0) << "the show runs";
  EXPECT_EQ(test::metric(m.body, "basalt_state{state=\"degraded\"}"), 1.0) << "degraded while the knob is absent";
  EXPECT_GT(test::metric(m.body, "basalt_frame_interval_seconds_count").value_or(0), 0) << m.body;
  EXPECT_GT(test::metric(m.body, "process_resident_memory_bytes").value_or(0), 0) << m.body;
  EXPECT_GT(test::metric(m.body, "process_open_fds").value_or(0), 0) << m.body;
  EXPECT_TRUE(test::metric(m.body, "process_cpu_seconds_total")) << m.body;
  // And promtool, Prometheus' own checker, finds nothing to say.
  if (::access("/usr/bin/promtool", X_OK) == 0) {
    const auto file = test::scratchDir("status-metrics") / "metrics.txt";
    std::ofstream(file) << m.body;
    const auto lint = test::run({"/bin/sh", "-c", "promtool check metrics < '" + file.string() + "'"});
    EXPECT_EQ(lint.exitCode, 0) << lint.output;
    EXPECT_EQ(lint.output, "") << m.body;
  }
}

TEST_F(StatusServer, SnapshotIsTheFrameOnScreen) {
  const auto s = show_->get("/snapshot.png");
  ASSERT_EQ(s.status, 200) << s.body;
  EXPECT_EQ(s.headers.at("Content-Type"), "image/png");
  const auto file = test::scratchDir("status-snapshot") / "s.png";
  std::ofstream(file, std::ios::binary) << s.body;
  auto image = media::readImage(file);
  ASSERT_TRUE(image) << image.error().describe();
  EXPECT_EQ(image->width, 160u);
  EXPECT_EQ(image->height, 120u);
  std::size_t lit = 0;
  for (std::uint32_t y = 0; y < image->height; ++y) {
    for (std::uint32_t x = 0; x < image->width; ++x) lit += image->at(x, y, 0) + image->at(x, y, 1) > 100 ? 1u : 0u;
  }
  EXPECT_GT(lit, 500u) << "the cube is in the snapshot";
  const auto thumb = show_->get("/snapshot.png?w=40");
  ASSERT_EQ(thumb.status, 200);
  std::ofstream(file, std::ios::binary) << thumb.body;
  auto small = media::readImage(file);
  ASSERT_TRUE(small);
  EXPECT_EQ(small->width, 40u);
  EXPECT_EQ(small->height, 30u);
  EXPECT_EQ(show_->get("/snapshot.png?w=0").status, 400);
  EXPECT_EQ(show_->get("/snapshot.png?w=wide").status, 400);
}

TEST_F(StatusServer, StatusPageIsServed) {
  const auto page = show_->get("/");
  ASSERT_EQ(page.status, 200);
  EXPECT_EQ(page.headers.at("Content-Type"), "text/html; charset=utf-8");
  EXPECT_NE(page.body.find("<title>Basalt status</title>"), std::string::npos);
  EXPECT_NE(page.body.find("name=\"viewport\""), std::string::npos) << "made for phones";
  EXPECT_NE(page.body.find("fetch(\"/health\""), std::string::npos);
}

TEST_F(StatusServer, ControlsNeedTheToken) {
  const auto none = show_->post("/control/next");
  EXPECT_EQ(none.status, 401) << none.body;
  EXPECT_EQ(none.headers.at("WWW-Authenticate"), "Bearer realm=\"basalt\"");
  const auto wrong = show_->post("/control/next", "", "Bearer 0123456789abcdef0123456789abcdeX");
  EXPECT_EQ(wrong.status, 403) << wrong.body;
  EXPECT_NE(wrong.body.find("wrong token"), std::string::npos);
  EXPECT_EQ(show_->post("/control/next", "", std::string("Basic ") + kToken).status, 403);
  EXPECT_EQ(show_->post("/control/next", "", "Bearer short").status, 403);
  EXPECT_NE(show_->get("/health").body.find("\"item\": \"first\""), std::string::npos) << "nothing moved";

  const std::string bearer = std::string("Bearer ") + kToken;
  const auto next = show_->post("/control/next", "", bearer);
  EXPECT_EQ(next.status, 200) << next.body;
  EXPECT_NE(next.body.find("'second' (2/2)"), std::string::npos) << next.body;
  EXPECT_NE(show_->get("/health").body.find("\"item\": \"second\""), std::string::npos);
  EXPECT_EQ(show_->post("/control/previous", "", bearer).status, 200);
  EXPECT_NE(show_->get("/health").body.find("\"item\": \"first\""), std::string::npos);
  const auto metrics = show_->get("/metrics");
  EXPECT_GE(test::metric(metrics.body, "basalt_http_rejected_total{reason=\"auth\"}").value_or(0), 4);
}

TEST_F(StatusServer, EachControlAnswersWhatItDid) {
  const std::string bearer = std::string("Bearer ") + kToken;
  const auto reload = show_->post("/control/reload", "", bearer);
  EXPECT_EQ(reload.status, 202) << reload.body;
  const auto command = show_->post("/control/command", "render.prim_type = wireframe", bearer);
  EXPECT_EQ(command.status, 200) << command.body;
  EXPECT_NE(command.body.find("ran: render.prim_type = wireframe"), std::string::npos) << command.body;
  const auto typo = show_->post("/control/command", "render.prim_type = wirefram", bearer);
  EXPECT_EQ(typo.status, 400) << typo.body;
  EXPECT_NE(typo.body.find("wirefram"), std::string::npos) << "the reason names what is wrong: " << typo.body;
  const auto gone = show_->post("/control/command", "load_object gone.obj", bearer);
  EXPECT_EQ(gone.status, 400) << gone.body;
  EXPECT_NE(gone.body.find("gone.obj"), std::string::npos) << gone.body;
  EXPECT_EQ(show_->post("/control/command", "", bearer).status, 400);
  EXPECT_EQ(show_->post("/control/command", "draw\ndraw", bearer).status, 400);
  const auto dials = show_->post("/control/restart-device?device=dials", "", bearer);
  EXPECT_EQ(dials.status, 200) << dials.body;
  const auto knob = show_->post("/control/restart-device", "knob", bearer);
  EXPECT_EQ(knob.status, 503) << "the knob is not plugged in: " << knob.body;
  EXPECT_NE(knob.body.find("'knob' could not be reopened: "), std::string::npos) << knob.body;
  EXPECT_NE(knob.body.find("077d:0410"), std::string::npos) << knob.body;
  EXPECT_EQ(show_->post("/control/restart-device?device=nope", "", bearer).status, 404);
  // The reload went through and the show is the same one.
  ::usleep(500000);
  const auto h = show_->get("/health");
  const auto health = nlohmann::json::parse(h.body);
  EXPECT_EQ(health["reloads"]["total"], 1) << h.body;
  EXPECT_EQ(health["reloads"]["failed"], 0) << h.body;
}

/// Makes sure the status page's Restart button works for a camera as for a dial box, over real
/// HTTP: the camera a texture shows is closed and opened again, answers 200, and its texture
/// shows new frames afterwards (the synthetic camera's box moves, so two snapshots apart differ).
/// Example failures: a camera refused (409) because its texture stream opens it; a camera
/// reopened under a texture stream that keeps the closed source, its picture frozen for good.
TEST(StatusServerRestart, TheRestartButtonRestartsACameraAndADialBox) {
  std::string why;
  if (!test::headlessEglWorks(why)) GTEST_SKIP() << "no headless EGL here: " << why;
  // The camera sculpture's scene (its sculpture wears the camera), still: nothing turns it.
  const auto dir = test::writeShow("status-restart-camera", R"(
[show]
name = "Restart test"
entry = "sculpture.sce"
fps = 30

[output]
kind = "headless"
size = "160x120"

[devices.dials]
kind = "dial_box"
backend = "synthetic"

[devices.cam]
kind = "camera"
backend = "synthetic"
size = "64x48"

[media.live]
kind = "camera"
device = "cam"

[textures."camera.png"]
source = "live"
fallback = "camera.png"

[status]
listen = "127.0.0.1:0"
token_file = "token"
)");
  const auto example = test::sourceDir() / "configs/shows/camera-sculpture";
  for (const char* file : {"sculpture.sce", "sculpture.obj", "camera.png"}) {
    std::filesystem::copy_file(example / file, dir / file, std::filesystem::copy_options::overwrite_existing);
  }
  std::ofstream(dir / "token") << kToken << "\n";
  const auto show = test::RunningShow::start({(dir / "show.toml").string(), "--realtime", "--no-resume"}, {}, why);
  ASSERT_TRUE(show) << why;
  const std::string bearer = std::string("Bearer ") + kToken;
  // The camera is live and its texture plays; `newFrames` sees its picture move.
  const auto cameraPlays = [&] {
    for (int i = 0; i < 50; ++i) {
      const auto h = nlohmann::json::parse(show->get("/health").body);
      const auto cam = named(h["devices"], "cam");
      if (cam.is_object() && cam["state"] == "live" && h["streams"].size() == 1 &&
          h["streams"][0]["state"] == "playing")
        return true;
      ::usleep(100000);
    }
    return false;
  };
  // The synthetic camera's box crosses its 64-pixel picture in about 5 s at 30 fps (6 pixels per
  // 16 frames) and the sculpture shows only part of the picture, so the box may be out of sight
  // for a while: look over 6.6 s, one snapshot every 1.1 s (the server reads the frame back at most
  // once a second and answers from that copy between).
  const auto newFrames = [&] {
    const auto first = show->get("/snapshot.png");
    if (first.status != 200) return false;
    for (int i = 0; i < 6; ++i) {
      ::usleep(1100000);
      const auto later = show->get("/snapshot.png");
      if (later.status == 200 && later.body != first.body) return true;
    }
    return false;
  };
  ASSERT_TRUE(cameraPlays()) << show->get("/health").body;
  ASSERT_TRUE(newFrames()) << "the camera's moving box shows before the restart";

  const auto cam = show->post("/control/restart-device?device=cam", "", bearer);
  EXPECT_EQ(cam.status, 200) << cam.body;
  EXPECT_NE(cam.body.find("'cam' restarted"), std::string::npos) << cam.body;
  ::usleep(300000);
  EXPECT_TRUE(cameraPlays()) << show->get("/health").body;
  EXPECT_TRUE(newFrames()) << "the texture shows the reopened camera's frames";
  const auto dials = show->post("/control/restart-device?device=dials", "", bearer);
  EXPECT_EQ(dials.status, 200) << dials.body;
  EXPECT_NE(dials.body.find("'dials' restarted"), std::string::npos) << dials.body;
  // Each restart is in the log, once.
  show->process().signal(SIGTERM);
  const std::string out = show->process().wait(std::chrono::seconds(20)).output;
  EXPECT_NE(out.find("device 'cam' restarted by the control server: live"), std::string::npos) << out;
  EXPECT_NE(out.find("video source 'cam': Synthetic camera (synthetic at synthetic:camera) is live again"),
            std::string::npos)
      << "the camera was really closed and opened: " << out;
  EXPECT_NE(out.find("device 'dials' restarted by the control server: live"), std::string::npos) << out;
}

TEST_F(StatusServer, MalformedAndOversizedRequestsAreRefused) {
  // A request line that is not HTTP gets a 400 or the connection closed, never an answer.
  for (const std::string& request : std::vector<std::string>{"HELLO THERE\r\n\r\n", "GET /health HTTP/9.9\r\n\r\n",
                                                             std::string("\0\xff\xfe junk\r\n\r\n", 12)}) {
    const std::string answer = show_->raw(request);
    EXPECT_TRUE(answer.empty() || answer.starts_with("HTTP/1.1 400")) << request << " -> " << answer;
  }
  const auto missing = show_->get("/nope");
  EXPECT_EQ(missing.status, 404);
  EXPECT_NE(missing.body.find("no such page: /nope"), std::string::npos) << missing.body;
  const auto wrongMethod = show_->post("/health");
  EXPECT_EQ(wrongMethod.status, 405);
  EXPECT_EQ(wrongMethod.headers.at("Allow"), "GET");
  EXPECT_EQ(show_->get("/control/next").status, 405);
  const auto big = show_->post("/control/command", std::string(4096, 'x'), std::string("Bearer ") + kToken);
  EXPECT_EQ(big.status, 413) << big.body;
  const std::string hugeHeader =
      show_->raw("GET /health HTTP/1.1\r\nHost: x\r\nX-Big: " + std::string(20000, 'a') + "\r\n\r\n");
  EXPECT_FALSE(hugeHeader.starts_with("HTTP/1.1 200")) << "an oversized header is not served";
  const std::string lying = show_->raw("POST /control/next HTTP/1.1\r\nHost: x\r\nContent-Length: 999999999\r\n\r\n");
  EXPECT_FALSE(lying.starts_with("HTTP/1.1 200")) << lying;
  // The server is still there and the show still runs.
  EXPECT_EQ(show_->get("/health").status, 200);
  EXPECT_EQ(::kill(show_->process().pid(), 0), 0);
}

TEST_F(StatusServer, TooManyRequestsAreLimited) {
  int limited = 0;
  bool retryAfter = false;
  for (int i = 0; i < 80; ++i) {
    const auto a = show_->get("/metrics");
    if (a.status == 429) {
      ++limited;
      retryAfter = a.headers.contains("Retry-After");
    }
  }
  EXPECT_GT(limited, 0) << "80 requests at once from one client, at most 20 a second allowed";
  EXPECT_TRUE(retryAfter);
  ::usleep(1500000);
  EXPECT_EQ(show_->get("/health").status, 200) << "allowed again after a pause";
}

TEST(StatusServerWithoutToken, ControlsAreOff) {
  std::string why;
  if (!test::headlessEglWorks(why)) GTEST_SKIP() << "no headless EGL here: " << why;
  const auto dir = test::writeShow("status-no-token", showManifest(false));
  auto show = test::RunningShow::start({(dir / "show.toml").string(), "--realtime", "--no-resume"}, {}, why);
  ASSERT_TRUE(show) << why;
  const auto r = show->post("/control/next", "", std::string("Bearer ") + kToken);
  EXPECT_EQ(r.status, 403);
  EXPECT_NE(r.body.find("controls are off"), std::string::npos) << r.body;
  EXPECT_EQ(show->get("/health").status, 200) << "reading needs no token";
}

// Makes sure a second Basalt beside a running one (one started by hand beside the service) gets
// none of the first one's requests, says the port is taken, plays on, and takes the port once the
// first is gone. Example failures: the second binds too (SO_REUSEPORT) and answers half the
// requests; it exits, and systemd restarts it in a loop; it never tries again.
TEST(StatusServerSecondProcess, SaysThePortIsTakenAndTakesItLater) {
  std::string why;
  if (!test::headlessEglWorks(why)) GTEST_SKIP() << "no headless EGL here: " << why;
  const auto firstDir = test::writeShow("status-port-first", showManifest(false));
  auto first = test::RunningShow::start({(firstDir / "show.toml").string(), "--realtime", "--no-resume"}, {}, why);
  ASSERT_TRUE(first) << why;
  const std::string port = std::to_string(first->port());
  std::string manifest = showManifest(false);
  manifest.replace(manifest.find("127.0.0.1:0"), 11, "127.0.0.1:" + port);
  manifest.replace(manifest.find("Status test"), 11, "Second show");
  const auto secondDir = test::writeShow("status-port-second", manifest);
  auto second = test::Process::start({(test::binaryDir() / "basalt").string(), "run",
                                      (secondDir / "show.toml").string(), "--realtime", "--no-resume"});
  ASSERT_TRUE(second.waitForOutput("basalt: status server: not up yet: ", std::chrono::seconds(30)))
      << second.outputSoFar();
  ASSERT_TRUE(second.waitForOutput("first frame on", std::chrono::seconds(30))) << second.outputSoFar();
  EXPECT_NE(second.outputSoFar().find("port " + port + " on 127.0.0.1 is taken: another Basalt may be running"),
            std::string::npos)
      << second.outputSoFar();
  // Both run; every request is the first show's.
  for (int i = 0; i < 10; ++i) {
    const auto h = first->get("/health");
    ASSERT_EQ(h.status, 200);
    EXPECT_NE(h.body.find("Status test"), std::string::npos) << "answered by the second show: " << h.body;
  }
  EXPECT_EQ(::kill(second.pid(), 0), 0) << "the second show plays on";

  first->process().signal(SIGTERM);
  (void)first->process().wait(std::chrono::seconds(20));
  ASSERT_TRUE(second.waitForOutput("status server on http://127.0.0.1:" + port + "/ (the port was free after",
                                   std::chrono::seconds(10)))
      << second.outputSoFar();
  httplib::Client client("127.0.0.1", first->port());
  const auto h = client.Get("/health");
  ASSERT_TRUE(h);
  EXPECT_NE(h->body.find("Second show"), std::string::npos) << h->body;
  second.signal(SIGTERM);
  EXPECT_EQ(second.wait(std::chrono::seconds(20)).exitCode, 0);
}

// ---- Calibrating a facet view -----------------------------------------------------------------

// Makes sure a facet view's calibration can be changed and saved over HTTP (issue 10: calibration
// "adjustable live ... and the control server"). Example failures: a calibration applied without
// a token; a bad statement half applied; a saved cave file the loader then rejects.
TEST(StatusServerCalibration, FacetViewsAreCalibratedAndSaved) {
  std::string why;
  if (!test::headlessEglWorks(why)) GTEST_SKIP() << "no headless EGL here: " << why;
  const auto dir = test::writeShow("status-calibrate", R"(
[show]
name = "Calibration test"
entry = "default"
fps = 30

[output]
kind = "headless"
size = "160x120"

[[views]]
name = "front"
kind = "facet"
cave = "display.cave"

[[views]]
name = "left"
kind = "facet"
cave = "display.cave"
facet = 0

[status]
listen = "127.0.0.1:0"
token_file = "token"
)");
  std::ofstream(dir / "token") << kToken << "\n";
  std::ofstream(dir / "display.obj") << test::cubeDisplayObj();
  std::ofstream(dir / "display.cave") << "model display.obj\nfacet[5]\n";
  auto show = test::RunningShow::start({(dir / "show.toml").string(), "--realtime", "--no-resume"}, {}, why);
  ASSERT_TRUE(show) << why;
  const std::string bearer = std::string("Bearer ") + kToken;

  EXPECT_EQ(show->post("/control/calibrate", "Xscale[1.2]").status, 401);
  const auto read = show->post("/control/calibrate", "", bearer);
  EXPECT_EQ(read.status, 200) << read.body;
  EXPECT_NE(read.body.find("view 'front': facet[5] side[0] Xscale[1] "), std::string::npos) << read.body;

  const auto changed = show->post("/control/calibrate?view=left", "Xscale[1.25]\nYskew[-2]; side[1]", bearer);
  EXPECT_EQ(changed.status, 200) << changed.body;
  EXPECT_NE(changed.body.find("view 'left': facet[0] side[1] Xscale[1.25] Yscale[1] Xskew[0] Yskew[-2]"),
            std::string::npos)
      << changed.body;
  // A bad statement changes nothing, and says what is wrong.
  const auto bad = show->post("/control/calibrate?view=left", "Xscale[1.5]; Yscale[0]", bearer);
  EXPECT_EQ(bad.status, 400) << bad.body;
  EXPECT_NE(bad.body.find("Yscale must be more than 0"), std::string::npos) << bad.body;
  EXPECT_EQ(show->post("/control/calibrate?view=left", "side[4]", bearer).status, 400);
  EXPECT_EQ(show->post("/control/calibrate?view=left", "model other.obj", bearer).status, 400);
  const auto unknown = show->post("/control/calibrate?view=back", "Xscale[1]", bearer);
  EXPECT_EQ(unknown.status, 404) << unknown.body;
  EXPECT_NE(unknown.body.find("the facet views are 'front', 'left'"), std::string::npos) << unknown.body;
  EXPECT_EQ(show->get("/control/calibrate").status, 405);

  // Saved: the cave file reads back with the new values (Xscale[1.5] was refused above).
  const auto saved = show->post("/control/calibrate?view=left&save=1", "Xskew[3]", bearer);
  EXPECT_EQ(saved.status, 200) << saved.body;
  EXPECT_NE(saved.body.find("saved to"), std::string::npos) << saved.body;
  auto cave = formats::loadCave(dir / "display.cave");
  ASSERT_TRUE(cave) << cave.error().describe();
  EXPECT_EQ(cave->settings.facet, 0u);
  EXPECT_EQ(cave->settings.side, 1u);
  EXPECT_FLOAT_EQ(cave->settings.xScale, 1.25f);
  EXPECT_FLOAT_EQ(cave->settings.xSkew, 3.0f);
  EXPECT_FLOAT_EQ(cave->settings.ySkew, -2.0f);
  EXPECT_EQ(cave->settings.model, "display.obj");
  EXPECT_EQ(::kill(show->process().pid(), 0), 0) << "the show still runs";
}

// ---- A view that draws nothing --------------------------------------------------------------

// Makes sure a facet view of a display wound outward (each facet's corners reversed from the test
// cube's), with no `winding` to turn it, makes /health "degraded" with a problem naming the view,
// and is logged once, not once a frame; and that with winding = "outward" the same show is "ok".
// Example failures: a black wall while /health says "ok"; last_errors full of the same line.
TEST(StatusServerViews, AViewThatDrawsNothingIsAProblemSaidOnce) {
  std::string why;
  if (!test::headlessEglWorks(why)) GTEST_SKIP() << "no headless EGL here: " << why;
  const std::string manifest = R"(
[show]
name = "Outward display"
entry = "default"
fps = 30

[output]
kind = "headless"
size = "160x120"

[[views]]
name = "front"
kind = "facet"
cave = "display.cave"
{}
[status]
listen = "127.0.0.1:0"
)";
  for (const bool turned : {false, true}) {
    const auto dir = test::writeShow(turned ? "status-views-turned" : "status-views-outward",
                                     fmt::format(fmt::runtime(manifest), turned ? "winding = \"outward\"" : ""));
    std::ofstream(dir / "display.obj") << test::reverseFacetWinding(test::cubeDisplayObj());
    std::ofstream(dir / "display.cave") << "model display.obj\nfacet[5]\n";
    auto show = test::RunningShow::start({(dir / "show.toml").string(), "--realtime", "--no-resume"}, {}, why);
    ASSERT_TRUE(show) << why;
    ::usleep(1000000);  // about 30 frames
    const auto h = show->get("/health");
    ASSERT_EQ(h.status, 200) << h.body;
    const auto health = nlohmann::json::parse(h.body);
    std::size_t problems = 0, logged = 0;
    for (const auto& p : health["problems"]) {
      problems += p.get<std::string>().find("view 'front' draws nothing") != std::string::npos ? 1U : 0U;
    }
    for (const auto& e : health["last_errors"]) {
      logged += e["message"].get<std::string>().find("view 'front' draws nothing") != std::string::npos ? 1U : 0U;
    }
    if (turned) {
      EXPECT_EQ(health["state"], "ok") << h.body;
      EXPECT_EQ(problems, 0u) << h.body;
      EXPECT_EQ(logged, 0u) << h.body;
    } else {
      EXPECT_EQ(health["state"], "degraded") << h.body;
      EXPECT_EQ(problems, 1u) << h.body;
      EXPECT_EQ(logged, 1u) << h.body;
    }
  }
}

// ---- The page in a browser -----------------------------------------------------------------

/// Runs headless Chromium on `url` in a window of `width` x `height` with `extra` arguments;
/// returns its output.
test::ProcessResult chromium(const std::string& url, const std::vector<std::string>& extra, int width = 412,
                             int height = 915) {
  // A profile of this test's own: ctest may run two of these tests at once.
  const auto profile = test::scratchDir(std::string("status-chromium-profile-") +
                                        testing::UnitTest::GetInstance()->current_test_info()->name());
  std::vector<std::string> argv{"/usr/bin/chromium",
                                "--headless",
                                "--no-sandbox",
                                "--disable-gpu",
                                "--no-first-run",
                                "--disable-background-networking",
                                "--disable-component-update",
                                "--disable-sync",
                                "--hide-scrollbars",
                                "--user-data-dir=" + profile.string(),
                                "--window-size=" + std::to_string(width) + "," + std::to_string(height),
                                "--virtual-time-budget=4000"};
  argv.insert(argv.end(), extra.begin(), extra.end());
  argv.push_back(url);
  return test::run(argv, {}, std::chrono::seconds(90));
}

/// The text of the element `<TAG ... id="ID" ...>` in `dom`, up to its closing tag (no nesting).
std::string element(const std::string& dom, const std::string& tag, const std::string& id) {
  const auto at = dom.find(" id=\"" + id + "\"");
  if (at == std::string::npos || dom.rfind("<" + tag + " ", at) != dom.rfind('<', at)) return {};
  if (at == std::string::npos) return {};
  const auto start = dom.find('>', at) + 1;
  return dom.substr(start, dom.find("</" + tag + ">", start) - start);
}

/// The first line of a file, or "".
std::string firstLineOf(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  return line;
}

/// True when the kernel offers a temperature the page could show: a thermal zone, or a hwmon
/// input (the page's choice among them is tested in machine_facts_test.cpp).
bool machineHasASensor() {
  std::error_code ec;
  for (const char* folder : {"/sys/class/thermal", "/sys/class/hwmon"}) {
    for (std::filesystem::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
      for (const char* file : {"temp", "temp1_input"}) {
        if (std::filesystem::exists(it->path() / file)) return true;
      }
    }
  }
  return false;
}

/// The screenshot's pixels: the header's colour at (5, 5), amber badge pixels in the top 60
/// rows, and pixels of the cube's saturated colours (the thumbnail; the page has none).
struct ShotFigures {
  bool header = false;
  std::size_t amber = 0;
  std::size_t cube = 0;
};
ShotFigures shotFigures(const Image& image) {
  const auto near = [&](std::uint32_t x, std::uint32_t y, int r0, int g0, int b0) {
    return std::abs(image.at(x, y, 0) - r0) < 12 && std::abs(image.at(x, y, 1) - g0) < 12 &&
           std::abs(image.at(x, y, 2) - b0) < 12;
  };
  ShotFigures f;
  f.header = near(5, 5, 0x20, 0x24, 0x2c);
  for (std::uint32_t y = 0; y < image.height; ++y) {
    for (std::uint32_t x = 0; x < image.width; ++x) {
      if (y < 60 && near(x, y, 0xc2, 0x7c, 0x0e)) ++f.amber;
      const int red = image.at(x, y, 0);
      const int green = image.at(x, y, 1);
      const int blue = image.at(x, y, 2);
      if ((red > 150 && green < 60 && blue < 60) || (green > 150 && red < 60 && blue < 60) ||
          (red > 150 && blue > 150 && green < 60) || (green > 150 && blue > 150 && red < 60)) {
        ++f.cube;
      }
    }
  }
  return f;
}

// Makes sure the status page shows what a signage technician looks for, filled from /health by
// its script in a real browser: version and build, host name and addresses, uptimes, disk,
// memory, CPU temperature (or "no sensor"), the last errors, the frame-lock figures, the devices
// with a restart button each, the log's tail and its download; and that it reads at desktop and
// phone widths (screenshots kept under build/docs-images/ for the README). Expected values come
// from elsewhere: `basalt --version`, git, /proc/sys/kernel/hostname, the machine's own
// addresses, /sys. Example failures: a field left at its placeholder because /health lacks it;
// a restart button missing for a device; a layout that a phone cuts off.
TEST(StatusPage, ShowsWhatATechnicianLooksFor) {
  std::string why;
  if (!test::headlessEglWorks(why)) GTEST_SKIP() << "no headless EGL here: " << why;
  if (::access("/usr/bin/chromium", X_OK) != 0) {
    GTEST_SKIP() << "chromium is not installed (apt-get install chromium; it is in scripts/packages-test.txt)";
  }
  std::string manifest = showManifest(true);
  manifest.replace(manifest.find("Status test"), 11, "Lobby wall");
  manifest.replace(manifest.find("160x120"), 7, "480x270");
  const auto dir = test::writeShow("status-page", manifest);
  std::ofstream(dir / "token") << kToken << "\n";
  auto show = test::RunningShow::start({(dir / "show.toml").string(), "--realtime", "--no-resume"}, {}, why);
  ASSERT_TRUE(show) << why;
  ::usleep(500000);
  const std::string url = "http://127.0.0.1:" + std::to_string(show->port()) + "/";
  const auto dom = chromium(url, {"--dump-dom"});
  ASSERT_EQ(dom.exitCode, 0) << dom.output;
  const std::string& d = dom.output;
  EXPECT_EQ(element(d, "h1", "show"), "Lobby wall") << d;
  EXPECT_NE(d.find("<span id=\"state\" class=\"degraded\">degraded</span>"), std::string::npos) << d;

  // Version and build: as `basalt --version` and git say.
  const auto version = test::run({(test::binaryDir() / "basalt").string(), "--version"});
  ASSERT_TRUE(version.output.starts_with("basalt ")) << version.output;
  const std::string number = version.output.substr(7, version.output.find('\n') - 7);
  EXPECT_EQ(element(d, "span", "version"), "Basalt " + number) << d;
  const std::string build = element(d, "dd", "build");
  EXPECT_TRUE(build.starts_with(number + ", revision ")) << build;
  // The revision is a commit git knows in this checkout, and HEAD is it or descends from it (the
  // build may predate commits made since; the build writes the revision, not the test run).
  const auto git = test::run({"/usr/bin/git", "-C", test::sourceDir().string(), "rev-parse", "--short=12", "HEAD"});
  if (git.exitCode == 0) {
    const auto at = build.find(", revision ");
    ASSERT_NE(at, std::string::npos) << build;
    const std::string revision = build.substr(at + 11, 12);
    EXPECT_EQ(revision.find_first_not_of("0123456789abcdef"), std::string::npos) << build;
    const auto ancestor =
        test::run({"/usr/bin/git", "-C", test::sourceDir().string(), "merge-base", "--is-ancestor", revision, "HEAD"});
    EXPECT_EQ(ancestor.exitCode, 0) << build << " is not HEAD (" << git.output << ") nor before it";
  }
  // The machine.
  EXPECT_EQ(element(d, "dd", "hostname"), firstLineOf("/proc/sys/kernel/hostname")) << d;
  const std::string addresses = element(d, "dd", "addresses");
  EXPECT_FALSE(addresses.empty() || addresses == "–") << d;
  EXPECT_EQ(addresses.find("127.0.0.1"), std::string::npos) << addresses;
  EXPECT_TRUE(
      std::regex_match(element(d, "dd", "uptimes"), std::regex(R"(Basalt [0-9]+ s · machine [0-9.]+ (s|min|h|days))")))
      << element(d, "dd", "uptimes");
  const std::string folder = std::filesystem::canonical(dir).string();
  EXPECT_TRUE(std::regex_match(element(d, "dd", "disk"),
                               std::regex(R"(show: [0-9.]+ [kMGT]?B free of [0-9.]+ [kMGT]?B \()" + folder + R"(\))")))
      << element(d, "dd", "disk") << " for " << folder;
  EXPECT_TRUE(
      std::regex_match(element(d, "dd", "memory"),
                       std::regex(R"([0-9.]+ [kMGT]?B available of [0-9.]+ [kMGT]?B · Basalt uses [0-9.]+ [kMGT]?B)")))
      << element(d, "dd", "memory");
  const std::string temperature = element(d, "dd", "temperature");
  if (machineHasASensor()) {
    EXPECT_NE(temperature.find(" °C ("), std::string::npos) << temperature;
  } else {
    EXPECT_EQ(temperature, "no sensor");
  }
  // The last errors (the knob is not plugged in), the frame lock (none here).
  const std::string errors = element(d, "table", "errors");
  EXPECT_NE(errors.find("<td class=\"warning nowrap\">warning</td>"), std::string::npos) << errors;
  EXPECT_NE(errors.find("kiosk: device 'knob' (hid): no hid 077d:0410 is plugged in"), std::string::npos) << errors;
  EXPECT_NE(element(d, "dl", "lock").find("not frame-locked"), std::string::npos) << d;
  // Devices, each with a restart button that the token enables; streams.
  for (const auto& [name, state] : {std::pair{"dials", "live"}, {"knob", "absent"}, {"cam", "live"}}) {
    EXPECT_NE(d.find(fmt::format("<span class=\"name\">{}</span><span class=\"{}\">{}</span>", name, state, state)),
              std::string::npos)
        << name << "\n"
        << d;
    EXPECT_TRUE(std::regex_search(
        d, std::regex(fmt::format(R"(<button data-device="{}" title="close and open {} again">Restart</button>)", name,
                                  name))))
        << name << "\n"
        << d;
  }
  EXPECT_NE(d.find("<td class=\"nowrap\">live</td><td class=\"playing nowrap\">playing</td>"), std::string::npos) << d;
  EXPECT_NE(d.find("open, playing: 'first' (1/2)"), std::string::npos) << d;
  EXPECT_NE(d.find("<p class=\"notice\" id=\"controls-off\" hidden=\"\">"), std::string::npos) << "controls are on";
  // The log's tail, newest last, and its download.
  const std::string tail = element(d, "div", "log");
  EXPECT_NE(tail.find("info kiosk: first frame on headless 480x270"), std::string::npos) << tail;
  EXPECT_NE(tail.find("warning kiosk: device 'knob' (hid): no hid 077d:0410 is plugged in"), std::string::npos) << tail;
  EXPECT_NE(d.find("<a id=\"log-download\" href=\"/log.txt\" download=\"basalt.log\">"), std::string::npos) << d;
  const auto log = show->get("/log.txt");
  EXPECT_EQ(log.status, 200);
  EXPECT_EQ(log.headers.at("Content-Type"), "text/plain; charset=utf-8");
  EXPECT_NE(log.body.find(" info kiosk: first frame on headless 480x270"), std::string::npos) << log.body;
  EXPECT_NE(log.body.find(" warning kiosk: device 'knob' (hid): no hid 077d:0410 is plugged in"), std::string::npos)
      << log.body;

  // What a desktop's and a phone's screens show: the header, the amber "degraded" badge, and the
  // live thumbnail with the cube's colours in it. Kept for the README.
  const auto shots = test::binaryDir() / "docs-images";
  std::filesystem::create_directories(shots);
  for (const auto& [name, width, height] :
       {std::tuple{"status-desktop.png", 1280, 1000}, {"status-phone.png", 412, 915}}) {
    const auto shot = shots / name;
    const auto r = chromium(url, {"--screenshot=" + shot.string()}, width, height);
    ASSERT_EQ(r.exitCode, 0) << r.output;
    auto image = media::readImage(shot);
    ASSERT_TRUE(image) << image.error().describe() << "\n" << r.output;
    EXPECT_EQ(image->width, static_cast<std::uint32_t>(width));
    EXPECT_EQ(image->height, static_cast<std::uint32_t>(height));
    const ShotFigures f = shotFigures(*image);
    EXPECT_TRUE(f.header) << name << ": the header's colour";
    EXPECT_GT(f.amber, 100u) << name << ": the degraded badge";
    EXPECT_GT(f.cube, 2000u) << name << ": the thumbnail of the frame on screen";
  }
}

// Makes sure a show without a token says on its page that the controls are off, and its
// buttons cannot be pressed. Example failure: buttons that answer 403 to a puzzled technician.
TEST(StatusPage, SaysWhenControlsAreOff) {
  std::string why;
  if (!test::headlessEglWorks(why)) GTEST_SKIP() << "no headless EGL here: " << why;
  if (::access("/usr/bin/chromium", X_OK) != 0) GTEST_SKIP() << "chromium is not installed";
  const auto dir = test::writeShow("status-page-no-token", showManifest(false));
  auto show = test::RunningShow::start({(dir / "show.toml").string(), "--realtime", "--no-resume"}, {}, why);
  ASSERT_TRUE(show) << why;
  const auto dom = chromium("http://127.0.0.1:" + std::to_string(show->port()) + "/", {"--dump-dom"});
  ASSERT_EQ(dom.exitCode, 0) << dom.output;
  EXPECT_NE(dom.output.find("<p class=\"notice\" id=\"controls-off\">Controls are off: this show has no token."),
            std::string::npos)
      << dom.output;
  EXPECT_NE(dom.output.find("<button data-device=\"dials\" disabled=\"\" title=\"controls are off: this show has no "
                            "token\">Restart</button>"),
            std::string::npos)
      << dom.output;
  EXPECT_NE(dom.output.find("<button data-control=\"next\" disabled=\"\">Next</button>"), std::string::npos)
      << dom.output;
}

// Makes sure a show with `[status] snapshot = false` serves no picture and its page shows none:
// the thumbnail is hidden and a note says why. Example failure: a broken-image icon, or the
// camera's visitors on the page after all.
TEST(StatusServerSnapshotOff, ThePageHidesTheThumbnail) {
  std::string why;
  if (!test::headlessEglWorks(why)) GTEST_SKIP() << "no headless EGL here: " << why;
  if (::access("/usr/bin/chromium", X_OK) != 0) GTEST_SKIP() << "chromium is not installed";
  std::string manifest = showManifest(true) + "snapshot = false\n";
  const auto dir = test::writeShow("status-snapshot-off", manifest);
  std::ofstream(dir / "token") << kToken << "\n";
  auto show = test::RunningShow::start({(dir / "show.toml").string(), "--realtime", "--no-resume"}, {}, why);
  ASSERT_TRUE(show) << why;
  const auto refused = show->get("/snapshot.png");
  EXPECT_EQ(refused.status, 403);
  EXPECT_NE(refused.body.find("snapshot is off"), std::string::npos) << refused.body;
  const auto dom = chromium("http://127.0.0.1:" + std::to_string(show->port()) + "/", {"--dump-dom"});
  ASSERT_EQ(dom.exitCode, 0) << dom.output;
  EXPECT_NE(dom.output.find("<img id=\"thumb\" alt=\"the frame on screen now\" hidden=\"\">"), std::string::npos)
      << dom.output;
  EXPECT_NE(dom.output.find("<p id=\"snapshot-off\">The snapshot is off"), std::string::npos) << dom.output;
}

}  // namespace
}  // namespace basalt
