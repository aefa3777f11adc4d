#pragma once

/// \file
/// \brief What every Basalt text-format parser shares: reading a file under a size cap, making
/// text of it (UTF-8 with or without BOM, UTF-16 decoded), the caps on counts, `file:line:column`
/// diagnostics, number scanning, and resolving the file names a file mentions.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/error.h"
#include "runtime/image.h"
#include "runtime/log.h"

namespace basalt::formats {

BASALT_LOG_CATEGORY(Formats, "formats");

/// \brief The caps that keep any input from allocating without bound or running for long.
/// A file over a cap is rejected as a whole, with a message naming the cap.
struct Limits {
  std::uint64_t maxFileBytes = std::uint64_t{1} << 30;  ///< 1 GiB of text
  std::uint32_t maxVertices = 1u << 26;                 ///< v, vt, vn each, and vertices after de-duplication
  std::uint32_t maxElements = 1u << 26;                 ///< faces + line segments + points
  std::uint32_t maxFaceCorners = 1u << 16;              ///< corners of one polygon
  std::uint32_t maxNames = 1u << 16;                    ///< objects, groups, materials, smoothing groups
  std::uint32_t maxImports = 4096;                      ///< models a scene imports (importdir included)
  std::uint32_t maxTerrainSide = 1024;                  ///< height-map pixels per side (1M grid vertices)
  std::uint32_t maxWarnings = 50;                       ///< warnings kept per file; the rest are counted
  /// Point-in-triangle tests one polygon's ear clipping may make before it falls back to a fan
  /// (bounds the O(n^2)..O(n^3) worst case of degenerate polygons).
  std::uint64_t triangulationBudget = 20'000'000;
};

/// \brief A problem in a file that did not stop it from loading: what was skipped and why.
struct Diagnostic {
  std::string where;    ///< "file:line:column", "file:line" or "file"
  std::string message;  ///< what is wrong and what Basalt did about it
  [[nodiscard]] std::string describe() const { return where.empty() ? message : where + ": " + message; }
  friend bool operator==(const Diagnostic&, const Diagnostic&) = default;
};

/// \brief Collects the warnings of one file: keeps the first `Limits::maxWarnings`, counts the
/// rest, and logs each kept one through the `formats` log category when asked to.
class Diagnostics {
 public:
  Diagnostics(std::string file, std::uint32_t cap, bool log);

  [[nodiscard]] const std::string& file() const { return file_; }
  /// \brief "file:line:column" (column 0 leaves it out; line 0 leaves both out).
  [[nodiscard]] std::string where(std::uint32_t line, std::uint32_t column = 0) const;
  void warn(std::uint32_t line, std::uint32_t column, std::string message);
  /// \brief Counts one use of a statement Basalt reads but does not use; `summarise` reports
  /// them in one warning ("ignored: vw (7), t (8)") instead of one per line.
  void ignored(std::string_view keyword, std::uint32_t line);
  /// \brief Adds the summaries (ignored statements, warnings over the cap) and returns them all.
  [[nodiscard]] std::vector<Diagnostic> finish();
  [[nodiscard]] std::size_t count() const { return kept_.size() + dropped_; }
  /// \brief The first warning, for a whole-file rejection that wants to say why.
  [[nodiscard]] const Diagnostic* first() const { return kept_.empty() ? nullptr : &kept_.front(); }

