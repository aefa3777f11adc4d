#include "render/gpu_mesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <unordered_map>

#include "runtime/log.h"

namespace basalt::render {

BASALT_LOG_CATEGORY(RenderMesh, "render");

namespace {

template <typename T>
gl::Buffer uploadBuffer(GLenum target, const T* data, std::size_t count) {
  gl::Buffer buffer = gl::Buffer::create();
  glBindBuffer(target, buffer.id());
  glBufferData(target, static_cast<GLsizeiptr>(count * sizeof(T)), data, GL_STATIC_DRAW);
  return buffer;
}

const void* byteOffset(std::size_t bytes) { return reinterpret_cast<const void*>(bytes); }

std::array<std::uint8_t, 4> toBytes(const Vec4& c) {
  auto b = [](float v) { return static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); };
  return {b(c.x), b(c.y), b(c.z), b(c.w)};
}

/// Area-weighted vertex normals from the triangles: what a mesh without normals is lit with.
std::vector<Vec3> makeNormals(const runtime::Mesh& mesh) {
  std::vector<Vec3> normals(mesh.positions.size());
  for (std::size_t t = 0; t + 2 < mesh.triangles.size(); t += 3) {
    const std::uint32_t a = mesh.triangles[t], b = mesh.triangles[t + 1], c = mesh.triangles[t + 2];
    if (a >= normals.size() || b >= normals.size() || c >= normals.size()) continue;
    const Vec3 n = cross(mesh.positions[b] - mesh.positions[a], mesh.positions[c] - mesh.positions[a]);
    normals[a] += n;
    normals[b] += n;
    normals[c] += n;
  }
  for (Vec3& n : normals) n = length(n) > 0 ? normalize(n) : Vec3{0, 0, 1};
  return normals;
}

/// LAVA's automatic binding (§6.2.2): each vertex projected onto the plane its normal faces most,
/// the mesh's bounds mapped to 0..1 on that plane.
std::vector<Vec2> makeTexcoords(const runtime::Mesh& mesh, const std::vector<Vec3>& normals) {
  const runtime::Bounds b = mesh.bounds();
  const Vec3 size = b.size();
  auto unit = [](float v, float lo, float extent) { return extent > 0 ? (v - lo) / extent : 0.5f; };
  std::vector<Vec2> uv(mesh.positions.size());
  for (std::size_t i = 0; i < uv.size(); ++i) {
    const Vec3& p = mesh.positions[i];
    const Vec3 n = i < normals.size() ? normals[i] : Vec3{0, 0, 1};
    const float ax = std::fabs(n.x), ay = std::fabs(n.y), az = std::fabs(n.z);
    const float x = unit(p.x, b.min.x, size.x), y = unit(p.y, b.min.y, size.y), z = unit(p.z, b.min.z, size.z);
    if (ax >= ay && ax >= az) {
      uv[i] = {n.x > 0 ? 1 - z : z, y};
    } else if (ay >= az) {
      uv[i] = {x, n.y > 0 ? 1 - z : z};
    } else {
      uv[i] = {n.z > 0 ? x : 1 - x, y};
    }
  }
  return uv;
}

struct EdgeKey {
  std::array<float, 6> v;
  friend bool operator==(const EdgeKey&, const EdgeKey&) = default;
};
struct EdgeKeyHash {
  std::size_t operator()(const EdgeKey& k) const {
    std::size_t h = 1469598103934665603ULL;
    for (float f : k.v) {
      std::uint32_t bits = 0;
      std::memcpy(&bits, &f, sizeof bits);
      h = (h ^ bits) * 1099511628211ULL;
    }
    return h;
  }
};
EdgeKey edgeKey(const Vec3& a, const Vec3& b) {
  const bool swap = std::tie(a.x, a.y, a.z) > std::tie(b.x, b.y, b.z);
  const Vec3& lo = swap ? b : a;
  const Vec3& hi = swap ? a : b;
  return {{lo.x, lo.y, lo.z, hi.x, hi.y, hi.z}};
}

Vec3 facetNormal(const runtime::Mesh& mesh, const std::vector<Vec3>& normals, std::uint32_t a, std::uint32_t b,
                 std::uint32_t c) {
  const Vec3 n = cross(mesh.positions[b] - mesh.positions[a], mesh.positions[c] - mesh.positions[a]);
  const Vec3 vertexSum = normals[a] + normals[b] + normals[c];
  if (length(n) <= 1e-12f) return normalize(vertexSum);
  const Vec3 unitN = normalize(n);
  // Trust the vertex normals' side where the winding disagrees with them.
  return dot(unitN, vertexSum) < 0 ? -unitN : unitN;
}

// Segment instance layout (see line.vert): p0, p1, prev, next, c0, c1, facet n0, facet n1.
struct SegmentVertex {
  float p0[3];
  float p1[3];
  float prev[4];
  float next[4];
  std::uint8_t c0[4];
  std::uint8_t c1[4];
  float n0[4];
  float n1[4];
};
static_assert(sizeof(SegmentVertex) == 96);

// Facet stream layout (see surface.vert): position, facet normal, facet colour, texcoord, and
// the point the facet is lit at.
struct FacetVertex {
  float p[3];
  float n[3];
  std::uint8_t c[4];
  float t[2];
  float q[3];
};
static_assert(sizeof(FacetVertex) == 48);

// VLTM per-triangle layout (see vltm.vert).
struct VltmTriangle {
  float p[3][3];
  float n[3][3];
  float t[3][2];
  std::uint8_t c[3][4];
};
static_assert(sizeof(VltmTriangle) == 108);

}  // namespace

