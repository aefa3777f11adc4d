// Video to the screen: CPU seconds per displayed frame of the same 1080p H.264 clip (I420,
// generated here), as fast as each path goes, all in one run:
//   (a) decodeOnlyFloor     gst-launch: decode to fakesink (the floor: nothing is shown)
//   (b) glimagesinkPeer     gst-launch: decode to glimagesink under Xvfb with Mesa (GStreamer's
//                           own GL path, what a user would pick); Xvfb's CPU is counted too
//   (c) naiveRgbaUpload     Basalt's player with videoconvert to RGBA on the CPU, uploaded and
//                           drawn by Basalt's renderer (the path a user might write)
//   (d) basaltPlayer        Basalt: decoder planes uploaded, converted in the shader, shown as a
//                           full-size picture headless, with the pass the renderer picks (on
//                           llvmpipe the packed one: eight pixels a fragment, the picture copied)
//   (d') basaltPlayerTwoPass the same, the stream not picture-only (what a part samples)
//   (d'') basaltPlayerPerPixel the per-pixel pass a GPU takes (picture-only: one pass from the
//                           planes to the screen), for comparison
// Targets: (d) well under (b), and under (c). Then the number of simultaneous 1080p30 and
// 720p30 streams Basalt shows in real time without dropping a frame.
// BASALT_BENCH_QUICK=1 (set when ctest runs it) uses fewer frames and shorter trials.

#include <benchmark/benchmark.h>

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "bench_main.h"
#include "media/movie_player.h"
#include "render/output.h"
#include "render/stream_texture.h"
#include "runtime/clock.h"

extern char** environ;

namespace {

bool quick() {
  const char* q = std::getenv("BASALT_BENCH_QUICK");
  return q && *q == '1';
}
int clipFrames() { return quick() ? 30 : 240; }

std::filesystem::path benchDir() {
  auto p = std::filesystem::path(BASALT_BINARY_DIR) / "bench-scratch";
  std::filesystem::create_directories(p);
  return p;
}

double cpuSecondsSelf() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec) * 1e-6;
}

/// Runs a command; returns the CPU seconds it used (all its threads), or -1.
double runForCpu(const std::vector<std::string>& args, const std::map<std::string, std::string>& extraEnv = {}) {
  std::vector<std::string> envStrings;
  for (char** e = environ; *e; ++e) envStrings.emplace_back(*e);
  for (const auto& [k, v] : extraEnv) {
    std::string entry = k;
    entry += '=';
    entry += v;
    envStrings.push_back(std::move(entry));
  }
  std::vector<char*> envp;
  envp.reserve(envStrings.size() + 1);
  for (auto& s : envStrings) envp.push_back(s.data());
  envp.push_back(nullptr);
  std::vector<char*> argv;
  argv.reserve(args.size() + 1);
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  pid_t pid = 0;
  const int rc = posix_spawnp(&pid, argv[0], &actions, nullptr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) return -1;
  int status = 0;
  rusage u{};
  wait4(pid, &status, 0, &u);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return -1;
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec) * 1e-6;
}

/// The 1080p (or 720p) H.264 clip, I420, made once per run with GStreamer's own tools.
std::filesystem::path clip(int width, int height) {
  auto path = benchDir() / ("clip-" + std::to_string(height) + "p-" + std::to_string(clipFrames()) + ".mp4");
  if (std::filesystem::exists(path)) return path;
  const auto partial = path.string() + ".partial.mp4";
  const double cpu = runForCpu({"gst-launch-1.0",
                                "-q",
                                "videotestsrc",
                                "num-buffers=" + std::to_string(clipFrames()),
                                "pattern=zone-plate",
                                "kx2=20",
                                "ky2=20",
                                "kt=1",
                                "!",
                                "video/x-raw,format=I420,width=" + std::to_string(width) +
                                    ",height=" + std::to_string(height) + ",framerate=30/1",
                                "!",
                                "x264enc",
                                "speed-preset=veryfast",
                                "bitrate=" + std::to_string(width * height / 300),
                                "key-int-max=30",
                                "!",
                                "h264parse",
                                "!",
                                "mp4mux",
                                "!",
                                "filesink",
                                "location=" + partial});
  if (cpu < 0) return {};
  std::filesystem::rename(partial, path);
  return path;
}

