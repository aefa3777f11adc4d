// Renderer speed and memory (issue 3, "Speed"), headless at 1280 x 720:
//  (a) a 100 000-triangle sphere under 32 lights of all four types, drawn by Basalt's Renderer
//      from a Show, against the same mesh drawn by a minimal GLES3 program with the same lighting
//      equations in one draw call, set up once (the baseline, measured in the same run). Figure:
//      Basalt's frame time as a ratio of the minimal one; target within 1.25. Measured for
//      per-vertex (Gouraud) and per-facet illumination, each against its own minimal program.
//  (b) the default show, absolute.
// Each frame ends in glFinish(), so the time is the GPU's (llvmpipe's) work too. Before timing,
// the two programs' pictures are compared, so the baseline is known to draw the same thing.
//
// Allocations: operator new is counted in this binary. After a warm-up, the frame loop
// (kiosk::FrameLoop with a ManualClock, the default show) and the renderer on a show using every
// feature are run for a number of frames; the figure is allocations per frame (target 0). The GL
// driver's own mallocs (Mesa is C) are outside what is counted.

#include <benchmark/benchmark.h>

#include <GLES3/gl3.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "bench_main.h"
#include "counting_allocator.h"
#include "kiosk/loop/frame_loop.h"
#include "render/output.h"
#include "render/renderer.h"
#include "runtime/event_loop.h"
#include "runtime/show/show.h"

namespace {

using namespace basalt;

constexpr std::uint32_t kWidth = 1280;
constexpr std::uint32_t kHeight = 720;

struct Bench {
  std::unique_ptr<render::Output> output;
  std::unique_ptr<render::Renderer> renderer;
  std::string problem;
};

Bench& bench() {
  static Bench b = [] {
    Bench x;
    auto output = render::createHeadlessOutput({kWidth, kHeight});
    if (!output) {
      x.problem = output.error().describe();
      return x;
    }
    x.output = std::move(*output);
    auto renderer = render::Renderer::create();
    if (!renderer) {
      x.problem = renderer.error().describe();
      return x;
    }
    x.renderer = std::move(*renderer);
    return x;
  }();
  return b;
}

/// Reports a failed step (the figures that follow are then meaningless, and say so by being absent).
template <typename T>
void check(const Result<T>& r) {
  if (!r) std::fprintf(stderr, "renderer bench: %s\n", r.error().describe().c_str());
}

/// A UV sphere of 224 x 224 quads: 100 352 triangles, smooth normals.
std::shared_ptr<runtime::Mesh> bigSphere() {
  static std::shared_ptr<runtime::Mesh> mesh = [] {
    auto m = std::make_shared<runtime::Mesh>();
    const int rings = 224, segments = 224;
    for (int r = 0; r <= rings; ++r) {
      const float theta = std::numbers::pi_v<float> * static_cast<float>(r) / rings;
      for (int s = 0; s <= segments; ++s) {
        const float phi = 2 * std::numbers::pi_v<float> * static_cast<float>(s) / segments;
        const Vec3 n{std::sin(theta) * std::cos(phi), std::cos(theta), -std::sin(theta) * std::sin(phi)};
        m->positions.push_back(n);
        m->normals.push_back(n);
      }
    }
    for (std::uint32_t r = 0; r < rings; ++r) {
      for (std::uint32_t s = 0; s < segments; ++s) {
        const std::uint32_t a = r * (segments + 1) + s, b = a + segments + 1, c = b + 1, d = a + 1;
        for (std::uint32_t v : {a, b, c, a, c, d}) m->triangles.push_back(v);
      }
    }
    runtime::MeshPart part;
    part.name = "sphere";
    part.triangleIndexCount = static_cast<std::uint32_t>(m->triangles.size());
    part.facetCount = part.triangleIndexCount / 3;
    m->parts.push_back(part);
    return m;
  }();
  return mesh;
}

/// 32 lights on: one ambient, then directional, positional and spot in turn, in varied colours.
std::array<runtime::Light, runtime::kMaxLights> thirtyTwoLights() {
  std::array<runtime::Light, runtime::kMaxLights> lights{};
  for (std::size_t i = 0; i < lights.size(); ++i) {
    runtime::Light& l = lights[i];
    const float t = static_cast<float>(i) / 32.0f;
    l.on = true;
    l.color = {0.1f + 0.1f * std::sin(6.28f * t), 0.1f + 0.1f * std::cos(6.28f * t), 0.12f};
    const float a = 6.28f * t;
    l.direction = normalize(Vec3{std::cos(a), std::sin(a), -1.5f});
    l.position = {2.0f * std::cos(a), 2.0f * std::sin(a), 2.5f};
    l.attenuation1 = 0.8f;
    l.attenuation2 = 0.1f;
    l.angle = 0.6f;
    l.exponent = 4.0f;
    l.type = i == 0 ? runtime::LightType::kAmbient
                    : static_cast<runtime::LightType>(1 + (i - 1) % 3);  // directional, positional, spot
  }
  lights[0].color = {0.3f, 0.3f, 0.3f};
  return lights;
}

runtime::Show meshShow(runtime::Illumination illumination) {
  runtime::Show show;
  runtime::SceneNode node;
  node.name = "sphere";
  node.mesh = bigSphere();
  show.addNode(node);
  show.lights() = thirtyTwoLights();
  show.editGlobalStyle([&](runtime::PartStyle& s) {
    s.front.illumination = illumination;
    s.front.color = {0.9f, 0.7f, 0.5f};
  });
  show.rotateGlobal({20, 30, 0});
  return show;
}

// ---- The minimal GLES3 program: the same equations, nothing else ----

const char* kMinimalVertex = R"(#version 300 es
precision highp float;
precision highp int;
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aNormal;
uniform mat4 uModel;
uniform mat4 uViewProjection;
uniform mat3 uNormalMatrix;
uniform vec3 uEye;
uniform vec3 uOd;
uniform vec3 uOs;
uniform vec4 uK;  // ka, kd, ks, Se
uniform int uCount;
uniform vec4 uLc[32];
uniform vec4 uLp[32];
uniform vec4 uLd[32];
uniform vec2 uSpot[32];
#ifdef FACET
flat out vec4 vColor;
#else
out vec4 vColor;
#endif
void main() {
  vec4 world = uModel * vec4(aPosition, 1.0);
  gl_Position = uViewProjection * world;
#ifdef FACET
  if (gl_VertexID % 3 != 2) { vColor = vec4(0.0); return; }
#endif
  vec3 N = normalize(uNormalMatrix * aNormal);
  vec3 E = normalize(uEye - world.xyz);
  vec3 sum = vec3(0.0);
  for (int i = 0; i < uCount; ++i) {
    int type = int(uLc[i].w);
    if (type == 0) { sum += uK.x * uOd * uLc[i].rgb; continue; }
    vec3 L; float A = 1.0;
    if (type == 1) {
      L = -uLd[i].xyz;
    } else {
      vec3 toLight = uLp[i].xyz - world.xyz;
      float d = length(toLight);
      L = toLight / d;
      A = 1.0 / (uLp[i].w + uLd[i].w * d);
      if (type == 3) {
        float c = dot(-L, uLd[i].xyz);
        A = c < uSpot[i].x ? 0.0 : A * pow(c, uSpot[i].y);
      }
    }
    float NL = dot(N, L);
    if (NL <= 0.0) continue;
    vec3 R = 2.0 * NL * N - L;
    sum += A * (uK.y * uOd * uLc[i].rgb * NL + uK.z * uOs * uLc[i].rgb * pow(max(dot(E, R), 0.0), uK.w));
  }
  vColor = vec4(clamp(sum, 0.0, 1.0), 1.0);
}
)";

