// OBJ loading: Basalt's loader against tinyobjloader (Debian's libtinyobjloader) on the same
// file in the same run. The file is generated here: a subdivided torus with v/vt/vn and quad
// faces, about 50 MB (BASALT_OBJ_BENCH_MB changes that; ctest runs a small one). Target:
// Basalt's MB/s at least tinyobjloader's, while it also de-duplicates vertices, triangulates
// (concave-safe), records polygon outlines and builds render-ready parts. Peak heap per million
// triangles is measured for both by counting every allocation during one load.
// Baseline figure: reading the file's bytes alone.

#include <benchmark/benchmark.h>

#include <malloc.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <new>
#include <numbers>
#include <string>

#include <fmt/format.h>
#include <tiny_obj_loader.h>

#include "bench_main.h"
#include "runtime/formats/model.h"

// ---- Heap accounting: every allocation of the process, current and peak bytes ----------------

namespace {
std::atomic<std::size_t> gCurrent{0};
std::atomic<std::size_t> gPeak{0};

void* allocate(std::size_t size) {
  void* p = std::malloc(size == 0 ? 1 : size);
  if (!p) throw std::bad_alloc();
  const std::size_t now = gCurrent.fetch_add(malloc_usable_size(p), std::memory_order_relaxed) + malloc_usable_size(p);
  std::size_t peak = gPeak.load(std::memory_order_relaxed);
  while (now > peak && !gPeak.compare_exchange_weak(peak, now, std::memory_order_relaxed)) {
  }
  return p;
}

void release(void* p) {
  if (!p) return;
  gCurrent.fetch_sub(malloc_usable_size(p), std::memory_order_relaxed);
  std::free(p);
}
}  // namespace

void* operator new(std::size_t size) { return allocate(size); }
void* operator new[](std::size_t size) { return allocate(size); }
void operator delete(void* p) noexcept { release(p); }
void operator delete[](void* p) noexcept { release(p); }
void operator delete(void* p, std::size_t) noexcept { release(p); }
void operator delete[](void* p, std::size_t) noexcept { release(p); }

namespace {

std::size_t benchMegabytes() {
  if (const char* env = std::getenv("BASALT_OBJ_BENCH_MB"); env && *env) {
    const long v = std::strtol(env, nullptr, 10);
    if (v >= 1 && v <= 2000) return static_cast<std::size_t>(v);
  }
  return 50;
}

/// Writes a torus of n x n quads with positions, texture coordinates and normals.
std::filesystem::path makeObj(std::size_t megabytes) {
  // About 170 bytes per grid cell: a v, vt and vn line per vertex and an f line per quad.
  const auto n = static_cast<std::size_t>(std::sqrt(static_cast<double>(megabytes) * 1e6 / 170.0));
  const std::filesystem::path dir = std::filesystem::path(BASALT_BINARY_DIR) / "bench-data";
  std::filesystem::create_directories(dir);
  std::filesystem::path path = dir / fmt::format("torus_{}.obj", n);
  if (std::filesystem::exists(path)) return path;
  std::FILE* f = std::fopen((path.string() + ".tmp").c_str(), "wb");
  if (!f) return {};
  std::string buffer;
  const double tau = 2 * std::numbers::pi;
  const auto flush = [&] {
    std::fwrite(buffer.data(), 1, buffer.size(), f);
    buffer.clear();
  };
  buffer += "# Basalt benchmark: a subdivided torus\no torus\n";
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < n; ++j) {
      const double u = tau * static_cast<double>(i) / static_cast<double>(n);
      const double v = tau * static_cast<double>(j) / static_cast<double>(n);
      const double r = 1.0 + 0.35 * std::cos(v);
      fmt::format_to(std::back_inserter(buffer), "v {:.6f} {:.6f} {:.6f}\n", r * std::cos(u), 0.35 * std::sin(v),
                     r * std::sin(u));
      fmt::format_to(std::back_inserter(buffer), "vt {:.6f} {:.6f}\n", static_cast<double>(i) / static_cast<double>(n),
                     static_cast<double>(j) / static_cast<double>(n));
      fmt::format_to(std::back_inserter(buffer), "vn {:.6f} {:.6f} {:.6f}\n", std::cos(v) * std::cos(u), std::sin(v),
                     std::cos(v) * std::sin(u));
      if (buffer.size() > (1u << 20)) flush();
    }
  }
  buffer += "g surface\ns 1\n";
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < n; ++j) {
      const std::size_t a = i * n + j + 1, b = ((i + 1) % n) * n + j + 1, c = ((i + 1) % n) * n + (j + 1) % n + 1,
                        d = i * n + (j + 1) % n + 1;
      fmt::format_to(std::back_inserter(buffer), "f {0}/{0}/{0} {1}/{1}/{1} {2}/{2}/{2} {3}/{3}/{3}\n", a, d, c, b);
      if (buffer.size() > (1u << 20)) flush();
    }
  }
  flush();
  std::fclose(f);
  std::filesystem::rename(path.string() + ".tmp", path);
  return path;
}

