#pragma once

/// \file
/// \brief What the content-format fuzz targets check beyond "no crash": the invariants a loaded
/// mesh must keep. A broken invariant traps, which libFuzzer and the replay test report.

#include <cmath>

#include "runtime/formats/model.h"

namespace basalt::fuzz {

/// \brief Traps unless `condition` holds: the fuzzers' assertion, active in every build type.
inline void require(bool condition) {
  if (!condition) __builtin_trap();
}

/// \brief Every index in range, every per-vertex array full or empty, polygons accounted for,
/// every position finite.
inline void checkModel(const formats::LoadedModel& model) {
  for (const formats::ModelObject& o : model.objects) {
    if (!o.mesh) continue;
    const runtime::Mesh& m = *o.mesh;
    const std::size_t count = m.positions.size();
    for (const auto* list : {&m.triangles, &m.edges, &m.lines, &m.points}) {
      for (std::uint32_t i : *list) require(i < count);
    }
    for (const Vec3& p : m.positions) require(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
    require(m.normals.empty() || m.normals.size() == count);
    require(m.texcoords.empty() || m.texcoords.size() == count);
    require(m.colors.empty() || m.colors.size() == count);
    std::size_t corners = 0, triangles = 0;
    for (std::uint32_t s : m.facetSizes) {
      require(s >= 3);
      corners += s;
      triangles += s - 2;
    }
    require(corners * 2 == m.edges.size());
    require(triangles * 3 == m.triangles.size());
    for (const runtime::MeshPart& p : m.parts) {
      require(p.firstTriangleIndex + p.triangleIndexCount <= m.triangles.size());
      require(p.firstEdgeIndex + p.edgeIndexCount <= m.edges.size());
      require(p.material < static_cast<std::int32_t>(m.materials.size()));
    }
  }
}

/// \brief Options for fuzzing: quiet, and a folder that does not exist, so that nothing on the
/// fuzzing machine changes what a file means.
inline formats::LoadOptions fuzzOptions() {
  formats::LoadOptions options;
  options.logWarnings = false;
  return options;
}

inline constexpr const char* kNoFolder = "/nonexistent-basalt-fuzz-folder";

}  // namespace basalt::fuzz
