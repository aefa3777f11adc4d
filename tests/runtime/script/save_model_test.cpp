// Save Model (LAVA manual section 8): the Show written as a script that, run on a fresh show,
// gives the same state, field for field, so that the picture is the same bit for bit (the
// render test checks the pixels). Also: the text reads back to the same text.
// Example failures: a per-part setting saved as global (it would stop winning over later
// global changes); a float written with too few digits; running motion restarted with the
// wrong frame count; deselected parts shown again; a texture lost.

#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <fstream>
#include <sstream>

#include "runtime/script/save_model.h"
#include "script_support.h"
#include "support/test_paths.h"

namespace basalt::script {
namespace {

using test::run;

/// A script that changes many settings: tests/runtime/script/scripts/rich_state.mdl.
std::string richScript() {
  std::ifstream in(basalt::test::sourceDir() / "tests/runtime/script/scripts/rich_state.mdl");
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_FALSE(text.str().empty()) << "tests/runtime/script/scripts/rich_state.mdl is missing";
  return text.str();
}

bool sameBits(const Mat4& a, const Mat4& b) {
  for (std::size_t i = 0; i < 16; ++i) {
    if (std::bit_cast<std::uint32_t>(a.m[i]) != std::bit_cast<std::uint32_t>(b.m[i])) return false;
  }
  return true;
}

/// Every part of the Show that a script can set, compared field by field.
void expectSameShow(const runtime::Show& a, const runtime::Show& b) {
  EXPECT_EQ(a.globalStyle(), b.globalStyle());
  EXPECT_EQ(a.lights(), b.lights());
  EXPECT_EQ(a.depthCue(), b.depthCue());
  EXPECT_EQ(a.fog(), b.fog());
  EXPECT_EQ(a.texture(), b.texture());
  EXPECT_EQ(a.modelClipping(), b.modelClipping());
  EXPECT_EQ(a.annotation(), b.annotation());
  EXPECT_EQ(a.picking(), b.picking());
  EXPECT_EQ(a.global(), b.global());
  EXPECT_EQ(a.motion(), b.motion());
  EXPECT_EQ(a.view(), b.view());
  EXPECT_EQ(a.environment(), b.environment());
  EXPECT_EQ(a.backgroundKind(), b.backgroundKind());
  EXPECT_EQ(a.earthSky(), b.earthSky());
  // Bit for bit, so that -0 and 0 count as different.
  EXPECT_TRUE(sameBits(a.position().global, b.position().global)) << "the global matrix differs";
  EXPECT_TRUE(sameBits(a.position().local, b.position().local)) << "the local matrix differs";
  EXPECT_TRUE(sameBits(a.position().view, b.position().view)) << "the view matrix differs";
  ASSERT_EQ(a.partCount(), b.partCount());
  for (runtime::PartId id = 0; id < a.partCount(); ++id) {
    const runtime::PartState& pa = a.part(id);
    const runtime::PartState& pb = b.part(id);
    EXPECT_EQ(pa.name, pb.name);
    EXPECT_EQ(pa.selected, pb.selected) << pa.name;
    EXPECT_EQ(pa.texture, pb.texture) << pa.name;
    EXPECT_EQ(pa.mask, pb.mask) << pa.name << ": which attributes the part sets itself";
    EXPECT_EQ(a.resolvedStyle(id), b.resolvedStyle(id)) << pa.name;
  }
}

TEST(SaveModel, RestoresEveryScriptableSetting) {
  const auto original = run(richScript());
  ASSERT_EQ(original.count(Severity::kError), 0u) << original.messages[0].describe();
  const std::string saved = saveModel(original.show, original.object);
  const auto restored = run(saved);
  EXPECT_EQ(restored.count(Severity::kError), 0u) << saved;
  expectSameShow(original.show, restored.show);
  EXPECT_EQ(saveModel(restored.show, restored.object), saved) << "saving again gives the same text";
}

TEST(SaveModel, RunningMotionGoesOnTheSame) {
  auto original = run(richScript());
  auto restored = run(saveModel(original.show, original.object));
  ASSERT_GT(original.show.motion().framesLeft, 0);
  for (int i = 0; i < 60; ++i) {
    original.show.advanceFrame();
    restored.show.advanceFrame();
  }
  expectSameShow(original.show, restored.show);
  EXPECT_FALSE(restored.show.motion().globalFreeRun) << "motion.start's 50 frames ran out on both";
}

TEST(SaveModel, AnotherObject) {
  const auto original =
      run("load_object \"models/boat.obj\"\nrender.prim_type mast = wireframe\n"
          "front_surf.color hull = 0.5 0.25 0\npart.deselect hull\n");
  const std::string saved = saveModel(original.show, original.object);
  EXPECT_NE(saved.find("load_object \"models/boat.obj\""), std::string::npos);
  EXPECT_EQ(saved.find("load_color_cube"), std::string::npos);
  const auto restored = run(saved);
  EXPECT_EQ(restored.host.objects.size(), 1u);
  expectSameShow(original.show, restored.show);
}

TEST(SaveModel, TheStartupShow) {
  const runtime::Show start = startupShow();
  const std::string saved = saveModel(start, ObjectSource{});
  EXPECT_EQ(saved.rfind("! Basalt Save Model", 0), 0u);
  EXPECT_NE(saved.find("\nload_color_cube\n"), std::string::npos);
  const auto restored = run(saved);
  EXPECT_TRUE(restored.messages.empty());
  expectSameShow(start, restored.show);
}

TEST(SaveModel, ExtremeNumbersReadBackExactly) {
  const auto original =
      run("position.local_matrix = 1e-38 -0 3.4028235e38 1.17549435e-38 0.1 0.2 0.3 1e-45 -1 -2 -3 -4 5 6 7 8\n"
          "front_surf.color = 0.333333343 1e-7 16777217\n");
  ASSERT_EQ(original.count(Severity::kError), 0u);
  const auto restored = run(saveModel(original.show, original.object));
  expectSameShow(original.show, restored.show);
}

TEST(SaveModel, SaysWhatItCannotSave) {
  runtime::Show show = startupShow();
  show.fog().mode = runtime::FogMode::kLinear;
  const std::string saved = saveModel(show, ObjectSource{});
  EXPECT_NE(saved.find("! Not saved"), std::string::npos);
  EXPECT_NE(saved.find("fog"), std::string::npos);
}

}  // namespace
}  // namespace basalt::script
