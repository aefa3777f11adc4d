// The status and control server of a real `basalt run`, over real HTTP: what /health, /metrics,
// /snapshot.png and / serve; controls with no token, a wrong token and the right one; malformed,
// oversized and too frequent requests; and the status page as a phone's browser shows it
// (headless Chromium), with its screenshot checked.
// Example failures: /health without the device that is down; a Prometheus line the scraper
// rejects; a control that runs without a token; a malformed request that crashes or hangs the
// server; a page that stays empty because its script failed.

#include <gtest/gtest.h>

#include <signal.h>
#include <unistd.h>

#include <fstream>
#include <regex>
#include <sstream>

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

TEST_F(StatusServer, HealthReportsTheShowItsFramesAndItsDevices) {
  ::usleep(400000);  // a few frames, and the synthetic dial's first turn
  const auto h = show_->get("/health");
  ASSERT_EQ(h.status, 200) << h.body;
  EXPECT_EQ(h.headers.at("Content-Type"), "application/json");
  EXPECT_NE(h.body.find("\"name\": \"Status test\""), std::string::npos) << h.body;
  EXPECT_NE(h.body.find("\"state\": \"degraded\""), std::string::npos) << "the knob is absent: " << h.body;
  EXPECT_NE(h.body.find("\"item\": \"first\""), std::string::npos) << h.body;
  EXPECT_NE(h.body.find("\"mode\": \"active\""), std::string::npos) << h.body;
  EXPECT_NE(h.body.find("\"name\": \"dials\", \"kind\": \"dial_box\", \"backend\": \"synthetic\", \"state\": \"live\""),
            std::string::npos)
      << h.body;
  EXPECT_NE(h.body.find("\"name\": \"knob\", \"kind\": \"dial_box\", \"backend\": \"hid\", \"state\": \"absent\""),
            std::string::npos)
      << h.body;
  EXPECT_NE(h.body.find("no hid 077d:0410 is plugged in"), std::string::npos) << "the reason: " << h.body;
  EXPECT_NE(h.body.find("\"frame_time_ms\": {\"p50\": "), std::string::npos) << h.body;
  EXPECT_EQ(h.body.find("\"frames\": {\n    \"total\": 0,"), std::string::npos) << "frames were drawn: " << h.body;
  EXPECT_NE(h.body.find("\"frames\": {\n    \"total\": "), std::string::npos) << h.body;
  EXPECT_NE(h.body.find("\"last_errors\": ["), std::string::npos) << h.body;
  EXPECT_NE(h.body.find("\"uptime_seconds\": "), std::string::npos) << h.body;
  // Each device says since when it is in its state (ISO 8601), and frames have a rate.
  EXPECT_TRUE(std::regex_search(
      h.body,
      std::regex(R"re("name": "dials", [^}]*"state": "live", "since": "[0-9]{4}-[0-9]{2}-[0-9]{2}T[0-9:.]+)re")))
      << h.body;
  EXPECT_TRUE(std::regex_search(
      h.body,
      std::regex(R"re("name": "knob", [^}]*"state": "absent", "since": "[0-9]{4}-[0-9]{2}-[0-9]{2}T[0-9:.]+)re")))
      << h.body;
  std::smatch rate;
  ASSERT_TRUE(std::regex_search(h.body, rate, std::regex(R"re("per_second": ([0-9.]+))re"))) << h.body;
  EXPECT_GT(std::stod(rate[1]), 0.0) << h.body;
  // The camera's stream plays, and the camera's row says so (its state is its stream's).
  EXPECT_NE(h.body.find("\"streams\": [\n    {\"name\": \"live\", \"kind\": \"camera\", \"state\": \"playing\""),
            std::string::npos)
      << h.body;
  EXPECT_NE(h.body.find("{\"name\": \"cam\", \"kind\": \"camera\", \"backend\": \"synthetic\", \"state\": \"live\""),
            std::string::npos)
      << h.body;
  EXPECT_NE(h.body.find("shown by texture 'camera': "), std::string::npos) << h.body;
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
  EXPECT_EQ(
      test::metric(m.body, "basalt_device_up{device=\"dials\",kind=\"dial_box\",backend=\"synthetic\",state=\"live\"}"),
      1.0)
      << m.body;
  EXPECT_EQ(
      test::metric(m.body, "basalt_device_up{device=\"knob\",kind=\"dial_box\",backend=\"hid\",state=\"absent\"}"), 0.0)
      << m.body;
  EXPECT_EQ(test::metric(m.body, "basalt_kiosk_mode{mode=\"active\"}"), 1.0);
  EXPECT_EQ(test::metric(m.body, "basalt_up"), 0.5) << "degraded while the knob is absent";
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
  EXPECT_NE(h.body.find("\"reloads\": {\"total\": 1, \"failed\": 0"), std::string::npos) << h.body;
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

// ---- The page in a browser -----------------------------------------------------------------

/// Runs headless Chromium on `url` with `extra` arguments; returns its output.
test::ProcessResult chromium(const std::string& url, const std::vector<std::string>& extra) {
  const auto profile = test::scratchDir("status-chromium-profile");
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
                                "--window-size=412,915",
                                "--virtual-time-budget=4000"};
  argv.insert(argv.end(), extra.begin(), extra.end());
  argv.push_back(url);
  return test::run(argv, {}, std::chrono::seconds(90));
}

TEST_F(StatusServer, PageRendersInABrowser) {
  if (::access("/usr/bin/chromium", X_OK) != 0) {
    GTEST_SKIP() << "chromium is not installed (apt-get install chromium; it is in scripts/packages-test.txt)";
  }
  ::usleep(300000);
  const std::string url = "http://127.0.0.1:" + std::to_string(show_->port()) + "/";
  // The page's script filled it from /health.
  const auto dom = chromium(url, {"--dump-dom"});
  ASSERT_EQ(dom.exitCode, 0) << dom.output;
  EXPECT_NE(dom.output.find("<h1 id=\"show\">Status test</h1>"), std::string::npos) << dom.output;
  EXPECT_NE(dom.output.find("<span id=\"state\" class=\"degraded\">degraded</span>"), std::string::npos) << dom.output;
  EXPECT_NE(dom.output.find("<td>dials</td><td class=\"live\">live</td>"), std::string::npos) << dom.output;
  EXPECT_NE(dom.output.find("<td>knob</td><td class=\"absent\">absent</td>"), std::string::npos) << dom.output;
  EXPECT_NE(dom.output.find("open, playing: 'first' (1/2)"), std::string::npos) << dom.output;
  EXPECT_NE(dom.output.find("<td>cam</td><td class=\"live\">live</td>"), std::string::npos) << dom.output;
  EXPECT_NE(dom.output.find("<td>live</td><td class=\"playing\">playing</td>"), std::string::npos) << dom.output;
  // The log tail, newest last.
  const auto log = dom.output.find("<div id=\"log\">");
  ASSERT_NE(log, std::string::npos) << dom.output;
  const auto logEnd = dom.output.find("</div>", log);
  const std::string tail = dom.output.substr(log, logEnd - log);
  EXPECT_NE(tail.find("info kiosk: first frame on headless 160x120"), std::string::npos) << tail;
  EXPECT_NE(tail.find("warning kiosk: device 'knob' (hid): no hid 077d:0410 is plugged in"), std::string::npos) << tail;

  // And what a phone's screen shows: the header, the amber "degraded" badge, and the live
  // thumbnail with the cube's colours in it.
  const auto shot = test::scratchDir("status-chromium") / "page.png";
  const auto r = chromium(url, {"--screenshot=" + shot.string()});
  ASSERT_EQ(r.exitCode, 0) << r.output;
  auto image = media::readImage(shot);
  ASSERT_TRUE(image) << image.error().describe() << "\n" << r.output;
  EXPECT_EQ(image->width, 412u);
  EXPECT_EQ(image->height, 915u);
  const auto near = [&](std::uint32_t x, std::uint32_t y, int r0, int g0, int b0) {
    return std::abs(image->at(x, y, 0) - r0) < 12 && std::abs(image->at(x, y, 1) - g0) < 12 &&
           std::abs(image->at(x, y, 2) - b0) < 12;
  };
  EXPECT_TRUE(near(5, 5, 0x20, 0x24, 0x2c)) << "the header's colour";
  std::size_t amber = 0;
  std::size_t cube = 0;
  for (std::uint32_t y = 0; y < image->height; ++y) {
    for (std::uint32_t x = 0; x < image->width; ++x) {
      if (y < 60 && near(x, y, 0xc2, 0x7c, 0x0e)) ++amber;
      const int red = image->at(x, y, 0);
      const int green = image->at(x, y, 1);
      const int blue = image->at(x, y, 2);
      // The cube's faces are saturated primaries and secondaries; the page has none.
      if ((red > 150 && green < 60 && blue < 60) || (green > 150 && red < 60 && blue < 60) ||
          (red > 150 && blue > 150 && green < 60) || (green > 150 && blue > 150 && red < 60)) {
        ++cube;
      }
    }
  }
  EXPECT_GT(amber, 100u) << "the degraded badge";
  EXPECT_GT(cube, 200u) << "the thumbnail of the frame on screen";
}

}  // namespace
}  // namespace basalt