std::unique_ptr<GpuMesh> GpuMesh::upload(const std::shared_ptr<const runtime::Mesh>& meshPtr) {
  const runtime::Mesh& mesh = *meshPtr;
  std::unique_ptr<GpuMesh> gpu(new GpuMesh);
  gpu->source_ = meshPtr;
  const std::size_t n = mesh.positions.size();
  if (mesh.normals.size() != n) gpu->madeNormals_ = makeNormals(mesh);
  const std::vector<Vec3>& normals = mesh.normals.size() == n ? mesh.normals : gpu->madeNormals_;
  if (mesh.texcoords.size() != n) gpu->madeTexcoords_ = makeTexcoords(mesh, normals);
  const std::vector<Vec2>& texcoords = mesh.texcoords.size() == n ? mesh.texcoords : gpu->madeTexcoords_;

  gpu->vao_ = gl::VertexArray::create();
  glBindVertexArray(gpu->vao_.id());
  gpu->positions_ = uploadBuffer(GL_ARRAY_BUFFER, mesh.positions.data(), n);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(Vec3), nullptr);
  gpu->normals_ = uploadBuffer(GL_ARRAY_BUFFER, normals.data(), n);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(Vec3), nullptr);
  if (mesh.colors.size() == n && n > 0) {
    gpu->colors_ = uploadBuffer(GL_ARRAY_BUFFER, mesh.colors.data(), n);
    glEnableVertexAttribArray(2);
    glVertexAttribPointer(2, 4, GL_FLOAT, GL_FALSE, sizeof(Vec4), nullptr);
    gpu->hasColors_ = true;
  }
  gpu->texcoords_ = uploadBuffer(GL_ARRAY_BUFFER, texcoords.data(), n);
  glEnableVertexAttribArray(3);
  glVertexAttribPointer(3, 2, GL_FLOAT, GL_FALSE, sizeof(Vec2), nullptr);

  // One index buffer: triangles, edges, lines, points, then each part's distinct vertices (markers).
  std::vector<std::uint32_t> all;
  all.reserve(mesh.triangles.size() + mesh.edges.size() + mesh.lines.size() + mesh.points.size() + n);
  all.insert(all.end(), mesh.triangles.begin(), mesh.triangles.end());
  gpu->edgeOffset_ = all.size() * sizeof(std::uint32_t);
  all.insert(all.end(), mesh.edges.begin(), mesh.edges.end());
  gpu->lineOffset_ = all.size() * sizeof(std::uint32_t);
  all.insert(all.end(), mesh.lines.begin(), mesh.lines.end());
  gpu->pointOffset_ = all.size() * sizeof(std::uint32_t);
  all.insert(all.end(), mesh.points.begin(), mesh.points.end());
  gpu->markerOffset_ = all.size() * sizeof(std::uint32_t);
  const std::size_t markerBase = all.size();
  gpu->parts_.resize(mesh.parts.size());
  std::vector<std::uint32_t> distinct;
  for (std::size_t p = 0; p < mesh.parts.size(); ++p) {
    const runtime::MeshPart& mp = mesh.parts[p];
    distinct.clear();
    auto take = [&](const std::vector<std::uint32_t>& from, std::uint32_t first, std::uint32_t count) {
      const std::size_t end = std::min<std::size_t>(std::size_t{first} + count, from.size());
      for (std::size_t i = first; i < end; ++i) {
        if (from[i] < n) distinct.push_back(from[i]);
      }
    };
    take(mesh.triangles, mp.firstTriangleIndex, mp.triangleIndexCount);
    take(mesh.edges, mp.firstEdgeIndex, mp.edgeIndexCount);
    take(mesh.lines, mp.firstLineIndex, mp.lineIndexCount);
    take(mesh.points, mp.firstPointIndex, mp.pointIndexCount);
    std::sort(distinct.begin(), distinct.end());
    distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
    GpuPart& gp = gpu->parts_[p];
    gp.firstMarkerIndex = static_cast<std::uint32_t>(all.size() - markerBase);
    gp.markerIndexCount = static_cast<std::uint32_t>(distinct.size());
    Vec3 sum{};
    for (std::uint32_t v : distinct) sum += mesh.positions[v];
    gp.centre = distinct.empty() ? Vec3{} : sum / static_cast<float>(distinct.size());
    const std::size_t triEnd =
        std::min<std::size_t>(std::size_t{mp.firstTriangleIndex} + mp.triangleIndexCount, mesh.triangles.size());
    for (std::size_t t = mp.firstTriangleIndex; t + 2 < triEnd; t += 3) {
      const Vec3& a = mesh.positions[mesh.triangles[t]];
      const Vec3& b = mesh.positions[mesh.triangles[t + 1]];
      const Vec3& c = mesh.positions[mesh.triangles[t + 2]];
      gp.longestEdge = std::max({gp.longestEdge, length(b - a), length(c - b), length(a - c)});
    }
    all.insert(all.end(), distinct.begin(), distinct.end());
  }
  gpu->indices_ = uploadBuffer(GL_ELEMENT_ARRAY_BUFFER, all.data(), all.size());
  glBindVertexArray(0);
  log::debug(kLogRenderMesh, "uploaded mesh {} ({} vertices, {} triangles)", mesh.id(), n, mesh.triangleCount());
  return gpu;
}

