#include "runtime/cave_aids.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>

#include <fmt/format.h>

namespace basalt::runtime {
namespace {

constexpr int kConeSegments = 16;
constexpr float kFieldOfView = 40.0f;  // degrees, vertical, of the outside camera

/// One part spanning the whole of a mesh's lines, points or triangles.
MeshPart wholePart(std::string name, const Mesh& mesh) {
  MeshPart p;
  p.name = std::move(name);
  p.triangleIndexCount = static_cast<std::uint32_t>(mesh.triangles.size());
  p.lineIndexCount = static_cast<std::uint32_t>(mesh.lines.size());
  p.pointIndexCount = static_cast<std::uint32_t>(mesh.points.size());
  p.facetCount = static_cast<std::uint32_t>(mesh.triangles.size() / 3);
  return p;
}

/// A segment from the origin to (0, 0, 1): placed by a matrix whose Z column is the vector.
std::shared_ptr<Mesh> segment(const std::string& name) {
  auto m = std::make_shared<Mesh>();
  m->positions = {{0, 0, 0}, {0, 0, 1}};
  m->lines = {0, 1};
  m->parts.push_back(wholePart(name, *m));
  return m;
}

/// The viewer: a cone with its apex at the origin opening along -Z (where an eye looks), one
/// unit long, its base half a unit across, closed by a disc.
std::shared_ptr<Mesh> viewerCone() {
  auto m = std::make_shared<Mesh>();
  const float radius = 0.25f;
  for (int i = 0; i < kConeSegments; ++i) {
    const float a0 = 2.0f * std::numbers::pi_v<float> * static_cast<float>(i) / kConeSegments;
    const float a1 = 2.0f * std::numbers::pi_v<float> * static_cast<float>(i + 1) / kConeSegments;
    const Vec3 b0{radius * std::cos(a0), radius * std::sin(a0), -1};
    const Vec3 b1{radius * std::cos(a1), radius * std::sin(a1), -1};
    // Side: apex, b0, b1 with the face's own normal (flat facets read better as a shape).
    const Vec3 n = normalize(cross(b0, b1));
    const auto base = static_cast<std::uint32_t>(m->positions.size());
    m->positions.insert(m->positions.end(), {{0, 0, 0}, b0, b1});
    m->normals.insert(m->normals.end(), {n, n, n});
    m->triangles.insert(m->triangles.end(), {base, base + 1, base + 2});
    // Base disc, facing away from the apex.
    const auto cap = static_cast<std::uint32_t>(m->positions.size());
    m->positions.insert(m->positions.end(), {{0, 0, -1}, b1, b0});
    m->normals.insert(m->normals.end(), {{0, 0, -1}, {0, 0, -1}, {0, 0, -1}});
    m->triangles.insert(m->triangles.end(), {cap, cap + 1, cap + 2});
  }
  m->parts.push_back(wholePart("viewer", *m));
  return m;
}

/// Two unit vectors perpendicular to `z` and to each other (any pair).
std::pair<Vec3, Vec3> perpendiculars(const Vec3& z) {
  const Vec3 n = normalize(z);
  const Vec3 helper = std::abs(n.y) < 0.9f ? Vec3{0, 1, 0} : Vec3{1, 0, 0};
  const Vec3 x = normalize(cross(helper, n));
  return {x, cross(n, x)};
}

Mat4 columns(const Vec3& x, const Vec3& y, const Vec3& z, const Vec3& t) {
  Mat4 m;
  const Vec3 c[4] = {x, y, z, t};
  for (int i = 0; i < 4; ++i) {
    m(0, i) = c[i].x;
    m(1, i) = c[i].y;
    m(2, i) = c[i].z;
  }
  return m;
}

/// Maps the unit segment onto `from` -> `to` (a point when they coincide).
Mat4 segmentFrom(const Vec3& from, const Vec3& to) {
  const Vec3 z = to - from;
  const float len = length(z);
  if (len <= 0) return columns({1e-6f, 0, 0}, {0, 1e-6f, 0}, {0, 0, 1e-6f}, from);
  const auto [x, y] = perpendiculars(z);
  return columns(x * len, y * len, z, from);
}

void flat(Show& show, PartId id, Color3 colour) {
  show.editPartStyle(id, AttrId::kFrontIllum, [](PartStyle& s) { s.front.illumination = Illumination::kNone; });
  show.editPartStyle(id, AttrId::kFrontColor, [&](PartStyle& s) { s.front.color = colour; });
}

void lineColour(Show& show, PartId id, Color3 colour, float width) {
  show.editPartStyle(id, AttrId::kLinesColor, [&](PartStyle& s) { s.lines.color = colour; });
  show.editPartStyle(id, AttrId::kLinesWidth, [&](PartStyle& s) { s.lines.width = width; });
}

}  // namespace

Result<CaveAids> CaveAids::create(std::shared_ptr<const formats::CaveGeometry> geometry) {
  if (!geometry || geometry->facets.empty()) {
    return fail(Errc::kInvalidArgument, "the visual aids need a display geometry with at least one facet");
  }
  CaveAids aids;
  aids.geometry_ = std::move(geometry);
  const formats::CaveGeometry& g = *aids.geometry_;
  float radius = 0;
  for (const formats::CaveFacet& f : g.facets) {
    for (const Vec3& c : f.corners) radius = std::max(radius, length(c - g.center));
  }
  aids.radius_ = radius > 0 ? radius : 1.0f;

  // The wireframe: every facet's outline.
  auto wire = std::make_shared<Mesh>();
  for (const formats::CaveFacet& f : g.facets) {
    const auto first = static_cast<std::uint32_t>(wire->positions.size());
    const auto n = static_cast<std::uint32_t>(f.corners.size());
    wire->positions.insert(wire->positions.end(), f.corners.begin(), f.corners.end());
    for (std::uint32_t i = 0; i < n; ++i) wire->lines.insert(wire->lines.end(), {first + i, first + (i + 1) % n});
  }
  wire->parts.push_back(wholePart("cave", *wire));

  // The facets, filled (a fan: they are convex), one part each, facing inwards.
  auto filled = std::make_shared<Mesh>();
  for (std::size_t k = 0; k < g.facets.size(); ++k) {
    const formats::CaveFacet& f = g.facets[k];
    const Vec3 inward = f.facesInward ? f.normal : -f.normal;
    MeshPart part;
    part.name = fmt::format("facet {}", k);
    part.firstTriangleIndex = static_cast<std::uint32_t>(filled->triangles.size());
    const auto first = static_cast<std::uint32_t>(filled->positions.size());
    for (const Vec3& c : f.corners) {
      filled->positions.push_back(c);
      filled->normals.push_back(inward);
    }
    for (std::uint32_t i = 1; i + 1 < f.corners.size(); ++i) {
      filled->triangles.insert(filled->triangles.end(), {first, first + i, first + i + 1});
    }
    part.triangleIndexCount = static_cast<std::uint32_t>(filled->triangles.size()) - part.firstTriangleIndex;
    part.facetCount = 1;
    filled->parts.push_back(std::move(part));
  }

  auto point = std::make_shared<Mesh>();
  point->positions = {{0, 0, 0}};
  point->points = {0};
  point->parts.push_back(wholePart("collision", *point));

  Show& show = aids.show_;
  auto add = [&](const std::string& name, std::shared_ptr<const Mesh> mesh) {
    SceneNode node;
    node.name = name;
    node.mesh = std::move(mesh);
    return show.addNode(std::move(node));
  };
  const NodeId wireNode = add("cave", wire);
  const NodeId facetsNode = add("facets", filled);
  aids.normal_ = add("normal", segment("normal"));
  aids.viewer_ = add("viewer", viewerCone());
  aids.sight_ = add("line of sight", segment("line of sight"));
  aids.up_ = add("up", segment("up"));
  aids.right_ = add("right", segment("right"));
  aids.collision_ = add("collision", point);

  // Looks: the wireframe grey, the current facet translucent yellow, the normal magenta, the
  // viewer lit white, the line of sight cyan, up green and right red (as axes are drawn), the
  // collision point a white cross.
  show.editGlobalStyle([](PartStyle& s) { s.render.faceCulling = FaceCulling::kOff; });
  lineColour(show, show.nodes()[wireNode].partIds[0], {0.7f, 0.7f, 0.7f}, 1.0f);
  aids.facetParts_ = show.nodes()[facetsNode].partIds;
  for (const PartId id : aids.facetParts_) {
    flat(show, id, {1.0f, 0.85f, 0.1f});
    show.editPartStyle(id, AttrId::kFrontTranspMethod,
                       [](PartStyle& s) { s.front.transparencyMethod = TransparencyMethod::kBlended; });
    show.editPartStyle(id, AttrId::kFrontTranspBlendEq,
                       [](PartStyle& s) { s.front.transparencyBlend = TransparencyBlend::kArbitraryBackground; });
    show.editPartStyle(id, AttrId::kFrontTransparency, [](PartStyle& s) { s.front.transparency = 0.35f; });
    show.setPartSelected(id, false);
  }
  lineColour(show, show.nodes()[aids.normal_].partIds[0], {1.0f, 0.2f, 1.0f}, 3.0f);
  lineColour(show, show.nodes()[aids.sight_].partIds[0], {0.1f, 0.9f, 1.0f}, 2.0f);
  lineColour(show, show.nodes()[aids.up_].partIds[0], {0.2f, 1.0f, 0.2f}, 3.0f);
  lineColour(show, show.nodes()[aids.right_].partIds[0], {1.0f, 0.25f, 0.2f}, 3.0f);
  const PartId collisionPart = show.nodes()[aids.collision_].partIds[0];
  show.editPartStyle(collisionPart, AttrId::kMarkersType, [](PartStyle& s) { s.markers.type = MarkerType::kCross; });
  show.editPartStyle(collisionPart, AttrId::kMarkersColor, [](PartStyle& s) { s.markers.color = {1, 1, 1}; });
  show.editPartStyle(collisionPart, AttrId::kMarkersScaleFactor, [](PartStyle& s) { s.markers.scaleFactor = 14.0f; });

  aids.update(0, FacetProjection{}, g.center);
  return aids;
}

void CaveAids::update(std::uint32_t facet, const FacetProjection& projection, const Vec3& viewer) {
  const formats::CaveGeometry& g = *geometry_;
  if (facet >= g.facets.size()) facet = 0;
  if (facet != current_ || !show_.part(facetParts_[facet]).selected) {
    show_.setPartSelected(facetParts_[current_], false);
    show_.setPartSelected(facetParts_[facet], true);
    current_ = facet;
  }
  const formats::CaveFacet& f = g.facets[facet];
  const Vec3 inward = f.facesInward ? f.normal : -f.normal;
  Vec3 centroid{0, 0, 0};
  for (const Vec3& c : f.corners) centroid += c;
  centroid = centroid / static_cast<float>(f.corners.size());
  const float unit = 0.25f * radius_;
  show_.setNodeTransform(normal_, segmentFrom(centroid, centroid + inward * unit));

  // The viewer looks along the line of sight, which is the facet's outward normal.
  const Vec3 forward = -inward;
  Vec3 up = projection.visible ? projection.up : perpendiculars(forward).second;
  up = normalize(up - forward * dot(up, forward));
  const Vec3 right = cross(forward, up);
  const float cone = 0.3f * radius_;
  show_.setNodeTransform(viewer_, columns(right * cone, up * cone, -forward * cone, viewer));

  for (const NodeId id : {sight_, up_, right_, collision_}) {
    show_.setPartSelected(show_.nodes()[id].partIds[0], projection.visible);
  }
  if (projection.visible) {
    show_.setNodeTransform(sight_, segmentFrom(viewer, projection.collision));
    show_.setNodeTransform(up_, segmentFrom(projection.collision, projection.collision + projection.up * unit));
    show_.setNodeTransform(right_, segmentFrom(projection.collision, projection.collision + projection.right * unit));
    show_.setNodeTransform(collision_, Mat4::translation(projection.collision));
  }
}

ViewTransforms CaveAids::outsideView(const Mat4& worldFromCave, const Vec3& from, float aspect) const {
  const Vec3 direction = length(from) > 0 ? normalize(from) : normalize(kDefaultFrom);
  const float halfFov = radians(kFieldOfView) * 0.5f;
  // Far enough that the bounding sphere fits the narrower of the two fields of view.
  const float fitY = radius_ / std::sin(halfFov);
  const float fitX = radius_ / std::sin(std::atan(std::tan(halfFov) * std::max(aspect, 1e-3f)));
  const float distance = 1.1f * std::max(fitX, fitY);
  const Vec3 centre = geometry_->center;
  const Vec3 eyeCave = centre + direction * distance;
  const Vec3 upCave = std::abs(direction.y) > 0.99f ? Vec3{0, 0, -1} : Vec3{0, 1, 0};

  ViewTransforms t;
  t.eye = worldFromCave.transformPoint(eyeCave);
  const Vec3 target = worldFromCave.transformPoint(centre);
  const Vec3 up = worldFromCave.transformDirection(upCave);
  const float scale = length(worldFromCave.transformDirection({1, 0, 0}));
  t.view = Mat4::lookAt(t.eye, target, up);
  // The world beyond the display is drawn too: keep it out to ten times the camera's distance.
  const float nearPlane = std::max(0.05f * distance, distance - 2.0f * radius_) * scale;
  const float farPlane = 10.0f * (distance + radius_) * scale;
  t.projection = Mat4::perspective(kFieldOfView, aspect, nearPlane, farPlane);
  return t;
}

}  // namespace basalt::runtime