const char* kMinimalFragment = R"(#version 300 es
precision highp float;
#ifdef FACET
flat in vec4 vColor;
#else
in vec4 vColor;
#endif
out vec4 fragColor;
void main() { fragColor = vColor; }
)";

GLuint compile(GLenum type, const std::string& source) {
  const GLuint s = glCreateShader(type);
  const char* text = source.c_str();
  glShaderSource(s, 1, &text, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048];
    glGetShaderInfoLog(s, sizeof log, nullptr, log);
    std::fprintf(stderr, "minimal program: %s\n", log);
  }
  return s;
}

struct Minimal {
  GLuint program = 0, vao = 0, buffers[3] = {};
  GLsizei count = 0;
  bool facet = false;
};

/// Builds the minimal program and its buffers, and sets every uniform once.
Minimal makeMinimal(const runtime::Show& show, bool facet) {
  Minimal m;
  m.facet = facet;
  const std::string prefix = facet ? "#define FACET 1\n" : "";
  auto withDefine = [&](const char* src) {
    std::string s = src;
    const auto eol = s.find('\n');
    return s.substr(0, eol + 1) + prefix + s.substr(eol + 1);
  };
  m.program = glCreateProgram();
  const GLuint vs = compile(GL_VERTEX_SHADER, withDefine(kMinimalVertex));
  const GLuint fs = compile(GL_FRAGMENT_SHADER, withDefine(kMinimalFragment));
  glAttachShader(m.program, vs);
  glAttachShader(m.program, fs);
  glLinkProgram(m.program);
  glDeleteShader(vs);
  glDeleteShader(fs);

  const runtime::Mesh& mesh = *bigSphere();
  std::vector<Vec3> positions, normals;
  if (facet) {
    // De-indexed, each triangle's normal on its vertices: per-facet lighting at the last vertex.
    for (std::size_t t = 0; t + 2 < mesh.triangles.size(); t += 3) {
      const Vec3 a = mesh.positions[mesh.triangles[t]], b = mesh.positions[mesh.triangles[t + 1]],
                 c = mesh.positions[mesh.triangles[t + 2]];
      Vec3 n = cross(b - a, c - a);
      n = length(n) > 1e-12f ? normalize(n) : normalize(mesh.normals[mesh.triangles[t]]);
      for (const Vec3& p : {a, b, c}) {
        positions.push_back(p);
        normals.push_back(n);
      }
    }
  } else {
    positions = mesh.positions;
    normals = mesh.normals;
  }
  glGenVertexArrays(1, &m.vao);
  glBindVertexArray(m.vao);
  glGenBuffers(3, m.buffers);
  glBindBuffer(GL_ARRAY_BUFFER, m.buffers[0]);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(positions.size() * sizeof(Vec3)), positions.data(),
               GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
  glBindBuffer(GL_ARRAY_BUFFER, m.buffers[1]);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(normals.size() * sizeof(Vec3)), normals.data(), GL_STATIC_DRAW);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
  if (!facet) {
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, m.buffers[2]);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(mesh.triangles.size() * 4), mesh.triangles.data(),
                 GL_STATIC_DRAW);
  }
  m.count = static_cast<GLsizei>(mesh.triangles.size());
  glBindVertexArray(0);

  glUseProgram(m.program);
  auto at = [&](const char* n) { return glGetUniformLocation(m.program, n); };
  const runtime::ViewTransforms view = runtime::computeView(show, static_cast<float>(kWidth) / kHeight);
  const Mat4 vp = view.projection * view.view;
  const Mat4 n = view.model.inverted().transposed();
  const float normal3[9] = {n(0, 0), n(1, 0), n(2, 0), n(0, 1), n(1, 1), n(2, 1), n(0, 2), n(1, 2), n(2, 2)};
  glUniformMatrix4fv(at("uModel"), 1, GL_FALSE, view.model.data());
  glUniformMatrix4fv(at("uViewProjection"), 1, GL_FALSE, vp.data());
  glUniformMatrix3fv(at("uNormalMatrix"), 1, GL_FALSE, normal3);
  glUniform3f(at("uEye"), view.eye.x, view.eye.y, view.eye.z);
  const runtime::SurfaceAttributes& s = show.globalStyle().front;
  glUniform3f(at("uOd"), s.color.r, s.color.g, s.color.b);
  glUniform3f(at("uOs"), s.specularColor.r, s.specularColor.g, s.specularColor.b);
  glUniform4f(at("uK"), s.ambient, s.diffuse, s.specular, s.specularPower);
  float lc[32][4], lp[32][4], ld[32][4], spot[32][2];
  int count = 0;
  for (const runtime::Light& l : show.lights()) {
    if (!l.on) continue;
    const auto i = static_cast<std::size_t>(count++);
    const Vec3 d = normalize(l.direction);
    lc[i][0] = l.color.r, lc[i][1] = l.color.g, lc[i][2] = l.color.b, lc[i][3] = static_cast<float>(l.type);
    lp[i][0] = l.position.x, lp[i][1] = l.position.y, lp[i][2] = l.position.z, lp[i][3] = l.attenuation1;
    ld[i][0] = d.x, ld[i][1] = d.y, ld[i][2] = d.z, ld[i][3] = l.attenuation2;
    spot[i][0] = std::cos(l.angle), spot[i][1] = l.exponent;
  }
  glUniform1i(at("uCount"), count);
  glUniform4fv(at("uLc"), count, &lc[0][0]);
  glUniform4fv(at("uLp"), count, &lp[0][0]);
  glUniform4fv(at("uLd"), count, &ld[0][0]);
  glUniform2fv(at("uSpot"), count, &spot[0][0]);
  return m;
}