double processCpuSeconds(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string field;
  double ticks = 0;
  for (int i = 1; i <= 15 && stat >> field; ++i) {
    if (i == 14 || i == 15) ticks += std::stod(field);
  }
  return ticks / static_cast<double>(sysconf(_SC_CLK_TCK));
}

// (a) and (b): GStreamer's own tools; a one-frame run is subtracted (process and plugin start).
void gstPath(benchmark::State& state, const std::string& sink, bool withX) {
  const auto file = clip(1920, 1080);
  if (file.empty()) {
    state.SkipWithError("cannot make the clip (gst-launch-1.0, x264enc missing?)");
    return;
  }
  pid_t xvfb = -1;
  std::map<std::string, std::string> env;
  if (withX) {
    std::vector<std::string> args = {"Xvfb", ":97", "-screen", "0", "1920x1080x24", "-nolisten", "tcp"};
    std::vector<char*> argv;
    argv.reserve(args.size() + 1);
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
    if (posix_spawnp(&xvfb, "Xvfb", &actions, nullptr, argv.data(), environ) != 0) xvfb = -1;
    posix_spawn_file_actions_destroy(&actions);
    if (xvfb < 0) {
      state.SkipWithError("Xvfb is not installed (apt-get install xvfb)");
      return;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(700));
    env["DISPLAY"] = ":97";
    env["LIBGL_ALWAYS_SOFTWARE"] = "1";
  }
  auto pipeline = [&](int frames) {
    return std::vector<std::string>{"gst-launch-1.0",
                                    "-q",
                                    "filesrc",
                                    "location=" + file.string(),
                                    "!",
                                    "qtdemux",
                                    "!",
                                    "h264parse",
                                    "!",
                                    "avdec_h264",
                                    "!",
                                    "identity",
                                    "eos-after=" + std::to_string(frames),
                                    "!",
                                    sink,
                                    "sync=false"};
  };
  for (auto _ : state) {
    const double one = runForCpu(pipeline(1), env);
    const double xBefore = withX ? processCpuSeconds(xvfb) : 0;
    const double all = runForCpu(pipeline(clipFrames()), env);
    const double xAfter = withX ? processCpuSeconds(xvfb) : 0;
    if (one < 0 || all < 0) {
      state.SkipWithError(("the " + sink + " pipeline failed").c_str());
      break;
    }
    state.SetIterationTime((all - one + (xAfter - xBefore)) / (clipFrames() - 1));
  }
  if (xvfb > 0) {
    kill(xvfb, SIGTERM);
    waitpid(xvfb, nullptr, 0);
  }
}

void decodeOnlyFloor(benchmark::State& state) { gstPath(state, "fakesink", false); }
void glimagesinkPeer(benchmark::State& state) { gstPath(state, "glimagesink", true); }

// (c) and (d): Basalt's player, stream texture and a full-screen textured quad, headless.
void basaltPath(benchmark::State& state, basalt::PixelFormat cpuConvertTo, bool pictureOnly = true,
                bool perPixel = false) {
  using namespace basalt;
  const auto file = clip(1920, 1080);
  if (file.empty()) {
    state.SkipWithError("cannot make the clip");
    return;
  }
  auto output = render::createHeadlessOutput({1920, 1080});
  if (!output) {
    state.SkipWithError(output.error().describe().c_str());
    return;
  }
  auto stream = render::StreamTexture::create("movie");
  auto overlay = render::PictureOverlay::create();
  if (!stream || !overlay) {
    state.SkipWithError("cannot set up the stream texture");
    return;
  }
  // Shown as a picture only (no part samples it): planar frames are drawn from their planes in
  // one pass; RGBA frames (c) go straight into the texture and are drawn from it. (d') keeps the
  // texture path parts use: a conversion pass into the RGBA texture, then the picture from it.
  (*stream)->setPictureOnly(pictureOnly);
  if (perPixel) (*stream)->setConversionPass(render::ConversionPass::kPerPixel);
  for (auto _ : state) {
    media::MoviePlayerOptions options;
    options.cpuConvertTo = cpuConvertTo;
    auto player = media::MoviePlayer::create(options);
    if (!player || !(*player)->load(file) || !(*player)->waitUntilLoaded(std::chrono::seconds(30))) {
      state.SkipWithError("the movie did not load");
      break;
    }
    (*player)->play();
    // The first frame (decoder start-up) is not counted, as with (a) and (b).
    Nanos t{0};
    const Nanos step = fromSeconds(1.0 / 30);
    (*player)->waitForFrameDue(t, std::chrono::seconds(10));
    if (!(*stream)->update((*player)->frameAt(t))) {
      state.SkipWithError("the first frame could not be shown");
      break;
    }
    const double start = cpuSecondsSelf();
    int shown = 0;
    while (shown < clipFrames() - 1) {
      t += step;
      (*player)->waitForFrameDue(t, std::chrono::seconds(10));
      const FrameRef f = (*player)->frameAt(t);
      if (!f) break;
      if (!(*stream)->update(f) || !(*output)->beginFrame()) break;
      (*stream)->drawPicture(**overlay, {0, 0, 1920, 1080}, (*output)->size());
      if (!(*output)->present()) break;
      glFinish();
      ++shown;
    }
    const double cpu = cpuSecondsSelf() - start;
    if (shown == 0) {
      state.SkipWithError("no frames shown");
      break;
    }
    state.SetIterationTime(cpu / shown);
  }
}

