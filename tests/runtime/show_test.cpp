// The Show and LAVA's attribute model: defaults as the manual lists them, global versus
// per-part settings, motion, view normalisation and the default cube.
// Example failures: a global change overwriting a part's own setting (the manual forbids it);
// a default that differs from the manual; motion that depends on anything but the frame count.

#include <gtest/gtest.h>

#include "runtime/bindings.h"
#include "runtime/show/show.h"

namespace basalt::runtime {
namespace {

TEST(Attributes, DefaultsAreTheManuals) {
  const PartStyle s;
  EXPECT_EQ(s.render.primType, PrimType::kSolid);
  EXPECT_EQ(s.render.faceCulling, FaceCulling::kOff);
  EXPECT_FALSE(s.render.faceDistinguishing);
  EXPECT_EQ(s.render.rasterOp, RasterOp::kCopy);
  EXPECT_TRUE(s.render.hiddenSurfaceRemoval);
  EXPECT_EQ(s.markers.type, MarkerType::kDot);
  EXPECT_EQ(s.markers.color, (Color3{0, 1, 0}));
  EXPECT_FLOAT_EQ(s.markers.scaleFactor, 10.0f);
  EXPECT_EQ(s.lines.color, (Color3{0, 1, 0}));
  EXPECT_FLOAT_EQ(s.lines.width, 1.0f);
  EXPECT_EQ(s.lines.endpointStyle, EndpointStyle::kButt);
  EXPECT_EQ(s.lines.joinStyle, JoinStyle::kMiter);
  EXPECT_FLOAT_EQ(s.lines.miterLimit, 2.0f);
  EXPECT_EQ(s.lines.style, LineStyle::kSolid);
  EXPECT_EQ(s.lines.pattern, LinePattern::kDotted);
  EXPECT_EQ(s.lines.altColor, (Color3{1, 1, 1}));
  EXPECT_EQ(s.front.color, (Color3{1, 1, 1}));
  EXPECT_EQ(s.front.fillStyle, FillStyle::kSolid);
  EXPECT_EQ(s.front.colorSelector, SurfaceColorSelector::kIllumIndependent);
  EXPECT_EQ(s.front.illumination, Illumination::kPerFacet);
  EXPECT_EQ(s.front.lightComponents, kLightAmbient | kLightDiffuse | kLightSpecular);
  EXPECT_FLOAT_EQ(s.front.ambient, 0.2f);
  EXPECT_FLOAT_EQ(s.front.diffuse, 0.8f);
  EXPECT_FLOAT_EQ(s.front.specular, 1.0f);
  EXPECT_FLOAT_EQ(s.front.specularPower, 20.0f);
  EXPECT_EQ(s.front.transparencyMethod, TransparencyMethod::kNone);
  EXPECT_EQ(s.front.transparencyBlend, TransparencyBlend::kNone);
  EXPECT_EQ(s.edges.show, EdgeMode::kOff);
  EXPECT_EQ(s.edges.color, (Color3{0, 0, 0}));
  EXPECT_FLOAT_EQ(s.edges.softwareOffset, 0.1f);
  EXPECT_EQ(s.nurbs.tessellation, NurbsTessellation::kDynamic);
  const DepthCue dc;
  EXPECT_EQ(dc.mode, DepthCueMode::kNone);
  EXPECT_FLOAT_EQ(dc.frontRefPlane, 0.2f);
  EXPECT_FLOAT_EQ(dc.backRefPlane, -0.2f);
  EXPECT_FLOAT_EQ(dc.maxScale, 1.0f);
  EXPECT_FLOAT_EQ(dc.minScale, 0.1f);
  const Annotation a;
  EXPECT_FLOAT_EQ(a.charHeight, 0.05f);
  EXPECT_EQ(a.style, AnnotationStyle::kLine);
  EXPECT_EQ(ModelClipping{}.numPlanes, 0);
  EXPECT_EQ(GlobalSettings{}.background, (Color3{0, 0, 0}));
  EXPECT_EQ(GlobalSettings{}.deferral, DeferralMode::kAsti);
}

TEST(Attributes, DefaultLightsFollowTheManual) {
  const auto lights = defaultLights();
  EXPECT_TRUE(lights[0].on);
  EXPECT_EQ(lights[0].type, LightType::kAmbient);
  EXPECT_TRUE(lights[1].on);
  EXPECT_EQ(lights[1].type, LightType::kDirectional);
  EXPECT_TRUE(lights[2].on);
  EXPECT_EQ(lights[2].type, LightType::kDirectional);
  EXPECT_EQ(lights[3].type, LightType::kSpot);
  EXPECT_EQ(lights[4].type, LightType::kPositional);
  for (std::size_t i = 3; i < kMaxLights; ++i) EXPECT_FALSE(lights[i].on) << "light " << i;
  for (std::size_t i = 5; i < kMaxLights; ++i) {
    EXPECT_EQ(lights[i].type, LightType::kDirectional) << "light " << i;
    if (i > 5) {
      EXPECT_NE(lights[i].color, lights[i - 1].color) << "lights 5..31 vary in colour";
    }
  }
}

TEST(Attributes, FieldTableNamesEveryAttribute) {
  for (const AttrField& f : attrFields()) {
    EXPECT_FALSE(f.name.empty());
    EXPECT_NE(f.name.find('.'), std::string_view::npos) << f.name;
    EXPECT_LE(f.offset + f.size, sizeof(PartStyle)) << f.name;
  }
  EXPECT_EQ(attrField(AttrId::kLinesWidth).name, "lines.line_width");
}

TEST(Show, PartSettingsWinOverGlobalOnes) {
  Show show = Show::makeDefault();
  const PartId face1 = *show.findPart("face 1");
  const PartId face2 = *show.findPart("face 2");
  show.editPartStyle(face1, AttrId::kRenderPrimType, [](PartStyle& s) { s.render.primType = PrimType::kWireframe; });
  show.editGlobalStyle([](PartStyle& s) {
    s.render.primType = PrimType::kMarkers;
    s.lines.width = 3;
  });
  EXPECT_EQ(show.resolvedStyle(face1).render.primType, PrimType::kWireframe)
      << "a global change must not affect an attribute the part set itself";
  EXPECT_EQ(show.resolvedStyle(face2).render.primType, PrimType::kMarkers);
  EXPECT_FLOAT_EQ(show.resolvedStyle(face1).lines.width, 3.0f) << "unset attributes follow global";
  show.clearPartAttr(face1, AttrId::kRenderPrimType);
  EXPECT_EQ(show.resolvedStyle(face1).render.primType, PrimType::kMarkers);
}

TEST(Show, PartNamesAreCaseSensitiveAndMayHaveSpaces) {
  Show show = Show::makeDefault();
  EXPECT_TRUE(show.findPart("face 3"));
  EXPECT_FALSE(show.findPart("Face 3"));
  EXPECT_EQ(show.partCount(), 6u);
}

TEST(Show, LoadingResetsAttributes) {
  Show show = Show::makeDefault();
  show.editGlobalStyle([](PartStyle& s) { s.lines.width = 5; });
  show.lights()[7].on = true;
  show.clear();
  EXPECT_EQ(show.partCount(), 0u);
  EXPECT_FLOAT_EQ(show.globalStyle().lines.width, 1.0f);
  EXPECT_FALSE(show.lights()[7].on);
}

TEST(Show, FreeRunMotionDependsOnlyOnFrames) {
  Show a = Show::makeDefault();
  Show b = Show::makeDefault();
  for (int i = 0; i < 60; ++i) a.advanceFrame();
  for (int i = 0; i < 60; ++i) b.advanceFrame();
  EXPECT_EQ(a.position().global, b.position().global);
  EXPECT_EQ(a.frameNumber(), 60u);
  EXPECT_NE(a.position().global, Show::makeDefault().position().global) << "the default show must turn";
}

TEST(Show, MotionStartRunsForNumFrames) {
  Show show;
  show.motion().globalRotate = {0, 1, 0};
  show.motion().numFrames = 3;
  show.startMotion();
  for (int i = 0; i < 10; ++i) show.advanceFrame();
  const Mat4 expected = Mat4::rotationY(3);
  for (std::size_t i = 0; i < 16; ++i) EXPECT_NEAR(show.position().global.m[i], expected.m[i], 1e-5f);
  EXPECT_FALSE(show.motion().globalFreeRun);
}

TEST(Show, InstancesShareTheirPartsAndGeometry) {
  Show show;
  auto cube = makeColorCube();
  SceneNode a;
  a.name = "a";
  a.mesh = cube;
  SceneNode b;
  b.name = "b";
  b.mesh = cube;
  b.local = Mat4::translation({3, 0, 0});
  show.addNode(a);
  show.addNode(b);
  EXPECT_EQ(show.partCount(), 6u);
  EXPECT_EQ(show.nodes()[0].mesh.get(), show.nodes()[1].mesh.get());
  const Bounds bounds = show.sceneBounds();
  EXPECT_FLOAT_EQ(bounds.min.x, -1);
  EXPECT_FLOAT_EQ(bounds.max.x, 4);
}

TEST(Show, ParentTransformsCompose) {
  Show show;
  SceneNode parent;
  parent.local = Mat4::translation({1, 0, 0});
  const NodeId p = show.addNode(parent);
  SceneNode child;
  child.parent = static_cast<std::int32_t>(p);
  child.local = Mat4::translation({0, 2, 0});
  const NodeId c = show.addNode(child);
  const Vec3 origin = show.worldTransform(c).transformPoint({0, 0, 0});
  EXPECT_EQ(origin, (Vec3{1, 2, 0}));
}

TEST(View, FullScreenFitsTheBoundingSphereInTheNarrowerDimension) {
  Show show = Show::makeDefault();
  show.position() = Position{};
  const ViewTransforms t = computeView(show, 2.0f);
  // The cube's corner (1,1,1) lies on the unit sphere after normalisation.
  const Vec3 corner = t.model.transformPoint({1, 1, 1});
  EXPECT_NEAR(length(corner), 1.0f, 1e-5f);
  // A point at the window's top edge (y = 1 on the z = 0 plane) projects to NDC y = 1.
  const Vec4 clip = t.projection * (t.view * Vec4{0, 1, 0, 1});
  EXPECT_NEAR(clip.y / clip.w, 1.0f, 1e-5f);
  const Vec4 side = t.projection * (t.view * Vec4{2, 0, 0, 1});
  EXPECT_NEAR(side.x / side.w, 1.0f, 1e-5f) << "wide windows extend to +-aspect horizontally";
}

TEST(Bindings, LavaDialTable) {
  Bindings b = Bindings::lavaDefaults();
  EXPECT_EQ(b.dial(0).action, Action::kRotateX);
  EXPECT_EQ(b.dial(1).action, Action::kRotateY);
  EXPECT_EQ(b.dial(2).action, Action::kRotateZ);
  EXPECT_EQ(b.dial(3).action, Action::kScale);
  EXPECT_EQ(b.dial(4).action, Action::kTranslateX);
  EXPECT_EQ(b.dial(5).action, Action::kTranslateY);
  EXPECT_EQ(b.dial(6).action, Action::kTranslateZ);
  EXPECT_EQ(b.dial(7).action, Action::kNone);
  Show show;
  EXPECT_TRUE(b.apply(Event{Nanos{0}, 1, EventKind::kDialDelta, 1, 0.25}, show));
  const Mat4 expected = Mat4::rotationY(90);
  for (std::size_t i = 0; i < 16; ++i) EXPECT_NEAR(show.position().global.m[i], expected.m[i], 1e-5f);
  EXPECT_FALSE(b.apply(Event{Nanos{0}, 1, EventKind::kDialDelta, 7, 1.0}, show));
}

}  // namespace
}  // namespace basalt::runtime
