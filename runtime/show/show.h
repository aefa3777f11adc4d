#pragma once

/// \file
/// \brief The Show: the scene state that scripts, bindings and the control server change and
/// the renderer draws. LAVA's object with its named parts and attributes, its lights, view,
/// motion and environment, and the thesis' scene graph of placed, parented, instanced meshes.
///
/// Threading: a Show belongs to the frame loop's thread. Devices and media never touch it;
/// they push events and frames that the loop applies.

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/clock.h"
#include "runtime/head_tracking.h"
#include "runtime/math.h"
#include "runtime/show/attributes.h"
#include "runtime/show/mesh.h"
#include "runtime/show/viewer.h"

namespace basalt::runtime {

using PartId = std::uint32_t;
using NodeId = std::uint32_t;

/// \brief One placed mesh (or a pure transform) in the scene graph.
struct SceneNode {
  std::string name;
  std::int32_t parent = -1;          ///< index of the parent node; parents come first
  Mat4 local;                        ///< relative to the parent
  std::shared_ptr<const Mesh> mesh;  ///< null for grouping nodes; shared by instances
  std::vector<PartId> partIds;       ///< the Show part of each mesh part, same order
  /// The Show part names of the mesh's parts, same order, when this node's parts are its own (an
  /// instance's); empty: the mesh's part names, shared with every node that has the same name.
  std::vector<std::string> partNames;
  bool visible = true;
  /// Extended OBJ `usemap` maps (thesis C.2), resolved against the model's folder: the colour
  /// map textures the node's parts that have no material map of their own; the spherical
  /// reflection map and the bump map are recorded for the renderer ("" = none).
  std::string colorMap;
  std::string reflectionMap;
  std::string bumpMap;
  std::string source;  ///< the file the node was loaded from ("" for built-in geometry)
};

/// \brief A part as LAVA's "Part Selection" and per-part attributes see it.
struct PartState {
  std::string name;      ///< case-sensitive, may contain spaces
  bool selected = true;  ///< displayed
  PartStyle own;         ///< this part's settings where `mask` has the bit
  AttrMask mask;         ///< attributes set for this part (override global)
  std::string texture;   ///< texture source name ("" = none): file or stream
  /// Sphere reflection map (thesis §4.2.6.2, Extended OBJ `usemap file reflect`): a texture name
  /// whose image is a mirrored sphere; "" = none. Modulates the surface like the colour map.
  std::string reflectionTexture;
};

/// \brief What one frame displayed, as LAVA's performance meter counts it (§9).
struct FrameCounts {
  std::uint64_t triangles = 0;
  std::uint64_t lines = 0;
  std::uint64_t points = 0;
  std::uint64_t parts = 0;
  std::uint64_t facets = 0;
  friend bool operator==(const FrameCounts&, const FrameCounts&) = default;
};

/// \brief LAVA's performance meter (§9), filled by the frame loop from the renderer's counts
/// and read by the status server. The counts are those of the last frame; the rates are
/// updated once a sample period has passed: frames (and primitives, the sum of triangles,
/// lines and points) drawn since the last update, divided by the time that passed.
struct PerformanceMeter {
  std::uint64_t triangles = 0;
  std::uint64_t lines = 0;
  std::uint64_t points = 0;
  std::uint64_t parts = 0;
  std::uint64_t facets = 0;
  double framesPerSecond = 0;
  double primitivesPerSecond = 0;
  double samplePeriodSeconds = 2.0;  ///< "The default value is 2 seconds"
  std::uint64_t updates = 0;         ///< how many times the rates were computed

  /// \brief Records a frame drawn at `now` (any monotonic time base: the frame loop passes
  /// real time so that the rates say how fast this machine draws).
  void recordFrame(const FrameCounts& counts, Nanos now);
  /// \brief Forgets the current sample (after a pause, or when the period changes).
  void restartSample() { sampleFrames_ = 0, samplePrimitives_ = 0, sampleStarted_ = false; }

