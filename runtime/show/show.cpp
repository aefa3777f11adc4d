#include "runtime/show/show.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace basalt::runtime {

Show::Show() = default;

NodeId Show::addNode(SceneNode node) {
  node.partIds.clear();
  if (node.mesh) {
    node.partIds.reserve(node.mesh->parts.size());
    const bool own = node.partNames.size() == node.mesh->parts.size();
    for (std::size_t k = 0; k < node.mesh->parts.size(); ++k) {
      node.partIds.push_back(internPart(own ? node.partNames[k] : node.mesh->parts[k].name));
    }
  }
  if (node.parent >= static_cast<std::int32_t>(nodes_.size())) node.parent = -1;
  nodes_.push_back(std::move(node));
  return static_cast<NodeId>(nodes_.size() - 1);
}

void Show::setNodeTransform(NodeId id, const Mat4& local) {
  if (id < nodes_.size()) nodes_[id].local = local;
}

Mat4 Show::worldTransform(NodeId id) const {
  Mat4 m = nodes_[id].local;
  for (std::int32_t p = nodes_[id].parent; p >= 0; p = nodes_[static_cast<std::size_t>(p)].parent) {
    m = nodes_[static_cast<std::size_t>(p)].local * m;
  }
  return m;
}

void Show::clear() {
  nodes_.clear();
  terrains_.clear();
  parts_.clear();
  resolved_.clear();
  resolvedAt_.clear();
  resetAttributes();
}

Bounds Show::sceneBounds() const {
  Bounds b;
  for (NodeId i = 0; i < nodes_.size(); ++i) {
    const SceneNode& n = nodes_[i];
    if (!n.mesh || n.mesh->positions.empty()) continue;
    const Bounds mb = n.mesh->bounds();
    const Mat4 w = worldTransform(i);
    for (int corner = 0; corner < 8; ++corner) {
      const Vec3 c{(corner & 1) ? mb.max.x : mb.min.x, (corner & 2) ? mb.max.y : mb.min.y,
                   (corner & 4) ? mb.max.z : mb.min.z};
      b.add(w.transformPoint(c));
    }
  }
  return b;
}

NodeId Show::addTerrain(SceneNode node, std::shared_ptr<const HeightField> heights) {
  const NodeId id = addNode(std::move(node));
  if (heights) terrains_.push_back(std::move(heights));
  return id;
}

std::optional<float> Show::terrainHeightAt(float x, float z) const {
  for (const auto& t : terrains_) {
    if (auto h = t->heightAt(x, z)) return h;
  }
  return std::nullopt;
}

std::optional<NodeId> Show::findNode(std::string_view name) const {
  for (NodeId i = 0; i < nodes_.size(); ++i) {
    if (nodes_[i].name == name) return i;
  }
  return std::nullopt;
}

PartId Show::internPart(const std::string& name) {
  if (auto existing = findPart(name)) return *existing;
  PartState state;
  state.name = name;
  parts_.push_back(std::move(state));
  resolved_.emplace_back();
  resolvedAt_.push_back(0);
  return static_cast<PartId>(parts_.size() - 1);
}

std::optional<PartId> Show::findPart(std::string_view name) const {
  for (PartId i = 0; i < parts_.size(); ++i) {
    if (parts_[i].name == name) return i;
  }
  return std::nullopt;
}

void Show::setPartSelected(PartId id, bool selected) { parts_[id].selected = selected; }

void Show::selectAll(bool selected) {
  for (PartState& p : parts_) p.selected = selected;
}

void Show::setPartTexture(PartId id, std::string texture) { parts_[id].texture = std::move(texture); }

void Show::setPartReflectionTexture(PartId id, std::string texture) {
  parts_[id].reflectionTexture = std::move(texture);
}

void Show::clearPartAttr(PartId id, AttrId attr) {
  parts_[id].mask.reset(static_cast<std::size_t>(attr));
  ++styleRevision_;
}