 private:
  void add(Diagnostic d);
  std::string file_;
  std::uint32_t cap_;
  bool log_;
  std::vector<Diagnostic> kept_;
  std::size_t dropped_ = 0;
  struct Ignored {
    std::string keyword;
    std::uint32_t count;
    std::uint32_t firstLine;
  };
  std::vector<Ignored> ignored_;
};

/// \brief Reads a whole file, refusing files over `maxBytes`.
[[nodiscard]] Result<std::string> readFileBytes(const std::filesystem::path& path, std::uint64_t maxBytes);

/// \brief Makes UTF-8 text of file bytes: drops a UTF-8 byte-order mark, decodes UTF-16 (with a
/// BOM, or recognised by its zero bytes) with a warning, and rejects other binary data (a zero
/// byte) with an error naming its line. Returns the input itself when nothing needs changing.
[[nodiscard]] Result<std::string> decodeText(std::string bytes, Diagnostics& diagnostics);

/// \brief Parses a floating-point number at the start of `text` as C and OBJ writers write it
/// ("1", "-.5", "+2.", "1e-3", "nan", "inf"); `used` gets the characters consumed. Fails when no
/// number starts there, or when it is out of float range.
[[nodiscard]] bool scanFloat(std::string_view text, float& value, std::size_t& used);
/// \brief Parses a whole token as a float; false when the token has anything else in it.
[[nodiscard]] bool parseFloat(std::string_view token, float& value);
/// \brief Parses a whole token as a signed 64-bit integer (an optional sign and digits).
[[nodiscard]] bool parseInt(std::string_view token, std::int64_t& value);

/// \brief True for the blanks that separate tokens (space, tab, vertical tab, form feed).
constexpr bool isBlank(char c) { return c == ' ' || c == '\t' || c == '\v' || c == '\f'; }
/// \brief `text` without leading and trailing blanks (and a trailing '\r').
std::string_view trim(std::string_view text);
/// \brief Splits on blanks; empty tokens are dropped.
std::vector<std::string_view> splitBlanks(std::string_view text);
/// \brief Trims and makes each run of blanks one space: how names are compared.
std::string normaliseName(std::string_view text);
/// \brief ASCII lower case.
std::string lowerAscii(std::string_view text);

/// \brief Walks the lines of a text: "\n", "\r\n" and a lone "\r" end a line, and the last line
/// needs no end.
class LineReader {
 public:
  /// \brief kObjData: a vertex or element statement (v, vt, vn, vc, f, l, p, ...) ending in a
  /// backslash continues on the next line, as the OBJ specification allows. Names and file
  /// names never continue, so that a name ending in a backslash reads back as written.
  enum class Continuation : std::uint8_t { kNone, kObjData };
  explicit LineReader(std::string_view text, Continuation continuation = Continuation::kNone,
                      std::uint32_t firstLine = 1)
      : text_(text), continuation_(continuation), nextNumber_(firstLine) {}
  /// \brief The next line without its end, or nothing at the end of the text. `number()` is its
  /// 1-based line number (the first line of a continued line).
  std::optional<std::string_view> next();
  [[nodiscard]] std::uint32_t number() const { return number_; }
  /// \brief The number the next line will have.
  [[nodiscard]] std::uint32_t nextNumber() const { return nextNumber_; }
  /// \brief 1-based column of `at`, a position inside the line `next()` returned last (after a
  /// continuation, columns count from the start of the joined line).
  [[nodiscard]] std::uint32_t column(std::string_view line, const char* at) const {
    return static_cast<std::uint32_t>(at - line.data()) + 1;
  }

 private:
  std::string_view text_;
  Continuation continuation_;
  std::uint32_t nextNumber_;
  std::size_t pos_ = 0;
  std::uint32_t number_ = 0;
  std::string joined_;
};

/// \brief True when an OBJ line is a vertex or element statement, whose arguments may continue
/// on the next line after a backslash.
bool isObjDataStatement(std::string_view line);

/// \brief One item of a thesis-style statement line: `name[arg,arg]` or a bare word.
struct StatementItem {
  std::string_view name;               ///< the word before '[' (or the bare word)
  std::vector<std::string_view> args;  ///< inside the brackets, split on commas and blanks
  bool bracketed = false;
  std::size_t offset = 0;      ///< where the item starts in the line
  std::size_t argsOffset = 0;  ///< where the first argument starts
};

/// \brief Splits a `.sce`/`.cave` line ("fog start[1] end[10] color[255,0,0]") into items; a
/// blank may separate a name from its '['. On an unclosed '[' returns false with `errorAt` set.
bool splitStatementItems(std::string_view line, std::vector<StatementItem>& items, std::size_t& errorAt);

/// \brief Where a file named inside another file was found.
struct ResolvedPath {
  std::filesystem::path path;  ///< the file found, or the best guess (base folder + name) when not
  bool found = false;
};

/// \brief Finds a file named in a model, material library or scene: Windows separators become
/// '/', a relative name is looked up in `base`, then by its last component in `base` (for
/// absolute paths from other machines), then in each search folder, then by a case-insensitive
/// match of its last component in `base`.
ResolvedPath resolveReferencedFile(std::string_view name, const std::filesystem::path& base,
                                   const std::vector<std::filesystem::path>& searchPaths);

/// \brief `target` relative to `folder` when that is possible, with '/' separators: how Basalt
/// writes file names into the files it saves.
std::string relativeReference(const std::filesystem::path& target, const std::filesystem::path& folder);

/// \brief Decodes an image file (media::readImage in a running Basalt): formats in runtime/
/// cannot reach media/, so whoever loads a scene passes the decoder down.
using ImageDecoder = std::function<Result<Image>(const std::filesystem::path&)>;

/// \brief How to load a file and the files it names.
struct LoadOptions {
  Limits limits;
  /// Folders searched after the file's own folder for material libraries, textures and imports.
  std::vector<std::filesystem::path> searchPaths;
  /// Log each warning through the `formats` category as well as returning it.
  bool logWarnings = true;
  /// Decodes height maps for `.sce` terrains; without it a terrain is skipped with a warning.
  ImageDecoder decodeImage;
};

/// \brief Builds a parse error at `where` ("file:line:column: message").
inline std::unexpected<Error> parseError(std::string where, std::string message) {
  return fail(Errc::kParse, std::move(message), std::move(where));
}

}  // namespace basalt::formats
