// The op-equals table (LAVA manual section 10): "any numeric value following an equals sign
// may also be followed by an operator-equals sign (+=, -=, *=, or /=)", except rotations. For
// every command: which forms it takes, and what each sign does to each kind of value.
// Example failures: a rotation accepting +=; a colour refusing it; `*=` adding; an integer
// divided into a fraction; a division by zero changing the value.

#include <gtest/gtest.h>

#include <string>

#include "runtime/script/command_table.h"
#include "script_support.h"

namespace basalt::script {
namespace {

using test::parse;
using test::run;

bool isRotation(std::string_view name) { return name.ends_with("_rotate"); }

TEST(OpEqualsTable, NumbersTakeItRotationsAndChoicesDoNot) {
  std::size_t numeric = 0;
  std::size_t rotations = 0;
  for (const CommandDef& def : commands()) {
    if (def.syntax != Syntax::kAssignment) continue;
    const bool number = def.kind == ValueKind::kFloat || def.kind == ValueKind::kInt;
    const bool expected = number && !isRotation(def.name);
    EXPECT_EQ(def.acceptsOpEquals(), expected) << def.name;
    numeric += number ? 1u : 0u;
    rotations += isRotation(def.name) ? 1u : 0u;
    // And the parser agrees, for every sign.
    std::string target(def.name);
    if (def.scope == Scope::kIndexed) target += " [2]";
    const std::string value = number ? "2" : (def.kind == ValueKind::kFile ? "\"f.png\"" : "on");
    for (const char* sign : {"+=", "-=", "*=", "/="}) {
      std::string line = target;
      line.append(" ").append(sign).append(" ").append(value);
      const Program p = parse(line);
      EXPECT_EQ(p.errorCount() == 0, expected) << target << " " << sign;
    }
  }
  EXPECT_EQ(rotations, 12u) << "motion.{global,local}_{x,y,z}_rotate and position.{global,local}_{x,y,z}_rotate";
  EXPECT_GT(numeric, 80u);
}

TEST(OpEqualsTable, RotationsTakeOnlyEquals) {
  for (const char* name : {"motion.global_x_rotate", "motion.global_y_rotate", "motion.global_z_rotate",
                           "motion.local_x_rotate", "motion.local_y_rotate", "motion.local_z_rotate",
                           "position.local_x_rotate", "position.local_y_rotate", "position.local_z_rotate",
                           "position.global_x_rotate", "position.global_y_rotate", "position.global_z_rotate"}) {
    EXPECT_EQ(parse(std::string(name) + " = 5").errorCount(), 0u) << name;
    const Program p = parse(std::string(name) + " += 5");
    ASSERT_EQ(p.errorCount(), 1u) << name;
    EXPECT_NE(p.diagnostics[0].message.find("rotations take only '='"), std::string::npos);
  }
}

TEST(OpEquals, EachSignOnAFloat) {
  const auto r =
      run("lines.line_width = 6\nlines.line_width += 2\nlines.line_width -= 1\nlines.line_width *= 3\n"
          "lines.line_width /= 7");
  EXPECT_FLOAT_EQ(r.show.globalStyle().lines.width, 3.0f);
}

TEST(OpEquals, OnAPartWorksFromThePartsValue) {
  const auto r =
      run("lines.line_width = 2\nlines.line_width \"face 1\" = 5\nlines.line_width \"face 1\" += 1\n"
          "lines.line_width \"face 2\" *= 4");
  const runtime::Show& s = r.show;
  EXPECT_FLOAT_EQ(s.resolvedStyle(*s.findPart("face 1")).lines.width, 6);
  EXPECT_FLOAT_EQ(s.resolvedStyle(*s.findPart("face 2")).lines.width, 8) << "from the global 2 it followed";
  EXPECT_FLOAT_EQ(s.globalStyle().lines.width, 2);
}

TEST(OpEquals, ColoursTakeOneNumberPerComponentOrOneForAll) {
  const auto r =
      run("front_surf.color = 0.5 0.5 0.5\nfront_surf.color += 0.25 0 -0.25\nfront_surf.color *= 0.5\n"
          "global.background_color -= 0.5");
  EXPECT_EQ(r.show.globalStyle().front.color, (runtime::Color3{0.375f, 0.25f, 0.125f}));
  EXPECT_EQ(r.show.global().background, (runtime::Color3{-0.5f, -0.5f, -0.5f}));
  EXPECT_EQ(parse("front_surf.color += 1 1").errorCount(), 1u) << "two numbers for three components";
}

TEST(OpEquals, IntegersStayWhole) {
  const auto r =
      run("nurbs.iso_curves_u = 7\nnurbs.iso_curves_u /= 2\nmotion.num_frames = 10\nmotion.num_frames -= 3\n"
          "picking.pick_aperture += 2\npicking.pick_aperture += 0.5");
  EXPECT_EQ(r.show.globalStyle().nurbs.isoCurvesU, 3);
  EXPECT_EQ(r.show.motion().numFrames, 7);
  EXPECT_EQ(r.show.picking().aperture, 3 + 2);
  EXPECT_EQ(r.count(Severity::kError, "needs a whole number"), 1u) << "an integer takes whole numbers only";
}

TEST(OpEquals, IndexedValues) {
  const auto r = run("lighting.atten_1 [3] = 2\nlighting.atten_1 [3] *= 4\nmodel_clipping.coord [5] += 1 2 3");
  EXPECT_FLOAT_EQ(r.show.lights()[3].attenuation1, 8);
  const Vec3 expected = runtime::ModelClipping::defaultClipPlanes()[5].point + Vec3{1, 2, 3};
  EXPECT_EQ(r.show.modelClipping().planes[5].point, expected);
}

TEST(OpEquals, RangesHoldAndDivisionByZeroChangesNothing) {
  const auto r =
      run("front_surf.transparency = 0.75\nfront_surf.transparency += 0.5\nlines.line_width /= 0\n"
          "model_clipping.num_planes += 20\nlines.line_width -= 5");
  EXPECT_FLOAT_EQ(r.show.globalStyle().front.transparency, 0.75f);
  EXPECT_FLOAT_EQ(r.show.globalStyle().lines.width, 1);
  EXPECT_EQ(r.show.modelClipping().numPlanes, 0);
  EXPECT_EQ(r.count(Severity::kError, "outside 0 to 1;"), 1u);
  EXPECT_EQ(r.count(Severity::kError, "division by zero"), 1u);
  EXPECT_EQ(r.count(Severity::kError, "outside 0 to 16;"), 1u);
  EXPECT_EQ(r.count(Severity::kError, "line_width would become -4"), 1u);
}

TEST(OpEquals, MatricesElementByElement) {
  const auto r = run("position.local_matrix += 0 0 0 0  0 0 0 0  0 0 0 0  1 2 3 0");
  EXPECT_EQ(r.show.position().local(0, 3), 1);
  EXPECT_EQ(r.show.position().local(2, 3), 3);
  EXPECT_EQ(r.show.position().local(0, 0), 1);
}

}  // namespace
}  // namespace basalt::script
