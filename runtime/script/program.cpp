#include "runtime/script/program.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace basalt::script {

namespace {

std::string quoted(std::string_view text) { return fmt::format("'{}'", text); }

bool isName(const Token& t) {
  return t.kind == TokenKind::kWord || t.kind == TokenKind::kString || t.kind == TokenKind::kNumber;
}

std::string choiceList(const CommandDef& def) {
  std::string s;
  for (std::size_t i = 0; i < def.choices.size(); ++i) s += fmt::format("{}{}", i ? ", " : "", def.choices[i]);
  return s;
}

std::string numberText(double v) { return fmt::format("{}", v); }

class Parser {
 public:
  Parser(std::string_view source, Program& program) : reader_(source), p_(program) {}

  void run() {
    while (reader_.next(line_)) {
      ++p_.commandLines;
      parseLine();
    }
    closeOpenBlocks();
    sortByLine(p_.diagnostics);
  }

 private:
  struct OpenBlock {
    Action kind;
    std::uint32_t instr;
    std::uint32_t line;
  };

  void error(std::string message) {
    p_.diagnostics.push_back({Severity::kError, p_.file, line_.line, std::move(message)});
  }

  std::uint32_t addString(std::string_view s) {
    p_.strings.emplace_back(s);
    return static_cast<std::uint32_t>(p_.strings.size() - 1);
  }

  void addNumber(double d, float f) {
    p_.numbers.push_back(d);
    p_.floats.push_back(f);
  }

  void parseLine() {
    if (std::string problem = tokenize(line_.text, tokens_); !problem.empty()) {
      error(problem);
      return;
    }
    if (tokens_.empty()) return;
    const Token& first = tokens_[0];
    if (first.kind != TokenKind::kWord && first.kind != TokenKind::kNumber) {
      error(fmt::format("a line starts with a command, not {}", quoted(first.text)));
      return;
    }
    const CommandDef* def = findCommand(first.text);
    if (!def) {
      if (auto guess = suggestCommand(first.text)) {
        error(fmt::format("unknown command {}; did you mean '{}'?", quoted(first.text), *guess));
      } else {
        error(fmt::format("unknown command {}; 'basalt help script' lists every command", quoted(first.text)));
      }
      return;
    }
    Instr in;
    in.command = commandIndex(*def);
    in.line = line_.line;
    in.values = static_cast<std::uint32_t>(p_.numbers.size());
    bool ok = false;
    switch (def->syntax) {
      case Syntax::kAction: ok = parseAction(*def); break;
      case Syntax::kArgument:
      case Syntax::kOptionalArgument: ok = parseArgument(*def, in); break;
      case Syntax::kAssignment: ok = parseAssignment(*def, in); break;
    }
    if (!ok) {
      p_.numbers.resize(in.values);
      p_.floats.resize(in.values);
      return;
    }
    if (!structure(*def, in)) return;
    p_.instrs.push_back(in);
  }

  bool parseAction(const CommandDef& def) {
    if (tokens_.size() > 1) {
      error(fmt::format("{} takes nothing after it; found {}", def.name, quoted(tokens_[1].text)));
      return false;
    }
    return true;
  }

  bool parseArgument(const CommandDef& def, Instr& in) {
    if (tokens_.size() == 1) {
      if (def.syntax == Syntax::kOptionalArgument) return true;
      error(fmt::format("{} needs {}: {}", def.name, def.valueForm(), def.form()));
      return false;
    }
    if (tokens_.size() > 2) {
      error(fmt::format("{} takes one {} ({}); found {} after it{}", def.name, def.valueForm(), def.form(),
                        quoted(tokens_[2].text),
                        def.kind == ValueKind::kPartName ? "; put a name with spaces in double quotes" : ""));
      return false;
    }
    const Token& t = tokens_[1];
    if (t.kind == TokenKind::kOperator) {
      error(fmt::format("{} takes no '{}': {}", def.name, t.text, def.form()));
      return false;
    }
    return parseSingleValue(def, t, AssignOp::kAssign, in);
  }