GLuint GpuMesh::facetVao() {
  if (facetBuilt_) return facetVao_.id();
  facetBuilt_ = true;
  const auto mesh = source_.lock();
  if (!mesh) return 0;
  const std::vector<Vec3>& normals = madeNormals_.empty() ? mesh->normals : madeNormals_;
  const std::vector<Vec2>& uv = madeTexcoords_.empty() ? mesh->texcoords : madeTexcoords_;
  const std::size_t n = mesh->positions.size();
  const std::size_t triangleCount = mesh->triangles.size() / 3;
  std::vector<FacetVertex> data(triangleCount * 3);
  // XGL lights a facet once: every triangle of a polygon carries the polygon's first corner (the
  // point lit, OpenGL's provoking vertex of a polygon), its normal and that corner's colour.
  const auto emit = [&](std::size_t t, std::uint32_t lit, const Vec3& fn) {
    const auto colour = hasColors_ ? toBytes(mesh->colors[lit]) : std::array<std::uint8_t, 4>{255, 255, 255, 255};
    const Vec3& q = mesh->positions[lit];
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint32_t v = mesh->triangles[3 * t + k];
      const Vec3& p = mesh->positions[v];
      data[3 * t + k] = {{p.x, p.y, p.z},
                         {fn.x, fn.y, fn.z},
                         {colour[0], colour[1], colour[2], colour[3]},
                         {uv[v].x, uv[v].y},
                         {q.x, q.y, q.z}};
    }
  };
  const auto valid = [&](std::size_t t) {
    return mesh->triangles[3 * t] < n && mesh->triangles[3 * t + 1] < n && mesh->triangles[3 * t + 2] < n;
  };
  std::size_t t = 0;
  std::size_t edge = 0;
  for (const std::uint32_t corners : mesh->facetSizes) {
    const std::size_t owned = corners >= 3 ? corners - 2 : 0;
    if (t + owned > triangleCount || edge + 2 * std::size_t{corners} > mesh->edges.size()) break;
    // The polygon's normal (Newell's, over its corners), on the side of its vertex normals.
    Vec3 newell{};
    Vec3 vertexSum{};
    bool inside = true;
    for (std::size_t i = 0; i < corners; ++i) {
      const std::uint32_t a = mesh->edges[edge + 2 * i];
      const std::uint32_t b = mesh->edges[edge + 2 * i + 1];
      if (a >= n || b >= n) {
        inside = false;
        break;
      }
      const Vec3& pa = mesh->positions[a];
      const Vec3& pb = mesh->positions[b];
      newell += Vec3{(pa.y - pb.y) * (pa.z + pb.z), (pa.z - pb.z) * (pa.x + pb.x), (pa.x - pb.x) * (pa.y + pb.y)};
      vertexSum += normals[a];
    }
    const std::uint32_t first = corners > 0 ? mesh->edges[edge] : 0;
    for (std::size_t k = 0; k < owned; ++k, ++t) {
      if (!valid(t)) continue;
      const std::uint32_t a = mesh->triangles[3 * t], b = mesh->triangles[3 * t + 1], c = mesh->triangles[3 * t + 2];
      if (!inside || length(newell) <= 1e-12f) {
        emit(t, a, facetNormal(*mesh, normals, a, b, c));
        continue;
      }
      const Vec3 unit = normalize(newell);
      emit(t, first, dot(unit, vertexSum) < 0 ? -unit : unit);
    }
    edge += 2 * std::size_t{corners};
  }
  // Triangles no polygon owns are facets of their own, lit at their first vertex.
  for (; t < triangleCount; ++t) {
    if (!valid(t)) continue;
    const std::uint32_t a = mesh->triangles[3 * t], b = mesh->triangles[3 * t + 1], c = mesh->triangles[3 * t + 2];
    emit(t, a, facetNormal(*mesh, normals, a, b, c));
  }
  facetVao_ = gl::VertexArray::create();
  glBindVertexArray(facetVao_.id());
  facetBuffer_ = uploadBuffer(GL_ARRAY_BUFFER, data.data(), data.size());
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(FacetVertex), byteOffset(offsetof(FacetVertex, p)));
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(FacetVertex), byteOffset(offsetof(FacetVertex, n)));
  glEnableVertexAttribArray(2);
  glVertexAttribPointer(2, 4, GL_UNSIGNED_BYTE, GL_TRUE, sizeof(FacetVertex), byteOffset(offsetof(FacetVertex, c)));
  glEnableVertexAttribArray(3);
  glVertexAttribPointer(3, 2, GL_FLOAT, GL_FALSE, sizeof(FacetVertex), byteOffset(offsetof(FacetVertex, t)));
  glEnableVertexAttribArray(4);
  glVertexAttribPointer(4, 3, GL_FLOAT, GL_FALSE, sizeof(FacetVertex), byteOffset(offsetof(FacetVertex, q)));
  glBindVertexArray(0);
  return facetVao_.id();
}