const PartStyle& Show::resolvedStyle(PartId id) const {
  if (resolvedAt_[id] != styleRevision_) {
    resolved_[id] = resolveStyle(global_, parts_[id].own, parts_[id].mask);
    resolvedAt_[id] = styleRevision_;
  }
  return resolved_[id];
}

void Show::resetAttributes() {
  global_ = PartStyle{};
  for (PartState& p : parts_) {
    p.own = PartStyle{};
    p.mask.reset();
    p.selected = true;
    p.texture.clear();
    p.reflectionTexture.clear();
  }
  ++styleRevision_;
  lights_ = defaultLights();
  depthCue_ = {};
  fog_ = {};
  texture_ = {};
  clipping_ = {};
  annotation_ = {};
  picking_ = {};
  globalSettings_ = {};
  motion_ = {};
  position_ = {};
  view_ = {};
  environment_ = {};
  backgroundKind_ = BackgroundKind::kColor;
  backgroundImage_.clear();
  earthSky_ = {};
  stereo_ = {};
  viewer_ = {};
}

void PerformanceMeter::recordFrame(const FrameCounts& counts, Nanos now) {
  triangles = counts.triangles;
  lines = counts.lines;
  points = counts.points;
  parts = counts.parts;
  facets = counts.facets;
  if (!sampleStarted_) {
    // The first frame opens the sample; rates count the frames drawn after it.
    sampleStarted_ = true;
    sampleStart_ = now;
    sampleFrames_ = 0;
    samplePrimitives_ = 0;
    return;
  }
  ++sampleFrames_;
  samplePrimitives_ += counts.triangles + counts.lines + counts.points;
  const double elapsed = toSeconds(now - sampleStart_);
  const double period = samplePeriodSeconds > 0 ? samplePeriodSeconds : 2.0;
  if (elapsed < period) return;
  framesPerSecond = static_cast<double>(sampleFrames_) / elapsed;
  primitivesPerSecond = static_cast<double>(samplePrimitives_) / elapsed;
  ++updates;
  sampleStart_ = now;
  sampleFrames_ = 0;
  samplePrimitives_ = 0;
}

namespace {
Mat4 rotationXYZ(const Vec3& d) {
  // X first, then Y, then Z: the column-vector product applies the rightmost first.
  return Mat4::rotationZ(d.z) * Mat4::rotationY(d.y) * Mat4::rotationX(d.x);
}
}  // namespace

void Show::rotateGlobal(const Vec3& degrees) { position_.global = rotationXYZ(degrees) * position_.global; }
void Show::rotateLocal(const Vec3& degrees) { position_.local = position_.local * rotationXYZ(degrees); }
void Show::translateGlobal(const Vec3& offset) { position_.global = Mat4::translation(offset) * position_.global; }
void Show::translateLocal(const Vec3& offset) { position_.local = position_.local * Mat4::translation(offset); }
void Show::scaleGlobal(float factor) { position_.global = Mat4::scaling({factor, factor, factor}) * position_.global; }
void Show::scaleLocal(float factor) { position_.local = position_.local * Mat4::scaling({factor, factor, factor}); }

void Show::resetTransforms() {
  position_.global = Mat4{};
  position_.local = Mat4{};
}

void Show::startMotion() {
  motion_.globalFreeRun = true;
  motion_.localFreeRun = true;
  motion_.framesLeft = motion_.numFrames > 0 ? motion_.numFrames : -1;
}

void Show::stopMotion() {
  motion_.globalFreeRun = false;
  motion_.localFreeRun = false;
  motion_.framesLeft = -1;
}

