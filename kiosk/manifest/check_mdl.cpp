#include "kiosk/manifest/check_mdl.h"

#include <string>

#include <fmt/format.h>

#include "runtime/script/interpreter.h"

namespace basalt::kiosk {

using script::Action;

std::vector<script::Diagnostic> checkScriptStatically(const script::Program& program,
                                                      const std::filesystem::path& folder) {
  std::vector<script::Diagnostic> found;
  const runtime::Show cube = script::startupShow();
  bool partsKnown = true;
  for (const script::Instr& in : program.instrs) {
    const script::CommandDef& def = program.def(in);
    const bool names = in.text != script::kNoString;
    if (def.action == Action::kLoadObject) partsKnown = false;
    if (def.action == Action::kLoadColorCube) partsKnown = true;
    if (!names) continue;
    const std::string& text = program.strings[in.text];
    const bool file = def.kind == script::ValueKind::kFile && def.action != Action::kSaveImage;
    if (file) {
      std::error_code ec;
      const std::filesystem::path path = (folder / text).lexically_normal();
      if (!std::filesystem::exists(path, ec)) {
        found.push_back({script::Severity::kError, program.file, in.line,
                         fmt::format("{}: there is no file {} (names are relative to the script's folder)", def.name,
                                     path.string())});
      } else if (std::filesystem::is_directory(path, ec)) {
        found.push_back({script::Severity::kError, program.file, in.line,
                         fmt::format("{}: {} is a folder, not a file", def.name, path.string())});
      }
      continue;
    }
    const bool namesPart = def.kind == script::ValueKind::kPartName ||
                           (def.scope == script::Scope::kPart && def.syntax == script::Syntax::kAssignment);
    if (!namesPart || !partsKnown || text == "Global") continue;
    if (cube.findPart(text)) continue;
    std::vector<std::string_view> candidates{"Global"};
    for (runtime::PartId id = 0; id < cube.partCount(); ++id) candidates.emplace_back(cube.part(id).name);
    std::string message = fmt::format("{}: the start-up cube has no part '{}'", def.name, text);
    if (auto guess = script::closestMatch(text, candidates)) message += fmt::format("; did you mean '{}'?", *guess);
    message += " (its parts are 'face 1' to 'face 6'; part names are case-sensitive)";
    found.push_back({script::Severity::kError, program.file, in.line, std::move(message)});
  }
  return found;
}

CheckResult checkMdl(const std::filesystem::path& file) {
  CheckResult result;
  auto interpreter = script::Interpreter::load(file);
  if (!interpreter) {
    result.diagnostics.push_back({Severity::kError, file, 0, interpreter.error().message()});
    return result;
  }
  const script::Program& program = interpreter->program();
  std::filesystem::path folder = file.parent_path();
  if (folder.empty()) folder = ".";
  std::vector<script::Diagnostic> all = program.diagnostics;
  const std::vector<script::Diagnostic> more = checkScriptStatically(program, folder);
  all.insert(all.end(), more.begin(), more.end());
  script::sortByLine(all);
  for (const script::Diagnostic& d : all) {
    const Severity severity = d.severity == script::Severity::kError     ? Severity::kError
                              : d.severity == script::Severity::kWarning ? Severity::kWarning
                                                                         : Severity::kNote;
    result.diagnostics.push_back({severity, d.file, static_cast<int>(d.line), d.message});
  }
  result.items = program.commandLines;
  return result;
}

}  // namespace basalt::kiosk
