// What scripts do to the Show (no rendering): LAVA's global-versus-part rule, part selection,
// lights with [N], motion and position commands, loops and jitter loops, quit, the host's
// services, and bad lines reported once and skipped while the show goes on.
// Example failures: a global change overwriting a part's own setting; a loop running once too
// often; position moves not applied once per pass; a run-time error repeated a thousand times
// by a loop; a command whose feature is not drawn passing without a word.

#include <gtest/gtest.h>

#include <cmath>

#include "runtime/script/interpreter.h"
#include "script_support.h"

namespace basalt::script {
namespace {

using runtime::AttrId;
using runtime::PrimType;
using test::run;

runtime::PartId partId(const runtime::Show& show, std::string_view name) {
  auto id = show.findPart(name);
  EXPECT_TRUE(id.has_value()) << name;
  return id.value_or(0);
}

void expectMatNear(const Mat4& a, const Mat4& b, float eps = 1e-5f) {
  for (int i = 0; i < 16; ++i)
    EXPECT_NEAR(a.m[static_cast<std::size_t>(i)], b.m[static_cast<std::size_t>(i)], eps) << "element " << i;
}

TEST(Startup, TheCubeAtRest) {
  const runtime::Show s = startupShow();
  EXPECT_EQ(s.partCount(), 6u);
  EXPECT_TRUE(s.findPart("face 1").has_value());
  EXPECT_FALSE(s.motion().globalFreeRun) << "a script starts from rest";
  EXPECT_FALSE(s.motion().localFreeRun);
  EXPECT_EQ(s.motion().globalRotate, runtime::Show::makeDefault().motion().globalRotate)
      << "motion.global_free_run resumes the default show's turn";
}

TEST(Attributes, GlobalAndPerPartFollowLavasRule) {
  const auto r = run(R"(
render.prim_type "face 2" = markers
render.prim_type = wireframe        ! global: face 2 keeps its own
lines.line_width Global = 3
lines.line_width "face 1" = 5
)");
  EXPECT_EQ(r.messages.size(), 0u);
  const runtime::Show& s = r.show;
  EXPECT_EQ(s.globalStyle().render.primType, PrimType::kWireframe);
  EXPECT_EQ(s.resolvedStyle(partId(s, "face 1")).render.primType, PrimType::kWireframe);
  EXPECT_EQ(s.resolvedStyle(partId(s, "face 2")).render.primType, PrimType::kMarkers);
  EXPECT_FLOAT_EQ(s.resolvedStyle(partId(s, "face 1")).lines.width, 5);
  EXPECT_FLOAT_EQ(s.resolvedStyle(partId(s, "face 3")).lines.width, 3);
}

TEST(Attributes, EveryKindOfValueLandsInTheShow) {
  const auto r = run(R"(
front_surf.color = 0.25 0.5 0.75
front_surf.light_component = diffuse
nurbs.iso_curves_u = 7
render.face_dist = on
global.background_color = 0.1 0.2 0.3
depth_cue.mode = scaled
annotation.up_vector = 1 0
view.perspective = 0
env.floor = fine_grid
position.view_matrix = 2 0 0 0  0 2 0 0  0 0 2 0  0 0 0 1
model_clipping.num_planes = 2
picking.pick_aperture = 9
texture.switch = video
)");
  const runtime::Show& s = r.show;
  EXPECT_EQ(s.globalStyle().front.color, (runtime::Color3{0.25f, 0.5f, 0.75f}));
  EXPECT_EQ(s.globalStyle().front.lightComponents, runtime::kLightDiffuse);
  EXPECT_EQ(s.globalStyle().nurbs.isoCurvesU, 7);
  EXPECT_TRUE(s.globalStyle().render.faceDistinguishing);
  EXPECT_EQ(s.global().background, (runtime::Color3{0.1f, 0.2f, 0.3f}));
  EXPECT_EQ(s.depthCue().mode, runtime::DepthCueMode::kScaled);
  EXPECT_EQ(s.annotation().upVector, (Vec2{1, 0}));
  EXPECT_EQ(s.view().perspective, 0);
  EXPECT_EQ(s.environment().floor, runtime::FloorKind::kFineGrid);
  EXPECT_EQ(s.position().view(0, 0), 2);
  EXPECT_EQ(s.modelClipping().numPlanes, 2);
  EXPECT_EQ(s.picking().aperture, 9);
  EXPECT_EQ(s.texture().source, runtime::TextureSource::kVideo);
}

TEST(Attributes, ObjColorsSetsSurfaceLineAndMarkerColour) {
  const auto r = run("obj_colors.part_color \"face 4\"= 0.5 0.25 1\nobj_colors.part_color = 0 0 1");
  const auto& own = r.show.resolvedStyle(partId(r.show, "face 4"));
  EXPECT_EQ(own.front.color, (runtime::Color3{0.5f, 0.25f, 1}));
  EXPECT_EQ(own.lines.color, own.front.color);
  EXPECT_EQ(own.markers.color, own.front.color);
  EXPECT_EQ(r.show.globalStyle().lines.color, (runtime::Color3{0, 0, 1}));
}

TEST(Parts, SelectAndDeselect) {
  const auto r = run("part.deselect_all\npart.select \"face 3\"\npart.select \"face 6\"\n");
  for (runtime::PartId id = 0; id < r.show.partCount(); ++id) {
    const bool expected = r.show.part(id).name == "face 3" || r.show.part(id).name == "face 6";
    EXPECT_EQ(r.show.part(id).selected, expected) << r.show.part(id).name;
  }
  const auto all = run("part.deselect_all\npart.select_all\npart.deselect \"face 1\"");
  EXPECT_FALSE(all.show.part(partId(all.show, "face 1")).selected);
  EXPECT_TRUE(all.show.part(partId(all.show, "face 2")).selected);
}

TEST(Parts, UnknownOrMiscasedPartIsReportedAndSkipped) {
  const auto r = run("render.prim_type \"Face 1\" = wireframe\npart.select face_2\nrender.prim_type = markers\n");
  ASSERT_EQ(r.count(Severity::kError), 2u);
  EXPECT_EQ(r.count(Severity::kError, "case-sensitive: 'face 1'"), 1u);
  EXPECT_EQ(r.count(Severity::kError, "did you mean 'face 2'?"), 1u);
  EXPECT_EQ(r.messages[0].line, 1u);
  // The show went on: the next line did its work, and no part was changed by the bad ones.
  EXPECT_EQ(r.show.globalStyle().render.primType, PrimType::kMarkers);
  EXPECT_FALSE(r.show.part(partId(r.show, "face 1")).mask.test(static_cast<std::size_t>(AttrId::kRenderPrimType)));
}

TEST(Parts, GlobalIsNotAPartToSelect) {
  const auto r = run("part.select Global");
  EXPECT_EQ(r.count(Severity::kError, "part.select_all"), 1u);
}

TEST(Lights, IndexedAndCurrentLight) {
  const auto r = run(R"(
lighting.switch [4] = on
lighting.color = 1 0 0        ! no index: light 4, named last
lighting.type [7] = spot
lighting.angle = 0.25
lighting.exponent [7] *= 2
)");
  const auto& lights = r.show.lights();
  EXPECT_TRUE(lights[4].on);
  EXPECT_EQ(lights[4].color, (runtime::Color3{1, 0, 0}));
  EXPECT_EQ(lights[7].type, runtime::LightType::kSpot);
  EXPECT_FLOAT_EQ(lights[7].angle, 0.25f);
  EXPECT_FLOAT_EQ(lights[7].exponent, 2 * runtime::defaultLights()[7].exponent);
  EXPECT_EQ(lights[0], runtime::defaultLights()[0]);
  const auto first = run("lighting.color = 0 1 0");
  EXPECT_EQ(first.show.lights()[0].color, (runtime::Color3{0, 1, 0})) << "the current light starts at 0";
}

TEST(Motion, FreeRunStartStopAndFrames) {
  auto r = run("motion.global_x_rotate = 2\nmotion.global_free_run\ndraw\ndraw\nmotion.global_stop\ndraw\n");
  // Two frames of free run (advanced after each draw), then stopped.
  runtime::Show expected = startupShow();
  // The start-up turn is 0.25 and 0.5 degrees about X and Y; the script changed X only.
  expected.rotateGlobal({2, 0.5f, 0});
  expected.rotateGlobal({2, 0.5f, 0});
  expectMatNear(r.show.position().global, expected.position().global);
  EXPECT_FALSE(r.show.motion().globalFreeRun);

  auto counted = run("motion.num_frames = 3\nmotion.local_y_rotate = 10\nmotion.start\nloop 5\n draw\nend_loop");
  runtime::Show e = startupShow();
  for (int i = 0; i < 3; ++i) e.rotateLocal({0, 10, 0});
  expectMatNear(counted.show.position().local, e.position().local);
  EXPECT_FALSE(counted.show.motion().localFreeRun) << "motion.start runs num_frames frames, then stops";

  auto localOnly = run("motion.local_free_run\nmotion.global_free_run\nmotion.local_stop");
  EXPECT_TRUE(localOnly.show.motion().globalFreeRun) << "stopping one matrix leaves the other running";
  auto reset = run("position.global_x_translate = 1\nmotion.reset_transforms");
  EXPECT_EQ(reset.show.position().global, Mat4{});
}

TEST(Position, MovesApplyOncePerCommandAndPass) {
  const auto r =
      run("position.reset_transforms\nloop 10\n position.local_x_translate = 0.1\n"
          " position.global_y_rotate = 3\n position.global_scale = 2\nend_loop");
  Mat4 local;
  Mat4 global;
  for (int i = 0; i < 10; ++i) {
    local = local * Mat4::translation({0.1f, 0, 0});
    global = Mat4::rotationY(3) * global;
    global = Mat4::scaling({2, 2, 2}) * global;
  }
  expectMatNear(r.show.position().local, local, 1e-4f);
  expectMatNear(r.show.position().global, global, 1e-2f);
}

TEST(Position, OpEqualsChangesTheAmountEachPass) {
  // Accelerating: the amount grows by 0.1 each pass: 0.1 + 0.2 + 0.3 = 0.6.
  const auto r = run("position.reset_transforms\nloop 3\n position.local_z_translate += 0.1\nend_loop");
  EXPECT_NEAR(r.show.position().local(2, 3), 0.6f, 1e-6f);
  const auto s = run("position.reset_transforms\nposition.global_scale = 2\nposition.global_scale /= 4");
  EXPECT_NEAR(s.show.position().global(0, 0), 1.0f, 1e-6f) << "2, then 2/4 = 0.5: 2 * 0.5";
}

TEST(Position, MatricesAreSetExactly) {
  const auto r =
      run("position.local_matrix = 1 0 0 0 0 1 0 0 0 0 1 0 0.5 -0 0.25 1\n"
          "position.global_matrix = 0 1 0 0 -1 0 0 0 0 0 1 0 0 0 0 1");
  EXPECT_EQ(r.show.position().local(0, 3), 0.5f) << "16 numbers in OpenGL order: the translation comes last";
  EXPECT_TRUE(std::signbit(r.show.position().local(1, 3)));
  EXPECT_EQ(r.show.position().global(1, 0), 1.0f);
}

TEST(Position, OverflowIsRefusedAndNothingMoves) {
  const auto r = run("position.reset_transforms\nloop 40\n position.global_scale = 1e30\nend_loop");
  EXPECT_EQ(r.count(Severity::kError, "overflows the matrix"), 1u) << "reported once, not once per pass";
  for (float f : r.show.position().global.m) EXPECT_TRUE(std::isfinite(f));
}

TEST(Loops, RunTheRightNumberOfTimes) {
  const auto r = run("loop 3\n loop 4\n  draw\n end_loop\n draw\nend_loop\nloop 0\n draw\nend_loop\n");
  std::size_t draws = 0;
  for (const StepResult& s : r.steps) draws += s.stop == StepStop::kDraw ? 1 : 0;
  EXPECT_EQ(draws, 3u * (4 + 1));
  EXPECT_EQ(r.steps.back().stop, StepStop::kEnd);
}

TEST(Loops, TwelveLevelsDeep) {
  std::string text;
  for (int i = 0; i < 12; ++i) text += "loop 2\n";
  text += "lines.line_width += 1\ndraw\n";
  for (int i = 0; i < 12; ++i) text += "end_loop\n";
  const auto r = run(text);
  EXPECT_FLOAT_EQ(r.show.globalStyle().lines.width, 1 + 4096);
  EXPECT_EQ(r.steps.size(), 4096u + 1);
}

TEST(Loops, ValuesChangeFromPassToPass) {
  // The manual's example: lines get fatter between the inner loops.
  const auto r =
      run("lines.line_width = 1\nloop 5\n draw\n lines.line_width += 1.0\n draw\n lines.line_width += 1.0\nend_loop");
  EXPECT_FLOAT_EQ(r.show.globalStyle().lines.width, 11);
}

TEST(Jitter, PassesHaveOffsetsAndAreAccumulated) {
  const auto r = run("jitter 8\n draw\nend_jitter\nsave_image\nquit");
  ASSERT_EQ(r.steps.size(), 9u);
  for (int i = 0; i < 8; ++i) {
    const StepResult& s = r.steps[static_cast<std::size_t>(i)];
    EXPECT_EQ(s.stop, StepStop::kDraw);
    EXPECT_EQ(s.jitterPass, i);
    EXPECT_EQ(s.jitterPasses, 8);
    EXPECT_EQ(s.offset, jitterOffset(i));
    EXPECT_LT(std::fabs(s.offset.x), 0.5f);
    EXPECT_LT(std::fabs(s.offset.y), 0.5f);
  }
  // Distinct offsets, averaging near the pixel centre.
  float sx = 0;
  float sy = 0;
  for (int i = 0; i < 8; ++i) {
    for (int j = i + 1; j < 8; ++j) EXPECT_NE(jitterOffset(i), jitterOffset(j));
    sx += jitterOffset(i).x;
    sy += jitterOffset(i).y;
  }
  EXPECT_LT(std::fabs(sx / 8), 0.1f);
  EXPECT_LT(std::fabs(sy / 8), 0.1f);
  ASSERT_EQ(r.host.passes.size(), 8u);
  EXPECT_EQ(r.host.passes[7], (std::pair<int, int>{7, 8}));
  ASSERT_EQ(r.host.images.size(), 1u);
  EXPECT_EQ(r.host.images[0], "") << "save_image without a name: the host's default (ras.im32)";
  EXPECT_EQ(r.steps.back().stop, StepStop::kQuit);
  EXPECT_EQ(r.count(Severity::kNote, "averaged"), 1u) << "the averaged picture is not shown yet: said once";
}

TEST(Jitter, OffsetCommandAddsToEveryDraw) {
  const auto r = run("jitter_offset = 0.25 -0.25\ndraw\njitter_offset *= 2\ndraw");
  EXPECT_EQ(r.steps[0].offset, (Vec2{0.25f, -0.25f}));
  EXPECT_EQ(r.steps[1].offset, (Vec2{0.5f, -0.5f}));
  EXPECT_EQ(r.steps[0].jitterPass, -1);
}

TEST(Quit, EndsTheScriptThere) {
  const auto r = run("draw\nquit\nrender.prim_type = wireframe\ndraw\n");
  ASSERT_EQ(r.steps.size(), 2u);
  EXPECT_EQ(r.steps[1].stop, StepStop::kQuit);
  EXPECT_EQ(r.steps[1].line, 2u);
  EXPECT_EQ(r.show.globalStyle().render.primType, PrimType::kSolid);
}

TEST(Host, ObjectsTexturesImagesAndTheVcr) {
  const auto r = run(R"(
load_object "models/boat.obj"
render.prim_type hull = wireframe
part.deselect_all
part.select mast
load_texture "tex/wood.png"
save_image "shot.png"
tv.movie = "clip.mkv"
tv.repeat = on
tv.shuttle = 10
tv.shuttle += 5
tv.camera = off
)");
  ASSERT_EQ(r.host.objects.size(), 1u);
  EXPECT_EQ(r.host.objects[0], std::filesystem::path("models/boat.obj"));
  EXPECT_FALSE(r.object.colorCube);
  EXPECT_EQ(r.object.file, "models/boat.obj");
  EXPECT_EQ(r.show.resolvedStyle(partId(r.show, "hull")).render.primType, PrimType::kWireframe);
  EXPECT_EQ(r.show.part(partId(r.show, "mast")).texture, "tex/wood.png") << "the texture goes on displayed parts";
  EXPECT_EQ(r.show.part(partId(r.show, "hull")).texture, "");
  EXPECT_EQ(r.show.texture().source, runtime::TextureSource::kImage) << "loading a texture turns texturing on";
  EXPECT_EQ(r.host.images, (std::vector<std::string>{"shot.png"}));
  ASSERT_EQ(r.host.tvRequests.size(), 5u);
  EXPECT_EQ(r.host.tvRequests[0].op, TvOp::kMovie);
  EXPECT_EQ(r.host.tvRequests[0].file, std::filesystem::path("clip.mkv"));
  EXPECT_TRUE(r.host.tvRequests[1].on);
  EXPECT_EQ(r.host.tvRequests[2].frames, 10);
  EXPECT_EQ(r.host.tvRequests[3].frames, 15) << "op-equals on the shuttle works from the last value";
  EXPECT_EQ(r.host.tvRequests[4].op, TvOp::kCamera);
  // The host answered "unavailable" to each VCR line: each reported once, with its line.
  EXPECT_EQ(r.count(Severity::kError, "no movie player"), 5u);
  EXPECT_EQ(r.count(Severity::kNote, "texture mapping"), 1u);
}

TEST(Host, AFailedLoadLeavesTheShowAndReportsTheLine) {
  test::Run r;
  Program program = test::parse("draw\nload_object \"missing.obj\"\nrender.prim_type \"face 1\" = wireframe\ndraw\n");
  Interpreter in(std::move(program), "shows");
  r.host.failObjects = true;
  in.setReporter([&r](const Diagnostic& d) { r.messages.push_back(d); });
  EXPECT_EQ(in.step(r.show, r.host).stop, StepStop::kDraw);
  EXPECT_EQ(in.step(r.show, r.host).stop, StepStop::kDraw);
  ASSERT_EQ(r.messages.size(), 1u);
  EXPECT_EQ(r.messages[0].line, 2u);
  EXPECT_NE(r.messages[0].message.find("load_object"), std::string::npos);
  EXPECT_EQ(r.host.objects[0], std::filesystem::path("shows/missing.obj")) << "resolved against the script's folder";
  EXPECT_TRUE(in.objectSource().colorCube);
  EXPECT_EQ(r.show.partCount(), 6u);
  EXPECT_EQ(r.show.resolvedStyle(partId(r.show, "face 1")).render.primType, PrimType::kWireframe);
}

TEST(Host, LoadColorCubeResetsEverything) {
  const auto r = run("load_object boat.obj\nrender.prim_type = markers\nlighting.switch [9] = on\nload_color_cube");
  EXPECT_TRUE(r.object.colorCube);
  EXPECT_EQ(r.show.partCount(), 6u);
  EXPECT_EQ(r.show.globalStyle().render.primType, PrimType::kSolid);
  EXPECT_FALSE(r.show.lights()[9].on);
  EXPECT_EQ(r.show.position(), startupShow().position());
}

TEST(Reports, ARuntimeErrorInALoopIsReportedOnce) {
  const auto r = run("loop 1000\n lines.line_width /= 0\n draw\nend_loop");
  EXPECT_EQ(r.count(Severity::kError, "division by zero"), 1u);
  EXPECT_EQ(r.steps.size(), 1001u) << "and the show went on";
  EXPECT_FLOAT_EQ(r.show.globalStyle().lines.width, 1);
}

TEST(Reports, UnrenderedFeaturesAreNotedOnceAndOnlyWhenChanged) {
  const auto quiet = run("edges.show_edges = off\ndepth_cue.mode = none\nlighting.switch [0] = on");
  EXPECT_EQ(quiet.count(Severity::kNote), 0u) << "settings at their start-up values change nothing on screen";
  const auto r =
      run("edges.show_edges = on\nedges.edge_color = 1 0 0\ndepth_cue.mode = linear\nloop 3\n"
          " depth_cue.color += 0.1 0.1 0.1\nend_loop\ntexture.binding\ntexture.binding\nupdate_menus");
  EXPECT_EQ(r.count(Severity::kNote, "not rendered yet: edges"), 1u);
  EXPECT_EQ(r.count(Severity::kNote, "not rendered yet: depth cueing"), 1u);
  EXPECT_EQ(r.count(Severity::kNote, "texture.binding has no effect"), 1u);
  EXPECT_EQ(r.count(Severity::kNote, "update_menus has no effect"), 1u);
  EXPECT_EQ(r.count(Severity::kError), 0u);
  EXPECT_EQ(r.show.environment(), startupShow().environment());
  EXPECT_EQ(r.show.globalStyle().edges.color, (runtime::Color3{1, 0, 0})) << "stored all the same";
}

TEST(Reports, ALoopWithoutDrawGivesTheFrameBack) {
  Program program = test::parse("loop 100000\n lines.line_width += 1\nend_loop\ndraw\n");
  Interpreter in(std::move(program), ".");
  std::vector<Diagnostic> messages;
  in.setReporter([&messages](const Diagnostic& d) { messages.push_back(d); });
  in.setInstructionBudget(1000);
  runtime::Show show = startupShow();
  test::RecordingHost host;
  EXPECT_EQ(in.step(show, host).stop, StepStop::kBudget);
  ASSERT_EQ(messages.size(), 1u);
  EXPECT_NE(messages[0].message.find("without a draw"), std::string::npos);
  int steps = 1;
  while (in.step(show, host).stop == StepStop::kBudget) ++steps;
  EXPECT_GT(steps, 100) << "the loop goes on over the following frames";
  EXPECT_FLOAT_EQ(show.globalStyle().lines.width, 100001);
}

TEST(Reports, NoFinalMoveIsStoredAndNoted) {
  test::Run r;
  Interpreter in(test::parse("no_final_move\ndraw_no_clear"), ".");
  in.setReporter([&r](const Diagnostic& d) { r.messages.push_back(d); });
  const StepResult s = in.step(r.show, r.host);
  EXPECT_TRUE(in.noFinalMove());
  EXPECT_FALSE(s.clear);
  EXPECT_EQ(r.count(Severity::kNote, "not rendered yet"), 2u);
}

TEST(Load, MissingFileIsAClearError) {
  auto in = Interpreter::load("/nonexistent/show.mdl");
  ASSERT_FALSE(in.has_value());
  EXPECT_EQ(in.error().code(), Errc::kNotFound);
  EXPECT_NE(in.error().describe().find("/nonexistent/show.mdl"), std::string::npos);
}

}  // namespace
}  // namespace basalt::script
