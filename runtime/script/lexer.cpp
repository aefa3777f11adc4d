#include "runtime/script/lexer.h"

#include <charconv>
#include <cmath>
#include <limits>

namespace basalt::script {

namespace {

bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f' || c == '\0'; }

bool isDigit(char c) { return c >= '0' && c <= '9'; }

bool isHexDigit(char c) { return isDigit(c) || (c >= 'a' && c <= 'f') || (c >= 'A' && c <= 'F'); }

char lower(char c) { return (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c; }

/// Where the comment of one physical line starts (a `!` outside double quotes), or its length.
std::size_t commentStart(std::string_view line) {
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    if (line[i] == '"') quoted = !quoted;
    if (line[i] == '!' && !quoted) return i;
  }
  return line.size();
}

std::string_view trimRight(std::string_view s) {
  while (!s.empty() && isSpace(s.back())) s.remove_suffix(1);
  return s;
}

bool isOperatorStart(std::string_view text, std::size_t i) {
  const char c = text[i];
  if (c == '=') return true;
  return (c == '+' || c == '-' || c == '*' || c == '/') && i + 1 < text.size() && text[i + 1] == '=';
}

/// Accepts C's integer suffixes: at most one u and one l or ll, in either order.
bool integerSuffix(std::string_view s) {
  int u = 0;
  int l = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const char c = lower(s[i]);
    if (c == 'u') {
      ++u;
    } else if (c == 'l') {
      if (l > 0 && lower(s[i - 1]) != 'l') return false;  // "lul" is not C
      ++l;
    } else {
      return false;
    }
  }
  return u <= 1 && l <= 2;
}

bool floatSuffix(std::string_view s) {
  return s.empty() || (s.size() == 1 && (lower(s[0]) == 'f' || lower(s[0]) == 'l'));
}

NumberParse integerValue(std::string_view digits, int base, bool negative, CNumber& out) {
  std::uint64_t magnitude = 0;
  if (digits.empty()) {
    magnitude = 0;
  } else {
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), magnitude, base);
    if (ec == std::errc::result_out_of_range) return NumberParse::kOutOfRange;
    if (ec != std::errc{} || end != digits.data() + digits.size()) return NumberParse::kNotANumber;
  }
  constexpr auto kMax = static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max());
  if (magnitude > kMax) return NumberParse::kOutOfRange;
  const auto v = static_cast<std::int64_t>(magnitude);
  out.integer = true;
  out.asInteger = negative ? -v : v;
  // Negated as floating point so that "-0" stays negative zero (Save Model writes it so).
  out.value = negative ? -static_cast<double>(magnitude) : static_cast<double>(magnitude);
  out.asFloat = negative ? -static_cast<float>(magnitude) : static_cast<float>(magnitude);
  return NumberParse::kOk;
}

NumberParse floatValue(std::string_view body, std::chars_format format, bool negative, CNumber& out) {
  double d = 0;
  const auto [dEnd, dEc] = std::from_chars(body.data(), body.data() + body.size(), d, format);
  if (dEc == std::errc::result_out_of_range) return NumberParse::kOutOfRange;
  if (dEc != std::errc{} || dEnd != body.data() + body.size()) return NumberParse::kNotANumber;
  float f = 0;
  const auto [fEnd, fEc] = std::from_chars(body.data(), body.data() + body.size(), f, format);
  // Too small or too large for a float: the double's rounding is kept (0, a denormal or inf);
  // float fields refuse values that are not finite.
  if (fEc != std::errc{} || fEnd != body.data() + body.size()) f = static_cast<float>(d);
  out.integer = false;
  out.value = negative ? -d : d;
  out.asFloat = negative ? -f : f;
  out.asInteger = 0;
  return NumberParse::kOk;
}

}  // namespace

std::string_view assignOpText(AssignOp op) {
  switch (op) {
    case AssignOp::kAssign: return "=";
    case AssignOp::kAdd: return "+=";
    case AssignOp::kSubtract: return "-=";
    case AssignOp::kMultiply: return "*=";
    case AssignOp::kDivide: return "/=";
  }
  return "=";
}

bool LineReader::next(LogicalLine& out) {
  out.text.clear();
  out.line = 0;
  bool continuing = false;
  while (pos_ < source_.size()) {
    std::size_t end = source_.find('\n', pos_);
    if (end == std::string_view::npos) end = source_.size();
    std::string_view physical = source_.substr(pos_, end - pos_);
    pos_ = end + 1;
    ++line_;
    if (!continuing) out.line = line_;
    std::string_view content = trimRight(physical.substr(0, commentStart(physical)));
    const bool continues = !content.empty() && content.back() == '\\';
    if (continues) content.remove_suffix(1);
    out.text.append(content);
    if (continues) {
      out.text.push_back(' ');
      continuing = true;
      continue;
    }
    continuing = false;
    bool blank = true;
    for (char c : out.text) blank = blank && isSpace(c);
    if (!blank) return true;
    out.text.clear();
  }
  if (continuing) {
    // A backslash on the last line: the command ends with the script.
    bool blank = true;
    for (char c : out.text) blank = blank && isSpace(c);
    if (!blank) return true;
  }
  return false;
}

