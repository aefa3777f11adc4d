#pragma once

/// \file
/// \brief LAVA's lexical rules for `.mdl` scripts (LAVA manual §10): one command per line, white
/// space anywhere, a backslash as the last character continues the command on the next line, `!`
/// starts a comment that runs to the end of the line, double quotes around names (required when
/// a name has a space), `[N]` indices, the op-equals signs `+= -= *= /=`, and numbers in any
/// form a C compiler accepts.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace basalt::script {

/// \brief One command's text after continuation lines are joined and comments removed.
struct LogicalLine {
  std::uint32_t line = 0;  ///< 1-based number of the physical line the command starts on
  std::string text;        ///< the joined text, without comments and continuation backslashes
};

/// \brief Splits a script into logical lines. Reuses `out`'s storage: reading a script
/// allocates only when a line is longer than any before.
class LineReader {
 public:
  explicit LineReader(std::string_view source) : source_(source) {}
  /// \brief The next line with a command (blank and comment-only lines are skipped), or false at
  /// the end of the script.
  bool next(LogicalLine& out);

 private:
  std::string_view source_;
  std::size_t pos_ = 0;
  std::uint32_t line_ = 0;
};

enum class TokenKind : std::uint8_t {
  kWord,      ///< a bare word: a command, a keyword, a part or file name without quotes
  kString,    ///< a double-quoted name; `text` is what is between the quotes
  kNumber,    ///< a word that is a whole C number literal (it may also be used as a name)
  kOperator,  ///< `=`, `+=`, `-=`, `*=` or `/=`
  kOpenBracket,
  kCloseBracket,
};

/// \brief The assignment forms. LAVA: "any numeric value following an equals sign (=) may also
/// be followed by an operator-equals sign (+=, -=, *=, or /=)".
enum class AssignOp : std::uint8_t { kAssign, kAdd, kSubtract, kMultiply, kDivide };

/// \brief "=", "+=", ...
std::string_view assignOpText(AssignOp op);

struct Token {
  TokenKind kind = TokenKind::kWord;
  AssignOp op = AssignOp::kAssign;  ///< for kOperator
  std::string_view text;            ///< a view into the LogicalLine's text
};

/// \brief Splits one logical line into tokens (appended to `out`, which is cleared first).
/// \return "" when the line is well formed, else what is wrong ("a name in quotes has no
/// closing quote").
std::string tokenize(std::string_view text, std::vector<Token>& out);

/// \brief A number as C writes it: decimal, octal (leading 0) and hexadecimal integers with
/// u/l suffixes; decimal and hexadecimal floating-point with f/l suffixes; an optional sign.
struct CNumber {
  double value = 0;      ///< the value as a double
  float asFloat = 0;     ///< the value rounded once, directly to float (what float fields take)
  bool integer = false;  ///< written as an integer literal
  std::int64_t asInteger = 0;
};

enum class NumberParse : std::uint8_t { kOk, kNotANumber, kOutOfRange };

/// \brief Parses `text` as one whole C number literal.
NumberParse parseCNumber(std::string_view text, CNumber& out);

/// \brief ASCII lower case, for case-insensitive names.
std::string toLower(std::string_view text);
bool equalsIgnoreCase(std::string_view a, std::string_view b);

}  // namespace basalt::script
