// Parsing every command of LAVA manual section 10 in every value form, the five per-part forms,
// [N] indices, case rules, loops nested deeper than LAVA's ten levels, and the messages for bad
// lines: file:line, the expected form, the valid choices and a "did you mean".
// Example failures: a command of the manual missing from the table; `render.prim_type Global`
// setting a part named Global; `RENDER.PRIM_TYPE = SOLID` refused; a part name matched without
// case; a misspelt command reported without a suggestion; an unclosed loop silently dropped.

#include <gtest/gtest.h>

#include <cctype>
#include <set>
#include <string>

#include "runtime/script/command_table.h"
#include "runtime/script/program.h"
#include "script_support.h"

namespace basalt::script {
namespace {

using test::parse;

/// Every command the manual's section 10 lists, with the manual's own spelling.
constexpr std::string_view kManualCommands[] = {"part.select",
                                                "part.deselect",
                                                "part.select_all",
                                                "part.deselect_all",
                                                "render.prim_type",
                                                "render.face_culling",
                                                "render.face_dist",
                                                "render.raster_op",
                                                "render.hlshr_mode",
                                                "markers.marker_type",
                                                "markers.marker_color",
                                                "markers.antialiasing",
                                                "markers.scale_factor",
                                                "markers.color_selector",
                                                "lines.line_color",
                                                "lines.antialiasing",
                                                "lines.line_width",
                                                "lines.endpoint_style",
                                                "lines.join_style",
                                                "lines.miter_limit",
                                                "lines.line_style",
                                                "lines.line_pattern",
                                                "lines.alt_line_color",
                                                "lines.color_selector",
                                                "lines.color_interp",
                                                "front_surf.color",
                                                "front_surf.fill_style",
                                                "front_surf.stipple_pattern",
                                                "front_surf.color_selector",
                                                "front_surf.illum",
                                                "front_surf.light_component",
                                                "front_surf.ambient",
                                                "front_surf.diffuse",
                                                "front_surf.specular",
                                                "front_surf.specular_color",
                                                "front_surf.specular_power",
                                                "front_surf.transp_method",
                                                "front_surf.transp_blend_eq",
                                                "front_surf.transparency",
                                                "back_surf.color",
                                                "back_surf.fill_style",
                                                "back_surf.stipple_pattern",
                                                "back_surf.color_selector",
                                                "back_surf.illum",
                                                "back_surf.light_component",
                                                "back_surf.ambient",
                                                "back_surf.diffuse",
                                                "back_surf.specular",
                                                "back_surf.specular_color",
                                                "back_surf.specular_power",
                                                "edges.show_edges",
                                                "edges.edge_color",
                                                "edges.antialiasing",
                                                "edges.edge_width",
                                                "edges.edge_style",
                                                "edges.edge_pattern",
                                                "edges.alt_edge_color",
                                                "edges.silhouette",
                                                "nurbs.approx_method",
                                                "nurbs.approx_val_u",
                                                "nurbs.approx_val_v",
                                                "nurbs.param_style",
                                                "nurbs.iso_curve_placement",
                                                "nurbs.iso_curves_u",
                                                "nurbs.iso_curves_v",
                                                "picking.picking",
                                                "picking.part_highlight_color",
                                                "picking.facet_highlight_color",
                                                "picking.pick_aperture",
                                                "lighting.switch",
                                                "lighting.type",
                                                "lighting.color",
                                                "lighting.direction",
                                                "lighting.position",
                                                "lighting.atten_1",
                                                "lighting.atten_2",
                                                "lighting.angle",
                                                "lighting.exponent",
                                                "depth_cue.mode",
                                                "depth_cue.color",
                                                "depth_cue.front_ref_plane",
                                                "depth_cue.back_ref_plane",
                                                "depth_cue.max_scale",
                                                "depth_cue.min_scale",
                                                "texture.switch",
                                                "texture.binding",
                                                "texture.approx",
                                                "texture.subseg",
                                                "texture.pixel_tol",
                                                "texture.tau_func",
                                                "texture.update",
                                                "model_clipping.num_planes",
                                                "model_clipping.coord",
                                                "model_clipping.normal",
                                                "annotation.show",
                                                "annotation.antialiasing",
                                                "annotation.char_height",
                                                "annotation.slant_angle",
                                                "annotation.up_vector",
                                                "annotation.color",
                                                "annotation.style",
                                                "annotation.pointer_length",
                                                "annotation.horiz_alignment",
                                                "annotation.vert_alignment",
                                                "annotation.text_path",
                                                "global.background_color",
                                                "global.deferral_mode",
                                                "global.double_buffered",
                                                "global.stereo_mode",
                                                "global.reset_attr",
                                                "motion.reset_transforms",
                                                "motion.stop",
                                                "motion.start",
                                                "motion.num_frames",
                                                "motion.global_x_rotate",
                                                "motion.global_y_rotate",
                                                "motion.global_z_rotate",
                                                "motion.global_scale",
                                                "motion.global_free_run",
                                                "motion.global_stop",
                                                "motion.local_x_rotate",
                                                "motion.local_y_rotate",
                                                "motion.local_z_rotate",
                                                "motion.local_free_run",
                                                "motion.local_stop",
                                                "view.center_x",
                                                "view.center_y",
                                                "view.center_z",
                                                "view.object_center",
                                                "view.object_scale",
                                                "view.view_scale",
                                                "view.z_clip_scale",
                                                "view.perspective",
                                                "env.floor",
                                                "env.floor_color",
                                                "env.floor_prim_type",
                                                "env.floor_position",
                                                "env.shadow",
                                                "env.shadow_darkness",
                                                "position.reset_transforms",
                                                "position.local_scale",
                                                "position.local_x_translate",
                                                "position.local_y_translate",
                                                "position.local_z_translate",
                                                "position.local_x_rotate",
                                                "position.local_y_rotate",
                                                "position.local_z_rotate",
                                                "position.global_scale",
                                                "position.global_x_translate",
                                                "position.global_y_translate",
                                                "position.global_z_translate",
                                                "position.global_x_rotate",
                                                "position.global_y_rotate",
                                                "position.global_z_rotate",
                                                "position.local_matrix",
                                                "position.global_matrix",
                                                "position.view_matrix",
                                                "obj_colors.part_color",
                                                "load_object",
                                                "load_texture",
                                                "draw",
                                                "draw_no_clear",
                                                "no_final_move",
                                                "update_menus",
                                                "loop",
                                                "end_loop",
                                                "quit",
                                                "save_image",
                                                "jitter",
                                                "end_jitter",
                                                "jitter_offset"};

/// A valid line for `def` with one sample value of every kind.
std::string sampleLine(const CommandDef& def) {
  std::string line(def.name);
  switch (def.syntax) {
    case Syntax::kAction: return line;
    case Syntax::kOptionalArgument:
    case Syntax::kArgument:
      if (def.kind == ValueKind::kInt) return line + " 2";
      if (def.kind == ValueKind::kPartName) return line + " \"face 1\"";
      return line + " \"file.png\"";
    case Syntax::kAssignment: break;
  }
  if (def.scope == Scope::kIndexed) line += " [1]";
  line += " = ";
  switch (def.kind) {
    case ValueKind::kBool: return line + "on";
    case ValueKind::kEnum: return line + std::string(def.choices.back());
    case ValueKind::kFlags: {
      for (std::string_view c : def.choices) line += std::string(c) + " ";
      return line;
    }
    case ValueKind::kFloat:
      for (int i = 0; i < def.count; ++i) line += "0.5 ";
      return line;
    case ValueKind::kInt: return line + "1";
    case ValueKind::kFile: return line + "\"movie.mpg\"";
    default: return line;
  }
}

TEST(CommandTable, HasEveryCommandOfTheManual) {
  for (std::string_view name : kManualCommands) {
    EXPECT_NE(findCommand(name), nullptr) << name << " (LAVA manual section 10) is missing from the table";
  }
}

TEST(CommandTable, NamesAreUniqueAndLowerCase) {
  std::set<std::string_view> seen;
  for (const CommandDef& def : commands()) {
    EXPECT_TRUE(seen.insert(def.name).second) << def.name << " twice";
    for (char c : def.name) EXPECT_FALSE(std::isupper(static_cast<unsigned char>(c))) << def.name;
    EXPECT_FALSE(def.summary.empty()) << def.name << " has no summary for the reference";
  }
}

TEST(CommandTable, PerPartCommandsStoreIntoTheAttributeTable) {
  // The table builds on runtime::attrFields(): every per-part attribute has a command, and the
  // command's value is exactly the attribute's size.
  std::set<runtime::AttrId> covered;
  for (const CommandDef& def : commands()) {
    if (def.action != Action::kStore || def.attr == runtime::AttrId::kCount) continue;
    covered.insert(def.attr);
    EXPECT_EQ(valueBytes(def), runtime::attrField(def.attr).size) << def.name;
    EXPECT_EQ(def.name, runtime::attrField(def.attr).name) << "the script name is the attribute table's";
  }
  // Back-surface transparency has no command: the manual says back faces use the front's. The
  // thesis' emission and ambient colour (scene materials) are not part of LAVA's language.
  for (const runtime::AttrField& f : runtime::attrFields()) {
    const bool backTransparency = f.id == runtime::AttrId::kBackTranspMethod ||
                                  f.id == runtime::AttrId::kBackTranspBlendEq ||
                                  f.id == runtime::AttrId::kBackTransparency;
    const bool sceneMaterial = f.id == runtime::AttrId::kFrontEmission || f.id == runtime::AttrId::kFrontAmbientColor ||
                               f.id == runtime::AttrId::kBackEmission || f.id == runtime::AttrId::kBackAmbientColor;
    EXPECT_EQ(covered.count(f.id) == 1, !backTransparency && !sceneMaterial) << f.name;
  }
}

TEST(Parse, EveryCommandInEveryValueForm) {
  for (const CommandDef& def : commands()) {
    const std::string line = sampleLine(def);
    const Program p = parse(line + "\n" + (def.action == Action::kLoop ? "end_loop\n" : "") +
                            (def.action == Action::kJitter ? "draw\nend_jitter\n" : ""));
    if (def.action == Action::kEndLoop || def.action == Action::kEndJitter) {
      // An end alone is an error; with its opener it is the second instruction.
      const Program opened = parse(std::string(def.action == Action::kEndLoop ? "loop 2\n" : "jitter 2\n") + line);
      EXPECT_TRUE(opened.diagnostics.empty()) << line;
      ASSERT_EQ(opened.instrs.size(), 2u) << line;
      EXPECT_EQ(&opened.def(opened.instrs[1]), &def);
      continue;
    }
    EXPECT_TRUE(p.diagnostics.empty()) << line << ": " << (p.diagnostics.empty() ? "" : p.diagnostics[0].describe());
    ASSERT_GE(p.instrs.size(), 1u) << line;
    const Instr& in = p.instrs[0];
    EXPECT_EQ(&p.def(in), &def) << line;
    EXPECT_EQ(in.line, 1u);
    if (def.scope == Scope::kIndexed) {
      EXPECT_EQ(in.index, 1) << line;
    }
    if (def.kind == ValueKind::kFloat) {
      ASSERT_EQ(in.count, def.count) << line;
      for (int i = 0; i < def.count; ++i) EXPECT_EQ(p.floats[in.values + static_cast<std::size_t>(i)], 0.5f) << line;
    }
    if (def.kind == ValueKind::kEnum) {
      EXPECT_EQ(p.numbers[in.values], static_cast<double>(def.choices.size() - 1)) << line;
    }
    if (def.kind == ValueKind::kFlags) {
      EXPECT_EQ(p.numbers[in.values], static_cast<double>((1u << def.choices.size()) - 1)) << line;
    }
    if (def.kind == ValueKind::kBool) {
      EXPECT_EQ(p.numbers[in.values], 1.0) << line;
    }
  }
}

TEST(Parse, EveryChoiceOfEveryEnumeratedValue) {
  for (const CommandDef& def : commands()) {
    if (def.kind != ValueKind::kEnum && def.kind != ValueKind::kBool) continue;
    for (std::size_t i = 0; i < def.choices.size(); ++i) {
      const Program p = parse(std::string(def.name) + (def.scope == Scope::kIndexed ? " [0]" : "") + " = " +
                              std::string(def.choices[i]));
      ASSERT_TRUE(p.diagnostics.empty()) << def.name << " " << def.choices[i];
      EXPECT_EQ(p.numbers[p.instrs[0].values], static_cast<double>(i)) << def.name << " " << def.choices[i];
    }
  }
}

TEST(Parse, FlagsTakeZeroOrMoreChoices) {
  const Program none = parse("front_surf.light_component =");
  ASSERT_TRUE(none.diagnostics.empty());
  EXPECT_EQ(none.numbers[0], 0);
  const Program two = parse("front_surf.light_component = specular AMBIENT");
  ASSERT_TRUE(two.diagnostics.empty());
  EXPECT_EQ(two.numbers[0], static_cast<double>(runtime::kLightAmbient | runtime::kLightSpecular));
  const Program tess = parse("nurbs.param_style = show_tess");
  ASSERT_TRUE(tess.diagnostics.empty());
  EXPECT_EQ(tess.numbers[0], static_cast<double>(runtime::kNurbsShowTess));
}

TEST(Parse, TheFivePerPartForms) {
  const char* global[] = {"render.prim_type = solid! Sets global primitive type to solid",
                          "render.prim_type Global = solid! Sets global primitive type to solid",
                          "render.prim_type \"Global\" = solid! Sets global primitive type to solid"};
  for (const char* line : global) {
    const Program p = parse(line);
    ASSERT_TRUE(p.diagnostics.empty()) << line;
    EXPECT_EQ(p.instrs[0].text, kNoString) << line << " must set the global value";
  }
  const char* part[] = {"render.prim_type part_1 = solid! Sets part_1 to solid",
                        "render.prim_type \"part_1\" = solid! Sets part_1 to solid"};
  for (const char* line : part) {
    const Program p = parse(line);
    ASSERT_TRUE(p.diagnostics.empty()) << line;
    ASSERT_NE(p.instrs[0].text, kNoString) << line;
    EXPECT_EQ(p.strings[p.instrs[0].text], "part_1") << line;
  }
  // A name with a space needs quotes; "global" (another case) is a part name, not Global.
  const Program spaced = parse("lines.line_width \"face 1\" = 2");
  ASSERT_TRUE(spaced.diagnostics.empty());
  EXPECT_EQ(spaced.strings[spaced.instrs[0].text], "face 1");
  const Program lower = parse("render.prim_type global = solid");
  ASSERT_TRUE(lower.diagnostics.empty());
  EXPECT_EQ(lower.strings[lower.instrs[0].text], "global");
  const Program unquoted = parse("lines.line_width face 1 = 2");
  EXPECT_EQ(unquoted.errorCount(), 1u) << "an unquoted name with a space is an error";
}

TEST(Parse, CommandsAndValuesIgnoreCasePartNamesKeepIt) {
  const Program p = parse("RENDER.Prim_Type \"Face 1\" = WireFrame\nDRAW\nLines.LINE_WIDTH += 1\nLoop 2\nEnd_Loop");
  ASSERT_TRUE(p.diagnostics.empty()) << p.diagnostics[0].describe();
  ASSERT_EQ(p.instrs.size(), 5u);
  EXPECT_EQ(p.def(p.instrs[0]).name, "render.prim_type");
  EXPECT_EQ(p.strings[p.instrs[0].text], "Face 1") << "part names keep their case";
  EXPECT_EQ(p.numbers[p.instrs[0].values], 0) << "WireFrame is wireframe";
  EXPECT_EQ(p.def(p.instrs[1]).name, "draw");
}

TEST(Parse, IndicesSelectLightsAndPlanes) {
  const Program p = parse(
      "lighting.switch [4] = on\nlighting.color[31]=1 0 0\nmodel_clipping.coord [ 15 ] = 0 0 0\n"
      "lighting.type = spot");
  ASSERT_TRUE(p.diagnostics.empty()) << p.diagnostics[0].describe();
  EXPECT_EQ(p.instrs[0].index, 4);
  EXPECT_EQ(p.instrs[1].index, 31);
  EXPECT_EQ(p.instrs[2].index, 15);
  EXPECT_EQ(p.instrs[3].index, -1) << "no index: the current light";
  for (const char* bad :
       {"lighting.switch [32] = on", "model_clipping.normal [16] = 0 0 1", "lighting.color [-1] = 1 1 1",
        "lighting.color [1.5] = 1 1 1", "lighting.color [x] = 1 1 1", "lighting.color [2 = 1 1 1"}) {
    const Program e = parse(bad);
    EXPECT_EQ(e.errorCount(), 1u) << bad;
    EXPECT_TRUE(e.instrs.empty()) << bad;
  }
}

TEST(Parse, TheManualsExampleParsesClean) {
  const Program p = parse(R"(!
! Make the model move
motion.reset_transforms! Reset all matrices
position.reset_transforms
draw
render.prim_type = solid! Draw a solid object for a while
loop 3
  loop 100    ! Move right while rotating
    position.local_x_translate = 0.002
    position.local_x_rotate = 1.0
    draw
  end_loop
end_loop
lines.line_width += 1.0! Make lines get fatter
)");
  EXPECT_TRUE(p.diagnostics.empty());
  EXPECT_EQ(p.instrs.size(), 12u);
}

TEST(Loops, NestMoreThanTenDeep) {
  std::string text;
  for (int i = 0; i < 12; ++i) text += "loop 2\n";
  text += "draw\n";
  for (int i = 0; i < 12; ++i) text += "end_loop\n";
  const Program p = parse(text);
  EXPECT_TRUE(p.diagnostics.empty());
  // Each loop points at its end and back.
  for (std::size_t i = 0; i < 12; ++i) {
    const auto end = static_cast<std::size_t>(p.instrs[i].jump);
    EXPECT_EQ(end, 24 - i) << i;
    EXPECT_EQ(static_cast<std::size_t>(p.instrs[end].jump), i);
  }
}

TEST(Loops, NestingBeyondTheLimitIsAnError) {
  std::string text;
  for (std::size_t i = 0; i < kMaxNesting + 1; ++i) text += "loop 1\n";
  text += "draw\n";
  for (std::size_t i = 0; i < kMaxNesting + 1; ++i) text += "end_loop\n";
  const Program p = parse(text);
  EXPECT_GE(p.errorCount(), 1u);
  EXPECT_NE(p.diagnostics[0].message.find("nest"), std::string::npos) << p.diagnostics[0].message;
}

TEST(Loops, UnbalancedLoopsAreReportedWithTheirLines) {
  const Program extra = parse("draw\nend_loop\n");
  ASSERT_EQ(extra.errorCount(), 1u);
  EXPECT_EQ(extra.diagnostics[0].line, 2u);
  EXPECT_NE(extra.diagnostics[0].message.find("without a loop"), std::string::npos);

  const Program open = parse("draw\nloop 3\n  draw\n");
  ASSERT_EQ(open.errorCount(), 1u);
  EXPECT_EQ(open.diagnostics[0].line, 2u);
  EXPECT_NE(open.diagnostics[0].message.find("no end_loop"), std::string::npos);
  // The loop still runs to the end of the script.
  ASSERT_EQ(open.instrs.size(), 4u);
  EXPECT_EQ(open.def(open.instrs[3]).action, Action::kEndLoop);

  const Program crossed = parse("loop 2\njitter 2\ndraw\nend_loop\nend_jitter\nend_loop\n");
  EXPECT_EQ(crossed.errorCount(), 1u);
  EXPECT_EQ(crossed.diagnostics[0].line, 4u);
  EXPECT_NE(crossed.diagnostics[0].message.find("expected end_jitter"), std::string::npos);

  const Program nestedJitter = parse("jitter 2\njitter 2\ndraw\nend_jitter\nend_jitter\n");
  EXPECT_GE(nestedJitter.errorCount(), 1u);
}

struct BadLine {
  const char* text;
  const char* expect;  ///< part of the message
};

TEST(Errors, SayWhatWasExpected) {
  const BadLine cases[] = {
      {"render.prim_typ = solid", "did you mean 'render.prim_type'?"},
      {"lines.width = 2", "did you mean 'lines.line_width'?"},
      {"rendr.prim_type = solid", "did you mean 'render.prim_type'?"},
      {"frobnicate", "unknown command 'frobnicate'"},
      {"render.prim_type = wirefame", "did you mean 'wireframe'?"},
      {"render.prim_type = cube", "takes one of: wireframe, markers, solid"},
      {"render.prim_type = solid wireframe", "takes one of"},
      {"render.prim_type =", "needs one of"},
      {"render.prim_type solid", "render.prim_type [\"part name\"] = wireframe | markers | solid"},
      {"lines.line_color = 1 0", "needs 3 numbers, found 2"},
      {"lines.line_color = 1 0 zero", "'zero' is not a number"},
      {"lines.line_width = 0x", "is not a number"},
      {"nurbs.iso_curves_u = 2.5", "needs a whole number"},
      {"model_clipping.num_planes = 17", "must be from 0 to 16"},
      {"front_surf.transparency = 1.5", "must be from 0 to 1"},
      {"depth_cue.mode part_1 = linear", "applies to the whole show and takes no part name"},
      {"draw now", "takes nothing after it"},
      {"loop", "loop needs <int>"},
      {"loop -1", "must be from 0"},
      {"loop three", "not a number"},
      {"jitter 0", "must be from 1"},
      {"part.select face 1", "put a name with spaces in double quotes"},
      {"load_object /etc/passwd", "absolute path"},
      {"load_texture ../../secret.png", "leaves the script's folder"},
      {"save_image \"../x.png\"", "leaves the script's folder"},
      {"render.prim_type += solid", "op-equals signs work on numbers"},
      {"motion.global_x_rotate += 2", "rotations take only '='"},
      {"position.local_y_rotate -= 1", "rotations take only '='"},
      {"lines.line_width = 1e999", "out of range"},
      {"global.background_color = 1e39 0 0", "too large for a float"},
      {"part.select \"face 1", "no closing quote"},
      {"= solid", "a line starts with a command"},
      {"render.prim_type [2] = solid", "part name"},
  };
  for (const BadLine& c : cases) {
    const Program p = parse(std::string("draw\n") + c.text + "\ndraw\n");
    ASSERT_EQ(p.errorCount(), 1u) << c.text;
    const Diagnostic& d = p.diagnostics[0];
    EXPECT_EQ(d.line, 2u) << c.text;
    EXPECT_EQ(d.file, "test.mdl");
    EXPECT_NE(d.message.find(c.expect), std::string::npos) << c.text << "\n  gave: " << d.message;
    EXPECT_EQ(d.describe().rfind("test.mdl:2: ", 0), 0u) << d.describe();
    // The bad line is left out; the lines around it are kept.
    EXPECT_EQ(p.instrs.size(), 2u) << c.text;
  }
}

TEST(Errors, EveryBadLineOfAScriptIsListed) {
  const Program p = parse("render.prim_typ = solid\ndraw\nlines.line_width = x\n\nfoo\ndraw\n");
  ASSERT_EQ(p.errorCount(), 3u);
  EXPECT_EQ(p.diagnostics[0].line, 1u);
  EXPECT_EQ(p.diagnostics[1].line, 3u);
  EXPECT_EQ(p.diagnostics[2].line, 5u);
  EXPECT_EQ(p.instrs.size(), 2u);
}

TEST(Aliases, TheManualsSpellingOfHlhsr) {
  const Program p = parse("render.hlshr_mode = off\nrender.hlhsr_mode = on");
  ASSERT_TRUE(p.diagnostics.empty());
  EXPECT_EQ(&p.def(p.instrs[0]), &p.def(p.instrs[1]));
}

TEST(Suggestions, CloseMatchesOnly) {
  const std::string_view choices[] = {"wireframe", "markers", "solid"};
  EXPECT_EQ(closestMatch("solod", choices).value_or(""), "solid");
  EXPECT_EQ(closestMatch("MARKER", choices).value_or(""), "markers");
  EXPECT_FALSE(closestMatch("banana", choices).has_value());
  EXPECT_FALSE(suggestCommand("xyzzy").has_value());
}

// Makes sure suggestions are bounded: a word longer than the documented 64 characters gets none
// (a command from the network may be up to 1024 bytes), and a near miss of 64 still gets one.
// Example failure: a 1000-character word compared with every command name.
TEST(Suggestions, LongWordsGetNone) {
  const std::string longWord(65, 'a');
  const std::string longChoice = std::string(63, 'a') + "b";
  const std::string_view choices[] = {longChoice};
  EXPECT_FALSE(closestMatch(longWord, choices).has_value()) << "two edits away, but longer than 64";
  EXPECT_FALSE(suggestCommand(std::string(1000, 'x') + "translate").has_value());
  EXPECT_EQ(closestMatch(std::string(64, 'a'), choices).value_or(""), longChoice);
}

}  // namespace
}  // namespace basalt::script