 private:
  std::uint64_t sampleFrames_ = 0;
  std::uint64_t samplePrimitives_ = 0;
  Nanos sampleStart_{0};
  bool sampleStarted_ = false;
};

class Show {
 public:
  /// \brief An empty show with every attribute at LAVA's default.
  Show();

  /// \brief LAVA's start-up scene: the colour cube on black under the default lights, turning
  /// slowly (global free run).
  static Show makeDefault();

  // ---- Scene graph ----
  [[nodiscard]] const std::vector<SceneNode>& nodes() const { return nodes_; }
  /// \brief Adds a node; its mesh parts become Show parts, named by `node.partNames` or the mesh
  /// (parts with the same name are shared, so repeated names are addressed together). Parents
  /// must be added first.
  NodeId addNode(SceneNode node);
  void setNodeTransform(NodeId id, const Mat4& local);
  /// \brief The first node with this name.
  [[nodiscard]] std::optional<NodeId> findNode(std::string_view name) const;
  /// \brief Adds a terrain's grid node and keeps its height field for `terrainHeightAt`.
  NodeId addTerrain(SceneNode node, std::shared_ptr<const HeightField> heights);
  [[nodiscard]] const std::vector<std::shared_ptr<const HeightField>>& terrains() const { return terrains_; }
  /// \brief Height of the first terrain under (x, z) in scene coordinates, if any: what keeps a
  /// walking viewer on the ground (thesis §4.6).
  [[nodiscard]] std::optional<float> terrainHeightAt(float x, float z) const;
  /// \brief The node's transform composed with all its parents'.
  [[nodiscard]] Mat4 worldTransform(NodeId id) const;
  /// \brief Removes all nodes and parts and resets every attribute: LAVA's "all attributes get
  /// reset whenever a new object is loaded".
  void clear();
  /// \brief Bounds of every node's mesh in scene coordinates (at the nodes' current placement).
  [[nodiscard]] Bounds sceneBounds() const;

  // ---- Parts ----
  [[nodiscard]] std::size_t partCount() const { return parts_.size(); }
  [[nodiscard]] std::optional<PartId> findPart(std::string_view name) const;
  [[nodiscard]] const PartState& part(PartId id) const { return parts_[id]; }
  void setPartSelected(PartId id, bool selected);
  void selectAll(bool selected);
  void setPartTexture(PartId id, std::string texture);
  void setPartReflectionTexture(PartId id, std::string texture);

  // ---- Attributes ----
  [[nodiscard]] const PartStyle& globalStyle() const { return global_; }
  /// \brief Changes the global style. Parts that set an attribute themselves keep their value.
  template <typename Edit>
  void editGlobalStyle(Edit&& edit) {
    edit(global_);
    ++styleRevision_;
  }
  /// \brief Changes attribute `attr` of one part through `edit`, which receives the part's
  /// current resolved style, and marks the attribute as the part's own.
  template <typename Edit>
  void editPartStyle(PartId id, AttrId attr, Edit&& edit) {
    PartStyle style = resolvedStyle(id);
    edit(style);
    copyAttr(attr, style, parts_[id].own);
    parts_[id].mask.set(static_cast<std::size_t>(attr));
    ++styleRevision_;
  }
  /// \brief Makes the part follow the global value of `attr` again.
  void clearPartAttr(PartId id, AttrId attr);
  /// \brief The style a part is drawn with: global, overridden by the part's own settings.
  /// Cached; never allocates once every part has been resolved.
  [[nodiscard]] const PartStyle& resolvedStyle(PartId id) const;
  /// \brief Bumped by every style change (renderers and Save Model compare it).
  [[nodiscard]] std::uint64_t styleRevision() const { return styleRevision_; }