void GpuMesh::buildSegments(bool edges) {
  SegmentStream& stream = edges ? edgeSegments_ : lineSegments_;
  stream.built = true;
  const auto mesh = source_.lock();
  if (!mesh) return;
  const std::vector<std::uint32_t>& indices = edges ? mesh->edges : mesh->lines;
  const std::size_t n = mesh->positions.size();
  const std::size_t segments = indices.size() / 2;
  std::vector<SegmentVertex> data(segments);

  // Facets on each side of every polygon edge, matched by position (faces often have their own
  // copies of shared corners).
  std::unordered_map<EdgeKey, std::array<Vec3, 2>, EdgeKeyHash> facets;
  std::unordered_map<EdgeKey, int, EdgeKeyHash> facetCount;
  if (edges) {
    const std::vector<Vec3>& normals = madeNormals_.empty() ? mesh->normals : madeNormals_;
    facets.reserve(mesh->triangles.size());
    for (std::size_t t = 0; t + 2 < mesh->triangles.size(); t += 3) {
      const std::uint32_t v[3] = {mesh->triangles[t], mesh->triangles[t + 1], mesh->triangles[t + 2]};
      if (v[0] >= n || v[1] >= n || v[2] >= n) continue;
      const Vec3 fn = facetNormal(*mesh, normals, v[0], v[1], v[2]);
      for (int k = 0; k < 3; ++k) {
        const EdgeKey key = edgeKey(mesh->positions[v[k]], mesh->positions[v[(k + 1) % 3]]);
        int& count = facetCount[key];
        if (count < 2) facets[key][static_cast<std::size_t>(count)] = fn;
        ++count;
      }
    }
  }

  // Joins: within a part, a vertex where exactly two segments meet joins them.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> ends;  // (vertex, segment * 2 + which end)
  auto partRanges = [&](const runtime::MeshPart& mp) {
    return edges ? std::pair{mp.firstEdgeIndex, mp.edgeIndexCount} : std::pair{mp.firstLineIndex, mp.lineIndexCount};
  };
  std::vector<std::int64_t> joinedTo(segments * 2, -1);  // segment end -> the other segment's far vertex
  for (const runtime::MeshPart& mp : mesh->parts) {
    const auto [first, count] = partRanges(mp);
    ends.clear();
    const std::size_t s0 = first / 2, s1 = std::min<std::size_t>((std::size_t{first} + count) / 2, segments);
    for (std::size_t s = s0; s < s1; ++s) {
      ends.emplace_back(indices[2 * s], static_cast<std::uint32_t>(2 * s));
      ends.emplace_back(indices[2 * s + 1], static_cast<std::uint32_t>(2 * s + 1));
    }
    std::sort(ends.begin(), ends.end());
    for (std::size_t i = 0; i < ends.size();) {
      std::size_t j = i;
      while (j < ends.size() && ends[j].first == ends[i].first) ++j;
      const std::uint32_t a = ends[i].second, b = ends[i + 1 < j ? i + 1 : i].second;
      if (j - i == 2 && a / 2 != b / 2) {  // exactly two segments meet here (not one from a vertex to itself)
        joinedTo[a] = indices[b ^ 1U];     // the far end of the other segment
        joinedTo[b] = indices[a ^ 1U];
      }
      i = j;
    }
  }

  for (std::size_t s = 0; s < segments; ++s) {
    SegmentVertex& sv = data[s];
    const std::uint32_t a = indices[2 * s], b = indices[2 * s + 1];
    if (a >= n || b >= n) {
      sv = {};
      continue;
    }
    const Vec3& pa = mesh->positions[a];
    const Vec3& pb = mesh->positions[b];
    sv = {};
    std::memcpy(sv.p0, &pa, sizeof sv.p0);
    std::memcpy(sv.p1, &pb, sizeof sv.p1);
    auto setJoin = [&](float(&out)[4], std::int64_t far) {
      if (far < 0 || static_cast<std::size_t>(far) >= n) return;
      const Vec3& p = mesh->positions[static_cast<std::size_t>(far)];
      out[0] = p.x, out[1] = p.y, out[2] = p.z, out[3] = 1;
    };
    setJoin(sv.prev, joinedTo[2 * s]);
    setJoin(sv.next, joinedTo[2 * s + 1]);
    const auto ca = hasColors_ ? toBytes(mesh->colors[a]) : std::array<std::uint8_t, 4>{255, 255, 255, 255};
    const auto cb = hasColors_ ? toBytes(mesh->colors[b]) : std::array<std::uint8_t, 4>{255, 255, 255, 255};
    std::memcpy(sv.c0, ca.data(), 4);
    std::memcpy(sv.c1, cb.data(), 4);
    if (edges) {
      const EdgeKey key = edgeKey(pa, pb);
      if (auto it = facetCount.find(key); it != facetCount.end()) {
        const auto& fn = facets[key];
        sv.n0[0] = fn[0].x, sv.n0[1] = fn[0].y, sv.n0[2] = fn[0].z, sv.n0[3] = 1;
        if (it->second >= 2) sv.n1[0] = fn[1].x, sv.n1[1] = fn[1].y, sv.n1[2] = fn[1].z, sv.n1[3] = 1;
      }
    }
  }
  stream.vao = gl::VertexArray::create();
  glBindVertexArray(stream.vao.id());
  stream.buffer = uploadBuffer(GL_ARRAY_BUFFER, data.data(), data.size());
  for (GLuint i = 0; i < 8; ++i) {
    glEnableVertexAttribArray(i);
    glVertexAttribDivisor(i, 1);
  }
  glBindVertexArray(0);
}