void Show::advanceFrame() {
  if (motion_.globalFreeRun) {
    rotateGlobal(motion_.globalRotate);
    if (motion_.globalScale != 1.0f) scaleGlobal(motion_.globalScale);
  }
  if (motion_.localFreeRun) {
    rotateLocal(motion_.localRotate);
    if (motion_.localScale != 1.0f) scaleLocal(motion_.localScale);
  }
  if (motion_.framesLeft > 0) {
    --motion_.framesLeft;
    if (motion_.framesLeft == 0) stopMotion();
  }
  ++frameNumber_;
}

Mat4 viewNormalisation(const Show& show) {
  // A scene drawn from its own camera keeps its own units.
  if (show.viewer().framing == Framing::kScene) return {};
  const ViewSettings& v = show.view();
  const Bounds b = show.sceneBounds();

  // Normalisation: centre the scene and scale it into window units.
  Vec3 center = b.empty ? Vec3{} : b.center();
  switch (v.objectCenter) {
    case ObjectCenter::kUseSlider: center = v.center; break;
    case ObjectCenter::kPlusX: center.x = b.max.x; break;
    case ObjectCenter::kMinusX: center.x = b.min.x; break;
    case ObjectCenter::kPlusY: center.y = b.max.y; break;
    case ObjectCenter::kMinusY: center.y = b.min.y; break;
    case ObjectCenter::kPlusZ: center.z = b.max.z; break;
    case ObjectCenter::kMinusZ: center.z = b.min.z; break;
    case ObjectCenter::kNone: break;
  }
  const float radius = b.empty ? 1.0f : std::max(b.radius(), 1e-6f);
  float scale = 1.0f;
  switch (v.objectScale) {
    case ObjectScale::kFullScreen: scale = 1.0f / radius; break;
    case ObjectScale::kHalfScreen: scale = 0.5f / radius; break;
    case ObjectScale::kOriginal: scale = 1.0f; break;
  }
  return Mat4::scaling({scale, scale, scale}) * Mat4::translation(-center);
}

float uniformScale(const Mat4& m) {
  const float det = m(0, 0) * (m(1, 1) * m(2, 2) - m(1, 2) * m(2, 1)) -
                    m(0, 1) * (m(1, 0) * m(2, 2) - m(1, 2) * m(2, 0)) +
                    m(0, 2) * (m(1, 0) * m(2, 1) - m(1, 1) * m(2, 0));
  return std::cbrt(std::fabs(det));
}

float sceneScale(const Show& show) {
  return uniformScale(show.position().global * show.position().local * viewNormalisation(show));
}

float eyeSpacingInWindowUnits(const Show& show) {
  const StereoSettings& s = show.stereo();
  if (s.units == Units::kWindow) return s.eyeSpacing;
  const float scale = sceneScale(show);
  return scale > 0 && std::isfinite(scale) ? s.eyeSpacing * scale : s.eyeSpacing;
}

ViewTransforms computeView(const Show& show, float aspect) { return computeEyeView(show, aspect, 0.0f); }

namespace {

/// The thesis' camera (§4.3.1): the world in its own units seen from the viewer, a symmetric
/// frustum of `fieldOfView` degrees (vertical, as gluPerspective takes it) between the near and
/// far clipping distances. A stereo eye moves `eyeOffset` along the camera's X axis and keeps
/// the plane through the scene's centre where the mono view shows it.
ViewTransforms sceneCameraView(const Show& show, float aspect, float eyeOffset) {
  const Viewer& c = show.viewer();
  ViewTransforms t;
  t.model = show.position().global * show.position().local;
  const Mat4 camera = cameraTransform(c.position, c.rotation);
  const Mat4 eye = camera * Mat4::translation({eyeOffset, 0, 0});
  t.eye = eye.transformPoint({0, 0, 0});
  t.view = eye.inverted();
  const float n = c.nearClip > 0 ? c.nearClip : 0.1f;
  const float f = c.farClip > n ? c.farClip : n * 1000.0f;
  const float fov = std::clamp(c.fieldOfView, 0.01f, 179.0f);
  const float halfH = n * std::tan(radians(fov) * 0.5f);
  const float halfW = halfH * (aspect > 0 ? aspect : 1.0f);
  float shift = 0;
  if (eyeOffset != 0) {
    // Zero parallax at the scene's centre, measured along the line of sight.
    const Bounds b = show.sceneBounds();
    const Vec3 centre = b.empty ? Vec3{} : t.model.transformPoint(b.center());
    float focus = -camera.inverted().transformPoint(centre).z;
    if (!(focus > n)) focus = std::max(n * 10.0f, 1.0f);
    shift = eyeOffset * n / focus;
  }
  t.projection = Mat4::frustum(-halfW - shift, halfW - shift, -halfH, halfH, n, f);
  return t;
}

}  // namespace