std::string tokenize(std::string_view text, std::vector<Token>& out) {
  out.clear();
  std::size_t i = 0;
  while (i < text.size()) {
    const char c = text[i];
    if (isSpace(c)) {
      ++i;
      continue;
    }
    if (c == '"') {
      const std::size_t close = text.find('"', i + 1);
      if (close == std::string_view::npos) return "a name in double quotes has no closing quote";
      out.push_back({TokenKind::kString, AssignOp::kAssign, text.substr(i + 1, close - i - 1)});
      i = close + 1;
      continue;
    }
    if (c == '[' || c == ']') {
      out.push_back(
          {c == '[' ? TokenKind::kOpenBracket : TokenKind::kCloseBracket, AssignOp::kAssign, text.substr(i, 1)});
      ++i;
      continue;
    }
    if (isOperatorStart(text, i)) {
      AssignOp op = AssignOp::kAssign;
      std::size_t length = 2;
      switch (c) {
        case '+': op = AssignOp::kAdd; break;
        case '-': op = AssignOp::kSubtract; break;
        case '*': op = AssignOp::kMultiply; break;
        case '/': op = AssignOp::kDivide; break;
        default: length = 1; break;
      }
      out.push_back({TokenKind::kOperator, op, text.substr(i, length)});
      i += length;
      continue;
    }
    const std::size_t start = i;
    while (i < text.size() && !isSpace(text[i]) && text[i] != '"' && text[i] != '[' && text[i] != ']' &&
           !isOperatorStart(text, i)) {
      ++i;
    }
    const std::string_view word = text.substr(start, i - start);
    CNumber number;
    const bool numeric = parseCNumber(word, number) != NumberParse::kNotANumber;
    out.push_back({numeric ? TokenKind::kNumber : TokenKind::kWord, AssignOp::kAssign, word});
  }
  return {};
}

NumberParse parseCNumber(std::string_view text, CNumber& out) {
  std::string_view s = text;
  bool negative = false;
  if (!s.empty() && (s[0] == '+' || s[0] == '-')) {
    negative = s[0] == '-';
    s.remove_prefix(1);
  }
  if (s.empty()) return NumberParse::kNotANumber;

  if (s.size() >= 2 && s[0] == '0' && lower(s[1]) == 'x') {
    std::string_view rest = s.substr(2);
    std::size_t n = 0;
    while (n < rest.size() && isHexDigit(rest[n])) ++n;
    const std::size_t intDigits = n;
    std::size_t fraction = 0;
    bool point = false;
    if (n < rest.size() && rest[n] == '.') {
      point = true;
      std::size_t k = n + 1;
      while (k < rest.size() && isHexDigit(rest[k])) ++k;
      fraction = k - n - 1;
      n = k;
    }
    if (n < rest.size() && lower(rest[n]) == 'p') {
      // Hexadecimal floating point: the binary exponent is required (C99).
      if (intDigits == 0 && fraction == 0) return NumberParse::kNotANumber;
      std::size_t k = n + 1;
      if (k < rest.size() && (rest[k] == '+' || rest[k] == '-')) ++k;
      const std::size_t expDigits = k;
      while (k < rest.size() && isDigit(rest[k])) ++k;
      if (k == expDigits) return NumberParse::kNotANumber;
      if (!floatSuffix(rest.substr(k))) return NumberParse::kNotANumber;
      return floatValue(rest.substr(0, k), std::chars_format::hex, negative, out);
    }
    if (point || n == 0) return NumberParse::kNotANumber;
    if (!integerSuffix(rest.substr(n))) return NumberParse::kNotANumber;
    return integerValue(rest.substr(0, n), 16, negative, out);
  }

  std::size_t n = 0;
  while (n < s.size() && isDigit(s[n])) ++n;
  const std::size_t intDigits = n;
  bool isFloat = false;
  std::size_t fracDigits = 0;
  if (n < s.size() && s[n] == '.') {
    isFloat = true;
    std::size_t k = n + 1;
    while (k < s.size() && isDigit(s[k])) ++k;
    fracDigits = k - n - 1;
    n = k;
  }
  if (intDigits == 0 && fracDigits == 0) return NumberParse::kNotANumber;
  if (n < s.size() && lower(s[n]) == 'e') {
    isFloat = true;
    std::size_t k = n + 1;
    if (k < s.size() && (s[k] == '+' || s[k] == '-')) ++k;
    const std::size_t expDigits = k;
    while (k < s.size() && isDigit(s[k])) ++k;
    if (k == expDigits) return NumberParse::kNotANumber;
    n = k;
  }
  if (isFloat) {
    if (!floatSuffix(s.substr(n))) return NumberParse::kNotANumber;
    return floatValue(s.substr(0, n), std::chars_format::general, negative, out);
  }
  if (!integerSuffix(s.substr(n))) return NumberParse::kNotANumber;
  const std::string_view digits = s.substr(0, n);
  if (digits.size() > 1 && digits[0] == '0') {
    for (char c : digits) {
      if (c > '7') return NumberParse::kNotANumber;  // "08" is not a C literal
    }
    return integerValue(digits.substr(1), 8, negative, out);
  }
  return integerValue(digits, 10, negative, out);
}

std::string toLower(std::string_view text) {
  std::string s(text);
  for (char& c : s) c = lower(c);
  return s;
}

bool equalsIgnoreCase(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (lower(a[i]) != lower(b[i])) return false;
  }
  return true;
}

}  // namespace basalt::script