void naiveRgbaUpload(benchmark::State& state) { basaltPath(state, basalt::PixelFormat::kRgba8); }
void basaltPlayer(benchmark::State& state) { basaltPath(state, basalt::PixelFormat::kUnknown); }
void basaltPlayerTwoPass(benchmark::State& state) { basaltPath(state, basalt::PixelFormat::kUnknown, false); }
void basaltPlayerPerPixel(benchmark::State& state) { basaltPath(state, basalt::PixelFormat::kUnknown, true, true); }

BENCHMARK(decodeOnlyFloor)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(1)->Repetitions(3);
BENCHMARK(glimagesinkPeer)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(1)->Repetitions(3);
BENCHMARK(naiveRgbaUpload)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(1)->Repetitions(3);
BENCHMARK(basaltPlayer)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(1)->Repetitions(3);
BENCHMARK(basaltPlayerTwoPass)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(1)->Repetitions(3);
BENCHMARK(basaltPlayerPerPixel)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(1)->Repetitions(3);

/// Says why a stream count could not be measured; returns -1.
std::int64_t failed(const std::string& why) {
  std::printf("  (cannot measure: %s)\n", why.c_str());
  return -1;
}

/// Plays `count` streams of `file` at 30 fps on the system clock for `seconds`, each through a
/// stream texture drawn as a quad, each frame showing what is due at the time it starts; returns
/// the frames dropped (shown frame numbers that skip or repeat after the first half second).
std::int64_t droppedWithStreams(const std::filesystem::path& file, int count, double seconds) {
  using namespace basalt;
  auto output = render::createHeadlessOutput({1280, 720});
  if (!output) return failed(output.error().describe());
  auto overlay = render::PictureOverlay::create();
  if (!overlay) return failed(overlay.error().describe());
  std::vector<std::unique_ptr<media::MoviePlayer>> players;
  std::vector<std::unique_ptr<render::StreamTexture>> streams;
  for (int i = 0; i < count; ++i) {
    media::MoviePlayerOptions o;
    o.queueFrames = 8;
    auto p = media::MoviePlayer::create(o);
    auto s = render::StreamTexture::create("s" + std::to_string(i));
    if (!p || !s) return failed("cannot make a player or a stream texture");
    if (!(*p)->load(file)) return failed("cannot load " + file.string());
    if (auto info = (*p)->waitUntilLoaded(std::chrono::seconds(30)); !info) return failed(info.error().describe());
    (*p)->setRepeat(true);
    players.push_back(std::move(*p));
    streams.push_back(std::move(*s));
  }
  // Let every decoder fill its queue before the clock starts, as a show's preroll does.
  for (auto& p : players) p->waitForFrameDue(Nanos{0}, std::chrono::seconds(10));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  for (auto& p : players) p->play();
  const SystemClock clock;
  const Nanos start = clock.now();
  std::vector<std::int64_t> last(static_cast<std::size_t>(count), -1);
  std::int64_t dropped = 0;
  const auto frames = static_cast<int>(seconds * 30);
  for (int n = 0; n < frames; ++n) {
    const Nanos due = frameTime(n, 30);
    while (clock.now() - start < due) std::this_thread::sleep_for(std::chrono::microseconds(500));
    // The frame shows what is due when it starts, as a show's frame loop does: a loop that falls
    // behind real time gets later movie frames, and skips some.
    const Nanos showTime = clock.now() - start;
    // Streams convert into their own textures first (update() leaves framebuffer 0 bound, which
    // a surfaceless output does not have); then the output's frame draws them.
    for (int i = 0; i < count; ++i) {
      const auto idx = static_cast<std::size_t>(i);
      if (auto r = streams[idx]->update(players[idx]->frameAt(showTime)); !r) return failed(r.error().describe());
    }
    if (auto r = (*output)->beginFrame(); !r) return failed(r.error().describe());
    for (int i = 0; i < count; ++i) {
      const auto idx = static_cast<std::size_t>(i);
      const float w = 1280.0f / static_cast<float>(count);
      (*overlay)->draw(streams[idx]->view(), {w * static_cast<float>(i), 0, w, 720}, (*output)->size());
      const std::int64_t now = players[idx]->currentFrame();
      if (n >= 15 && last[idx] >= 0) {
        const std::int64_t expected = (last[idx] + 1) % clipFrames();
        if (now != expected) ++dropped;
      }
      last[idx] = now;
    }
    if (auto r = (*output)->present(); !r) return failed(r.error().describe());
    glFinish();
  }
  return dropped;
}

