#include "runtime/show/mesh.h"

#include <algorithm>

namespace basalt::runtime {

void Bounds::add(const Vec3& p) {
  if (empty) {
    min = max = p;
    empty = false;
    return;
  }
  min = {std::min(min.x, p.x), std::min(min.y, p.y), std::min(min.z, p.z)};
  max = {std::max(max.x, p.x), std::max(max.y, p.y), std::max(max.z, p.z)};
}

std::uint64_t Mesh::nextId() {
  static std::atomic<std::uint64_t> counter{1};
  return counter.fetch_add(1, std::memory_order_relaxed);
}

Mesh::Mesh() : id_(nextId()) {}

Mesh::Mesh(const Mesh& other)
    : positions(other.positions),
      normals(other.normals),
      texcoords(other.texcoords),
      colors(other.colors),
      triangles(other.triangles),
      edges(other.edges),
      lines(other.lines),
      points(other.points),
      facetSizes(other.facetSizes),
      parts(other.parts),
      materials(other.materials),
      id_(nextId()) {}

Mesh& Mesh::operator=(const Mesh& other) {
  if (this != &other) {
    Mesh copy(other);
    *this = std::move(copy);
  }
  return *this;
}

Bounds Mesh::bounds() const {
  Bounds b;
  for (const Vec3& p : positions) b.add(p);
  return b;
}

}  // namespace basalt::runtime