  /// One value for kInt, kFile, kPartName (arguments and tv.movie).
  bool parseSingleValue(const CommandDef& def, const Token& t, AssignOp op, Instr& in) {
    switch (def.kind) {
      case ValueKind::kInt: return parseNumbers(def, std::span(&t, 1), op, in);
      case ValueKind::kFile: {
        if (!isName(t)) {
          error(fmt::format("{} needs a file name, not {}: {}", def.name, quoted(t.text), def.form()));
          return false;
        }
        if (std::string problem = confinedPathProblem(t.text); !problem.empty()) {
          error(fmt::format("{}: {}", def.name, problem));
          return false;
        }
        in.text = addString(t.text);
        return true;
      }
      case ValueKind::kPartName: {
        if (!isName(t)) {
          error(fmt::format("{} needs a part name, not {}: {}", def.name, quoted(t.text), def.form()));
          return false;
        }
        if (t.text.empty()) {
          error(fmt::format("{} needs a part name; \"\" is empty", def.name));
          return false;
        }
        in.text = addString(t.text);
        return true;
      }
      default: break;
    }
    error(fmt::format("{}: internal error: no single value of this kind", def.name));
    return false;
  }

  bool parseAssignment(const CommandDef& def, Instr& in) {
    std::size_t pos = 1;
    if (def.scope == Scope::kPart && pos < tokens_.size() && tokens_[pos].kind != TokenKind::kOperator) {
      const Token& t = tokens_[pos];
      if (!isName(t)) {
        error(fmt::format("{} takes a part name (or nothing for Global) before '=', not {}: {}", def.name,
                          quoted(t.text), def.form()));
        return false;
      }
      // "Global" (case-sensitive, like every part name) sets the global value.
      if (t.text != "Global") in.text = addString(t.text);
      ++pos;
    } else if (def.scope == Scope::kIndexed && pos < tokens_.size() && tokens_[pos].kind == TokenKind::kOpenBracket) {
      if (!parseIndex(def, pos, in)) return false;
    }
    if (pos >= tokens_.size()) {
      error(fmt::format("{} needs '=' and {}: {}", def.name, def.valueForm(), def.form()));
      return false;
    }
    const Token& sign = tokens_[pos];
    if (sign.kind != TokenKind::kOperator) {
      if (def.scope == Scope::kGlobal && isName(sign)) {
        error(fmt::format("{} applies to the whole show and takes no part name; found {}: {}", def.name,
                          quoted(sign.text), def.form()));
      } else if (def.scope == Scope::kIndexed) {
        error(fmt::format("{} takes '[N]' or '=' here, not {}: {}", def.name, quoted(sign.text), def.form()));
      } else {
        error(fmt::format("expected '=' after {}, not {}: {}", def.name, quoted(sign.text), def.form()));
      }
      return false;
    }
    ++pos;
    in.op = sign.op;
    if (in.op != AssignOp::kAssign && !def.acceptsOpEquals()) {
      if (def.noOpEquals) {
        error(fmt::format("{} does not take '{}': rotations take only '=' (LAVA manual §10)", def.name, sign.text));
      } else {
        error(fmt::format("{} does not take '{}': op-equals signs work on numbers; use '=': {}", def.name, sign.text,
                          def.form()));
      }
      return false;
    }
    const std::span<const Token> values = std::span(tokens_).subspan(pos);
    switch (def.kind) {
      case ValueKind::kBool:
      case ValueKind::kEnum: return parseChoice(def, values, in);
      case ValueKind::kFlags: return parseFlags(def, values, in);
      case ValueKind::kFloat:
      case ValueKind::kInt: return parseNumbers(def, values, in.op, in);
      case ValueKind::kFile:
      case ValueKind::kPartName:
        if (values.size() != 1) {
          error(fmt::format("{} takes one {}: {}", def.name, def.valueForm(), def.form()));
          return false;
        }
        return parseSingleValue(def, values[0], in.op, in);
      case ValueKind::kNone: break;
    }
    return false;
  }

  bool parseIndex(const CommandDef& def, std::size_t& pos, Instr& in) {
    const bool closed = pos + 2 < tokens_.size() && tokens_[pos + 2].kind == TokenKind::kCloseBracket;
    if (pos + 1 >= tokens_.size() || tokens_[pos + 1].kind != TokenKind::kNumber || !closed) {
      error(
          fmt::format("{} takes an index as '[N]' with N from 0 to {}: {}", def.name, def.indexCount - 1, def.form()));
      return false;
    }
    CNumber n;
    const NumberParse r = parseCNumber(tokens_[pos + 1].text, n);
    if (r != NumberParse::kOk || !n.integer || n.asInteger < 0 || n.asInteger >= def.indexCount) {
      error(fmt::format("{}: index {} is out of range; use 0 to {}", def.name, tokens_[pos + 1].text,
                        def.indexCount - 1));
      return false;
    }
    in.index = static_cast<std::int16_t>(n.asInteger);
    pos += 3;
    return true;
  }

