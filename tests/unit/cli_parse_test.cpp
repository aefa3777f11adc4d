// The command line: every option of `basalt run`, and clear usage errors for bad input.
// Example failure: '--frames abc' silently running forever instead of saying what is wrong.

#include <gtest/gtest.h>

#include <vector>

#include "kiosk/cli.h"

namespace basalt::kiosk {
namespace {

Result<Command> parse(std::vector<std::string_view> args) { return parseCommandLine(args); }

TEST(CommandLine, RunOptions) {
  auto c = parse({"run", "--frames", "30", "--size=1280x720", "--headless", "--snapshot", "x/y.png", "--seconds", "2.5",
                  "--fps=30", "--fast", "--output-dir", "o"});
  ASSERT_TRUE(c) << c.error().describe();
  EXPECT_EQ(c->kind, Command::Kind::kRun);
  EXPECT_EQ(c->run.frames, 30);
  EXPECT_EQ(c->run.width, 1280u);
  EXPECT_EQ(c->run.height, 720u);
  EXPECT_TRUE(c->run.headless);
  EXPECT_EQ(c->run.snapshot, std::filesystem::path("x/y.png"));
  EXPECT_DOUBLE_EQ(*c->run.seconds, 2.5);
  EXPECT_DOUBLE_EQ(c->run.fps, 30);
  EXPECT_EQ(c->run.clock, ClockMode::kManual);
  EXPECT_EQ(c->run.outputDir, std::filesystem::path("o"));
}

TEST(CommandLine, DefaultsAreLavasWindow) {
  auto c = parse({"run"});
  ASSERT_TRUE(c);
  EXPECT_EQ(c->run.width, 500u);
  EXPECT_EQ(c->run.height, 500u);
  EXPECT_FALSE(c->run.frames);
}

TEST(CommandLine, HelpAndVersion) {
  EXPECT_EQ(parse({})->kind, Command::Kind::kHelp);
  EXPECT_EQ(parse({"--help"})->kind, Command::Kind::kHelp);
  auto runHelp = parse({"run", "--help"});
  ASSERT_TRUE(runHelp);
  EXPECT_EQ(runHelp->helpTopic, "run");
  EXPECT_EQ(parse({"--version"})->kind, Command::Kind::kVersion);
  for (std::string_view option : {"--frames", "--seconds", "--size", "--headless", "--snapshot"}) {
    EXPECT_NE(helpText("run").find(option), std::string::npos) << option << " is not in 'basalt run --help'";
  }
}

TEST(CommandLine, BadInputSaysWhatIsWrong) {
  struct Case {
    std::vector<std::string_view> args;
    std::string_view expected;
  };
  const Case cases[] = {
      {{"run", "--bogus"}, "unknown option '--bogus'"},
      {{"run", "--frames"}, "--frames needs a value"},
      {{"run", "--frames", "abc"}, "--frames needs a whole number, not 'abc'"},
      {{"run", "--frames", "0"}, "--frames must be at least 1"},
      {{"run", "--seconds", "-1"}, "--seconds must be more than 0"},
      {{"run", "--size", "640"}, "--size needs WIDTHxHEIGHT"},
      {{"run", "--size", "0x10"}, "between 1 and"},
      {{"run", "--fps", "0"}, "--fps must be between 1 and 1000"},
      {{"run", "extra"}, "unexpected argument 'extra'"},
      {{"fly"}, "unknown command 'fly'"},
      {{"--nope"}, "unknown option '--nope'"},
  };
  for (const Case& c : cases) {
    auto r = parse(c.args);
    ASSERT_FALSE(r) << c.expected;
    EXPECT_NE(r.error().message().find(c.expected), std::string::npos)
        << "got: " << r.error().message() << "\nwanted: " << c.expected;
  }
}

}  // namespace
}  // namespace basalt::kiosk