  std::array<Light, kMaxLights>& lights() { return lights_; }
  [[nodiscard]] const std::array<Light, kMaxLights>& lights() const { return lights_; }
  DepthCue& depthCue() { return depthCue_; }
  [[nodiscard]] const DepthCue& depthCue() const { return depthCue_; }
  Fog& fog() { return fog_; }
  [[nodiscard]] const Fog& fog() const { return fog_; }
  TextureSettings& texture() { return texture_; }
  [[nodiscard]] const TextureSettings& texture() const { return texture_; }
  ModelClipping& modelClipping() { return clipping_; }
  [[nodiscard]] const ModelClipping& modelClipping() const { return clipping_; }
  Annotation& annotation() { return annotation_; }
  [[nodiscard]] const Annotation& annotation() const { return annotation_; }
  Picking& picking() { return picking_; }
  [[nodiscard]] const Picking& picking() const { return picking_; }
  GlobalSettings& global() { return globalSettings_; }
  [[nodiscard]] const GlobalSettings& global() const { return globalSettings_; }
  Motion& motion() { return motion_; }
  [[nodiscard]] const Motion& motion() const { return motion_; }
  ViewSettings& view() { return view_; }
  [[nodiscard]] const ViewSettings& view() const { return view_; }
  Environment& environment() { return environment_; }
  [[nodiscard]] const Environment& environment() const { return environment_; }
  BackgroundKind& backgroundKind() { return backgroundKind_; }
  [[nodiscard]] BackgroundKind backgroundKind() const { return backgroundKind_; }
  std::string& backgroundImage() { return backgroundImage_; }
  [[nodiscard]] const std::string& backgroundImage() const { return backgroundImage_; }
  EarthSky& earthSky() { return earthSky_; }
  [[nodiscard]] const EarthSky& earthSky() const { return earthSky_; }
  /// \brief Eye spacing and how stereo is shown; `global().stereo` switches it on.
  StereoSettings& stereo() { return stereo_; }
  [[nodiscard]] const StereoSettings& stereo() const { return stereo_; }
  /// \brief The thesis' walk-through viewer (camera, projection, stereo eye spacing, navigation
  /// bounds and speeds) as a `.sce` scene sets it.
  Viewer& viewer() { return viewer_; }
  [[nodiscard]] const Viewer& viewer() const { return viewer_; }
  /// \brief The tracked head of an immersive display's viewer (display units), when a tracker
  /// drives it: the facet views draw from it instead of their fixed viewer.
  HeadPose& head() { return head_; }
  [[nodiscard]] const HeadPose& head() const { return head_; }
  PerformanceMeter& performance() { return performance_; }
  [[nodiscard]] const PerformanceMeter& performance() const { return performance_; }

  /// \brief Resets the global settings (LAVA `global.reset_attr`): background, deferral,
  /// buffering and stereo. Per-part attributes are untouched, as in LAVA.
  void resetGlobalSettings() { globalSettings_ = GlobalSettings{}; }
  /// \brief Everything back to LAVA's defaults, keeping the scene (and part names).
  void resetAttributes();

  // ---- Placement and motion ----
  [[nodiscard]] const Position& position() const { return position_; }
  Position& position() { return position_; }
  /// \brief Rotates the global matrix about the world axes, X then Y then Z, in degrees.
  void rotateGlobal(const Vec3& degrees);
  /// \brief Rotates the local matrix about the object's own axes, X then Y then Z.
  void rotateLocal(const Vec3& degrees);
  void translateGlobal(const Vec3& offset);
  void translateLocal(const Vec3& offset);
  void scaleGlobal(float factor);
  void scaleLocal(float factor);
  /// \brief Global and local matrices back to identity (motion keeps running).
  void resetTransforms();
  /// \brief Starts motion for `motion().numFrames` frames (0: until stopped).
  void startMotion();
  void stopMotion();
  /// \brief Advances one frame: applies free-run motion and counts the frame.
  void advanceFrame();
  [[nodiscard]] std::uint64_t frameNumber() const { return frameNumber_; }

 private:
  PartId internPart(const std::string& name);

  std::vector<SceneNode> nodes_;
  std::vector<std::shared_ptr<const HeightField>> terrains_;
  std::vector<PartState> parts_;
  PartStyle global_;
  mutable std::vector<PartStyle> resolved_;        // cache, one per part
  mutable std::vector<std::uint64_t> resolvedAt_;  // styleRevision_ each cache entry was made at
  std::uint64_t styleRevision_ = 1;

