// The manual page (docs/basalt.1.in, configured into the build folder and installed as
// man1/basalt.1): `man` renders it without a warning, and it names every option that a command's
// --help lists, so the two cannot drift apart.
// Example failures: a roff typo that man renders as garbage or warns about; an option added to
// `basalt run --help` and forgotten in the manual page.

#include <gtest/gtest.h>

#include <unistd.h>

#include <regex>
#include <set>
#include <sstream>

#include "support/process.h"
#include "support/test_paths.h"

namespace basalt {
namespace {

const std::filesystem::path kManPage = test::binaryDir() / "basalt.1";

/// The rendered page, as `man -l` shows it, in plain text.
test::ProcessResult renderManPage() {
  return test::run({"/usr/bin/man", "--warnings", "-P", "cat", "-l", kManPage.string()},
                   {{"LC_ALL", "C.UTF-8"}, {"MANWIDTH", "100"}, {"MAN_KEEP_FORMATTING", ""}});
}

/// The long options a help text lists: lines that start (after the indent) with --name or -x, --name.
std::set<std::string> optionsIn(const std::string& help) {
  std::set<std::string> options;
  const std::regex line(R"(^\s+(?:-[A-Za-z], )?(--[a-z][a-z-]*))");
  std::istringstream in(help);
  std::string text;
  std::smatch m;
  while (std::getline(in, text)) {
    if (std::regex_search(text, m, line)) options.insert(m[1]);
  }
  return options;
}

TEST(ManPage, RendersWithoutWarnings) {
  if (::access("/usr/bin/man", X_OK) != 0) GTEST_SKIP() << "man is not installed (man-db, scripts/packages-test.txt)";
  ASSERT_TRUE(std::filesystem::exists(kManPage)) << kManPage << ": CMake configures it from docs/basalt.1.in";
  const auto page = renderManPage();
  EXPECT_EQ(page.exitCode, 0) << page.output;
  EXPECT_EQ(page.output.find("warning"), std::string::npos) << page.output;
  EXPECT_FALSE(std::regex_search(page.output, std::regex("@[A-Z_]+@")))
      << "a placeholder CMake did not fill in: " << page.output;
  for (const char* section :
       {"NAME", "SYNOPSIS", "DESCRIPTION", "COMMANDS", "OPTIONS", "EXIT STATUS", "ENVIRONMENT", "FILES", "EXAMPLES"}) {
    EXPECT_NE(page.output.find(std::string("\n") + section + "\n"), std::string::npos) << section;
  }
  EXPECT_NE(page.output.find("systemctl enable --now basalt"), std::string::npos) << page.output;
}

TEST(ManPage, NamesEveryOptionOfEveryCommand) {
  if (::access("/usr/bin/man", X_OK) != 0) GTEST_SKIP() << "man is not installed (man-db, scripts/packages-test.txt)";
  const auto page = renderManPage();
  ASSERT_EQ(page.exitCode, 0) << page.output;
  std::size_t checked = 0;
  for (const std::string command : {"", "run", "check", "devices", "record"}) {
    std::vector<std::string> argv{(test::binaryDir() / "basalt").string()};
    if (!command.empty()) argv.push_back(command);
    argv.push_back("--help");
    const auto help = test::run(argv);
    ASSERT_EQ(help.exitCode, 0) << help.output;
    const auto options = optionsIn(help.output);
    EXPECT_FALSE(options.empty()) << "no option found in basalt " << command << " --help:\n" << help.output;
    for (const std::string& option : options) {
      // An option starts its entry: "       --frames N", "       -h, --help".
      const std::regex entry("\n {7}(-[A-Za-z], )?" + option + "( |,|\n)");
      EXPECT_TRUE(std::regex_search(page.output, entry))
          << "basalt " << command << " --help lists " << option << "; the manual page has no entry for it";
      ++checked;
    }
  }
  EXPECT_GE(checked, 40u) << "the help texts list fewer options than they do today";
}

}  // namespace
}  // namespace basalt
