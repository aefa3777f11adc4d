// LAVA's lexical rules (manual section 10): logical lines with backslash continuation and `!`
// comments, tokens (quoted names, [N], op-equals signs) and C number syntax.
// Example failures: a `!` inside a quoted part name cutting the line; a continuation that
// drops the next line or keeps the backslash; "-0" read as +0 (Save Model would not read back
// bit for bit); "08" or "1f" accepted although no C compiler takes them; "-=" read as a number.

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "runtime/script/lexer.h"

namespace basalt::script {
namespace {

std::vector<LogicalLine> lines(std::string_view source) {
  LineReader reader(source);
  std::vector<LogicalLine> out;
  LogicalLine line;
  while (reader.next(line)) out.push_back(line);
  return out;
}

std::vector<Token> tokens(std::string_view text) {
  std::vector<Token> out;
  EXPECT_EQ(tokenize(text, out), "") << text;
  return out;
}

TEST(Lines, CommentsBlankLinesAndLineNumbers) {
  const auto l = lines("! a comment\n\n   \ndraw ! trailing\n  render.prim_type = solid! Sets global\n");
  ASSERT_EQ(l.size(), 2u);
  EXPECT_EQ(l[0].line, 4u);
  EXPECT_EQ(l[0].text, "draw");
  EXPECT_EQ(l[1].line, 5u);
  EXPECT_EQ(l[1].text, "  render.prim_type = solid");
}

TEST(Lines, BackslashContinuesTheCommand) {
  const auto l = lines("render.raster_op = \\\n    copy\ndraw\n");
  ASSERT_EQ(l.size(), 2u);
  EXPECT_EQ(l[0].line, 1u);
  EXPECT_EQ(l[0].text, "render.raster_op =      copy");
  EXPECT_EQ(l[1].line, 3u);
}

TEST(Lines, ContinuationAcrossSeveralLinesAndAfterAComment) {
  // The backslash counts as the last character once the comment is taken off.
  const auto l = lines("lines.line_color = 1 \\ ! red\n 0 \\\n 0\n");
  ASSERT_EQ(l.size(), 1u);
  std::vector<Token> t = tokens(l[0].text);
  ASSERT_EQ(t.size(), 5u);
  EXPECT_EQ(t[4].text, "0");
}

TEST(Lines, BackslashOnTheLastLineEndsTheCommand) {
  const auto l = lines("draw \\");
  ASSERT_EQ(l.size(), 1u);
  EXPECT_EQ(l[0].text, "draw  ");
}

TEST(Lines, ExclamationInsideQuotesIsNotAComment) {
  const auto l = lines("part.select \"wow! a part\" ! comment\r\n");
  ASSERT_EQ(l.size(), 1u);
  const auto t = tokens(l[0].text);
  ASSERT_EQ(t.size(), 2u);
  EXPECT_EQ(t[1].kind, TokenKind::kString);
  EXPECT_EQ(t[1].text, "wow! a part");
}

TEST(Lines, WindowsLineEndsAndTabs) {
  const auto l = lines("draw\r\n\tquit\t\r\n");
  ASSERT_EQ(l.size(), 2u);
  EXPECT_EQ(tokens(l[1].text)[0].text, "quit");
}

TEST(Tokens, OperatorsBracketsAndQuotedNames) {
  const auto t = tokens("lighting.color[4]+=0.5 -.25 1e-3");
  ASSERT_EQ(t.size(), 8u);
  EXPECT_EQ(t[0].kind, TokenKind::kWord);
  EXPECT_EQ(t[1].kind, TokenKind::kOpenBracket);
  EXPECT_EQ(t[2].kind, TokenKind::kNumber);
  EXPECT_EQ(t[3].kind, TokenKind::kCloseBracket);
  EXPECT_EQ(t[4].kind, TokenKind::kOperator);
  EXPECT_EQ(t[4].op, AssignOp::kAdd);
  EXPECT_EQ(t[6].text, "-.25");
  EXPECT_EQ(t[7].text, "1e-3");
}

TEST(Tokens, EveryOpEqualsSign) {
  const AssignOp ops[] = {AssignOp::kAssign, AssignOp::kAdd, AssignOp::kSubtract, AssignOp::kMultiply,
                          AssignOp::kDivide};
  const char* texts[] = {"=", "+=", "-=", "*=", "/="};
  for (int i = 0; i < 5; ++i) {
    const auto t = tokens(std::string("x ") + texts[i] + " 2");
    ASSERT_EQ(t.size(), 3u) << texts[i];
    EXPECT_EQ(t[1].kind, TokenKind::kOperator);
    EXPECT_EQ(t[1].op, ops[i]) << texts[i];
    EXPECT_EQ(assignOpText(ops[i]), texts[i]);
  }
  // Without spaces: the sign still splits the words.
  const auto t = tokens("lines.line_width-=1");
  ASSERT_EQ(t.size(), 3u);
  EXPECT_EQ(t[1].op, AssignOp::kSubtract);
  // A part name next to a quote and an equals sign, as the manual writes obj_colors.
  const auto q = tokens("obj_colors.part_color \"part name\"= 1 0 0");
  ASSERT_EQ(q.size(), 6u);
  EXPECT_EQ(q[1].text, "part name");
  EXPECT_EQ(q[2].op, AssignOp::kAssign);
}

TEST(Tokens, UnclosedQuoteIsAnError) {
  std::vector<Token> out;
  EXPECT_NE(tokenize("part.select \"face 1", out), "");
}

struct NumberCase {
  const char* text;
  double value;
  bool integer;
};

TEST(Numbers, EveryFormACompilerAccepts) {
  const NumberCase cases[] = {
      {"0", 0, true},         {"42", 42, true},      {"-7", -7, true},         {"+3", 3, true},
      {"017", 15, true},      {"0x1F", 31, true},    {"0X1f", 31, true},       {"10u", 10, true},
      {"10UL", 10, true},     {"10llu", 10, true},   {"1.", 1, false},         {".5", 0.5, false},
      {"-.25", -0.25, false}, {"1e3", 1000, false},  {"1E-3", 0.001, false},   {"2.5e+2", 250, false},
      {"2.f", 2, false},      {"1.5F", 1.5, false},  {"3.0L", 3, false},       {"0x1.8p1", 3, false},
      {"0x.8p1", 1, false},   {"0x10p-2", 4, false}, {"-0x1p-1", -0.5, false}, {"0.002", 0.002, false},
  };
  for (const NumberCase& c : cases) {
    CNumber n;
    ASSERT_EQ(parseCNumber(c.text, n), NumberParse::kOk) << c.text;
    EXPECT_DOUBLE_EQ(n.value, c.value) << c.text;
    EXPECT_EQ(n.integer, c.integer) << c.text;
    EXPECT_EQ(n.asFloat, static_cast<float>(c.value)) << c.text;
  }
}

TEST(Numbers, WhatACompilerRefuses) {
  for (const char* text : {"",     "-",    "+",     ".",    "e3",   "1e",  "1e+", "08",  "0x",  "0xg", "1f",
                           "1.5x", "1..2", "0x1.8", "1ul2", "1lul", "--1", "abc", "1,5", "nan", "inf"}) {
    CNumber n;
    EXPECT_EQ(parseCNumber(text, n), NumberParse::kNotANumber) << "'" << text << "'";
  }
}

TEST(Numbers, OutOfRange) {
  CNumber n;
  EXPECT_EQ(parseCNumber("1e999", n), NumberParse::kOutOfRange);
  EXPECT_EQ(parseCNumber("99999999999999999999999", n), NumberParse::kOutOfRange);
}

TEST(Numbers, NegativeZeroStaysNegative) {
  // Save Model writes -0 for a matrix entry of -0.0f; it must read back as the same bits.
  for (const char* text : {"-0", "-0.0", "-0x0p0"}) {
    CNumber n;
    ASSERT_EQ(parseCNumber(text, n), NumberParse::kOk) << text;
    EXPECT_TRUE(std::signbit(n.asFloat)) << text;
    EXPECT_TRUE(std::signbit(n.value)) << text;
  }
}

TEST(Numbers, FloatsAreRoundedOnceFromTheText) {
  // 0.1 rounded straight to float, not through double: the same bits as the compiler's 0.1f.
  CNumber n;
  ASSERT_EQ(parseCNumber("0.1", n), NumberParse::kOk);
  EXPECT_EQ(std::bit_cast<std::uint32_t>(n.asFloat), std::bit_cast<std::uint32_t>(0.1f));
}

TEST(Case, NamesCompareWithoutCase) {
  EXPECT_TRUE(equalsIgnoreCase("Render.Prim_Type", "render.prim_type"));
  EXPECT_FALSE(equalsIgnoreCase("render.prim", "render.prim_type"));
  EXPECT_EQ(toLower("WireFrame"), "wireframe");
}

}  // namespace
}  // namespace basalt::script