int maxStreams(int width, int height, double seconds, int limit) {
  const auto file = clip(width, height);
  if (file.empty()) return -1;
  int best = 0;
  for (int n = 1; n <= limit; ++n) {
    const std::int64_t dropped = droppedWithStreams(file, n, seconds);
    std::printf("  %dp30 x %d: %lld frames dropped\n", height, n, static_cast<long long>(dropped));
    if (dropped != 0) break;
    best = n;
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  // Under ctest (quick): a smoke run of the floor and Basalt's path only; `make bench` runs all.
  std::vector<char*> args(argv, argv + argc);
  std::string quickFilter = "--benchmark_filter=decodeOnlyFloor|basaltPlayer";
  if (quick() && argc == 1) args.push_back(quickFilter.data());
  int count = static_cast<int>(args.size());
  return basalt::bench::runBenchmarks(count, args.data(), [](const basalt::bench::Medians& m) {
    auto at = [&](const char* name) {
      const auto it = m.find(name);
      return it == m.end() ? -1.0 : it->second * 1e3;
    };
    const double a = at("decodeOnlyFloor"), b = at("glimagesinkPeer"), c = at("naiveRgbaUpload"),
                 d = at("basaltPlayer"), d2 = at("basaltPlayerTwoPass"), d3 = at("basaltPlayerPerPixel");
    std::printf("video: CPU ms per displayed 1080p H.264 frame (median of 3, %d-frame clip):\n", clipFrames());
    std::printf("  (a) decode only to fakesink (floor)      %7.2f\n", a);
    std::printf("  (b) GStreamer glimagesink, Xvfb + Mesa    %7.2f\n", b);
    std::printf("  (c) videoconvert to RGBA + Basalt upload  %7.2f\n", c);
    std::printf("  (d) Basalt player, shader conversion      %7.2f  (the renderer's pick: packed on llvmpipe)\n", d);
    std::printf("  (d') the same, not picture-only           %7.2f  (the RGBA texture a part samples)\n", d2);
    std::printf("  (d'') the per-pixel pass a GPU takes      %7.2f  (one pass from the planes)\n", d3);
    if (b > 0 && c > 0 && d > 0) {
      std::printf("video: (d)/(b) = %.2f (target well under 1: %s); (d)/(c) = %.2f (target under 1: %s)\n", d / b,
                  d < 0.5 * b ? "met" : "NOT MET", d / c, d < c ? "met" : "NOT MET");
    }
    const double seconds = quick() ? 1.0 : 4.0;
    const int limit = quick() ? 1 : 8;
    std::printf("video: simultaneous streams shown at 30 fps in real time without a dropped frame (%.1f s each):\n",
                seconds);
    const int s1080 = quick() ? -1 : maxStreams(1920, 1080, seconds, limit);
    const int s720 = maxStreams(1280, 720, seconds, limit);
    std::printf("video: %d x 1080p30, %d x 720p30 (tried up to %d)\n", s1080, s720, limit);
  });
}
