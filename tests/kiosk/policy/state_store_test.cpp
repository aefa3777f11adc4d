// Crash recovery's state file: what is saved comes back; a torn, edited, foreign or garbage
// file is refused with the reason (the show then starts from the beginning, never from a wrong
// place); writes are atomic, leaving no partial file behind, and never block the caller.
// Example failures: a file cut short by a power loss read as position 0 of the wrong item; a
// state of one show resumed by another; a half-written file left beside the real one.

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "kiosk/policy/state_store.h"
#include "support/test_paths.h"

namespace basalt::kiosk {
namespace {

const ResumePoint kPoint{KioskMode::kActive, 1, "free cube", std::chrono::milliseconds(73250)};

TEST(StateFile, RoundTrips) {
  const std::string text = encodeState("/shows/museum/show.toml", kPoint);
  auto back = decodeState(text, "/shows/museum/show.toml");
  ASSERT_TRUE(back) << back.error().describe();
  EXPECT_EQ(back->mode, KioskMode::kActive);
  EXPECT_EQ(back->index, 1u);
  EXPECT_EQ(back->item, "free cube");
  EXPECT_EQ(back->position, std::chrono::milliseconds(73250));
}

TEST(StateFile, DamageIsRefusedWithTheReason) {
  const std::string good = encodeState("/show.toml", kPoint);
  // Every cut of the file, as a power loss mid-write would leave it.
  for (std::size_t n = 0; n < good.size(); ++n) {
    EXPECT_FALSE(decodeState(good.substr(0, n), "/show.toml")) << "cut at " << n;
  }
  // Every single changed byte.
  for (std::size_t i = 0; i < good.size(); ++i) {
    std::string edited = good;
    edited[i] = static_cast<char>(edited[i] ^ 0x20);
    EXPECT_FALSE(decodeState(edited, "/show.toml")) << "byte " << i;
  }
  const auto appended = decodeState(good + "position_ns=1\n", "/show.toml");
  ASSERT_FALSE(appended);
  EXPECT_NE(appended.error().message().find("checksum"), std::string::npos);
  const auto foreign = decodeState(good, "/another/show.toml");
  ASSERT_FALSE(foreign);
  EXPECT_NE(foreign.error().message().find("another show"), std::string::npos);
  const auto garbage = decodeState(
      "\x7f"
      "ELF...",
      "/show.toml");
  ASSERT_FALSE(garbage);
  EXPECT_NE(garbage.error().message().find("not a Basalt state file"), std::string::npos);
}

TEST(StateStore, SavesAtomicallyAndLoadsBack) {
  const auto dir = test::scratchDir("state-store");
  {
    auto store = StateStore::open(dir / "state", "/shows/a/show.toml");
    ASSERT_TRUE(store) << store.error().describe();
    EXPECT_FALSE((*store)->load()) << "nothing saved yet";
    for (int i = 0; i < 200; ++i) {
      ResumePoint p = kPoint;
      p.position = std::chrono::seconds(i);
      (*store)->save(p);  // never waits for the disk; the newest point wins
    }
    (*store)->flush();
    const auto loaded = (*store)->load();
    ASSERT_TRUE(loaded);
    EXPECT_EQ(loaded->position, std::chrono::seconds(199));
    EXPECT_EQ((*store)->failures(), 0u);
  }
  std::size_t files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir / "state")) {
    ++files;
    EXPECT_EQ(e.path().extension(), ".state") << "no temporary file left: " << e.path();
  }
  EXPECT_EQ(files, 1u);
  // Another show in the same folder keeps its own file.
  auto other = StateStore::open(dir / "state", "/shows/b/show.toml");
  ASSERT_TRUE(other);
  EXPECT_FALSE((*other)->load());
}

TEST(StateStore, AFolderThatCannotBeWrittenIsOneClearError) {
  const auto dir = test::scratchDir("state-store-file");
  std::ofstream(dir / "file") << "x";
  const auto store = StateStore::open(dir / "file" / "state", "/show.toml");
  ASSERT_FALSE(store);
  EXPECT_NE(store.error().message().find("--state-dir"), std::string::npos) << store.error().message();
}

TEST(StateStore, TheDefaultFolderFollowsSystemd) {
  ::setenv("STATE_DIRECTORY", "/var/lib/basalt:/var/lib/other", 1);
  EXPECT_EQ(defaultStateFolder(), std::filesystem::path("/var/lib/basalt"));
  ::unsetenv("STATE_DIRECTORY");
  ::setenv("XDG_STATE_HOME", "/home/k/.state", 1);
  EXPECT_EQ(defaultStateFolder(), std::filesystem::path("/home/k/.state/basalt"));
  ::unsetenv("XDG_STATE_HOME");
}

}  // namespace
}  // namespace basalt::kiosk