ViewTransforms computeEyeView(const Show& show, float aspect, float eyeOffset) {
  if (show.viewer().framing == Framing::kScene) return sceneCameraView(show, aspect, eyeOffset);
  const ViewSettings& v = show.view();
  ViewTransforms t;
  t.model = show.position().global * show.position().local * viewNormalisation(show);

  // The walking viewer moves from LAVA's eye, its scene units scaled into window units.
  const Viewer& walker = show.viewer();
  const float walkScale = uniformScale(t.model);
  const Mat4 walk = cameraTransform(walker.position * (walkScale > 0 && std::isfinite(walkScale) ? walkScale : 1.0f),
                                    walker.rotation);

  // Window bounds -1..1 at the narrower dimension, shrunk or grown by the view scale.
  const float viewScale = v.viewScale > 0 ? v.viewScale : 1.0f;
  float halfW = aspect >= 1 ? aspect : 1.0f;
  float halfH = aspect >= 1 ? 1.0f : 1.0f / aspect;
  halfW /= viewScale;
  halfH /= viewScale;
  const float zClip = std::max(v.zClipScale, 1e-3f);
  const float e = eyeOffset;
  if (v.perspective > 0) {
    const float d = v.perspective;
    const Mat4 eye = Mat4::translation({0, 0, d}) * walk * Mat4::translation({e, 0, 0});
    t.eye = eye.transformPoint({0, 0, 0});
    t.view = eye.inverted();
    const float n = std::max(d - zClip, d * 1e-3f);
    const float f = d + zClip;
    // The window -halfW..halfW on the z = 0 plane, seen from the (moved) eye: an off-axis frustum.
    const float k = n / d;
    t.projection = Mat4::frustum((-halfW - e) * k, (halfW - e) * k, -halfH * k, halfH * k, n, f);
  } else {
    const float d = zClip + 1.0f;
    const Mat4 eye = Mat4::translation({0, 0, d}) * walk;
    t.eye = eye.transformPoint({e, 0, 0});
    t.view = eye.inverted();
    // Parallel eyes see no parallax, so the eye's view is sheared instead: a point z window units
    // in front of the centre plane moves by -e z / d, as it would seen in perspective from d.
    Mat4 shear;
    shear(0, 2) = -e / d;
    shear(0, 3) = -e;  // view z = -d is the centre plane: it stays put
    t.projection = Mat4::orthographic(-halfW, halfW, -halfH, halfH, d - zClip, d + zClip) * shear;
  }
  return t;
}

FloorGeometry computeFloor(const Show& show) {
  FloorGeometry g;
  const Mat4 object = show.position().local * viewNormalisation(show);
  const Bounds b = show.sceneBounds();
  float lowest = 0;
  float radius = 1;
  Vec3 centre{};
  if (!b.empty) {
    lowest = std::numeric_limits<float>::max();
    for (int corner = 0; corner < 8; ++corner) {
      const Vec3 c{(corner & 1) ? b.max.x : b.min.x, (corner & 2) ? b.max.y : b.min.y,
                   (corner & 4) ? b.max.z : b.min.z};
      lowest = std::min(lowest, object.transformPoint(c).y);
    }
    centre = object.transformPoint(b.center());
    radius = std::max(length(object.transformPoint(b.max) - object.transformPoint(b.min)) * 0.5f, 1e-3f);
  }
  g.y = lowest + show.environment().floorPosition;
  const float half = 2.0f * radius;
  const Mat4& global = show.position().global;
  g.floor = global * Mat4::translation({centre.x, g.y, centre.z}) * Mat4::scaling({half, 1, half});
  g.shadow = global * Mat4::translation({0, g.y, 0}) * Mat4::scaling({1, 0, 1}) * object;
  return g;
}