  bool parseChoice(const CommandDef& def, std::span<const Token> values, Instr& in) {
    if (values.empty()) {
      error(fmt::format("{} needs one of: {}", def.name, choiceList(def)));
      return false;
    }
    if (values.size() > 1) {
      error(fmt::format("{} takes one of: {}; found {} after {}", def.name, choiceList(def), quoted(values[1].text),
                        quoted(values[0].text)));
      return false;
    }
    const int choice = findChoice(def, values[0]);
    if (choice < 0) return false;
    addNumber(choice, static_cast<float>(choice));
    in.count = 1;
    return true;
  }

  int findChoice(const CommandDef& def, const Token& t) {
    for (std::size_t i = 0; i < def.choices.size(); ++i) {
      if (t.kind == TokenKind::kWord && equalsIgnoreCase(t.text, def.choices[i])) return static_cast<int>(i);
    }
    std::string message = fmt::format("{} takes one of: {}; not {}", def.name, choiceList(def), quoted(t.text));
    if (auto guess = closestMatch(t.text, def.choices)) message += fmt::format(" (did you mean '{}'?)", *guess);
    error(std::move(message));
    return -1;
  }

  bool parseFlags(const CommandDef& def, std::span<const Token> values, Instr& in) {
    unsigned mask = 0;
    for (const Token& t : values) {
      const int choice = findChoice(def, t);
      if (choice < 0) return false;
      mask |= 1u << static_cast<unsigned>(choice);
    }
    addNumber(mask, static_cast<float>(mask));
    in.count = 1;
    return true;
  }

  bool parseNumbers(const CommandDef& def, std::span<const Token> values, AssignOp op, Instr& in) {
    const bool opEquals = op != AssignOp::kAssign;
    const std::size_t want = def.count;
    if (values.size() != want && !(opEquals && values.size() == 1)) {
      const char* noun = want == 1 ? "number" : "numbers";
      error(fmt::format("{} needs {} {}{}, found {}: {}", def.name, want, noun,
                        opEquals && want > 1 ? " (or one, for every component)" : "", values.size(), def.form()));
      return false;
    }
    for (const Token& t : values) {
      CNumber n;
      const NumberParse r = t.kind == TokenKind::kString ? NumberParse::kNotANumber : parseCNumber(t.text, n);
      if (r == NumberParse::kNotANumber) {
        error(fmt::format("{} needs {}; {} is not a number: {}", def.name,
                          def.kind == ValueKind::kInt ? "whole numbers" : "numbers", quoted(t.text), def.form()));
        return false;
      }
      if (r == NumberParse::kOutOfRange || !std::isfinite(n.value)) {
        error(fmt::format("{}: {} is out of range", def.name, quoted(t.text)));
        return false;
      }
      if (def.kind == ValueKind::kInt) {
        if (!n.integer) {
          error(fmt::format("{} needs a whole number, not {}", def.name, quoted(t.text)));
          return false;
        }
        if (!opEquals && (n.value < def.min || n.value > def.max)) {
          error(fmt::format("{} must be from {} to {}, not {}", def.name, numberText(def.min), numberText(def.max),
                            t.text));
          return false;
        }
        addNumber(static_cast<double>(n.asInteger), static_cast<float>(n.asInteger));
        continue;
      }
      if (!std::isfinite(n.asFloat)) {
        error(fmt::format("{}: {} is too large for a float", def.name, quoted(t.text)));
        return false;
      }
      if (!opEquals && (n.value < def.min || n.value > def.max)) {
        error(fmt::format("{} must be from {} to {}, not {}", def.name, numberText(def.min), numberText(def.max),
                          t.text));
        return false;
      }
      addNumber(n.value, n.asFloat);
    }
    in.count = static_cast<std::uint8_t>(values.size());
    return true;
  }