void drawMinimal(const Minimal& m) {
  glViewport(0, 0, kWidth, kHeight);
  glClearColor(0, 0, 0, 1);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glEnable(GL_DEPTH_TEST);
  glUseProgram(m.program);
  glBindVertexArray(m.vao);
  if (m.facet) {
    glDrawArrays(GL_TRIANGLES, 0, m.count);
  } else {
    glDrawElements(GL_TRIANGLES, m.count, GL_UNSIGNED_INT, nullptr);
  }
  glBindVertexArray(0);
}

void drawBasalt(const runtime::Show& show) { bench().renderer->drawShow(show, {0, 0, kWidth, kHeight}); }

/// Largest channel difference between Basalt's and the minimal program's picture.
int pictureDifference(const runtime::Show& show, const Minimal& m) {
  Image a, b;
  check(bench().output->beginFrame());
  drawBasalt(show);
  check(bench().output->readBack(a));
  check(bench().output->beginFrame());
  drawMinimal(m);
  check(bench().output->readBack(b));
  return compareImages(a, b, 2).maxChannelDelta;
}

std::map<std::string, int> gDifferences;

template <typename Draw>
void timeFrames(benchmark::State& state, Draw&& draw) {
  if (!bench().renderer) {
    state.SkipWithError(("no headless EGL: " + bench().problem).c_str());
    return;
  }
  check(bench().output->beginFrame());
  draw();
  glFinish();
  for (auto _ : state) {
    check(bench().output->beginFrame());
    draw();
    glFinish();
  }
}

