// Show manifests (show.toml): every example in configs/ is valid, and every kind of mistake a
// person makes in one is reported as `file:line: message`, all of them in one pass.
// Example failures: an example show that no longer validates after a schema change; a path that
// escapes the show folder through "..", an absolute path or a symbolic link and is accepted; a
// typo'd key silently ignored; a binding to a device that does not exist accepted; a message
// without its line number.

#include <gtest/gtest.h>

#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "kiosk/manifest/content_check.h"
#include "kiosk/manifest/manifest.h"
#include "kiosk/show/show_loader.h"
#include "kiosk/show/stream_factories.h"
#include "runtime/unique_fd.h"
#include "support/process.h"
#include "support/test_paths.h"

namespace basalt::kiosk {
namespace {

namespace fs = std::filesystem;

void writeFile(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path) << text;
}

/// A show folder with a manifest and the files manifests in these tests name.
struct ShowFolder {
  fs::path dir;
  explicit ShowFolder(const std::string& name) : dir(test::scratchDir("manifest-" + name)) {
    writeFile(dir / "tour.mdl", "draw\n");
    writeFile(dir / "wall.sce", "import wall.obj\n");
    writeFile(dir / "wall.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    writeFile(dir / "room.cave", "facet[2]\n");
    fs::create_directories(dir / "clips");
    fs::copy_file(test::sourceDir() / "configs/shows/video-wall/clips/loop.webm", dir / "clips" / "loop.webm");
    writeFile(dir / "clips" / "broken.webm", "not really a movie");
    writeFile(dir / "site.trace" / "trace.toml", "format = 1\nfps = 60\n");
    fs::create_directories(dir / "empty.trace");
    fs::copy_file(test::sourceDir() / "configs/shows/camera-sculpture/camera.png", dir / "offline.png");
  }
  struct Read {
    std::optional<Manifest> manifest;
    Diagnostics diagnostics;
    std::string text;  // every diagnostic, formatted
  };
  Read read(const std::string& toml) const {
    writeFile(dir / "show.toml", toml);
    Read r;
    ReadOptions options;
    options.fileCheckers = &contentCheckers();
    r.manifest = readManifest(dir / "show.toml", r.diagnostics, options);
    r.text = r.diagnostics.format();
    return r;
  }
};

/// True when some diagnostic is an error on `line` containing `needle`.
bool hasError(const ShowFolder::Read& r, int line, const std::string& needle) {
  for (const Diagnostic& d : r.diagnostics.items()) {
    if (d.severity == Severity::kError && d.line == line && d.message.find(needle) != std::string::npos) return true;
  }
  return false;
}

bool hasWarning(const ShowFolder::Read& r, int line, const std::string& needle) {
  for (const Diagnostic& d : r.diagnostics.items()) {
    if (d.severity == Severity::kWarning && d.line == line && d.message.find(needle) != std::string::npos) return true;
  }
  return false;
}

// ---- The examples ---------------------------------------------------------------------------

class ExampleShow : public testing::TestWithParam<const char*> {};

TEST_P(ExampleShow, IsValid) {
  const fs::path file = test::sourceDir() / "configs/shows" / GetParam() / "show.toml";
  Diagnostics diagnostics;
  ReadOptions options;
  options.fileCheckers = &contentCheckers();
  const auto manifest = readManifest(file, diagnostics, options);
  ASSERT_TRUE(manifest) << diagnostics.format();
  EXPECT_EQ(diagnostics.errorCount(), 0u) << diagnostics.format();
  EXPECT_FALSE(manifest->name.empty());
  EXPECT_EQ(manifest->folder, fs::canonical(file.parent_path()));
  // Every path it resolved lies inside the show folder and exists.
  const auto inside = [&](const fs::path& p) {
    if (p.empty()) return;
    EXPECT_TRUE(fs::exists(p)) << p;
    EXPECT_EQ(p.string().rfind(manifest->folder.string(), 0), 0u) << p;
  };
  inside(manifest->entry.path);
  for (const auto& m : manifest->media) inside(m.file);
  for (const auto& t : manifest->textures) {
    inside(t.file);
    inside(t.fallback);
  }
  for (const auto& item : manifest->kiosk.playlist) inside(item.entry.path);
  for (const auto& item : manifest->kiosk.attract.items) inside(item.entry.path);
}

INSTANTIATE_TEST_SUITE_P(Configs, ExampleShow,
                         testing::Values("default", "video-wall", "camera-sculpture", "lava-script", "cube-cave"),
                         [](const auto& p) { return test::caseName(p.param); });

TEST(ExampleShows, EachHasWhatItsDescriptionSays) {
  const fs::path shows = test::sourceDir() / "configs/shows";
  Diagnostics d;
  const auto demo = readManifest(shows / "default/show.toml", d);
  ASSERT_TRUE(demo) << d.format();
  EXPECT_EQ(demo->entry.kind, EntryKind::kBuiltinDefault);
  ASSERT_EQ(demo->devices.size(), 1u);
  EXPECT_EQ(demo->devices[0].backend, DeviceBackend::kSynthetic);
  EXPECT_EQ(demo->devices[0].script.size(), 4u);
  EXPECT_EQ(demo->bindings.size(), 4u);
  EXPECT_TRUE(demo->status.enabled);
  EXPECT_TRUE(demo->status.loopbackOnly());

  const auto wall = readManifest(shows / "video-wall/show.toml", d);
  ASSERT_TRUE(wall) << d.format();
  EXPECT_EQ(wall->entry.kind, EntryKind::kScene);
  ASSERT_EQ(wall->media.size(), 1u);
  EXPECT_EQ(wall->media[0].kind, MediaKind::kMovie);
  EXPECT_TRUE(wall->media[0].loop);
  ASSERT_EQ(wall->textures.size(), 1u);
  EXPECT_EQ(wall->textures[0].name, "screens.png");
  EXPECT_EQ(wall->textures[0].source, "loop");

  const auto sculpture = readManifest(shows / "camera-sculpture/show.toml", d);
  ASSERT_TRUE(sculpture) << d.format();
  EXPECT_EQ(sculpture->output.kind, OutputKind::kKms);
  EXPECT_EQ(sculpture->output.connector, "HDMI-A-1");
  const DeviceSpec* knob = sculpture->findDevice("knob");
  ASSERT_NE(knob, nullptr);
  EXPECT_EQ(knob->match.vendor, 0x077d);
  EXPECT_EQ(knob->match.product, 0x0410);
  EXPECT_EQ(sculpture->findDevice("camera")->width, 1280u);

  const auto lava = readManifest(shows / "lava-script/show.toml", d);
  ASSERT_TRUE(lava) << d.format();
  EXPECT_EQ(lava->entry.kind, EntryKind::kScript);
  ASSERT_EQ(lava->kiosk.playlist.size(), 2u);
  EXPECT_EQ(lava->kiosk.playlist[1].duration, std::chrono::minutes(2));
  EXPECT_TRUE(lava->kiosk.attract.present);
  EXPECT_EQ(lava->kiosk.attract.idleTimeout, std::chrono::seconds(90));
  const ScheduleSpec& s = lava->kiosk.schedule;
  EXPECT_EQ(s.timezone, "Europe/Paris");
  EXPECT_TRUE(s.week[0].empty()) << "closed on Mondays";
  EXPECT_EQ(s.week[3].size(), 2u) << "late opening on Thursdays";
  EXPECT_EQ(s.week[1], (std::vector<TimeRange>{{600, 1080}}));
  ASSERT_EQ(s.exceptions.size(), 2u);
  EXPECT_TRUE(s.exceptions[0].hours.empty());
  EXPECT_EQ(s.exceptions[1].date, (Date{2026, 12, 31}));
  EXPECT_EQ(s.outside, OutsideHours::kStandby);
}

TEST(ExampleShows, BasaltCheckAcceptsEveryExample) {
  for (const char* name : {"default", "video-wall", "camera-sculpture", "lava-script", "cube-cave"}) {
    const auto file = test::sourceDir() / "configs/shows" / name / "show.toml";
    const auto r = test::run({(test::binaryDir() / "basalt").string(), "check", file.string()});
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("ok: '"), std::string::npos) << r.output;  // after the counts when there are warnings
  }
}

// ---- Broken variants ------------------------------------------------------------------------

TEST(ManifestErrors, InvalidTomlNamesTheLine) {
  ShowFolder f("toml");
  const auto r = f.read("[show]\nname = \"x\"\nentry = \n");
  EXPECT_FALSE(r.manifest);
  EXPECT_TRUE(hasError(r, 3, "not valid TOML")) << r.text;
  EXPECT_NE(r.text.find("show.toml:3: not valid TOML"), std::string::npos) << r.text;
}

// Non-ASCII outside quotes is invalid TOML, and toml++ 3.3's whitespace test has undefined
// behaviour on most such characters (a fuzzing finding): the manifest reader screens for them.
TEST(ManifestErrors, NonAsciiOutsideQuotesNamesLineAndColumn) {
  ShowFolder f("toml-non-ascii");
  const auto r = f.read(
      "[show]\nname = \"Caf\xC3\xA9\" # d\xC3\xA9j\xC3\xA0 vu\n"
      "entry = \xC2\xA1\"default\"\n");
  EXPECT_FALSE(r.manifest);
  EXPECT_TRUE(hasError(r, 3, "non-ASCII character at column 9 outside quotes")) << r.text;

  const auto escaped = f.read("[show]\nname = \"\"\"a\\\xC3\xA9\"\"\"\n");
  EXPECT_FALSE(escaped.manifest);
  EXPECT_TRUE(hasError(escaped, 2, "non-ASCII character at column 13")) << escaped.text;

  const auto lineEnd = f.read("[show]\nname = \"\"\"a \\  \n   \xC3\xA9\"\"\"\n");
  EXPECT_FALSE(lineEnd.manifest);
  EXPECT_TRUE(hasError(lineEnd, 3, "non-ASCII character at column 4")) << lineEnd.text;
}

TEST(ManifestErrors, NonAsciiInStringsAndCommentsIsFine) {
  ShowFolder f("toml-unicode");
  const auto r = f.read(
      "# Mus\xC3\xA9"
      "e d'Orsay, salle \xE2\x84\x96 3\n[show]\nname = '''Caf\xC3\xA9 ''\xC3\xA9'''\n"
      "[\"status\"]\nlisten = \"127.0.0.1:0\" # \xC2\xA1ok!\n");
  EXPECT_TRUE(r.manifest) << r.text;
}

// The fuzzing reproducer `i=8'` then U+046F: the quote follows a number, so it starts no string
// (toml++ reads it as part of the number token), and the Cyrillic letter after it reached
// toml++'s whitespace test, which has undefined behaviour for U+00A1..U+0499.
TEST(ManifestErrors, QuoteThatStartsNoStringLeavesNonAsciiOutside) {
  ShowFolder f("toml-quote-after-token");
  const auto r = f.read("i=8'\xD1\xAF");
  EXPECT_FALSE(r.manifest);
  EXPECT_TRUE(hasError(r, 1, "non-ASCII character at column 5 outside quotes")) << r.text;

  // After a string that ended, after a number's dot, after a bare key: no string starts.
  const auto afterString = f.read("[show]\nname = 'a''\xC3\xA9'\n");
  EXPECT_FALSE(afterString.manifest);
  EXPECT_TRUE(hasError(afterString, 2, "non-ASCII character at column 12 outside quotes")) << afterString.text;
  const auto afterDot = f.read("[show]\nfps = 1.'\xC3\xA9'\n");
  EXPECT_FALSE(afterDot.manifest);
  EXPECT_TRUE(hasError(afterDot, 2, "non-ASCII character at column 10 outside quotes")) << afterDot.text;
  const auto afterKey = f.read("[show]\nname'\xC3\xA9' = 1\n");
  EXPECT_FALSE(afterKey.manifest);
  EXPECT_TRUE(hasError(afterKey, 2, "non-ASCII character at column 6 outside quotes")) << afterKey.text;
}

// The fuzzing reproducer `i=8'='-i8-` then U+046F: toml++ reads a value that starts with a digit
// (or a letter: true, inf, a date) up to whitespace, `,`, `]`, `}` or `#`, so the `=` and the
// quotes inside it start no string, and the Cyrillic letter reached toml++'s whitespace test.
TEST(ManifestErrors, EqualsInsideABareValueStartsNoString) {
  ShowFolder f("toml-equals-in-value");
  const auto r = f.read("i=8'='-i8-\xD1\xAF");
  EXPECT_FALSE(r.manifest);
  EXPECT_TRUE(hasError(r, 1, "non-ASCII character at column 11 outside quotes")) << r.text;
  for (const std::string value : {"8=", "true=", "1979-05-27T07:32:00=", "inf[", "1{", "8'"}) {
    const auto v = f.read("[show]\nfps = " + value + "'\xC3\xA9'\n");
    EXPECT_FALSE(v.manifest) << value;
    const std::string column = std::to_string(8 + value.size());
    EXPECT_TRUE(hasError(v, 2, "non-ASCII character at column " + column + " outside quotes")) << value << v.text;
  }
  // A value terminator ends the bare value: strings after it are strings.
  const auto arrays = f.read(
      "[show]\nname = 'x' # 1=\xC3\xA9\n[\"status\"]\nlisten = \"127.0.0.1:0\"\n"
      "[schedule]\nholidays = [1979-05-27,'\xC3\xA9', {a=1,b='\xC3\xA9'}]\n");
  for (const Diagnostic& d : arrays.diagnostics.items()) {
    EXPECT_EQ(d.message.find("outside quotes"), std::string::npos) << arrays.text;
  }
}

// Found by replaying the fuzzed corpus with toml++'s assertions on: after a table header's `[`,
// toml++ reads a key without checking that one starts, assuming it (undefined behaviour under
// clang when it does not). Basalt reports such a header itself.
TEST(ManifestErrors, TableHeaderWithoutAKeyIsReportedBeforeToml) {
  ShowFolder f("toml-header-without-key");
  for (const std::string header : {"[#", "[=", "[ ,x]", "[[.", "[[[", "[\n", "[\r\n", "[ "}) {
    const auto r = f.read("[show]\nname = 'x'\n" + header + "\n");
    EXPECT_FALSE(r.manifest) << header;
    EXPECT_TRUE(hasError(r, 3, "a table header without a key after its '['")) << header << ": " << r.text;
  }
  // Keys, quoted keys, arrays of tables and `[]` (toml++'s own error) are not this.
  for (const std::string header : {"[ status ]", "['show']", "[[a]]", "[]", "[ -x]"}) {
    const auto r = f.read("[show]\nname = 'x'\n" + header + "\n");
    EXPECT_FALSE(hasError(r, 3, "a table header without a key")) << header << ": " << r.text;
  }
}

// Also found by replaying the fuzzed corpus with assertions on: toml++ takes a `}` inside an
// array for the start of a value, which it assumes cannot be a value terminator.
TEST(ManifestErrors, ArrayClosedByABraceIsReportedBeforeToml) {
  ShowFolder f("toml-array-brace");
  for (const std::string value : {"[}", "[ 1, }", "[ { at = 1 }, }, ]", "[ [ 1 } ]"}) {
    const auto r = f.read("[show]\nname = 'x'\n[dial]\nscript = " + value + "\n");
    EXPECT_FALSE(r.manifest) << value;
    EXPECT_TRUE(hasError(r, 4, "an array closed by '}'")) << value << ": " << r.text;
  }
  const auto inline_tables = f.read("[show]\nname = 'x'\n[dial]\nscript = [ {a = [1]}, { b = 2 } ]\n");
  for (const Diagnostic& d : inline_tables.diagnostics.items()) {
    EXPECT_EQ(d.message.find("closed by"), std::string::npos) << inline_tables.text;
  }
}

// Strings cut off by the end of the file right after a multibyte character: a clear TOML
// error from toml++ (the text is valid UTF-8 and the character is inside the string).
TEST(ManifestErrors, UnterminatedStringsEndingInMultibyteAreTomlErrors) {
  ShowFolder f("toml-unterminated");
  for (const std::string open : {"'", "\"", "'''", "\"\"\""}) {
    for (const std::string tail : {"\xD1\xAF", "Caf\xC3\xA9", "\xE3\x80\x80", "\xF0\x9F\x8E\xA5"}) {
      const auto r = f.read("[show]\nname = " + open + tail);
      EXPECT_FALSE(r.manifest) << open << tail;
      EXPECT_TRUE(hasError(r, 2, "not valid TOML")) << open << tail << ": " << r.text;
    }
  }
}

TEST(ManifestErrors, InvalidUtf8NamesLineAndColumn) {
  ShowFolder f("toml-utf8");
  struct Case {
    std::string text;
    int line;
    std::string needle;
  };
  const std::vector<Case> cases = {
      // Cut short by the end of the file, inside a literal string (column 10: n,a,m,e, ,=, ,',x).
      {"[show]\nname = 'x\xD1", 2, "not valid UTF-8 at column 10: the file ends inside a UTF-8 character"},
      {"[show]\nname = 'x\xF0\x9F\x8E", 2, "not valid UTF-8 at column 10: the file ends inside"},
      // A continuation byte with no lead byte, in a comment after two-byte characters.
      {"# \xC3\xA9\xC3\xA9\x80\n[show]\n", 1, "not valid UTF-8 at column 5: byte 0x80 cannot start"},
      // An overlong '/' (C0 AF), a UTF-16 surrogate (ED A0 80), a code point above U+10FFFF.
      {"[show]\n# \xC0\xAF\n", 2, "column 3: byte 0xC0 cannot start"},
      {"[show]\nname = \"\xED\xA0\x80\"\n", 2, "column 9: byte 0xA0 after 0xED is not part of a valid"},
      {"[show]\nname = \"\xF4\x90\x80\x80\"\n", 2, "column 9: byte 0x90 after 0xF4 is not part of a valid"},
      // A lead byte followed by ASCII.
      {"[show]\nname = \"\xC3(\"\n", 2, "column 9: byte 0x28 after 0xC3"},
  };
  for (const Case& c : cases) {
    const auto r = f.read(c.text);
    EXPECT_FALSE(r.manifest) << c.needle;
    EXPECT_TRUE(hasError(r, c.line, c.needle)) << c.needle << "\n" << r.text;
    EXPECT_NE(r.text.find("show.toml:" + std::to_string(c.line) + ": not valid UTF-8"), std::string::npos) << r.text;
  }
}

TEST(ManifestErrors, ValidUtf8InStringsAndCommentsIsRead) {
  ShowFolder f("toml-utf8-valid");
  // Two-, three- and four-byte characters in a comment and in the show's name.
  const auto r = f.read(
      "# \xF0\x9F\x8E\xA5 salle \xE2\x84\x96 3, \xD0\x9C\xD0\xBE\xD1\x81\xD0\xBA\xD0\xB2\xD0\xB0\n"
      "[show]\nname = \"\xF0\x9F\x8E\xA5 Caf\xC3\xA9 \xD1\xAF\"\n");
  ASSERT_TRUE(r.manifest) << r.text;
  EXPECT_EQ(r.manifest->name, "\xF0\x9F\x8E\xA5 Caf\xC3\xA9 \xD1\xAF");
}

TEST(ManifestErrors, MissingManifestIsOneMessage) {
  Diagnostics d;
  EXPECT_FALSE(readManifest(test::scratchDir("manifest-none") / "show.toml", d));
  ASSERT_EQ(d.items().size(), 1u);
  EXPECT_NE(d.items()[0].message.find("no such manifest"), std::string::npos);
}

TEST(ManifestErrors, UnknownKeysSuggestTheNearestOne) {
  ShowFolder f("keys");
  const auto r = f.read(
      "[show]\nentyr = \"tour.mdl\"\n\n[outptu]\nkind = \"headless\"\n[status]\nlisten = "
      "\"127.0.0.1:1\"\nfrobnicate = 1\n");
  EXPECT_FALSE(r.manifest);
  EXPECT_TRUE(hasError(r, 2, "show.entyr: unknown key; did you mean 'entry'?")) << r.text;
  EXPECT_TRUE(hasError(r, 4, "outptu: unknown key; did you mean 'output'?")) << r.text;
  EXPECT_TRUE(hasError(r, 8, "status.frobnicate: unknown key; status takes")) << r.text;
}

TEST(ManifestErrors, WrongTypesSayWhatIsExpected) {
  ShowFolder f("types");
  const auto r = f.read("[show]\nname = 3\nfps = \"fast\"\n[output]\nfullscreen = \"yes\"\n");
  EXPECT_TRUE(hasError(r, 2, "show.name: must be a string, not an integer")) << r.text;
  EXPECT_TRUE(hasError(r, 3, "show.fps: must be a number, not a string")) << r.text;
  EXPECT_TRUE(hasError(r, 5, "output.fullscreen: must be true or false")) << r.text;
}

TEST(ManifestErrors, EveryProblemIsReportedInOnePass) {
  ShowFolder f("many");
  const auto r = f.read(
      "[show]\nentry = \"missing.mdl\"\nfps = 0\n[output]\nkind = \"hologram\"\n[kiosk.schedule]\ndaily = "
      "\"18:00-09:00\"\n");
  EXPECT_GE(r.diagnostics.errorCount(), 4u) << r.text;
  EXPECT_TRUE(hasError(r, 2, "'missing.mdl' does not exist")) << r.text;
  EXPECT_TRUE(hasError(r, 3, "show.fps: 0 is out of range")) << r.text;
  EXPECT_TRUE(hasError(r, 5, "output.kind: 'hologram' is not one of auto, headless, kms or window")) << r.text;
  EXPECT_TRUE(hasError(r, 7, "cannot cross midnight")) << r.text;
  // Sorted by line.
  int last = 0;
  for (const Diagnostic& d : r.diagnostics.items()) {
    EXPECT_GE(d.line, last) << r.text;
    last = d.line;
  }
}

TEST(ManifestErrors, PathsCannotLeaveTheShowFolder) {
  ShowFolder f("confine");
  const fs::path outside = test::scratchDir("manifest-confine-outside");
  writeFile(outside / "secret.mdl", "draw\n");
  fs::create_symlink(outside / "secret.mdl", f.dir / "link.mdl");
  const auto dotdot = f.read("[show]\nentry = \"../manifest-confine-outside/secret.mdl\"\n");
  EXPECT_TRUE(hasError(dotdot, 2, "leaves the show folder")) << dotdot.text;
  const auto absolute = f.read("[show]\nentry = \"" + (outside / "secret.mdl").string() + "\"\n");
  EXPECT_TRUE(hasError(absolute, 2, "leaves the show folder")) << absolute.text;
  const auto link = f.read("[show]\nentry = \"link.mdl\"\n");
  EXPECT_TRUE(hasError(link, 2, "leaves the show folder")) << link.text;
  // An absolute path that lies inside is fine.
  const auto inside = f.read("[show]\nentry = \"" + (f.dir / "tour.mdl").string() + "\"\n");
  EXPECT_TRUE(inside.manifest) << inside.text;
}

TEST(ManifestErrors, EntriesMustBeSomethingAShowPlays) {
  ShowFolder f("entry");
  writeFile(f.dir / "notes.txt", "hello");
  const auto r = f.read("[show]\nentry = \"notes.txt\"\n");
  EXPECT_TRUE(hasError(r, 2, "'notes.txt' is not something a show plays")) << r.text;
  const auto folder = f.read("[show]\nentry = \"site.trace/../clips\"\n");
  EXPECT_FALSE(folder.manifest) << folder.text;
  const auto ok = f.read("[show]\nentry = \"wall.sce\"\n");
  ASSERT_TRUE(ok.manifest) << ok.text;
  EXPECT_EQ(ok.manifest->entry.kind, EntryKind::kScene);
  EXPECT_EQ(ok.text.find("contents are not checked"), std::string::npos) << "scenes are parsed: " << ok.text;
}

// Makes sure `basalt check` reads the movies a manifest names with GStreamer (bounded in time)
// and reports a file it cannot play at the manifest line that names it; a real clip passes.
// Example failure: a text file renamed .webm passes the check and fails on the wall.
TEST(ManifestErrors, MoviesAreReadByGStreamer) {
  ShowFolder f("movies");
  const auto bad = f.read("[show]\nentry = \"clips/broken.webm\"\n");
  EXPECT_FALSE(bad.manifest) << bad.text;
  EXPECT_TRUE(hasError(bad, 2, "show.entry: clips/broken.webm: cannot be read as a movie")) << bad.text;
  EXPECT_NE(bad.text.find("show.toml:2: show.entry: clips/broken.webm: "), std::string::npos) << bad.text;
  const auto media = f.read("[media.m]\nkind = \"movie\"\nfile = \"clips/broken.webm\"\n");
  EXPECT_TRUE(hasError(media, 3, "media.m.file: clips/broken.webm: ")) << media.text;
  const auto ok = f.read("[show]\nentry = \"clips/loop.webm\"\n");
  ASSERT_TRUE(ok.manifest) << ok.text;
  EXPECT_EQ(ok.text.find("contents are not checked"), std::string::npos) << ok.text;
  EXPECT_EQ(ok.diagnostics.errorCount(), 0u) << ok.text;
}

// Makes sure replay traces a manifest names are read by the trace reader: a damaged trace.toml
// or recording is reported with its own file and line, and a trace recorded from the real
// Surface Dial recording (../shared/testdata/hid) passes. Example failure: a trace folder that
// only has to contain a file called trace.toml.
TEST(ManifestErrors, ReplayTracesAreReadByTheTraceReader) {
  ShowFolder f("traces");
  const fs::path dial = test::testdataDir() / "hid/udev-hid-bpf/microsoft_surface_dial_rdesc.hid";
  if (!fs::exists(dial)) GTEST_SKIP() << "no " << dial << " (../shared/testdata is not here)";
  writeFile(f.dir / "bad.trace" / "trace.toml", "format = 1\nfps = sixty\n");
  const auto bad = f.read("[devices.d]\nkind = \"dial_box\"\nbackend = \"replay\"\ntrace = \"bad.trace\"\n");
  EXPECT_FALSE(bad.manifest) << bad.text;
  EXPECT_NE(bad.text.find("bad.trace/trace.toml:2: "), std::string::npos) << bad.text;

  const std::string device = "\n[[device]]\nname = \"dials\"\nkind = \"dial box\"\nfile = \"dials.hid\"\n";
  writeFile(f.dir / "torn.trace" / "trace.toml", "format = 1\nfps = 60\n" + device);
  writeFile(f.dir / "torn.trace" / "dials.hid", "R: 4 05 01 09\nE: 0.000001 2 zz 00\n");
  const auto torn = f.read("[devices.d]\nkind = \"dial_box\"\nbackend = \"replay\"\ntrace = \"torn.trace\"\n");
  EXPECT_FALSE(torn.manifest) << torn.text;
  EXPECT_NE(torn.text.find("torn.trace/dials.hid"), std::string::npos) << torn.text;

  fs::create_directories(f.dir / "dial.trace");
  fs::copy_file(dial, f.dir / "dial.trace" / "dials.hid");
  writeFile(f.dir / "dial.trace" / "trace.toml", "format = 1\nfps = 60\n" + device);
  const auto ok = f.read("[devices.d]\nkind = \"dial_box\"\nbackend = \"replay\"\ntrace = \"dial.trace\"\n");
  ASSERT_TRUE(ok.manifest) << ok.text;
  EXPECT_EQ(ok.diagnostics.errorCount(), 0u) << ok.text;
}

TEST(ManifestErrors, ReferencedFilesAreParsedByTheirChecker) {
  ShowFolder f("checker");
  writeFile(f.dir / "broken.png", "this is not a PNG");
  const auto r = f.read("[textures.wall]\nfile = \"broken.png\"\n");
  EXPECT_FALSE(r.manifest) << r.text;
  EXPECT_NE(r.text.find("broken.png: cannot be read as an image"), std::string::npos) << r.text;
}

TEST(ManifestErrors, DevicesAreCoherent) {
  ShowFolder f("devices");
  const auto r = f.read(
      "[devices.a]\nbackend = \"hid\"\n"                                                      // 1-2: no kind
      "[devices.b]\nkind = \"camera\"\nbackend = \"hid\"\n"                                   // 3-5: hid camera
      "[devices.c]\nkind = \"dial_box\"\nbackend = \"hid\"\nmatch = { usb = \"77d:410\" }\n"  // 6-9
      "[devices.d]\nkind = \"dial_box\"\nbackend = \"replay\"\n"                              // 10-12: no trace
      "[devices.e]\nkind = \"dial_box\"\nbackend = \"replay\"\ntrace = \"empty.trace\"\n"     // 13-16
      "[devices.f]\nkind = \"dial_box\"\nbackend = \"bluetooth\"\n");                         // 17-19
  EXPECT_TRUE(hasError(r, 1, "devices.a: needs kind")) << r.text;
  EXPECT_TRUE(hasError(r, 5, "a camera cannot use the hid backend")) << r.text;
  EXPECT_TRUE(hasError(r, 9, "'77d:410' is not VVVV:PPPP")) << r.text;
  EXPECT_TRUE(hasError(r, 10, "the replay backend needs trace")) << r.text;
  EXPECT_TRUE(hasError(r, 16, "has no trace.toml")) << r.text;
  EXPECT_TRUE(hasError(r, 19, "'bluetooth' is not one of hid, serial, midi, osc, v4l2, libcamera, replay or synthetic"))
      << r.text;
  // A tracker fed by OSC needs the show's OSC input; a camera cannot be fed so.
  const auto osc = f.read(
      "[devices.head]\nkind = \"tracker\"\nbackend = \"osc\"\n"
      "[devices.eye]\nkind = \"camera\"\nbackend = \"osc\"\n");
  EXPECT_TRUE(hasError(osc, 1, "an osc tracker takes /tracker/head messages from the show's OSC input")) << osc.text;
  EXPECT_TRUE(hasError(osc, 6, "a camera cannot use the osc backend")) << osc.text;
  const auto fed = f.read(
      "[devices.head]\nkind = \"tracker\"\nbackend = \"osc\"\nmatch = { name = \"hmd\" }\n"
      "[osc]\nlisten = \"127.0.0.1:9000\"\n");
  ASSERT_TRUE(fed.manifest) << fed.text;
  EXPECT_EQ(fed.manifest->devices[0].backend, DeviceBackend::kOsc);
  EXPECT_EQ(fed.manifest->devices[0].match.name, "hmd");
  const auto ok = f.read("[devices.d]\nkind = \"dial_box\"\nbackend = \"replay\"\ntrace = \"site.trace\"\n");
  ASSERT_TRUE(ok.manifest) << ok.text;
  EXPECT_EQ(ok.manifest->devices[0].trace, fs::canonical(f.dir / "site.trace"));
}

TEST(ManifestErrors, AMovieOrCameraNoTextureShowsIsAWarning) {
  ShowFolder f("unshown-media");
  const auto r = f.read(
      "[devices.cam]\nkind = \"camera\"\nbackend = \"synthetic\"\n"    // 1-3
      "[media.live]\nkind = \"camera\"\ndevice = \"cam\"\n"            // 4-6
      "[media.loop]\nkind = \"movie\"\nfile = \"clips/loop.webm\"\n"   // 7-9
      "[media.card]\nkind = \"image\"\nfile = \"offline.png\"\n"       // 10-12
      "[media.shown]\nkind = \"movie\"\nfile = \"clips/loop.webm\"\n"  // 13-15
      "[textures.wall]\nsource = \"shown\"\nfallback = \"offline.png\"\n");
  ASSERT_TRUE(r.manifest) << "warnings only: " << r.text;
  EXPECT_TRUE(hasWarning(r, 4, "media.live: no texture shows it, so the camera is never opened")) << r.text;
  EXPECT_TRUE(hasWarning(r, 7,
                         "media.loop: no texture shows it, so the movie is never played; add [textures.NAME] "
                         "with source = \"loop\""))
      << r.text;
  EXPECT_EQ(r.text.find("media.card"), std::string::npos) << "an image shown by nothing is harmless: " << r.text;
  EXPECT_EQ(r.text.find("media.shown"), std::string::npos) << r.text;
}

TEST(ManifestErrors, SyntheticScriptsAreChecked) {
  ShowFolder f("synthetic");
  const auto r = f.read(
      "[devices.s]\nkind = \"dial_box\"\nbackend = \"synthetic\"\nscript = [\n"
      "  { at = \"2s\", dial = 0, turns = 0.5 },\n"
      "  { at = \"1s\", dial = 1, turns = 0.5 },\n"
      "  { at = \"3s\", dial = 9, turns = 0.5 },\n"
      "  { at = \"4s\", dial = 1, button = 2 },\n"
      "  { at = \"soon\", button = 2 },\n"
      "]\n");
  EXPECT_TRUE(hasError(r, 6, "times must not go backwards")) << r.text;
  EXPECT_TRUE(hasError(r, 7, "dial: 9 is out of range; use 0 to 7")) << r.text;
  EXPECT_TRUE(hasError(r, 8, "give one of dial = N with turns, button = N with pressed, or shuttle = N")) << r.text;
  EXPECT_TRUE(hasError(r, 9, "'soon' is not a duration")) << r.text;
  const auto shuttle = f.read(
      "[devices.s]\nkind = \"dial_box\"\nbackend = \"synthetic\"\nscript = [\n"
      "  { at = \"1s\", shuttle = 0, position = 0.5 },\n"  // 5
      "  { at = \"2s\", shuttle = 0, position = 2 },\n"    // 6
      "  { at = \"3s\", shuttle = 0 },\n"                  // 7
      "]\n");
  EXPECT_TRUE(hasError(shuttle, 6, "position: 2 is out of range")) << shuttle.text;
  EXPECT_TRUE(hasError(shuttle, 7, "needs position = N")) << shuttle.text;
  const auto held = f.read(
      "[devices.s]\nkind = \"dial_box\"\nbackend = \"synthetic\"\n"
      "script = [ { at = \"1s\", shuttle = 1, position = -0.5 } ]\n");
  ASSERT_TRUE(held.manifest) << held.text;
  ASSERT_EQ(held.manifest->devices[0].script.size(), 1u);
  EXPECT_TRUE(held.manifest->devices[0].script[0].shuttle);
  EXPECT_EQ(held.manifest->devices[0].script[0].index, 1);
  EXPECT_DOUBLE_EQ(held.manifest->devices[0].script[0].value, -0.5);
}

TEST(ManifestErrors, BindingsNeedADialBoxThatExists) {
  ShowFolder f("bindings");
  const auto r = f.read(
      "[devices.cam]\nkind = \"camera\"\nbackend = \"v4l2\"\n"                 // 1-3
      "[devices.dials]\nkind = \"dial_box\"\nbackend = \"synthetic\"\n"        // 4-6
      "[[bindings]]\ndevice = \"knob\"\ndial = 0\naction = \"rotate_x\"\n"     // 7-10
      "[[bindings]]\ndevice = \"cam\"\ndial = 0\naction = \"rotate_x\"\n"      // 11-14
      "[[bindings]]\ndevice = \"dials\"\ndial = 8\naction = \"rotate_x\"\n"    // 15-18
      "[[bindings]]\ndevice = \"dials\"\ndial = 1\naction = \"spin\"\n"        // 19-22
      "[[bindings]]\ndevice = \"dials\"\ndial = 2\naction = \"scale\"\n"       // 23-26
      "[[bindings]]\ndevice = \"dials\"\ndial = 2\naction = \"rotate_z\"\n"    // 27-30
      "[[bindings]]\ndevice = \"dials\"\nbutton = 0\naction = \"rotate_z\"\n"  // 31-34
      "[[bindings]]\ndevice = \"dials\"\naction = \"next\"\n");                // 35-37
  EXPECT_TRUE(hasError(r, 8, "no device 'knob' in [devices]")) << r.text;
  EXPECT_TRUE(hasError(r, 12, "'cam' is a camera; only dial boxes have dials and buttons")) << r.text;
  EXPECT_TRUE(hasError(r, 17, "dial: 8 is out of range; use 0 to 7")) << r.text;
  EXPECT_TRUE(hasError(r, 22, "'spin' is not one of none, rotate_x")) << r.text;
  EXPECT_TRUE(hasError(r, 27, "dial 2 of 'dials' is already bound")) << r.text;
  EXPECT_TRUE(hasError(r, 34, "'rotate_z' is not one of none, next, previous or reset_view")) << r.text;
  EXPECT_TRUE(hasError(r, 35, "give either dial = N or button = N")) << r.text;
}

TEST(ManifestErrors, GainAccelerationAndOverridesAreChecked) {
  ShowFolder f("gain");
  const auto r = f.read(
      "[devices.cam]\nkind = \"camera\"\nbackend = \"synthetic\"\ngain = 2\n"               // 1-4
      "[devices.dials]\nkind = \"dial_box\"\nbackend = \"synthetic\"\nacceleration = -1\n"  // 5-8
      "[[bindings]]\ndevice = \"dials\"\ndial = 3\nacceleration = \"fast\"\n"               // 9-12
      "[[bindings]]\ndevice = \"dials\"\nbutton = 1\naction = \"next\"\ninvert = true\n"    // 13-17
      "[[bindings]]\ndevice = \"dials\"\ndial = 7\ngain = 3\n"                              // 18-21
      "[[bindings]]\ndevice = \"dials\"\nbutton = 2\n");                                    // 22-24
  EXPECT_TRUE(hasWarning(r, 4, "devices.cam.gain: only dial boxes have one")) << r.text;
  EXPECT_TRUE(hasError(r, 8, "acceleration: -1 is out of range")) << r.text;
  EXPECT_TRUE(hasError(r, 12, "acceleration: must be a number")) << r.text;
  EXPECT_TRUE(hasWarning(r, 17, "bindings[1].invert: buttons have no invert")) << r.text;
  EXPECT_TRUE(hasWarning(r, 18, "dial 7 does nothing, so its gain")) << r.text;
  EXPECT_TRUE(hasError(r, 22, "bindings[3]: needs action")) << r.text;
}

TEST(ManifestBindings, OverridesChangeOneDialOfLavasTable) {
  ShowFolder f("overrides");
  const auto r = f.read(
      "[devices.dials]\nkind = \"dial_box\"\nbackend = \"hid\"\ngain = 0.5\nacceleration = 2\n"
      "[[bindings]]\ndevice = \"dials\"\ndial = 1\naction = \"scale\"\n"
      "[[bindings]]\ndevice = \"dials\"\ndial = 4\ngain = 3\nacceleration = 0\ninvert = true\n"
      "[[bindings]]\ndevice = \"dials\"\ndial = 9\naction = \"rotate_z\"\ngain = 90\n"
      "[[bindings]]\ndevice = \"dials\"\nbutton = 0\naction = \"reset_view\"\n");
  ASSERT_TRUE(r.manifest) << r.text;
  ManualClock clock;
  auto loaded = loadShow(*r.manifest, clock, ShowFactories{}, false);
  ASSERT_TRUE(loaded) << loaded.error().describe();
  ASSERT_EQ((*loaded)->devices.size(), 1u);
  const runtime::Bindings& b = (*loaded)->devices[0].dials;
  EXPECT_DOUBLE_EQ(b.gain(), 0.5) << "the device's gain multiplies every dial";
  // Dials no binding names keep LAVA's action and gain, with the device's acceleration.
  EXPECT_EQ(b.dial(0), (runtime::DialBinding{runtime::Action::kRotateX, 360, 2, false}));
  EXPECT_EQ(b.dial(2), (runtime::DialBinding{runtime::Action::kRotateZ, 360, 2, false}));
  EXPECT_EQ(b.dial(5), (runtime::DialBinding{runtime::Action::kTranslateY, 1, 2, false}));
  EXPECT_EQ(b.dial(6), (runtime::DialBinding{runtime::Action::kTranslateZ, 1, 2, false}));
  // A new action with its default gain; LAVA's action with a new gain, acceleration, direction.
  EXPECT_EQ(b.dial(1), (runtime::DialBinding{runtime::Action::kScale, 1, 2, false}));
  EXPECT_EQ(b.dial(4), (runtime::DialBinding{runtime::Action::kTranslateX, 3, 0, true}));
  // A dial beyond LAVA's eight.
  EXPECT_EQ(b.dial(9), (runtime::DialBinding{runtime::Action::kRotateZ, 90, 2, false}));
  EXPECT_EQ((*loaded)->devices[0].buttons[0], KioskAction::kResetView);

  // Without bindings or device keys: exactly LAVA's table.
  const auto plain = f.read("[devices.dials]\nkind = \"dial_box\"\nbackend = \"synthetic\"\n");
  ASSERT_TRUE(plain.manifest) << plain.text;
  auto lava = loadShow(*plain.manifest, clock, ShowFactories{}, false);
  ASSERT_TRUE(lava) << lava.error().describe();
  const runtime::Bindings expected = runtime::Bindings::lavaDefaults();
  for (std::size_t i = 0; i < runtime::kMaxBoundDials; ++i)
    EXPECT_EQ((*lava)->devices[0].dials.dial(i), expected.dial(i));
  EXPECT_DOUBLE_EQ((*lava)->devices[0].dials.gain(), 1);
}

TEST(ManifestErrors, MediaAndTextures) {
  ShowFolder f("media");
  const auto r = f.read(
      "[devices.dials]\nkind = \"dial_box\"\nbackend = \"synthetic\"\n"  // 1-3
      "[media.cam]\nkind = \"camera\"\n"                                 // 4-5
      "[media.cam2]\nkind = \"camera\"\ndevice = \"dials\"\n"            // 6-8
      "[media.clip]\nkind = \"movie\"\nfile = \"tour.mdl\"\n"            // 9-11
      "[media.gone]\nkind = \"movie\"\nfile = \"clips/gone.mkv\"\n"      // 12-14
      "[textures.a]\nsource = \"nothing\"\n"                             // 15-16
      "[textures.b]\nsource = \"clip\"\nfile = \"offline.png\"\n"        // 17-19
      "[textures.c]\nfile = \"offline.png\"\nfallback = \"wall.obj\"\n"  // 20-22
      "[textures.d]\n");                                                 // 23
  EXPECT_TRUE(hasError(r, 4, "a camera needs device")) << r.text;
  EXPECT_TRUE(hasError(r, 8, "'dials' is a dial_box, not a camera")) << r.text;
  EXPECT_TRUE(hasError(r, 11, "'tour.mdl' is not a movie file")) << r.text;
  EXPECT_TRUE(hasError(r, 14, "'clips/gone.mkv' does not exist")) << r.text;
  EXPECT_TRUE(hasError(r, 16, "no media 'nothing' in [media]")) << r.text;
  EXPECT_TRUE(hasError(r, 17, "give either source")) << r.text;
  EXPECT_TRUE(hasError(r, 22, "'wall.obj' is not an image")) << r.text;
  EXPECT_TRUE(hasError(r, 23, "give either source")) << r.text;
  const auto warn =
      f.read("[media.clip]\nkind = \"movie\"\nfile = \"clips/loop.webm\"\n[textures.t]\nsource = \"clip\"\n");
  ASSERT_TRUE(warn.manifest) << warn.text;
  EXPECT_TRUE(hasWarning(warn, 4, "no fallback image")) << warn.text;
}

TEST(ManifestErrors, ScheduleMistakes) {
  ShowFolder f("schedule");
  const auto r = f.read(
      "[kiosk.schedule]\n"                              // 1
      "timezone = \"Mars/Olympus_Mons\"\n"              // 2
      "monday = \"9:00-1700\"\n"                        // 3
      "tuesday = [\"09:00-12:00\", \"11:00-18:00\"]\n"  // 4
      "wednesday = \"25:00-26:00\"\n"                   // 5
      "outside = \"standby\"\n"                         // 6
      "[[kiosk.schedule.exceptions]]\n"                 // 7
      "date = 2026-12-25\nhours = \"closed\"\n"         // 8-9
      "[[kiosk.schedule.exceptions]]\n"                 // 10
      "date = 2026-12-25\nhours = \"closed\"\n"         // 11-12
      "[[kiosk.schedule.exceptions]]\n"                 // 13
      "date = \"2026-02-30\"\nhours = \"closed\"\n"     // 14-15
      "[[kiosk.schedule.exceptions]]\n"                 // 16
      "date = 2026-05-01\n");                           // 17
  EXPECT_TRUE(hasError(r, 2, "unknown time zone 'Mars/Olympus_Mons'")) << r.text;
  EXPECT_TRUE(hasError(r, 3, "'9:00-1700' is not a range of hours")) << r.text;
  EXPECT_TRUE(hasError(r, 4, "ranges overlap")) << r.text;
  EXPECT_TRUE(hasError(r, 5, "'25:00-26:00' is not a range of hours")) << r.text;
  EXPECT_TRUE(hasError(r, 6, "outside = \"standby\" needs standby")) << r.text;
  EXPECT_TRUE(hasError(r, 10, "2026-12-25 is listed twice")) << r.text;
  EXPECT_TRUE(hasError(r, 14, "2026-02-30 is not a day of the calendar")) << r.text;
  EXPECT_TRUE(hasError(r, 16, "needs hours")) << r.text;
  const auto empty = f.read("[kiosk.schedule]\ntimezone = \"UTC\"\n");
  EXPECT_TRUE(hasError(empty, 1, "no opening hours")) << empty.text;
  const auto noZone = f.read("[kiosk.schedule]\ndaily = \"10:00-18:00\"\n");
  EXPECT_TRUE(noZone.manifest) << noZone.text;
  EXPECT_TRUE(hasWarning(noZone, 1, "no timezone")) << noZone.text;
}

TEST(ManifestErrors, PlaylistAndAttract) {
  ShowFolder f("playlist");
  const auto r = f.read(
      "[[kiosk.playlist]]\nentry = \"wall.sce\"\n"                       // 1-2: never ends
      "[[kiosk.playlist]]\nentry = \"tour.mdl\"\nduration = \"0.5s\"\n"  // 3-5
      "[[kiosk.playlist]]\nduration = \"1m\"\n"                          // 6-7
      "[kiosk.attract]\nidle_timeout = \"1s\"\n");                       // 8-9
  EXPECT_TRUE(hasError(r, 1, "never ends by itself; give it a duration")) << r.text;
  EXPECT_TRUE(hasError(r, 5, "an item plays at least one second")) << r.text;
  EXPECT_TRUE(hasError(r, 6, "needs entry")) << r.text;
  EXPECT_TRUE(hasError(r, 8, "kiosk.attract: needs items")) << r.text;
  EXPECT_TRUE(hasError(r, 9, "at least 5 seconds")) << r.text;
}

TEST(ManifestErrors, StatusServerStaysOnLoopbackWithoutAToken) {
  ShowFolder f("status");
  const auto open = f.read("[status]\nlisten = \"0.0.0.0:8180\"\n");
  EXPECT_TRUE(hasError(open, 2, "opens the server beyond this machine; that needs token_file")) << open.text;
  const auto shortToken = f.read("[status]\ntoken = \"abc\"\n");
  EXPECT_TRUE(hasError(shortToken, 2, "at least 16 characters")) << shortToken.text;
  const auto badPort = f.read("[status]\nlisten = \"127.0.0.1:99999\"\n");
  EXPECT_TRUE(hasError(badPort, 2, "port '99999' is not 0 to 65535")) << badPort.text;
  const auto noPort = f.read("[status]\nlisten = \"127.0.0.1\"\n");
  EXPECT_TRUE(hasError(noPort, 2, "needs a port")) << noPort.text;
  writeFile(f.dir / "token", "0123456789abcdef0123456789abcdef\n");
  const auto ok = f.read("[status]\nlisten = \"[::]:8181\"\ntoken_file = \"token\"\n");
  ASSERT_TRUE(ok.manifest) << ok.text;
  EXPECT_EQ(ok.manifest->status.host, "::");
  EXPECT_EQ(ok.manifest->status.port, 8181);
  EXPECT_FALSE(ok.manifest->status.loopbackOnly());
}

// Makes sure the read token and the snapshot switch are read and checked like the other
// [status] keys: misspelt keys get a suggestion, a short token is refused, a read token on a
// loopback-only server is said to do nothing. Example failure: `snapshot = flase` ignored, and
// a camera show's visitors visible to anyone on the network.
TEST(ManifestErrors, StatusReadTokenAndSnapshot) {
  ShowFolder f("status-read");
  const auto typo =
      f.read("[status]\nlisten = \"0.0.0.0:8180\"\ntoken_file = \"token\"\nread_tokn = \"x\"\nsnapshots = false\n");
  EXPECT_TRUE(hasError(typo, 4, "status.read_tokn: unknown key; did you mean 'read_token'?")) << typo.text;
  EXPECT_TRUE(hasError(typo, 5, "status.snapshots: unknown key; did you mean 'snapshot'?")) << typo.text;
  const auto shortToken = f.read("[status]\nread_token = \"abc\"\n");
  EXPECT_TRUE(hasError(shortToken, 2, "status.read_token: at least 16 characters")) << shortToken.text;
  const auto notABool = f.read("[status]\nsnapshot = \"no\"\n");
  EXPECT_FALSE(notABool.manifest) << notABool.text;
  EXPECT_TRUE(hasError(notABool, 2, "snapshot")) << notABool.text;
  const auto both = f.read(
      "[status]\nlisten = \"0.0.0.0:8180\"\ntoken_file = \"token\"\nread_token = \"0123456789abcdef\"\n"
      "read_token_file = \"read\"\n");
  EXPECT_TRUE(hasError(both, 5, "give read_token or read_token_file, not both")) << both.text;
  EXPECT_TRUE(hasWarning(both, 5, "status.read_token_file: 'read' does not exist yet")) << both.text;
  const auto loopback = f.read("[status]\nread_token = \"0123456789abcdef\"\n");
  ASSERT_TRUE(loopback.manifest) << loopback.text;
  EXPECT_TRUE(hasWarning(loopback, 2, "only this machine reaches")) << loopback.text;

  writeFile(f.dir / "token", "0123456789abcdef0123456789abcdef\n");
  writeFile(f.dir / "read", "fedcba9876543210fedcba9876543210\n");
  const auto ok = f.read(
      "[status]\nlisten = \"0.0.0.0:8180\"\ntoken_file = \"token\"\nread_token_file = \"read\"\nsnapshot = false\n");
  ASSERT_TRUE(ok.manifest) << ok.text;
  EXPECT_TRUE(fs::equivalent(ok.manifest->status.readTokenFile, f.dir / "read"));
  EXPECT_FALSE(ok.manifest->status.snapshot);
  EXPECT_FALSE(hasWarning(ok, 4, "")) << ok.text;
  const auto plain = f.read("[status]\n");
  ASSERT_TRUE(plain.manifest);
  EXPECT_TRUE(plain.manifest->status.snapshot) << "on unless the show turns it off";
  EXPECT_TRUE(plain.manifest->status.readToken.empty());
}

TEST(ManifestErrors, OutputsAndViews) {
  ShowFolder f("output");
  const auto r = f.read(
      "[output]\nsize = \"big\"\nmode = \"1920x1080@0\"\ndevice = \"/dev/fb0\"\n"  // 1-4
      "[[views]]\nname = \"a\"\nkind = \"facet\"\n"                                // 5-7
      "[[views]]\nname = \"a\"\nviewport = [0, 0, 10]\n"                           // 8-10
      "[[views]]\ncave = \"wall.obj\"\n");                                         // 11-12
  EXPECT_TRUE(hasError(r, 2, "output.size: 'big' is not a size")) << r.text;
  EXPECT_TRUE(hasError(r, 3, "'1920x1080@0' is not a mode")) << r.text;
  EXPECT_TRUE(hasError(r, 4, "'/dev/fb0' is not a DRM device")) << r.text;
  EXPECT_TRUE(hasError(r, 5, "a facet view needs cave")) << r.text;
  EXPECT_TRUE(hasError(r, 8, "a view named 'a' already exists")) << r.text;
  EXPECT_TRUE(hasError(r, 10, "must be [x, y, width, height]")) << r.text;
  EXPECT_TRUE(hasError(r, 12, "'wall.obj' is not a cave file")) << r.text;
  const auto fit = f.read("[output]\nsize = \"640x480\"\n[[views]]\nviewport = [320, 0, 640, 480]\n");
  EXPECT_TRUE(hasError(fit, 4, "does not fit the 640x480 output")) << fit.text;
  const auto ok = f.read(
      "[output]\nkind = \"kms\"\nmode = \"1280x720@59.94\"\n[[views]]\nkind = \"facet\"\ncave = "
      "\"room.cave\"\nfacet = 2\n");
  ASSERT_TRUE(ok.manifest) << ok.text;
  EXPECT_DOUBLE_EQ(ok.manifest->output.mode->refresh, 59.94);
  EXPECT_EQ(ok.manifest->views[0].facet, 2u);
}

// Makes sure a facet view's `winding` is read with its three values and a "did you mean" for a
// mistyped key or value. Example failures: "outwards" silently read as the default (the view stays
// black); a typo of the key accepted.
TEST(ManifestErrors, FacetWindingIsOneOfThreeWithSuggestions) {
  ShowFolder f("winding");
  const auto ok = f.read(
      "[[views]]\nname = \"a\"\nkind = \"facet\"\ncave = \"room.cave\"\nwinding = \"outward\"\n"
      "[[views]]\nname = \"b\"\nkind = \"facet\"\ncave = \"room.cave\"\nwinding = \"auto\"\n"
      "[[views]]\nname = \"c\"\nkind = \"facet\"\ncave = \"room.cave\"\n");
  ASSERT_TRUE(ok.manifest) << ok.text;
  EXPECT_EQ(ok.manifest->views[0].winding, formats::FacetWinding::kOutward);
  EXPECT_EQ(ok.manifest->views[1].winding, formats::FacetWinding::kAuto);
  EXPECT_EQ(ok.manifest->views[2].winding, formats::FacetWinding::kInward) << "the thesis' default";
  const auto bad = f.read(
      "[[views]]\nname = \"a\"\nkind = \"facet\"\ncave = \"room.cave\"\nwinding = \"outwards\"\n"  // 1-5
      "[[views]]\nname = \"b\"\nkind = \"facet\"\ncave = \"room.cave\"\nwindng = \"auto\"\n"       // 6-10
      "[[views]]\nname = \"c\"\nwinding = \"auto\"\n");                                            // 11-13
  EXPECT_FALSE(bad.manifest);
  EXPECT_TRUE(
      hasError(bad, 5, "views[0].winding: 'outwards' is not one of inward, outward or auto; did you mean 'outward'?"))
      << bad.text;
  EXPECT_TRUE(hasError(bad, 10, "views[1].windng: unknown key; did you mean 'winding'?")) << bad.text;
  EXPECT_TRUE(hasWarning(bad, 11, "views[2]: winding applies to facet views only")) << bad.text;
}

// Makes sure `[viewer]` places the facet views' viewer and names a tracker that moves it, with
// its smoothing, and that `basalt check` says what is wrong with each key. Example failures: a
// viewer tracker naming a dial box accepted (the viewer never moves); a time constant given to
// the one-euro filter silently ignored; a synthetic tracker's path read as a dial box's.
TEST(ManifestErrors, TheViewerStandsWhereItIsPutAndFollowsATracker) {
  ShowFolder f("viewer");
  const auto ok = f.read(
      "[[views]]\nname = \"a\"\nkind = \"facet\"\ncave = \"room.cave\"\n"
      "[viewer]\nposition = [0.1, -0.2, 0.3]\ntracker = \"head\"\nsmoothing = \"exponential\"\n"
      "time_constant_ms = 80\ntracker_offset = [0, -1.6, 0]\ntracker_scale = 0.001\n"
      "[devices.head]\nkind = \"tracker\"\nbackend = \"synthetic\"\nmotion = \"figure_eight\"\nradius = 0.4\n"
      "period = 6\nrate = 120\ncentre = [0, 1.6, 0]\n");
  ASSERT_TRUE(ok.manifest) << ok.text;
  const ViewerSpec& v = ok.manifest->viewer;
  EXPECT_EQ(v.position, (std::array<float, 3>{0.1f, -0.2f, 0.3f}));
  EXPECT_EQ(v.tracker, "head");
  EXPECT_EQ(v.smoothing.kind, runtime::HeadSmoothing::Kind::kExponential);
  EXPECT_EQ(v.smoothing.timeConstant, std::chrono::milliseconds(80));
  EXPECT_EQ(v.trackerOffset, (std::array<float, 3>{0, -1.6f, 0}));
  EXPECT_FLOAT_EQ(v.trackerScale, 0.001f);
  const DeviceSpec* head = ok.manifest->findDevice("head");
  ASSERT_NE(head, nullptr);
  EXPECT_EQ(head->kind, DeviceKind::kTracker);
  EXPECT_EQ(head->motion.shape, TrackerMotion::Shape::kFigureEight);
  EXPECT_FLOAT_EQ(head->motion.radius, 0.4f);
  EXPECT_DOUBLE_EQ(head->motion.period, 6);
  EXPECT_EQ(head->motion.rate, 120u);

  const auto bad = f.read(
      "[[views]]\nname = \"a\"\nkind = \"facet\"\ncave = \"room.cave\"\n"            // 1-4
      "[viewer]\nposition = [0, 0]\ntracker = \"dials\"\n"                           // 5-7
      "min_cutoff = 2\nsmoothing = \"exponential\"\n"                                // 8-9
      "[devices.dials]\nkind = \"dial_box\"\nbackend = \"synthetic\"\nradius = 1\n"  // 10-13
      "[devices.cam]\nkind = \"tracker\"\nbackend = \"v4l2\"\n");                    // 14-16
  EXPECT_FALSE(bad.manifest);
  EXPECT_TRUE(hasError(bad, 6, "viewer.position: must be a point [x, y, z] in the display geometry's units"))
      << bad.text;
  EXPECT_TRUE(hasError(bad, 7, "viewer.tracker: 'dials' is a dial_box, not a tracker")) << bad.text;
  EXPECT_TRUE(hasWarning(bad, 5, "viewer: min_cutoff and beta apply to smoothing = \"one_euro\" only")) << bad.text;
  EXPECT_TRUE(hasWarning(bad, 13, "devices.dials.radius: only synthetic trackers move by themselves")) << bad.text;
  EXPECT_TRUE(hasError(bad, 16, "devices.cam: a tracker cannot use the v4l2 backend")) << bad.text;

  const auto noFacets = f.read("[viewer]\nposition = [0, 0, 1]\nbeta = 1\n");
  ASSERT_TRUE(noFacets.manifest) << noFacets.text;
  EXPECT_TRUE(hasWarning(noFacets, 1, "viewer: only facet views draw from the viewer; this show has none"))
      << noFacets.text;
  EXPECT_TRUE(hasWarning(noFacets, 3, "viewer.beta: applies to a tracked viewer; there is no tracker"))
      << noFacets.text;
}

TEST(ManifestErrors, AnEmptyManifestPlaysTheDefaultShow) {
  ShowFolder f("empty");
  const auto r = f.read("");
  ASSERT_TRUE(r.manifest) << r.text;
  EXPECT_EQ(r.manifest->entry.kind, EntryKind::kBuiltinDefault);
  EXPECT_FALSE(r.manifest->status.enabled);
  EXPECT_EQ(r.manifest->name, "manifest-empty");
}

TEST(CheckCommand, PrintsFileLineMessagesAndFails) {
  ShowFolder f("cli");
  writeFile(f.dir / "show.toml", "[show]\nentry = \"gone.mdl\"\n[devices.x]\nkind = \"dial_box\"\n");
  const auto r = test::run({(test::binaryDir() / "basalt").string(), "check", (f.dir / "show.toml").string()});
  EXPECT_EQ(r.exitCode, 1) << r.output;
  EXPECT_NE(r.output.find((f.dir / "show.toml").string() + ":2: error: show.entry: 'gone.mdl' does not exist"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find(":3: error: devices.x: needs backend"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(": 2 errors, 0 warnings; its last good copy plays until they are fixed"), std::string::npos)
      << r.output;
  const auto unknown = test::run({(test::binaryDir() / "basalt").string(), "check", "readme.txt"});
  EXPECT_EQ(unknown.exitCode, 2) << "a file of an unknown kind is a usage error";
  EXPECT_NE(unknown.output.find("does not know '.txt' files"), std::string::npos) << unknown.output;
  const auto usage = test::run({(test::binaryDir() / "basalt").string(), "check"});
  EXPECT_EQ(usage.exitCode, 2) << usage.output;
}

// ---- Values ---------------------------------------------------------------------------------

TEST(ManifestValues, Durations) {
  EXPECT_EQ(*parseDuration("90s"), std::chrono::seconds(90));
  EXPECT_EQ(*parseDuration("1h30m"), std::chrono::minutes(90));
  EXPECT_EQ(*parseDuration("250ms"), std::chrono::milliseconds(250));
  EXPECT_EQ(*parseDuration("2d"), std::chrono::hours(48));
  EXPECT_EQ(*parseDuration("1.5"), std::chrono::milliseconds(1500));
  EXPECT_FALSE(parseDuration(""));
  EXPECT_FALSE(parseDuration("5 minutes"));
  EXPECT_FALSE(parseDuration("-3s"));
  EXPECT_FALSE(parseDuration("400d"));
}

TEST(ManifestValues, TimeRangesDatesAndModes) {
  EXPECT_EQ(*parseTimeRange("09:00-17:30"), (TimeRange{540, 1050}));
  EXPECT_EQ(*parseTimeRange("22:00-24:00"), (TimeRange{1320, 1440}));
  EXPECT_FALSE(parseTimeRange("24:00-24:00"));
  EXPECT_FALSE(parseTimeRange("10:00-10:00"));
  EXPECT_FALSE(parseTimeRange("10:60-11:00"));
  EXPECT_EQ(*parseDate("2028-02-29"), (Date{2028, 2, 29}));
  EXPECT_FALSE(parseDate("2027-02-29"));
  EXPECT_FALSE(parseDate("2027-2-1"));
  const auto mode = parseMode("1920x1080@60");
  ASSERT_TRUE(mode);
  EXPECT_EQ(mode->width, 1920u);
  EXPECT_EQ(mode->height, 1080u);
  EXPECT_DOUBLE_EQ(mode->refresh, 60);
  EXPECT_FALSE(parseMode("1920x"));
  EXPECT_FALSE(parseMode("0x10"));
}

// ---- Dial boxes a manifest names ------------------------------------------------------------

TEST(ManifestDevices, TheSerialBackendNeedsAPort) {
  ShowFolder f("serial-errors");
  const auto r = f.read(
      "[devices.a]\nkind = \"dial_box\"\nbackend = \"serial\"\n"                                    // 1-3
      "[devices.b]\nkind = \"camera\"\nbackend = \"serial\"\n"                                      // 4-6
      "[devices.c]\nkind = \"dial_box\"\nbackend = \"serial\"\nmatch = { path = \"usb:1-2\" }\n");  // 7-10
  EXPECT_TRUE(hasError(r, 1, "the serial backend needs the port: match = { path = \"/dev/ttyUSB0\" }")) << r.text;
  EXPECT_TRUE(hasError(r, 6, "a camera cannot use the serial backend")) << r.text;
  EXPECT_TRUE(hasError(r, 10, "'usb:1-2': the serial backend needs a /dev node")) << r.text;
}

// Makes sure a MIDI dial box's keys reach the backend as its options, and that what the backend
// would refuse (an unknown profile, a channel out of range, a 14-bit dial above CC 31, a path
// that is no sequencer port, MIDI keys on another backend) is named at its line by basalt check.
// Example failure: a misspelt profile accepted, the controller then read with the generic map.
TEST(ManifestDevices, MidiDialBoxesAndTheirOptions) {
  ShowFolder f("midi");
  const auto r = f.read(
      "[devices.mini]\nkind = \"dial_box\"\nbackend = \"midi\"\nmatch = { name = \"X-TOUCH MINI\" }\n"
      "midi = { profile = \"xtouch-mini-mc\", encoding = \"sign_magnitude\" }\n"
      "[devices.any]\nkind = \"dial_box\"\nbackend = \"midi\"\n"
      "midi = { channel = 2, dials = [16, 17, 18], notes = [36, 37], nrpn = [300], echo = true }\n");
  ASSERT_TRUE(r.manifest) << r.text;
  const DeviceSpec* mini = nullptr;
  const DeviceSpec* any = nullptr;
  for (const DeviceSpec& d : r.manifest->devices) {
    if (d.name == "mini") mini = &d;
    if (d.name == "any") any = &d;
  }
  ASSERT_TRUE(mini && any) << r.text;
  EXPECT_EQ(mini->backend, DeviceBackend::kMidi);
  EXPECT_EQ(mini->match.name, "X-TOUCH MINI");
  EXPECT_EQ(mini->midi.at("profile"), "xtouch-mini-mc");
  EXPECT_EQ(mini->midi.at("encoding"), "sign_magnitude");
  EXPECT_EQ(any->midi.at("channel"), "2");
  EXPECT_EQ(any->midi.at("dials"), "16,17,18");
  EXPECT_EQ(any->midi.at("notes"), "36,37");
  EXPECT_EQ(any->midi.at("nrpn"), "300");
  EXPECT_EQ(any->midi.at("echo"), "true");
}

TEST(ManifestDevices, MidiOptionsTheBackendWouldRefuseAreNamed) {
  ShowFolder f("midi-errors");
  const auto r = f.read(
      "[devices.bad]\nkind = \"dial_box\"\nbackend = \"midi\"\nmatch = { path = \"/dev/snd/midiC1D0\" }\n"  // 1-4
      "midi = { profile = \"launchpad\" }\n"                                                                // 5
      "[devices.wide]\nkind = \"dial_box\"\nbackend = \"midi\"\n"                                           // 6-8
      "midi = { dials = [40], high_resolution = true, channel = 17 }\n"                                     // 9
      "[devices.cam]\nkind = \"camera\"\nbackend = \"midi\"\n"                                              // 10-12
      "[devices.hid]\nkind = \"dial_box\"\nbackend = \"hid\"\nmidi = { profile = \"midimix\" }\n");         // 13-16
  EXPECT_TRUE(hasError(r, 4, "a MIDI port's path is seq:CLIENT:PORT")) << r.text;
  EXPECT_TRUE(hasError(r, 5, "'launchpad' is not one of")) << r.text;
  EXPECT_TRUE(hasError(r, 9, "17 is out of range")) << r.text;
  EXPECT_TRUE(hasError(r, 9, "CC 40 cannot be a 14-bit MSB")) << r.text;
  EXPECT_TRUE(hasError(r, 12, "a camera cannot use the midi backend")) << r.text;
  EXPECT_TRUE(hasWarning(r, 16, "only the midi backend reads it")) << r.text;
}

TEST(ManifestDevices, TheSgiSerialBoxOpensOnItsPortAndTurnsItsDials) {
  UniqueFd master(::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC));
  if (!master || ::grantpt(master.get()) != 0 || ::unlockpt(master.get()) != 0) {
    GTEST_SKIP() << "no pseudo-terminals here (/dev/ptmx)";
  }
  const std::string port = ::ptsname(master.get());
  ShowFolder f("serial");
  const auto r =
      f.read("[devices.sgi]\nkind = \"dial_box\"\nbackend = \"serial\"\nmatch = { path = \"" + port + "\" }\n");
  ASSERT_TRUE(r.manifest) << r.text;
  EXPECT_EQ(r.manifest->devices[0].backend, DeviceBackend::kSerial);
  ManualClock clock;
  ShowFactories factories;
  factories.devices = makeDeviceSource;
  auto loaded = loadShow(*r.manifest, clock, factories, false);
  ASSERT_TRUE(loaded) << loaded.error().describe();
  DeviceSlot& slot = (*loaded)->devices[0];
  ASSERT_TRUE(slot.source.provider) << slot.unavailable;
  // The show's dial box is the DeviceManager's to open, as the director asks for it.
  BoundedQueue<Event> events(64);
  devices::DeviceManager manager(clock, events);
  ASSERT_TRUE(manager.request(std::move(slot.source.request), std::move(slot.source.provider), slot.source.upkeep));
  // The box answers the reset (0x20) as the real one does.
  std::thread answer([&] {
    pollfd p{master.get(), POLLIN, 0};
    if (::poll(&p, 1, 3000) > 0) {
      std::uint8_t b[16];
      (void)!::read(master.get(), b, sizeof b);
      const std::uint8_t ok = 0x20;
      (void)!::write(master.get(), &ok, 1);
    }
  });
  manager.step(clock.now());
  answer.join();
  const devices::DialBox* box = manager.dialBox("sgi");
  ASSERT_NE(box, nullptr) << manager.status().at(0).lastError;
  EXPECT_EQ(box->info().path, port);
  const std::uint8_t turn[] = {0x33, 0x00, 0x32};  // dial 3 to count 50: a quarter turn
  ASSERT_EQ(::write(master.get(), turn, 3), 3);
  Event e;
  bool got = false;
  for (int i = 0; i < 400 && !got; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    manager.step(clock.now());
    while (events.pop(e)) {
      if (e.kind == EventKind::kDialDelta) got = true;
      if (got) break;
    }
  }
  ASSERT_TRUE(got) << "the turn reached the show's event queue";
  EXPECT_EQ(e.index, 3);
  EXPECT_DOUBLE_EQ(e.value, 0.25);
  // LAVA's table: dial 3 scales.
  EXPECT_EQ(slot.dials.dial(3).action, runtime::Action::kScale);
}

TEST(ManifestDevices, AHidRecorderFileReplaysAsADialBox) {
  const fs::path file = test::testdataDir() / "hid" / "udev-hid-bpf" / "huion_keydial_mini050_bluetooth.hid";
  if (test::testdataDir().empty() || !fs::exists(file)) GTEST_SKIP() << "../shared/testdata/hid is missing";
  ShowFolder f("hid-recorder");
  fs::copy_file(file, f.dir / "keydial.hid", fs::copy_options::overwrite_existing);
  writeFile(f.dir / "notes.hid", "this is not a recording\n");
  const auto bad = f.read(
      "[devices.a]\nkind = \"dial_box\"\nbackend = \"replay\"\ntrace = \"notes.hid\"\n"    // 1-4
      "[devices.b]\nkind = \"camera\"\nbackend = \"replay\"\ntrace = \"keydial.hid\"\n");  // 5-8
  EXPECT_TRUE(hasError(bad, 4, "'notes.hid' is not a hid-recorder file")) << bad.text;
  EXPECT_TRUE(hasError(bad, 8, "a camera replays a NAME.trace folder")) << bad.text;

  const auto r =
      f.read("[devices.keydial]\nkind = \"dial_box\"\nbackend = \"replay\"\ntrace = \"keydial.hid\"\nloop = false\n");
  ASSERT_TRUE(r.manifest) << r.text;
  ManualClock clock;
  ShowFactories factories;
  factories.devices = makeDeviceSource;
  auto loaded = loadShow(*r.manifest, clock, factories, false);
  ASSERT_TRUE(loaded) << loaded.error().describe();
  DeviceSlot& slot = (*loaded)->devices[0];
  ASSERT_TRUE(slot.source.provider) << slot.unavailable;
  BoundedQueue<Event> events(64);
  devices::DeviceManager manager(clock, events);
  ASSERT_TRUE(manager.request(std::move(slot.source.request), std::move(slot.source.provider), slot.source.upkeep));
  manager.step(clock.now());
  const devices::DialBox* box = manager.dialBox("keydial");
  ASSERT_NE(box, nullptr) << manager.status().at(0).lastError;
  EXPECT_EQ(box->info().vendor, 0x256c) << "the Huion keydial of the recording";
  // The recording's dial turn comes at 64.86 s after the start, on the show's clock.
  std::vector<Event> got;
  for (int i = 0; i < 700; ++i) {
    clock.advance(std::chrono::milliseconds(100));
    manager.step(clock.now());
    Event e;
    while (events.pop(e)) {
      if (e.kind != EventKind::kDeviceState) got.push_back(e);
    }
  }
  ASSERT_FALSE(got.empty()) << "the recording's reports came out as events";
  EXPECT_EQ(got[0].kind, EventKind::kDialDelta);
  EXPECT_EQ(got[0].time, Nanos{64'859'915'000});
}

// Makes sure a camera's `format` reaches the device spec and the corrupt fault needs MJPEG.
// Example failure: a misspelt format passed to the device (the camera then fails at every open
// instead of `basalt check` naming the line), or a corrupt fault on raw frames accepted.
TEST(ManifestCameraFormat, FormatsAndTheCorruptFault) {
  ShowFolder f("camera-format");
  const auto good = f.read(
      "[devices.cam]\nkind = \"camera\"\nbackend = \"synthetic\"\nformat = \"MJPEG\"\n"
      "faults = [ { at = \"1s\", fault = \"corrupt\" } ]\n");
  ASSERT_TRUE(good.manifest) << good.text;
  ASSERT_EQ(good.manifest->devices.size(), 1u);
  EXPECT_EQ(good.manifest->devices[0].format, "MJPEG");
  ASSERT_EQ(good.manifest->devices[0].faults.size(), 1u);
  EXPECT_EQ(good.manifest->devices[0].faults[0].kind, SyntheticFault::Kind::kCorrupt);
  EXPECT_EQ(good.manifest->devices[0].faults[0].at, std::chrono::seconds(1));

  const auto bad = f.read(
      "[devices.cam]\nkind = \"camera\"\nbackend = \"synthetic\"\nformat = \"JPEG\"\n"  // 1-4
      "faults = [ { at = \"1s\", fault = \"corrupt\" } ]\n");                           // 5
  EXPECT_FALSE(bad.manifest);
  EXPECT_TRUE(hasError(bad, 4, "'JPEG' is not one of")) << bad.text;
  EXPECT_TRUE(hasError(bad, 5, "only MJPEG frames can be corrupt")) << bad.text;
}

// Makes sure `[input]` (keyboards and mice from evdev) is read and checked like the rest.
// Example failure: a misspelt mode is taken as "auto" without a word, or a name list holding a
// number is accepted.
TEST(ManifestInput, EvdevModesNamesAndMistakes) {
  ShowFolder f("input");
  const auto defaults = f.read("[show]\nname = \"x\"\n");
  ASSERT_TRUE(defaults.manifest) << defaults.text;
  EXPECT_EQ(defaults.manifest->input.evdev, EvdevMode::kAuto);
  EXPECT_TRUE(defaults.manifest->input.keyboards);
  EXPECT_TRUE(defaults.manifest->input.pointers);

  const auto given = f.read("[input]\nevdev = \"on\"\npointers = false\nnames = [\"Dell KB216\", \"Logitech\"]\n");
  ASSERT_TRUE(given.manifest) << given.text;
  EXPECT_EQ(given.manifest->input.evdev, EvdevMode::kOn);
  EXPECT_TRUE(given.manifest->input.keyboards);
  EXPECT_FALSE(given.manifest->input.pointers);
  EXPECT_EQ(given.manifest->input.names, (std::vector<std::string>{"Dell KB216", "Logitech"}));

  const auto bad = f.read("[input]\nevdev = \"sometimes\"\nnames = [3]\nmice = true\n");
  EXPECT_FALSE(bad.manifest);
  EXPECT_TRUE(hasError(bad, 2, "input.evdev")) << bad.text;
  EXPECT_TRUE(hasError(bad, 3, "input.names: each entry must be a device name")) << bad.text;
  EXPECT_TRUE(hasError(bad, 4, "input.mice: unknown key")) << bad.text;

  const auto off = f.read("[output]\nkind = \"window\"\n[input]\nevdev = \"on\"\n");
  ASSERT_TRUE(off.manifest) << off.text;
  EXPECT_NE(off.text.find("reads every key twice"), std::string::npos) << off.text;
}

// Makes sure [osc] is read into its spec: listen, protocols, the allow-list, the rate (the HTTP
// controls' by default), each binding's action, types, input, range and mode, and each
// destination. Example failure: a fader's range read as input, and every move 127 times too far.
TEST(ManifestOsc, BindingsAndDestinationsAreRead) {
  ShowFolder f("osc-ok");
  const auto r = f.read(R"([status]
requests_per_second = 30

[osc]
listen = "0.0.0.0:9100"
protocols = ["udp"]
allow = ["10.0.0.5", "::1"]

[[osc.bind]]
address = "/basalt/spin"
action = "rotate_y"
input = [0, 127]
range = [-90, 90]
mode = "absolute"

[[osc.bind]]
address = "/basalt/next"
action = "next"
types = "f"

[[osc.bind]]
address = "/basalt/look"
action = "command"
command = "render.prim_type = $1"
types = "s"

[[osc.bind]]
address = "/basalt/zoom"
action = "scale"

[[osc.send]]
to = "192.168.1.20:53000"
protocol = "tcp"
prefix = "/node1"
events = ["item"]
figures = ["fps", "late_frames"]
rate = 5
)");
  ASSERT_TRUE(r.manifest) << r.text;
  const OscSpec& o = r.manifest->osc;
  EXPECT_TRUE(o.enabled);
  EXPECT_EQ(o.host, "0.0.0.0");
  EXPECT_EQ(o.port, 9100);
  EXPECT_TRUE(o.udp);
  EXPECT_FALSE(o.tcp);
  EXPECT_EQ(o.allow, (std::vector<std::string>{"10.0.0.5", "::1"}));
  EXPECT_EQ(o.messagesPerSecond, 30) << "the HTTP controls' rate when [osc] names none";
  ASSERT_EQ(o.bindings.size(), 4u);
  EXPECT_EQ(o.bindings[0].what, OscDo::kDial);
  EXPECT_EQ(o.bindings[0].action, runtime::Action::kRotateY);
  EXPECT_EQ(o.bindings[0].types, "f");
  EXPECT_EQ(o.bindings[0].input, (std::array<double, 2>{0, 127}));
  EXPECT_EQ(o.bindings[0].range, (std::array<double, 2>{-90, 90}));
  EXPECT_TRUE(o.bindings[0].absolute);
  EXPECT_EQ(o.bindings[0].line, 9);  // its first key: toml++ places a table of an array there
  EXPECT_EQ(o.bindings[1].what, OscDo::kNext);
  EXPECT_EQ(o.bindings[1].types, "f");
  EXPECT_EQ(o.bindings[2].what, OscDo::kCommand);
  EXPECT_EQ(o.bindings[2].command, "render.prim_type = $1");
  // A dial action without a range: one input (0..1) is a turn of LAVA's dial, a doubling for scale.
  EXPECT_EQ(o.bindings[3].range, (std::array<double, 2>{0, 1}));
  ASSERT_EQ(o.send.size(), 1u);
  EXPECT_EQ(o.send[0].host, "192.168.1.20");
  EXPECT_EQ(o.send[0].port, 53000);
  EXPECT_TRUE(o.send[0].tcp);
  EXPECT_EQ(o.send[0].prefix, "/node1");
  EXPECT_TRUE(o.send[0].item);
  EXPECT_FALSE(o.send[0].devices);
  EXPECT_FALSE(o.send[0].lock);
  EXPECT_EQ(o.send[0].figures, (std::vector<std::string>{"fps", "late_frames"}));
  EXPECT_EQ(o.send[0].rate, 5);
  // No allow-list on an open port: said, not refused.
  const auto open = f.read("[osc]\nlisten = \"0.0.0.0:9000\"\n");
  ASSERT_TRUE(open.manifest) << open.text;
  EXPECT_TRUE(hasWarning(open, 2, "lets any machine that reaches port 9000 drive the show")) << open.text;
  // Without [osc], nothing listens.
  const auto none = f.read("[show]\nname = \"x\"\n");
  ASSERT_TRUE(none.manifest) << none.text;
  EXPECT_FALSE(none.manifest->osc.enabled);
}

// Makes sure `basalt check` names the line of every OSC mistake: a bad listen address or port,
// an unknown action (with a suggestion), the wrong number of arguments for an action or a
// command's placeholders, a bad address, a duplicate, an unknown key, a bad destination.
// Example failure: `action = "rotate"` accepted and the binding doing nothing on site.
TEST(ManifestOsc, MistakesAreReportedAtTheirLine) {
  ShowFolder f("osc-errors");
  const auto r = f.read(R"([osc]
listen = "127.0.0.1:70000"
allow = ["somehost"]
protocol = ["udp"]

[[osc.bind]]
address = "/a"
action = "rotate"

[[osc.bind]]
address = "/b"
action = "rotate_x"
types = "ff"

[[osc.bind]]
address = "/c"
action = "command"
command = "load_object $2"
types = "s"

[[osc.bind]]
address = "basalt/d"
action = "next"

[[osc.bind]]
address = "/e/*"
action = "next"

[[osc.bind]]
address = "/f"
action = "next"
types = "s"

[[osc.bind]]
address = "/g"
action = "command"

[[osc.bind]]
address = "/h"
action = "reload"

[[osc.bind]]
address = "/h"
action = "previous"

[[osc.bind]]
address = "/tracker/1"
action = "next"

[[osc.bind]]
address = "/i"
action = "command"
command = "render.prim_type = $1"
types = "sf"

[[osc.send]]
to = "127.0.0.1"

[[osc.send]]
to = "127.0.0.1:0"
figures = ["fps", "frame_rate"]
events = ["items"]
)");
  EXPECT_FALSE(r.manifest) << r.text;
  EXPECT_TRUE(hasError(r, 2, "osc.listen: port '70000' is not 0 to 65535")) << r.text;
  EXPECT_TRUE(hasError(r, 3, "osc.allow: 'somehost' is not an IPv4 or IPv6 address")) << r.text;
  EXPECT_TRUE(hasError(r, 4, "osc.protocol: unknown key; did you mean 'protocols'?")) << r.text;
  EXPECT_TRUE(hasError(r, 8, "unknown action 'rotate'")) << r.text;
  EXPECT_TRUE(hasError(r, 13, "wrong arity: 'rotate_x' takes one number")) << r.text;
  EXPECT_TRUE(hasError(r, 19, "wrong arity: types = \"s\" gives 1 arguments, but the command has no $1")) << r.text;
  EXPECT_TRUE(hasError(r, 19, "the command uses $2, but types = \"s\" gives 1 argument")) << r.text;
  EXPECT_TRUE(hasError(r, 22, "osc.bind[3].address: 'basalt/d' must start with '/'")) << r.text;
  EXPECT_TRUE(hasError(r, 26, "holds '*'")) << r.text;
  EXPECT_TRUE(hasError(r, 32, "wrong arity: 'next' takes no argument, or one number")) << r.text;
  EXPECT_TRUE(hasError(r, 34, "action = \"command\" needs command")) << r.text;
  EXPECT_TRUE(hasError(r, 42, "osc.bind[8].address: '/h' is already bound")) << r.text;
  EXPECT_TRUE(hasError(r, 47, "kept for tracker devices")) << r.text;
  EXPECT_TRUE(hasError(r, 54, "types = \"sf\" gives 2 arguments, but the command has no $2")) << r.text;
  EXPECT_TRUE(hasError(r, 57, "osc.send[0].to: '127.0.0.1' needs a port")) << r.text;
  EXPECT_TRUE(hasError(r, 60, "port 0 is no destination")) << r.text;
  EXPECT_TRUE(hasError(r, 61, "'frame_rate' is not one of fps")) << r.text;
  EXPECT_TRUE(hasError(r, 62, "'items' is not one of item, devices or lock")) << r.text;
}

// Makes sure `basalt check` itself names the line of an OSC mistake and, for a good show, says
// what OSC it sets up. Example failure: a wrong arity reported without its line, or a good show's
// OSC bindings not mentioned, so the technician cannot tell they were read.
TEST(ManifestOsc, BasaltCheckNamesTheLineAndTheBindings) {
  ShowFolder f("osc-check");
  writeFile(f.dir / "show.toml",
            "[osc]\nlisten = \"127.0.0.1:9000\"\n\n[[osc.bind]]\naddress = \"/spin\"\n"
            "action = \"rotate_y\"\ntypes = \"fs\"\n");
  const auto bad = test::run({(test::binaryDir() / "basalt").string(), "check", (f.dir / "show.toml").string()});
  EXPECT_NE(bad.exitCode, 0) << bad.output;
  EXPECT_NE(bad.output.find("show.toml:7: error: osc.bind[0]: wrong arity: 'rotate_y' takes one number"),
            std::string::npos)
      << bad.output;
  writeFile(f.dir / "show.toml",
            "[osc]\nlisten = \"127.0.0.1:9000\"\n\n[[osc.bind]]\naddress = \"/spin\"\n"
            "action = \"rotate_y\"\n\n[[osc.send]]\nto = \"127.0.0.1:9001\"\n");
  const auto good = test::run({(test::binaryDir() / "basalt").string(), "check", (f.dir / "show.toml").string()});
  EXPECT_EQ(good.exitCode, 0) << good.output;
  EXPECT_NE(good.output.find("; OSC on 127.0.0.1:9000 with 1 binding and 1 destination"), std::string::npos)
      << good.output;
}

}  // namespace
}  // namespace basalt::kiosk