  std::array<Light, kMaxLights> lights_ = defaultLights();
  DepthCue depthCue_;
  Fog fog_;
  TextureSettings texture_;
  ModelClipping clipping_;
  Annotation annotation_;
  Picking picking_;
  GlobalSettings globalSettings_;
  Motion motion_;
  Position position_;
  ViewSettings view_;
  Environment environment_;
  BackgroundKind backgroundKind_ = BackgroundKind::kColor;
  std::string backgroundImage_;
  EarthSky earthSky_;
  StereoSettings stereo_;
  Viewer viewer_;
  HeadPose head_;
  PerformanceMeter performance_;
  std::uint64_t frameNumber_ = 0;
};

/// \brief The transforms one plain view of the Show needs.
struct ViewTransforms {
  Mat4 model;       ///< object coordinates to world: global * local * normalisation
  Mat4 view;        ///< world to eye
  Mat4 projection;  ///< eye to clip
  Vec3 eye;         ///< eye position in world coordinates
};

/// \brief The plain view, framed as `viewer().framing` says.
///
/// Framing::kFit is LAVA's view (§6.1 "View"): the scene centred and scaled into window bounds
/// -1..1 at the narrower dimension, seen from `view().perspective` units away on +Z
/// (orthographic at 0), the walking viewer's moves (its position scaled into window units, its
/// rotation) applied at that eye. Framing::kScene is the thesis' camera (§4.3.1): the scene in
/// its own units seen from `viewer().position` turned by `viewer().rotation` (cameraTransform)
/// through a symmetric frustum of `fieldOfView` degrees vertically at `aspect`, between
/// `nearClip` and `farClip`.
ViewTransforms computeView(const Show& show, float aspect);

/// \brief One eye of a stereo pair (thesis §5.1): the eye moved `eyeOffset` window units along
/// the eye's X axis (negative: left eye) from computeView()'s eye, with an off-axis frustum that
/// keeps the object's centre plane where the mono view shows it, so the two images agree there
/// and differ in front of and behind it (for a scene camera: the plane through the centre of
/// the scene's bounds, across the line of sight). Orthographic views are sheared the same way.
ViewTransforms computeEyeView(const Show& show, float aspect, float eyeOffset);

/// \brief The scene's normalisation (centre and scale into window units, LAVA "View"): what
/// computeView() puts between the scene and the local matrix. Identity for a scene drawn from
/// its own camera (Framing::kScene).
Mat4 viewNormalisation(const Show& show);

/// \brief The uniform scale of a transform: the cube root of its 3 x 3 determinant's magnitude
/// (how many units of the target one unit of the source is, for similarity transforms).
float uniformScale(const Mat4& m);

/// \brief How many window units one scene unit is in the plain view: the scale of the global
/// and local matrices and the normalisation (what `Units::kScene` lengths are multiplied by).
float sceneScale(const Show& show);

/// \brief The stereo eye spacing in window units (a scene's `eyespacing` is in scene units).
float eyeSpacingInWindowUnits(const Show& show);

/// \brief Where the floor and the fake shadow go (LAVA "Environment").
struct FloorGeometry {
  Mat4 floor;   ///< maps the floor's square (x and z in -1..1, y = 0) into the world
  Mat4 shadow;  ///< object coordinates to world, squashed onto the floor (use instead of the model)
  float y = 0;  ///< the floor's height in the global frame, window units
};

/// \brief The floor under the object: horizontal in the global frame, `floorPosition` above the
/// lowest point of the scene's bounding box after the local matrix, centred under the object and
/// two scene radii from the centre to each side. `shadow` is LAVA's fake shadow: the model
/// matrix with Y scaled to 0 onto the floor, in the global frame.
FloorGeometry computeFloor(const Show& show);

/// \brief The colour cube LAVA starts with: six faces, parts "face 1" to "face 6", each with
/// its own colour, unit half-size, outward normals.
std::shared_ptr<const Mesh> makeColorCube();

}  // namespace basalt::runtime