void basaltPerVertex(benchmark::State& state) {
  const runtime::Show show = meshShow(runtime::Illumination::kPerVertex);
  timeFrames(state, [&] { drawBasalt(show); });
}
void minimalPerVertex(benchmark::State& state) {
  if (!bench().renderer) return state.SkipWithError("no headless EGL");
  const runtime::Show show = meshShow(runtime::Illumination::kPerVertex);
  const Minimal m = makeMinimal(show, false);
  gDifferences["per vertex"] = pictureDifference(show, m);
  timeFrames(state, [&] { drawMinimal(m); });
}
void basaltPerFacet(benchmark::State& state) {
  const runtime::Show show = meshShow(runtime::Illumination::kPerFacet);
  timeFrames(state, [&] { drawBasalt(show); });
}
void minimalPerFacet(benchmark::State& state) {
  if (!bench().renderer) return state.SkipWithError("no headless EGL");
  const runtime::Show show = meshShow(runtime::Illumination::kPerFacet);
  const Minimal m = makeMinimal(show, true);
  gDifferences["per facet"] = pictureDifference(show, m);
  timeFrames(state, [&] { drawMinimal(m); });
}
void defaultShow(benchmark::State& state) {
  const runtime::Show show = runtime::Show::makeDefault();
  timeFrames(state, [&] { drawBasalt(show); });
}

/// Registers the benchmarks. `quick` (what `make test` runs through ctest) times fewer frames
/// and leaves out the per-facet pair; `make bench` runs everything.
void registerBenchmarks(bool quick) {
  const int meshFrames = quick ? 2 : 5;
  const int repetitions = quick ? 2 : 3;
  auto add = [&](const char* name, void (*fn)(benchmark::State&), int frames) {
    benchmark::RegisterBenchmark(name, fn)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime()
        ->Iterations(frames)
        ->Repetitions(repetitions);
  };
  add("minimalPerVertex", minimalPerVertex, meshFrames);
  add("basaltPerVertex", basaltPerVertex, meshFrames);
  if (!quick) {
    add("minimalPerFacet", minimalPerFacet, meshFrames);
    add("basaltPerFacet", basaltPerFacet, meshFrames);
  }
  add("defaultShow", defaultShow, quick ? 10 : 30);
}

// ---- Allocations per frame ----

/// A show with every renderer feature on: floor and shadow, fog, depth cue, clipping, edges,
/// markers, wide patterned lines, transparency, a texture, stereo.
runtime::Show everythingShow() {
  runtime::Show show = runtime::Show::makeDefault();
  using runtime::AttrId;
  using runtime::PartStyle;
  show.environment().floor = runtime::FloorKind::kCoarseGrid;
  show.environment().shadow = true;
  show.fog().mode = runtime::FogMode::kExp;
  show.depthCue().mode = runtime::DepthCueMode::kScaled;
  show.modelClipping().numPlanes = 1;
  show.global().stereo = true;
  show.backgroundKind() = runtime::BackgroundKind::kEarthSky;
  show.earthSky().mode = runtime::EarthSkyClear::kSkyGround;
  show.editGlobalStyle([](PartStyle& s) {
    s.edges.show = runtime::EdgeMode::kOn;
    s.edges.width = 2;
    s.edges.style = runtime::LineStyle::kPatterned;
  });
  show.editPartStyle(1, AttrId::kRenderPrimType, [](PartStyle& s) { s.render.primType = runtime::PrimType::kMarkers; });
  show.editPartStyle(2, AttrId::kFrontTranspMethod,
                     [](PartStyle& s) { s.front.transparencyMethod = runtime::TransparencyMethod::kBlended; });
  show.editPartStyle(2, AttrId::kFrontTranspBlendEq, [](PartStyle& s) {
    s.front.transparencyBlend = runtime::TransparencyBlend::kArbitraryBackground;
  });
  show.editPartStyle(3, AttrId::kRenderRasterOp, [](PartStyle& s) { s.render.rasterOp = runtime::RasterOp::kXor; });
  show.setPartTexture(4, "bench texture");
  return show;
}

