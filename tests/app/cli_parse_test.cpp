// The command line: every option of `basalt run`, and clear usage errors for bad input.
// Example failure: '--frames abc' silently running forever instead of saying what is wrong.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <vector>

#include "app/commands.h"
#include "app/options.h"
#include "app/run_command.h"
#include "support/test_paths.h"

namespace basalt::kiosk {
namespace {

Result<RunOptions> parse(std::vector<std::string_view> args) { return parseRunOptions(args); }

TEST(CommandLine, RunOptions) {
  auto c = parse({"--frames", "30", "--size=1280x720", "--headless", "--snapshot", "x/y.png", "--seconds", "2.5",
                  "--fps=30", "--fast", "--output-dir", "o"});
  ASSERT_TRUE(c) << c.error().describe();
  EXPECT_EQ(c->frames, 30);
  EXPECT_EQ(c->width, 1280u);
  EXPECT_EQ(c->height, 720u);
  EXPECT_TRUE(c->headless);
  EXPECT_EQ(c->snapshot, std::filesystem::path("x/y.png"));
  EXPECT_DOUBLE_EQ(*c->seconds, 2.5);
  EXPECT_DOUBLE_EQ(c->fps, 30);
  EXPECT_EQ(c->clock, ClockMode::kManual);
  EXPECT_EQ(c->outputDir, std::filesystem::path("o"));
  EXPECT_FALSE(c->help);
}

TEST(CommandLine, DefaultsAreLavasWindow) {
  auto c = parse({});
  ASSERT_TRUE(c);
  EXPECT_EQ(c->width, 500u);
  EXPECT_EQ(c->height, 500u);
  EXPECT_FALSE(c->frames);
}

TEST(CommandLine, HelpAndVersion) {
  EXPECT_TRUE(parse({"--help"})->help);
  EXPECT_TRUE(parse({"-h"})->help);
  for (std::string_view option : {"--frames", "--seconds", "--size", "--headless", "--snapshot"}) {
    EXPECT_NE(runUsage().find(option), std::string::npos) << option << " is not in 'basalt run --help'";
  }
  EXPECT_NE(overviewHelp().find("run"), std::string::npos);
  const std::vector<std::string_view> version{"--version"};
  EXPECT_EQ(dispatch(version), 0);
}

TEST(CommandLine, BadInputSaysWhatIsWrong) {
  struct Case {
    std::vector<std::string_view> args;
    std::string_view expected;
  };
  const Case cases[] = {
      {{"--bogus"}, "unknown option '--bogus' for 'basalt run'"},
      {{"--frames"}, "--frames needs a value"},
      {{"--frames", "abc"}, "--frames needs a whole number, not 'abc'"},
      {{"--frames", "0"}, "--frames must be between 1 and"},
      {{"--seconds", "-1"}, "--seconds must be between"},
      {{"--size", "640"}, "--size needs WIDTHxHEIGHT"},
      {{"--size", "0x10"}, "between 1 and 16384"},
      {{"--fps", "0"}, "--fps must be between 1 and 1000"},
      {{"--headless=yes"}, "--headless takes no value"},
      {{"a.mdl", "extra"}, "'basalt run' plays one show; 'extra' comes after 'a.mdl'"},
  };
  for (const Case& c : cases) {
    auto r = parse(c.args);
    ASSERT_FALSE(r) << c.expected;
    EXPECT_NE(r.error().message().find(c.expected), std::string::npos)
        << "got: " << r.error().message() << "\nwanted: " << c.expected;
  }
}

TEST(CommandLine, AShowFolderMeansItsShowToml) {
  // Makes sure `basalt run DIR` plays DIR/show.toml, and that a folder without one is refused
  // with what it holds. Example failure: a folder taken for a LAVA script and refused as neither.
  const auto dir = test::scratchDir("cli-parse-folder");
  std::filesystem::create_directories(dir / "show");
  std::ofstream(dir / "show" / "show.toml") << "[show]\n";
  const std::string folder = (dir / "show").string();
  auto c = parse({folder});
  ASSERT_TRUE(c) << c.error().describe();
  EXPECT_EQ(c->manifest, dir / "show" / "show.toml");
  EXPECT_FALSE(c->show);

  std::filesystem::create_directories(dir / "bare");
  const std::string bare = (dir / "bare").string();
  auto none = parse({bare});
  ASSERT_FALSE(none);
  EXPECT_EQ(none.error().message(), "the folder " + bare +
                                        " has no show.toml (basalt run plays a show folder's show.toml); give a show "
                                        "manifest (show.toml) or a LAVA script (.mdl)");
  for (const char* name : {"b.toml", "a.mdl", "notes.txt"}) std::ofstream(dir / "bare" / name) << "\n";
  auto other = parse({bare});
  ASSERT_FALSE(other);
  EXPECT_NE(other.error().message().find("; it holds a.mdl, b.toml: give one of them"), std::string::npos)
      << other.error().message();
}

TEST(CommandLine, UnknownCommandsAndOptionsAreUsageErrors) {
  const std::vector<std::string_view> fly{"fly"};
  EXPECT_EQ(dispatch(fly), 2);
  const std::vector<std::string_view> nope{"--nope"};
  EXPECT_EQ(dispatch(nope), 2);
  const std::vector<std::string_view> helpFly{"help", "fly"};
  EXPECT_EQ(dispatch(helpFly), 2);
}

TEST(Options, PositionalsFlagsAndValues) {
  const std::vector<std::string_view> args{"show.toml", "--verbose", "--level=3", "--", "--not-an-option"};
  auto parsed = parseOptions("check", args, {{"--verbose|-v"}, {"--level", true}});
  ASSERT_TRUE(parsed) << parsed.error().describe();
  ASSERT_EQ(parsed->size(), 4u);
  EXPECT_EQ((*parsed)[0].name, "");
  EXPECT_EQ((*parsed)[0].value, "show.toml");
  EXPECT_EQ((*parsed)[1].name, "--verbose");
  EXPECT_EQ((*parsed)[2].value, "3");
  EXPECT_EQ((*parsed)[3].value, "--not-an-option");
}

}  // namespace
}  // namespace basalt::kiosk
