#pragma once

/// \file
/// \brief Geometry as loaders produce it and the renderer uploads it: indexed vertices with
/// optional normals, texture coordinates and colours, grouped into named parts.

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "runtime/math.h"
#include "runtime/show/attributes.h"

namespace basalt::runtime {

/// \brief A material from an MTL file (or a loader's default), by name.
struct Material {
  std::string name;
  Color3 ambient{0.2f, 0.2f, 0.2f};
  Color3 diffuse{0.8f, 0.8f, 0.8f};
  Color3 specular{0, 0, 0};
  Color3 emissive{0, 0, 0};
  float shininess = 0;
  float opacity = 1;
  std::string diffuseMap;  ///< texture file, resolved against the model's folder
  // Other maps an MTL file names (`map_bump`/`bump`, `refl`, `map_d`), resolved the same way.
  // Recorded so that they survive a save; the renderer draws only the diffuse map today.
  std::string bumpMap;
  std::string reflectionMap;
  std::string alphaMap;
  friend bool operator==(const Material&, const Material&) = default;
};

/// \brief A named group of primitives (OBJ `g`/`o`, a cube face): what LAVA attributes address.
///
/// Ranges index into Mesh::triangles, Mesh::edges, Mesh::lines and Mesh::points (counts of
/// indices, not of primitives).
struct MeshPart {
  std::string name;
  std::uint32_t firstTriangleIndex = 0;
  std::uint32_t triangleIndexCount = 0;
  std::uint32_t firstEdgeIndex = 0;
  std::uint32_t edgeIndexCount = 0;
  std::uint32_t firstLineIndex = 0;
  std::uint32_t lineIndexCount = 0;
  std::uint32_t firstPointIndex = 0;
  std::uint32_t pointIndexCount = 0;
  std::int32_t material = -1;    ///< index into Mesh::materials, -1 for none
  std::uint32_t facetCount = 0;  ///< polygons before triangulation (LAVA's "Facets")
  std::uint32_t firstFacet = 0;  ///< index of the part's first polygon in Mesh::facetSizes
  friend bool operator==(const MeshPart&, const MeshPart&) = default;
};

struct Bounds {
  Vec3 min{0, 0, 0};
  Vec3 max{0, 0, 0};
  bool empty = true;
  void add(const Vec3& p);
  [[nodiscard]] Vec3 center() const { return (min + max) * 0.5f; }
  [[nodiscard]] Vec3 size() const { return max - min; }
  /// \brief Radius of the sphere around center() that holds the box.
  [[nodiscard]] float radius() const { return length(size()) * 0.5f; }
};

/// \brief Indexed geometry. All per-vertex arrays are either empty or as long as `positions`.
///
/// Meshes are immutable once shared with the Show (`std::shared_ptr<const Mesh>`), so instances
/// share one copy in memory and on the GPU; the renderer keys its GPU buffers by `id()`.
class Mesh {
 public:
  Mesh();
  Mesh(const Mesh& other);
  Mesh& operator=(const Mesh& other);
  Mesh(Mesh&&) noexcept = default;
  Mesh& operator=(Mesh&&) noexcept = default;

  std::vector<Vec3> positions;
  std::vector<Vec3> normals;
  std::vector<Vec2> texcoords;
  std::vector<Vec4> colors;
  std::vector<std::uint32_t> triangles;  ///< 3 indices per triangle, grouped by part
  /// 2 indices per segment: the outlines of the polygons before triangulation (what wireframe
  /// and edges draw), grouped by part
  std::vector<std::uint32_t> edges;
  std::vector<std::uint32_t> lines;   ///< 2 indices per segment, grouped by part
  std::vector<std::uint32_t> points;  ///< 1 index per point, grouped by part
  /// The polygons before triangulation, in part order: polygon k has facetSizes[k] corners,
  /// owns the next facetSizes[k] segments of `edges` (its outline, corner i to corner i+1, so
  /// the corners are the first index of each segment) and the next facetSizes[k] - 2 triangles.
  /// Empty when the mesh's producer did not record polygons (each triangle is then a facet).
  std::vector<std::uint32_t> facetSizes;
  std::vector<MeshPart> parts;
  std::vector<Material> materials;

  /// \brief A process-unique identity, new for every mesh and every copy.
  [[nodiscard]] std::uint64_t id() const { return id_; }
  [[nodiscard]] Bounds bounds() const;
  [[nodiscard]] std::size_t triangleCount() const { return triangles.size() / 3; }

 private:
  static std::uint64_t nextId();
  std::uint64_t id_;
};

}  // namespace basalt::runtime