struct AllocationFigures {
  double frameLoop = -1;
  double everything = -1;
  int frames = 0;
};

AllocationFigures countAllocations(int kFrames) {
  AllocationFigures f;
  if (!bench().renderer) return f;
  f.frames = kFrames;
  Image texture = Image::make(16, 16, 3);
  check(bench().renderer->textures().setImage("bench texture", texture));

  // The renderer alone, every feature.
  runtime::Show show = everythingShow();
  for (int i = 0; i < 10; ++i) {
    check(bench().output->beginFrame());
    bench().renderer->drawShow(show, {0, 0, kWidth, kHeight});
    show.advanceFrame();
  }
  std::uint64_t before = bench::allocationCount();
  for (int i = 0; i < kFrames; ++i) {
    check(bench().output->beginFrame());
    bench().renderer->drawShow(show, {0, 0, kWidth, kHeight});
    show.performance().recordFrame(bench().renderer->takeFrameCounts(), Nanos{std::int64_t{i} * 16'666'667});
    show.advanceFrame();
  }
  glFinish();
  f.everything = static_cast<double>(bench::allocationCount() - before) / kFrames;

  // The frame loop as `basalt run` drives it, on the default show.
  ManualClock clock;
  auto loop = runtime::EventLoop::create(clock);
  if (!loop) return f;
  runtime::Show defaultShow = runtime::Show::makeDefault();
  {
    kiosk::FrameLoop warmUp({60, 10}, clock, &clock, **loop, defaultShow, *bench().output, *bench().renderer);
    check(warmUp.run());
  }
  kiosk::FrameLoop frameLoop({60, kFrames}, clock, &clock, **loop, defaultShow, *bench().output, *bench().renderer);
  before = bench::allocationCount();
  check(frameLoop.run());
  f.frameLoop = static_cast<double>(bench::allocationCount() - before) / kFrames;
  return f;
}

}  // namespace

int main(int argc, char** argv) {
  // `--quick` (ctest) is ours; the rest go to Google Benchmark.
  bool quick = false;
  int kept = 1;
  for (int i = 1; i < argc; ++i) {
    if (std::string_view(argv[i]) == "--quick") {
      quick = true;
    } else {
      argv[kept++] = argv[i];
    }
  }
  argc = kept;
  registerBenchmarks(quick);
  return basalt::bench::runBenchmarks(argc, argv, [quick](const basalt::bench::Medians& m) {
    auto ratio = [&](const char* name, const char* basalt, const char* minimal) {
      const auto b = m.find(basalt), mm = m.find(minimal);
      if (b == m.end() || mm == m.end()) {
        std::printf("renderer: %s: no figures (a benchmark failed)\n", name);
        return;
      }
      const double r = b->second / mm->second;
      std::printf(
          "renderer: 100k triangles, 32 lights, %s, 1280x720: Basalt %.2f ms, minimal GLES3 program %.2f ms "
          "(same picture within %d/255), ratio %.3f; target <= 1.25: %s\n",
          name, b->second * 1e3, mm->second * 1e3, gDifferences[name], r, r <= 1.25 ? "met" : "NOT MET");
    };
    ratio("per vertex", "basaltPerVertex", "minimalPerVertex");
    if (quick) {
      std::printf("renderer: per facet: not timed in the quick run (make bench times it)\n");
    } else {
      ratio("per facet", "basaltPerFacet", "minimalPerFacet");
    }
    if (const auto d = m.find("defaultShow"); d != m.end()) {
      std::printf("renderer: the default show at 1280x720: %.2f ms per frame\n", d->second * 1e3);
    }
    const AllocationFigures a = countAllocations(quick ? 60 : 240);
    if (a.frames == 0) {
      std::printf("renderer: allocations: not measured (no headless EGL)\n");
      return;
    }
    std::printf(
        "renderer: allocations per frame after warm-up (operator new, %d frames): frame loop on the default show "
        "%.2f, renderer on a show using every feature %.2f; target 0: %s\n",
        a.frames, a.frameLoop, a.everything, a.frameLoop == 0 && a.everything == 0 ? "met" : "NOT MET");
  });
}