GLuint GpuMesh::segmentVao(bool edges) {
  SegmentStream& stream = edges ? edgeSegments_ : lineSegments_;
  if (!stream.built) buildSegments(edges);
  return stream.vao.id();
}

void GpuMesh::bindSegments(bool edges, std::uint32_t firstSegment) {
  // Instanced arrays start at the part's first segment (ES 3.0 has no base instance).
  SegmentStream& stream = edges ? edgeSegments_ : lineSegments_;
  glBindBuffer(GL_ARRAY_BUFFER, stream.buffer.id());
  const std::size_t base = std::size_t{firstSegment} * sizeof(SegmentVertex);
  const GLsizei stride = sizeof(SegmentVertex);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, stride, byteOffset(base + offsetof(SegmentVertex, p0)));
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, stride, byteOffset(base + offsetof(SegmentVertex, p1)));
  glVertexAttribPointer(2, 4, GL_FLOAT, GL_FALSE, stride, byteOffset(base + offsetof(SegmentVertex, prev)));
  glVertexAttribPointer(3, 4, GL_FLOAT, GL_FALSE, stride, byteOffset(base + offsetof(SegmentVertex, next)));
  glVertexAttribPointer(4, 4, GL_UNSIGNED_BYTE, GL_TRUE, stride, byteOffset(base + offsetof(SegmentVertex, c0)));
  glVertexAttribPointer(5, 4, GL_UNSIGNED_BYTE, GL_TRUE, stride, byteOffset(base + offsetof(SegmentVertex, c1)));
  glVertexAttribPointer(6, 4, GL_FLOAT, GL_FALSE, stride, byteOffset(base + offsetof(SegmentVertex, n0)));
  glVertexAttribPointer(7, 4, GL_FLOAT, GL_FALSE, stride, byteOffset(base + offsetof(SegmentVertex, n1)));
}