  /// Loops and jitter loops: matches ends with their beginnings.
  bool structure(const CommandDef& def, Instr& in) {
    const auto here = static_cast<std::uint32_t>(p_.instrs.size());
    if (def.action == Action::kLoop || def.action == Action::kJitter) {
      if (open_.size() >= kMaxNesting) {
        error(fmt::format("{} nests too deep: loops nest at most {} levels", def.name, kMaxNesting));
        return false;
      }
      if (def.action == Action::kJitter) {
        for (const OpenBlock& b : open_) {
          if (b.kind == Action::kJitter) {
            error(fmt::format("a jitter loop cannot be inside another (line {} opened one)", b.line));
            return false;
          }
        }
      }
      open_.push_back({def.action, here, line_.line});
      return true;
    }
    if (def.action == Action::kEndLoop || def.action == Action::kEndJitter) {
      const Action opener = def.action == Action::kEndLoop ? Action::kLoop : Action::kJitter;
      const std::string_view openerName = opener == Action::kLoop ? "loop" : "jitter";
      if (open_.empty()) {
        error(fmt::format("{} without a {} before it", def.name, openerName));
        return false;
      }
      const OpenBlock top = open_.back();
      if (top.kind != opener) {
        error(fmt::format("{} cannot close the {} of line {}; expected {}", def.name,
                          top.kind == Action::kLoop ? "loop" : "jitter", top.line,
                          top.kind == Action::kLoop ? "end_loop" : "end_jitter"));
        return false;
      }
      open_.pop_back();
      in.jump = static_cast<std::int32_t>(top.instr);
      p_.instrs[top.instr].jump = static_cast<std::int32_t>(here);
    }
    return true;
  }

  void closeOpenBlocks() {
    while (!open_.empty()) {
      const OpenBlock top = open_.back();
      open_.pop_back();
      const bool loop = top.kind == Action::kLoop;
      p_.diagnostics.push_back({Severity::kError, p_.file, top.line,
                                fmt::format("this {} has no {}; it ends with the script", loop ? "loop" : "jitter",
                                            loop ? "end_loop" : "end_jitter")});
      Instr end;
      end.command = commandIndex(*findCommand(loop ? "end_loop" : "end_jitter"));
      end.line = p_.lines;
      end.jump = static_cast<std::int32_t>(top.instr);
      p_.instrs[top.instr].jump = static_cast<std::int32_t>(p_.instrs.size());
      p_.instrs.push_back(end);
    }
  }

  LineReader reader_;
  Program& p_;
  LogicalLine line_;
  std::vector<Token> tokens_;
  std::vector<OpenBlock> open_;
};

}  // namespace

std::string_view severityName(Severity severity) {
  switch (severity) {
    case Severity::kError: return "error";
    case Severity::kWarning: return "warning";
    case Severity::kNote: return "note";
  }
  return "error";
}

std::string Diagnostic::describe() const { return fmt::format("{}:{}: {}", file, line, message); }

void sortByLine(std::vector<Diagnostic>& diagnostics) {
  // std::sort on (line, position) rather than std::stable_sort, whose temporary buffer
  // libstdc++ 12 implements with a function clang-19 reports as deprecated.
  std::vector<std::size_t> order(diagnostics.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return diagnostics[a].line != diagnostics[b].line ? diagnostics[a].line < diagnostics[b].line : a < b;
  });
  std::vector<Diagnostic> sorted;
  sorted.reserve(diagnostics.size());
  for (std::size_t i : order) sorted.push_back(std::move(diagnostics[i]));
  diagnostics = std::move(sorted);
}

std::size_t Program::errorCount() const {
  std::size_t n = 0;
  for (const Diagnostic& d : diagnostics) n += d.severity == Severity::kError ? 1 : 0;
  return n;
}

Program parseScript(std::string_view source, std::string file) {
  Program program;
  program.file = std::move(file);
  // Count physical lines for the end-of-script position of unclosed loops.
  std::uint32_t physical = 0;
  for (char c : source) physical += c == '\n' ? 1 : 0;
  if (!source.empty() && source.back() != '\n') ++physical;
  program.lines = physical;
  Parser parser(source, program);
  parser.run();
  return program;
}

std::string confinedPathProblem(std::string_view name) {
  if (name.empty()) return "the file name is empty";
  if (name.find('\0') != std::string_view::npos) return "the file name contains a NUL character";
  if (name.front() == '/') {
    return fmt::format(
        "'{}' is an absolute path; a script names files relative to its own folder, and may not leave it", name);
  }
  int depth = 0;
  std::size_t start = 0;
  while (start <= name.size()) {
    std::size_t end = name.find('/', start);
    if (end == std::string_view::npos) end = name.size();
    const std::string_view part = name.substr(start, end - start);
    if (part == "..") {
      if (--depth < 0) {
        return fmt::format("'{}' leaves the script's folder; a script may only name files inside it", name);
      }
    } else if (!part.empty() && part != ".") {
      ++depth;
    }
    start = end + 1;
  }
  return {};
}

}  // namespace basalt::script
