// The last good copy of a show: the whole show folder is copied (not the state folder inside
// it), the copy is found with its time, a changed show replaces it in one swap, an unchanged
// show is left alone, and another show's copy is never found.
// Example failures: the state folder copied into itself; a copy that keeps an old file's
// contents after the show changed; a half-written copy found as good.

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "kiosk/policy/last_good.h"
#include "support/test_paths.h"

namespace basalt::kiosk {
namespace {

namespace fs = std::filesystem;

std::string readAll(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

fs::path makeShow(const std::string& name) {
  const fs::path dir = test::scratchDir(name);
  fs::remove_all(dir);
  fs::create_directories(dir / "models");
  std::ofstream(dir / "show.toml") << "[show]\nentry = \"default\"\n";
  std::ofstream(dir / "models" / "cube.obj") << "v 0 0 0\n";
  return dir;
}

TEST(LastGood, CopiesTheShowFolderButNotTheStateInIt) {
  const fs::path show = makeShow("last-good-copy");
  const fs::path state = show / "state";
  fs::create_directories(state);
  std::ofstream(state / "other.state") << "not part of the show";
  EXPECT_FALSE(findLastGood(state, show / "show.toml")) << "nothing is kept yet";

  auto kept = keepLastGood(state, show / "show.toml", show);
  ASSERT_TRUE(kept) << kept.error().describe();
  EXPECT_EQ(*kept, KeptCopy::kWritten);
  auto found = findLastGood(state, show / "show.toml");
  ASSERT_TRUE(found);
  EXPECT_EQ(readAll(found->manifest), "[show]\nentry = \"default\"\n");
  EXPECT_EQ(readAll(found->manifest.parent_path() / "models" / "cube.obj"), "v 0 0 0\n");
  EXPECT_FALSE(fs::exists(found->manifest.parent_path() / "state"));
  EXPECT_EQ(found->savedAt.size(), 20u) << found->savedAt;  // 2026-11-27T13:45:00Z
  EXPECT_EQ(found->savedAt.back(), 'Z');
  EXPECT_FALSE(findLastGood(state, show / "other.toml")) << "another show's copy is not this one";
}

TEST(LastGood, AChangedShowReplacesTheCopyAndAnUnchangedOneIsLeft) {
  const fs::path show = makeShow("last-good-change");
  const fs::path state = test::scratchDir("last-good-change-state");
  fs::remove_all(state);
  ASSERT_TRUE(keepLastGood(state, show / "show.toml", show));
  auto again = keepLastGood(state, show / "show.toml", show);
  ASSERT_TRUE(again);
  EXPECT_EQ(*again, KeptCopy::kUnchanged);

  std::ofstream(show / "models" / "cube.obj", std::ios::trunc) << "v 1 1 1\nv 2 2 2\n";
  fs::remove(show / "show.toml");
  std::ofstream(show / "show.toml") << "[show]\nentry = \"black\"\n";
  auto changed = keepLastGood(state, show / "show.toml", show);
  ASSERT_TRUE(changed) << changed.error().describe();
  EXPECT_EQ(*changed, KeptCopy::kWritten);
  auto found = findLastGood(state, show / "show.toml");
  ASSERT_TRUE(found);
  EXPECT_EQ(readAll(found->manifest), "[show]\nentry = \"black\"\n");
  EXPECT_EQ(readAll(found->manifest.parent_path() / "models" / "cube.obj"), "v 1 1 1\nv 2 2 2\n");
  // One copy, no temporary folder left beside it.
  int entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(state / "last-good")) ++entries;
  EXPECT_EQ(entries, 1);
}

TEST(LastGood, AHalfWrittenCopyIsNotFound) {
  const fs::path show = makeShow("last-good-torn");
  const fs::path state = test::scratchDir("last-good-torn-state");
  fs::remove_all(state);
  const fs::path folder = lastGoodFolder(state, show / "show.toml");
  fs::create_directories(folder);
  std::ofstream(folder / "show.toml") << "[show]\n";  // no record of what it is: not a kept copy
  EXPECT_FALSE(findLastGood(state, show / "show.toml"));
}

}  // namespace
}  // namespace basalt::kiosk
