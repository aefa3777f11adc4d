// The reference page docs/script-reference.md is generated from the command table; this test
// fails when the committed page and the table disagree, so the documentation cannot go stale.
// Example failures: a command added to the table without regenerating the page; a default
// changed in attributes.h while the page still shows the old one.

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "runtime/script/command_table.h"
#include "runtime/script/reference.h"
#include "support/test_paths.h"

namespace basalt::script {
namespace {

TEST(Reference, TheCommittedPageIsTheGeneratedOne) {
  const auto path = basalt::test::sourceDir() / "docs/script-reference.md";
  std::ifstream in(path);
  ASSERT_TRUE(in) << path << " is missing; run: cmake --build build --target script-reference";
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_TRUE(text.str() == scriptReference())
      << path << " differs from the command table; regenerate it: cmake --build build --target script-reference";
}

TEST(Reference, ListsEveryCommandWithItsForm) {
  const std::string page = scriptReference();
  for (const CommandDef& def : commands()) {
    std::string form;
    for (char c : def.form()) form += c == '|' ? std::string("\\|") : std::string(1, c);
    EXPECT_NE(page.find("| `" + form + "`"), std::string::npos) << def.name;
  }
  EXPECT_NE(page.find("| `render.prim_type [\"part name\"] = wireframe \\| markers \\| solid` | solid |"),
            std::string::npos)
      << "defaults come from the start-up show";
  EXPECT_NE(page.find("| `lines.line_width [\"part name\"] = <float>` | 1 |"), std::string::npos);
}

}  // namespace
}  // namespace basalt::script
