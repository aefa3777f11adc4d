#pragma once

/// \file
/// \brief A parsed `.mdl` script: its commands as instructions the interpreter runs, and every
/// error found on the way with its file and line. Parsing never stops at a bad line: the line is
/// reported and left out, as LAVA skipped what it could not read.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/script/command_table.h"
#include "runtime/script/lexer.h"

namespace basalt::script {

enum class Severity : std::uint8_t {
  kError,    ///< the line was not understood or could not be carried out; it was skipped
  kWarning,  ///< carried out, but not all of it (a value clamped, a file written in another format)
  kNote,     ///< carried out; something about it is worth knowing (not rendered yet)
};

std::string_view severityName(Severity severity);

/// \brief One message about a script, tied to its line.
struct Diagnostic {
  Severity severity = Severity::kError;
  std::string file;
  std::uint32_t line = 0;
  std::string message;
  /// \brief "file:line: message".
  [[nodiscard]] std::string describe() const;
};

inline constexpr std::uint32_t kNoString = UINT32_MAX;

/// \brief One command ready to run. Values live in the Program's pools.
struct Instr {
  std::uint16_t command = 0;        ///< index into commands()
  AssignOp op = AssignOp::kAssign;  ///< = or an op-equals sign
  std::uint8_t count = 0;           ///< numbers in the value (1 for op-equals on a vector: every component)
  std::int16_t index = -1;          ///< `[N]`, or -1 when not given
  std::uint32_t line = 0;           ///< where the command starts in the script
  std::uint32_t text = kNoString;   ///< the part name, file name or argument (Program::strings)
  std::uint32_t values = 0;         ///< first number in Program::numbers and Program::floats
  std::int32_t jump = -1;           ///< loops: the matching end; ends: the matching loop
};

/// \brief A whole script.
struct Program {
  std::string file;                     ///< the name messages use
  std::vector<Instr> instrs;            ///< in script order
  std::vector<double> numbers;          ///< values as doubles (enum indices, flag masks, numbers)
  std::vector<float> floats;            ///< the same numbers rounded once to float, for float fields
  std::vector<std::string> strings;     ///< part and file names
  std::vector<Diagnostic> diagnostics;  ///< what parsing found wrong, in line order
  std::uint32_t lines = 0;              ///< physical lines read
  std::uint32_t commandLines = 0;       ///< logical lines with a command (good or bad)

  [[nodiscard]] const CommandDef& def(const Instr& in) const { return commands()[in.command]; }
  [[nodiscard]] std::size_t errorCount() const;
};

/// \brief Loops and jitter loops nest at most this deep (LAVA: 10).
inline constexpr std::size_t kMaxNesting = 32;

/// \brief Orders messages by line, keeping the order of messages about the same line.
void sortByLine(std::vector<Diagnostic>& diagnostics);

/// \brief Parses a script. `file` names it in messages.
Program parseScript(std::string_view source, std::string file);

/// \brief Whether `name` is a file name a script may use: relative, inside the show folder (no
/// `..` that leaves it). "" when it may, else why not.
std::string confinedPathProblem(std::string_view name);

}  // namespace basalt::script
