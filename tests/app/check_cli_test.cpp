// `basalt check` as CI runs it: each file's line counts exactly the errors and warnings printed
// above it, the totals add up, and `--json` is one valid JSON document with every diagnostic
// (file, line, severity, message), even for names and lines that are not clean UTF-8.
// Example failures: "2 problems" then "1 error, 0 warnings" for the same manifest; a warning
// left out of the count; --json broken by a control character or a stray byte in a message.

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/process.h"
#include "support/test_paths.h"

namespace basalt {
namespace {

namespace fs = std::filesystem;

test::ProcessResult check(const std::vector<std::string>& arguments) {
  std::vector<std::string> argv{(test::binaryDir() / "basalt").string(), "check"};
  argv.insert(argv.end(), arguments.begin(), arguments.end());
  return test::run(argv);
}

/// Standard output alone (what CI parses), through the shell.
test::ProcessResult checkStdout(const std::vector<std::string>& arguments) {
  std::string command = "exec '" + (test::binaryDir() / "basalt").string() + "' check";
  for (const std::string& a : arguments) command += " '" + a + "'";
  return test::run({"/bin/sh", "-c", command + " 2>/dev/null"});
}

void writeFile(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << text;
}

/// Lines of `output` that contain `needle`.
std::size_t linesWith(const std::string& output, const std::string& needle) {
  std::istringstream in(output);
  std::size_t n = 0;
  for (std::string line; std::getline(in, line);) n += line.find(needle) != std::string::npos ? 1u : 0u;
  return n;
}

// Two errors (a missing entry on line 2, a device without a backend on line 3) and one warning
// (a KMS connector on a headless output, on the [output] line 5).
constexpr const char* kTwoErrorsOneWarning =
    "[show]\nentry = \"gone.mdl\"\n[devices.x]\nkind = \"dial_box\"\n[output]\nkind = \"headless\"\n"
    "connector = \"HDMI-A-1\"\n";

TEST(CheckCli, TheFileLineCountsWhatIsPrinted) {
  const fs::path dir = test::scratchDir("check-cli-counts");
  writeFile(dir / "show.toml", kTwoErrorsOneWarning);
  const std::string file = (dir / "show.toml").string();
  const auto r = check({file});
  EXPECT_EQ(r.exitCode, 1) << r.output;
  EXPECT_EQ(linesWith(r.output, file + ":2: error: show.entry"), 1u) << r.output;
  EXPECT_EQ(linesWith(r.output, file + ":3: error: devices.x"), 1u) << r.output;
  EXPECT_EQ(linesWith(r.output, file + ":5: warning: output:"), 1u) << r.output;
  EXPECT_EQ(linesWith(r.output, ": error: "), 2u) << r.output;
  EXPECT_EQ(linesWith(r.output, ": warning: "), 1u) << r.output;
  EXPECT_NE(r.output.find("basalt: " + file + ": 2 errors, 1 warning; its last good copy plays until they are fixed\n"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(r.output.find("problem"), std::string::npos) << "one way of counting: " << r.output;

  // A manifest with one warning and no error starts: it says so on the same line.
  writeFile(dir / "warned" / "show.toml", "[output]\nkind = \"headless\"\nconnector = \"HDMI-A-1\"\n");
  const auto warned = check({(dir / "warned" / "show.toml").string()});
  EXPECT_EQ(warned.exitCode, 0) << warned.output;
  EXPECT_EQ(linesWith(warned.output, ": warning: "), 1u) << warned.output;
  EXPECT_NE(warned.output.find(": 0 errors, 1 warning; ok: '"), std::string::npos) << warned.output;
}

// Makes sure `basalt check scene.sce` names, at its line, a camera value the scene cannot be
// drawn with as written. Example failure: a viewport with no resolution passing the check and
// then silently filling the view.
TEST(CheckCli, ASceneCameraItCannotHonourIsNamedAtItsLine) {
  const fs::path dir = test::scratchDir("check-cli-scene-camera");
  writeFile(dir / "box.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n");
  writeFile(dir / "s.sce", "import box.obj\nviewport position[10,10]\nprojection fov[50]\n");
  const std::string file = (dir / "s.sce").string();
  const auto r = check({file});
  EXPECT_EQ(linesWith(r.output, file + ":2:"), 1u) << r.output;
  EXPECT_NE(r.output.find("the viewport has no area"), std::string::npos) << r.output;
}

TEST(CheckCli, SeveralFilesAddUp) {
  const fs::path dir = test::scratchDir("check-cli-several");
  writeFile(dir / "a" / "show.toml", kTwoErrorsOneWarning);
  writeFile(dir / "b.mdl", "render.prim_type = wirefame\nloop 2\n draw\n");  // 2 errors: the value, the loop
  writeFile(dir / "c.mdl", "draw\nquit\n");
  const auto r = check({(dir / "a" / "show.toml").string(), (dir / "b.mdl").string(), (dir / "c.mdl").string()});
  EXPECT_EQ(r.exitCode, 1) << r.output;
  EXPECT_NE(r.output.find((dir / "b.mdl").string() + ": 2 errors, 0 warnings\n"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find((dir / "c.mdl").string() + ": no errors (2 commands checked)"), std::string::npos)
      << r.output;
  EXPECT_EQ(linesWith(r.output, ": error: "), 4u) << r.output;
  EXPECT_NE(r.output.find("basalt: 3 files: 4 errors, 1 warning\n"), std::string::npos) << r.output;
}

TEST(CheckCli, JsonForCi) {
  const fs::path dir = test::scratchDir("check-cli-json");
  writeFile(dir / "show" / "show.toml", kTwoErrorsOneWarning);
  writeFile(dir / "good.mdl", "draw\nquit\n");
  const std::string manifest = (dir / "show" / "show.toml").string();
  const auto r = checkStdout({"--json", manifest, (dir / "good.mdl").string()});
  EXPECT_EQ(r.exitCode, 1) << "errors fail the check in JSON too: " << r.output;
  nlohmann::json doc;
  ASSERT_NO_THROW(doc = nlohmann::json::parse(r.output)) << r.output;
  EXPECT_EQ(doc["errors"], 2);
  EXPECT_EQ(doc["warnings"], 1);
  ASSERT_EQ(doc["files"].size(), 2u);
  const auto& first = doc["files"][0];
  EXPECT_EQ(first["file"], manifest);
  EXPECT_EQ(first["kind"], "show manifest");
  EXPECT_EQ(first["errors"], 2);
  EXPECT_EQ(first["warnings"], 1);
  EXPECT_EQ(first["verdict"], "its last good copy plays until they are fixed");
  ASSERT_EQ(first["diagnostics"].size(), 3u) << first.dump(2);
  const int lines[] = {2, 3, 5};
  const char* severities[] = {"error", "error", "warning"};
  for (std::size_t i = 0; i < 3; ++i) {
    const auto& d = first["diagnostics"][i];
    EXPECT_EQ(d["file"], manifest);
    EXPECT_EQ(d["line"], lines[i]);
    EXPECT_EQ(d["severity"], severities[i]);
    EXPECT_TRUE(d["message"].is_string() && !d["message"].get<std::string>().empty());
  }
  EXPECT_NE(first["diagnostics"][0]["message"].get<std::string>().find("show.entry: 'gone.mdl' does not exist"),
            std::string::npos);
  const auto& second = doc["files"][1];
  EXPECT_EQ(second["kind"], "LAVA script");
  EXPECT_EQ(second["errors"], 0);
  EXPECT_EQ(second["items"], 2);
  EXPECT_EQ(second["items_are"], "commands");
  EXPECT_TRUE(second["diagnostics"].empty());
}

TEST(CheckCli, JsonStaysValidForControlCharactersAndStrayBytes) {
  const fs::path dir = test::scratchDir("check-cli-json-bytes");
  // A file name with a byte that is not UTF-8, and a line with a control character and more
  // stray bytes, which the "unknown command" message quotes back.
  const fs::path odd = dir / "odd\xff.mdl";
  writeFile(odd, std::string("\x01") + "bogus\xfe\xfd\tx\n");
  const auto r = checkStdout({"--json", odd.string()});
  EXPECT_EQ(r.exitCode, 1) << r.output;
  nlohmann::json doc;
  ASSERT_NO_THROW(doc = nlohmann::json::parse(r.output)) << r.output;
  ASSERT_EQ(doc["files"].size(), 1u);
  ASSERT_EQ(doc["files"][0]["diagnostics"].size(), 1u) << doc.dump(2);
  const std::string message = doc["files"][0]["diagnostics"][0]["message"];
  EXPECT_NE(message.find("\x01"
                         "bogus"),
            std::string::npos)
      << "the control character survives, escaped: " << message;
  EXPECT_NE(message.find("\xEF\xBF\xBD"), std::string::npos) << "stray bytes become U+FFFD: " << message;
  EXPECT_NE(doc["files"][0]["file"].get<std::string>().find("odd\xEF\xBF\xBD.mdl"), std::string::npos);
}

TEST(CheckCli, JsonIsInTheHelp) {
  const auto r = check({"--help"});
  EXPECT_EQ(r.exitCode, 0);
  EXPECT_NE(r.output.find("--json"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace basalt