const std::filesystem::path& objPath() {
  static const std::filesystem::path path = makeObj(benchMegabytes());
  return path;
}

double fileMegabytes() { return static_cast<double>(std::filesystem::file_size(objPath())) / 1e6; }

basalt::formats::LoadOptions options() {
  basalt::formats::LoadOptions o;
  o.logWarnings = false;
  return o;
}

std::size_t basaltTriangles = 0, tinyTriangles = 0;

void readBytesOnly(benchmark::State& state) {
  for (auto _ : state) {
    auto bytes = basalt::formats::readFileBytes(objPath(), std::uint64_t{1} << 32);
    if (!bytes) {
      state.SkipWithError("cannot read the benchmark file");
      return;
    }
    benchmark::DoNotOptimize(bytes->data());
  }
}

void basaltLoader(benchmark::State& state) {
  for (auto _ : state) {
    auto model = basalt::formats::loadModel(objPath(), options());
    if (!model) {
      state.SkipWithError(model.error().describe().c_str());
      return;
    }
    basaltTriangles = basalt::formats::countModel(*model).triangles;
    benchmark::DoNotOptimize(model->objects.data());
  }
}

void tinyobjLoader(benchmark::State& state) {
  for (auto _ : state) {
    tinyobj::ObjReader reader;
    tinyobj::ObjReaderConfig config;
    config.vertex_color = false;  // its fastest configuration: the file has no colours
    if (!reader.ParseFromFile(objPath().string(), config)) {
      state.SkipWithError(reader.Error().c_str());
      return;
    }
    std::size_t triangles = 0;
    for (const auto& shape : reader.GetShapes()) triangles += shape.mesh.num_face_vertices.size();
    tinyTriangles = triangles;
    benchmark::DoNotOptimize(reader.GetAttrib().vertices.data());
  }
}

BENCHMARK(readBytesOnly)->Unit(benchmark::kMillisecond)->Iterations(1)->Repetitions(5);
BENCHMARK(basaltLoader)->Unit(benchmark::kMillisecond)->Iterations(1)->Repetitions(5);
BENCHMARK(tinyobjLoader)->Unit(benchmark::kMillisecond)->Iterations(1)->Repetitions(5);

/// Peak heap during one load, above what was in use before it.
template <typename Load>
std::size_t peakDuring(Load&& load) {
  gPeak.store(gCurrent.load());
  const std::size_t before = gCurrent.load();
  load();
  return gPeak.load() - before;
}

}  // namespace

int main(int argc, char** argv) {
  if (objPath().empty()) {
    std::printf("obj load: cannot write the benchmark file under %s\n", BASALT_BINARY_DIR);
    return 1;
  }
  return basalt::bench::runBenchmarks(argc, argv, [](const basalt::bench::Medians& m) {
    const auto bytes = m.find("readBytesOnly");
    const auto ours = m.find("basaltLoader");
    const auto tiny = m.find("tinyobjLoader");
    if (bytes == m.end() || ours == m.end() || tiny == m.end()) {
      std::printf("obj load: no figures (a benchmark failed)\n");
      return;
    }
    const double mb = fileMegabytes();
    const double oursRate = mb / ours->second, tinyRate = mb / tiny->second;
    const std::size_t oursPeak = peakDuring([] {
      auto model = basalt::formats::loadModel(objPath(), options());
      benchmark::DoNotOptimize(model);
    });
    const std::size_t tinyPeak = peakDuring([] {
      tinyobj::ObjReader reader;
      tinyobj::ObjReaderConfig config;
      config.vertex_color = false;
      (void)reader.ParseFromFile(objPath().string(), config);
    });
    std::printf("obj load: %.1f MB file, %zu triangles (tinyobjloader: %zu)\n", mb, basaltTriangles, tinyTriangles);
    std::printf(
        "obj load: Basalt %.1f MB/s, tinyobjloader %.1f MB/s (same file, same run), reading the bytes alone "
        "%.1f MB/s; Basalt / tinyobjloader = %.2f; target >= 1.00: %s\n",
        oursRate, tinyRate, mb / bytes->second, oursRate / tinyRate, oursRate >= tinyRate ? "met" : "NOT MET");
    const double millions = static_cast<double>(basaltTriangles) / 1e6;
    std::printf(
        "obj load: peak heap per million triangles: Basalt %.1f MB, tinyobjloader %.1f MB (every allocation "
        "during one load: Basalt reads the file in 1 MiB chunks, tinyobjloader line by line)\n",
        static_cast<double>(oursPeak) / 1e6 / millions, static_cast<double>(tinyPeak) / 1e6 / millions);
  });
}
