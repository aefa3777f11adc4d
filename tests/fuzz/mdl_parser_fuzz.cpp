// Fuzzes the LAVA script parser and interpreter: any bytes must give a Program (with errors
// for what is wrong) and a bounded run, never a crash, a hang or an exception. And Save Model
// of whatever state the run reached must read back without a single error: it is the
// interpreter's own language.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "runtime/script/host.h"
#include "runtime/script/interpreter.h"
#include "runtime/script/program.h"
#include "runtime/script/save_model.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace basalt::script;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  Program program = parseScript(text, "fuzz.mdl");
  for (const Instr& in : program.instrs) {
    // The parser's own contract: every instruction's values are in the pools.
    if (in.values + in.count > program.numbers.size() || program.numbers.size() != program.floats.size()) {
      __builtin_trap();
    }
    if (in.text != kNoString && in.text >= program.strings.size()) __builtin_trap();
  }
  Interpreter interpreter(std::move(program), ".");
  interpreter.setReporter([](const Diagnostic&) {});
  interpreter.setInstructionBudget(4000);
  basalt::runtime::Show show = startupShow();
  OfflineHost host;
  for (int frame = 0; frame < 24; ++frame) {
    const StepResult step = interpreter.step(show, host);
    if (step.stop != StepStop::kDraw && step.stop != StepStop::kBudget) break;
    show.advanceFrame();
  }
  const Program saved = parseScript(saveModel(show, interpreter.objectSource()), "saved.mdl");
  if (saved.errorCount() != 0) __builtin_trap();
  return 0;
}
