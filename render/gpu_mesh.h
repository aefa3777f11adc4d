#pragma once

/// \file
/// \brief A Mesh on the GPU (private to render/): the indexed stream every draw starts from, and
/// streams made the first time a draw needs them: the de-indexed facet stream (per-facet
/// illumination and facet colours), segment streams for wide, patterned, antialiased and
/// silhouette lines, and the per-triangle stream of vertex-level texture mapping.

#include <cstdint>
#include <memory>
#include <vector>

#include "render/gl.h"
#include "runtime/show/mesh.h"

namespace basalt::render {

/// \brief Per-part figures kept beside the buffers.
struct GpuPart {
  std::uint32_t firstMarkerIndex = 0;  ///< into the marker range of the index buffer
  std::uint32_t markerIndexCount = 0;  ///< distinct vertices of the part
  Vec3 centre;                         ///< of the part's vertices, object coordinates (sorting)
  float longestEdge = 0;               ///< longest triangle side, object coordinates (VLTM)
};

/// \brief Instanced data for one family of segments (a mesh's polygon edges or its lines).
struct SegmentStream {
  gl::VertexArray vao;
  gl::Buffer buffer;
  bool built = false;
};

class GpuMesh {
 public:
  /// \brief Uploads positions, normals (made from the faces when the mesh has none), colours,
  /// texture coordinates (LAVA's automatic binding when the mesh has none) and indices.
  static std::unique_ptr<GpuMesh> upload(const std::shared_ptr<const runtime::Mesh>& mesh);

  [[nodiscard]] bool alive() const { return !source_.expired(); }
  [[nodiscard]] const std::vector<GpuPart>& parts() const { return parts_; }
  [[nodiscard]] bool hasColors() const { return hasColors_; }
  [[nodiscard]] GLuint indexedVao() const { return vao_.id(); }
  /// \brief Byte offsets into the index buffer of each index family.
  [[nodiscard]] std::size_t edgeOffset() const { return edgeOffset_; }
  [[nodiscard]] std::size_t lineOffset() const { return lineOffset_; }
  [[nodiscard]] std::size_t pointOffset() const { return pointOffset_; }
  [[nodiscard]] std::size_t markerOffset() const { return markerOffset_; }

  /// \brief The facet stream's vertex array (3 vertices per triangle, in triangle order: draw
  /// `3 * firstTriangle` onwards), made on first use. Every triangle of a polygon carries the
  /// polygon's normal (Newell's), its first corner as the point to light (attribute 4) and that
  /// corner's colour, so that a polygon is lit once (XGL per-facet illumination).
  GLuint facetVao();
  /// \brief The segment stream of the polygon edges (`edges`) or the lines, made on first use.
  /// Bind it, then point it at the part's first segment with bindSegments().
  GLuint segmentVao(bool edges);
  void bindSegments(bool edges, std::uint32_t firstSegment);
  /// \brief The per-triangle VLTM stream; point it at the part's first triangle with bindVltm().
  GLuint vltmVao();
  void bindVltm(std::uint32_t firstTriangle);

 private:
  GpuMesh() = default;
  void buildSegments(bool edges);

  std::weak_ptr<const runtime::Mesh> source_;  // lazy streams are built while a node holds it
  gl::VertexArray vao_;
  gl::Buffer positions_, normals_, colors_, texcoords_, indices_;
  std::size_t edgeOffset_ = 0, lineOffset_ = 0, pointOffset_ = 0, markerOffset_ = 0;
  std::vector<GpuPart> parts_;
  bool hasColors_ = false;

  gl::VertexArray facetVao_;
  gl::Buffer facetBuffer_;
  bool facetBuilt_ = false;
  SegmentStream edgeSegments_, lineSegments_;
  gl::VertexArray vltmVao_;
  gl::Buffer vltmBuffer_;
  bool vltmBuilt_ = false;

  // Normals and texture coordinates made here for meshes without them (the lazy streams use
  // them too); empty when the mesh has its own.
  std::vector<Vec3> madeNormals_;
  std::vector<Vec2> madeTexcoords_;
};

}  // namespace basalt::render