std::shared_ptr<const Mesh> makeColorCube() {
  auto mesh = std::make_shared<Mesh>();
  struct Face {
    const char* name;
    Vec3 normal, u, v;
  };
  // Parts follow LAVA's demo script naming ("face 3", "face 6").
  const Face faces[6] = {
      {"face 1", {0, 0, 1}, {1, 0, 0}, {0, 1, 0}},  {"face 2", {0, 0, -1}, {-1, 0, 0}, {0, 1, 0}},
      {"face 3", {1, 0, 0}, {0, 0, -1}, {0, 1, 0}}, {"face 4", {-1, 0, 0}, {0, 0, 1}, {0, 1, 0}},
      {"face 5", {0, 1, 0}, {1, 0, 0}, {0, 0, -1}}, {"face 6", {0, -1, 0}, {1, 0, 0}, {0, 0, 1}},
  };
  for (const Face& f : faces) {
    const auto base = static_cast<std::uint32_t>(mesh->positions.size());
    const Vec2 uv[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    const float su[4] = {-1, 1, 1, -1}, sv[4] = {-1, -1, 1, 1};
    for (int i = 0; i < 4; ++i) {
      mesh->positions.push_back(f.normal + f.u * su[i] + f.v * sv[i]);
      mesh->normals.push_back(f.normal);
      mesh->texcoords.push_back(uv[i]);
    }
    MeshPart part;
    part.name = f.name;
    part.firstTriangleIndex = static_cast<std::uint32_t>(mesh->triangles.size());
    for (std::uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) mesh->triangles.push_back(base + i);
    part.triangleIndexCount = 6;
    part.firstEdgeIndex = static_cast<std::uint32_t>(mesh->edges.size());
    for (std::uint32_t i : {0u, 1u, 1u, 2u, 2u, 3u, 3u, 0u}) mesh->edges.push_back(base + i);
    part.edgeIndexCount = 8;
    part.facetCount = 1;
    part.firstFacet = static_cast<std::uint32_t>(mesh->facetSizes.size());
    mesh->facetSizes.push_back(4);
    mesh->parts.push_back(std::move(part));
  }
  return mesh;
}

Show Show::makeDefault() {
  Show show;
  SceneNode node;
  node.name = "cube";
  node.mesh = makeColorCube();
  show.addNode(std::move(node));
  // One colour per face, set as `obj_colors.part_color` does: surface, line and marker colour.
  const Color3 colours[6] = {{1, 0, 0}, {0, 1, 1}, {0, 1, 0}, {1, 0, 1}, {0, 0, 1}, {1, 1, 0}};
  for (PartId id = 0; id < show.partCount(); ++id) {
    const Color3 c = colours[id % 6];
    show.editPartStyle(id, AttrId::kFrontColor, [&](PartStyle& s) { s.front.color = c; });
    show.editPartStyle(id, AttrId::kLinesColor, [&](PartStyle& s) { s.lines.color = c; });
    show.editPartStyle(id, AttrId::kMarkersColor, [&](PartStyle& s) { s.markers.color = c; });
  }
  // Start turned so that three faces show, then turn slowly about X and Y.
  show.rotateGlobal({25, -35, 0});
  show.motion().globalRotate = {0.25f, 0.5f, 0};
  show.motion().globalFreeRun = true;
  return show;
}

}  // namespace basalt::runtime