GLuint GpuMesh::vltmVao() {
  if (vltmBuilt_) return vltmVao_.id();
  vltmBuilt_ = true;
  const auto mesh = source_.lock();
  if (!mesh) return 0;
  const std::vector<Vec3>& normals = madeNormals_.empty() ? mesh->normals : madeNormals_;
  const std::vector<Vec2>& uv = madeTexcoords_.empty() ? mesh->texcoords : madeTexcoords_;
  const std::size_t n = mesh->positions.size();
  std::vector<VltmTriangle> data(mesh->triangles.size() / 3);
  for (std::size_t t = 0; t < data.size(); ++t) {
    VltmTriangle& tri = data[t];
    tri = {};
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint32_t v = mesh->triangles[t * 3 + k];
      if (v >= n) continue;
      std::memcpy(tri.p[k], &mesh->positions[v], sizeof tri.p[k]);
      std::memcpy(tri.n[k], &normals[v], sizeof tri.n[k]);
      std::memcpy(tri.t[k], &uv[v], sizeof tri.t[k]);
      const auto c = hasColors_ ? toBytes(mesh->colors[v]) : std::array<std::uint8_t, 4>{255, 255, 255, 255};
      std::memcpy(tri.c[k], c.data(), 4);
    }
  }
  vltmVao_ = gl::VertexArray::create();
  glBindVertexArray(vltmVao_.id());
  vltmBuffer_ = uploadBuffer(GL_ARRAY_BUFFER, data.data(), data.size());
  for (GLuint i = 0; i < 12; ++i) {
    glEnableVertexAttribArray(i);
    glVertexAttribDivisor(i, 1);
  }
  glBindVertexArray(0);
  return vltmVao_.id();
}

void GpuMesh::bindVltm(std::uint32_t firstTriangle) {
  glBindBuffer(GL_ARRAY_BUFFER, vltmBuffer_.id());
  const std::size_t base = std::size_t{firstTriangle} * sizeof(VltmTriangle);
  const GLsizei stride = sizeof(VltmTriangle);
  for (GLuint k = 0; k < 3; ++k) {
    glVertexAttribPointer(k, 3, GL_FLOAT, GL_FALSE, stride,
                          byteOffset(base + offsetof(VltmTriangle, p) + std::size_t{k} * 12));
    glVertexAttribPointer(3 + k, 3, GL_FLOAT, GL_FALSE, stride,
                          byteOffset(base + offsetof(VltmTriangle, n) + std::size_t{k} * 12));
    glVertexAttribPointer(6 + k, 2, GL_FLOAT, GL_FALSE, stride,
                          byteOffset(base + offsetof(VltmTriangle, t) + std::size_t{k} * 8));
    glVertexAttribPointer(9 + k, 4, GL_UNSIGNED_BYTE, GL_TRUE, stride,
                          byteOffset(base + offsetof(VltmTriangle, c) + std::size_t{k} * 4));
  }
}

}  // namespace basalt::render
