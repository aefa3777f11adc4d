// "Did you mean": a mistyped command, option or help topic gets the nearest real one, as the
// real `basalt` binary says it; a word near nothing gets the pointer to --help instead; and the
// search stays bounded for long words and long lists.
// Example failures: `basalt rnu` answering only "unknown command"; a suggestion for a word that
// is nothing like any command; a 10 000-character argument compared against every option.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "app/suggest.h"
#include "support/process.h"
#include "support/test_paths.h"

namespace basalt::kiosk {
namespace {

test::ProcessResult basalt(const std::vector<std::string>& arguments) {
  std::vector<std::string> argv{(test::binaryDir() / "basalt").string()};
  argv.insert(argv.end(), arguments.begin(), arguments.end());
  return test::run(argv);
}

TEST(DidYouMean, CommandsOptionsAndHelpTopics) {
  struct Case {
    std::vector<std::string> args;
    std::string said;
  };
  const Case cases[] = {
      {{"rnu"}, "basalt: error: unknown command 'rnu'; did you mean 'run'?"},
      {{"chekc", "show.toml"}, "unknown command 'chekc'; did you mean 'check'?"},
      {{"devcies"}, "did you mean 'devices'?"},
      {{"recrod"}, "did you mean 'record'?"},
      {{"hlep"}, "did you mean 'help'?"},
      {{"help", "rnu"}, "no command 'rnu'; did you mean 'run'?"},
      {{"help", "scirpt"}, "no command 'scirpt'; did you mean 'script'?"},
      {{"--verison"}, "unknown option '--verison'; did you mean '--version'?"},
      {{"run", "--frmaes", "10"}, "unknown option '--frmaes' for 'basalt run'; did you mean '--frames'?"},
      {{"run", "--Frames", "10"}, "did you mean '--frames'?"},
      {{"run", "--headles"}, "did you mean '--headless'?"},
      {{"record", "--secnods", "3"}, "unknown option '--secnods' for 'basalt record'; did you mean '--seconds'?"},
      {{"check", "--hepl"}, "unknown option '--hepl' for 'basalt check'; did you mean '--help'?"},
      {{"devices", "--synthetci"}, "did you mean '--synthetic'?"},
      {{"run", "--zoom", "mvoie", "--movie", "movie=clip.mp4"},
       "--zoom mvoie: no movie of that name; did you mean 'movie'?"},
  };
  for (const Case& c : cases) {
    const auto r = basalt(c.args);
    EXPECT_EQ(r.exitCode, 2) << c.args[0] << ": " << r.output;
    EXPECT_NE(r.output.find(c.said), std::string::npos) << "wanted: " << c.said << "\ngot: " << r.output;
  }
}

TEST(DidYouMean, AWordNearNothingPointsAtHelp) {
  struct Case {
    std::vector<std::string> args;
    std::string said;
  };
  const Case cases[] = {
      {{"fly"}, "unknown command 'fly'; see 'basalt --help'"},
      {{"--nope"}, "unknown option '--nope'; see 'basalt --help'"},
      {{"run", "--teleport"}, "unknown option '--teleport' for 'basalt run'; see 'basalt run --help'"},
      {{"run", "--zoom", "x", "--movie", "movie=clip.mp4"}, "--zoom x: no movie of that name; give --movie x=FILE too"},
      {{"run", std::string("--") + std::string(10000, 'f')}, "see 'basalt run --help'"},
  };
  for (const Case& c : cases) {
    const auto r = basalt(c.args);
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find(c.said), std::string::npos) << "wanted: " << c.said << "\ngot: " << r.output;
    EXPECT_EQ(r.output.find("did you mean"), std::string::npos) << r.output;
  }
}

TEST(DidYouMean, TheSearchIsBounded) {
  // A candidate past the first kMaxSuggestionCandidates is not compared, however close.
  std::vector<std::string> names;
  for (std::size_t i = 0; i < 300; ++i) names.push_back("zzzzzzzz" + std::to_string(i));
  names.back() = "frames";
  std::vector<std::string_view> views(names.begin(), names.end());
  EXPECT_FALSE(nearestWord("frmaes", views)) << "candidate 300 of 300 is past the bound (256)";
  std::swap(views.front(), views.back());
  ASSERT_TRUE(nearestWord("frmaes", views)) << "the same candidate first is found";
  EXPECT_EQ(*nearestWord("frmaes", views), "frames");
  // Words past kMaxSuggestedWord (64) are not compared, not even with a candidate one edit away.
  const std::string longWord(65, 'a');
  const std::string longCandidate = std::string(64, 'a') + "b";
  const std::vector<std::string_view> one{longCandidate};
  EXPECT_FALSE(nearestWord(longWord, one));
  const std::string shorter(64, 'a');
  const std::vector<std::string_view> near{std::string_view(shorter).substr(0, 63)};
  EXPECT_EQ(nearestWord(shorter, near), near[0]);
  // The same word is no misspelling; one differing in case is the likeliest meaning.
  const std::vector<std::string_view> frames{"--frames", "--fps"};
  EXPECT_FALSE(nearestWord("--frames", frames));
  EXPECT_EQ(nearestWord("--FRAMES", frames), "--frames");
  EXPECT_EQ(didYouMean("--frmaes", frames), "; did you mean '--frames'?");
  EXPECT_EQ(didYouMean("--qqqqqq", frames, "; see --help"), "; see --help");
}

}  // namespace
}  // namespace basalt::kiosk
