#pragma once

/// \file
/// \brief Runs a parsed `.mdl` script against a Show, one frame at a time: `step()` carries out
/// commands until a `draw` ends the frame, the script quits, or it ends. The frame loop calls it
/// once per frame (kiosk/show/script_player.h), so a script is a sequence of frames played at the
/// show's frame rate, or as fast as possible under a ManualClock.
///
/// Threading: the frame loop's thread, like the Show. Steady state allocates nothing: loops,
/// part look-ups and values use storage sized when the script is loaded; only messages about
/// bad lines allocate, and each is given once.

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "runtime/math.h"
#include "runtime/script/host.h"
#include "runtime/script/program.h"
#include "runtime/show/show.h"

namespace basalt::script {

/// \brief Why step() returned.
enum class StepStop : std::uint8_t {
  kDraw,    ///< a `draw` (or `draw_no_clear`): draw this frame
  kEnd,     ///< the script has ended; the show goes on without it
  kQuit,    ///< `quit`: the program should end after this frame
  kBudget,  ///< the per-frame instruction budget ran out (a loop without `draw`): draw and go on
};

/// \brief What the frame that step() ended should look like.
struct StepResult {
  StepStop stop = StepStop::kEnd;
  bool clear = true;             ///< false for draw_no_clear
  std::int32_t jitterPass = -1;  ///< inside a jitter loop: this pass (from 0), else -1
  std::int32_t jitterPasses = 0;
  Vec2 offset;             ///< sub-pixel offset of the picture, in pixels (jitter + jitter_offset)
  std::uint32_t line = 0;  ///< the script line that ended the step
};

/// \brief Which object a script has loaded, for Save Model.
struct ObjectSource {
  bool colorCube = true;  ///< LAVA's colour cube (start-up, or load_color_cube)
  std::string file;       ///< otherwise the file given to load_object, as the script named it
  /// Per part (by PartId), the texture the object's own materials gave it when it was loaded:
  /// loading the object again gives it again, so Save Model leaves these to the model (a
  /// material's texture is named by its resolved path, which a script may not name).
  std::vector<std::string> textures;
};

/// \brief LAVA's start-up state as a script finds it: the colour cube, turned to show three
/// faces, at rest. (The default show without a script also turns the cube; a script starts from
/// rest so that its motion is its own. `motion.global_free_run` resumes the turn.)
runtime::Show startupShow();

/// \brief The sub-pixel offset of jitter pass `pass`, in pixels within (-0.5, 0.5): a Halton
/// (2, 3) sequence, so that any number of passes covers the pixel evenly.
Vec2 jitterOffset(int pass);

class Interpreter {
 public:
  /// \brief Receives every message about the script as it runs (errors, warnings, notes).
  using Reporter = std::function<void(const Diagnostic&)>;

  /// \brief Runs `program`; file names in it resolve against `scriptFolder`.
  Interpreter(Program program, std::filesystem::path scriptFolder);

  /// \brief Reads and parses a script file. Fails only when the file cannot be read; errors in
  /// the script are in `program().diagnostics`.
  [[nodiscard]] static Result<Interpreter> load(const std::filesystem::path& file);

  /// \brief Where messages go (by default: the log, category "script").
  void setReporter(Reporter reporter) { reporter_ = std::move(reporter); }
  /// \brief Instructions one step may carry out before it gives the frame back (default 1e6).
  void setInstructionBudget(std::uint64_t budget) { budget_ = budget; }

  /// \brief Carries out commands until the frame ends. Bad lines are reported (once each) and
  /// skipped; the show goes on.
  StepResult step(runtime::Show& show, Host& host);

  [[nodiscard]] bool finished() const { return pc_ >= program_.instrs.size(); }
  /// \brief The script line being carried out (or last carried out), for hosts' messages.
  [[nodiscard]] std::uint32_t currentLine() const {
    return pc_ < program_.instrs.size() ? program_.instrs[pc_].line : program_.lines;
  }
  [[nodiscard]] bool quit() const { return quit_; }
  [[nodiscard]] const Program& program() const { return program_; }
  [[nodiscard]] const ObjectSource& objectSource() const { return object_; }
  [[nodiscard]] bool noFinalMove() const { return noFinalMove_; }
  /// \brief Instructions carried out so far, and frames ended by draw.
  [[nodiscard]] std::uint64_t instructionsRun() const { return executed_; }
  [[nodiscard]] std::uint64_t draws() const { return draws_; }
  /// \brief Messages given at run time (errors and warnings, not notes).
  [[nodiscard]] std::uint64_t runtimeProblems() const { return problems_; }

 private:
  struct Block {
    std::uint32_t begin = 0;     // first instruction of the body
    std::int64_t remaining = 0;  // loop: passes left; jitter: passes done
    std::int32_t passes = 0;     // jitter: passes in all (0 for a loop)
    bool jitter = false;
  };

  void execute(const Instr& in, runtime::Show& show, Host& host);
  /// Stores the value; true when it now differs from the start-up value.
  bool store(const Instr& in, const CommandDef& def, runtime::Show& show);
  void partColor(const Instr& in, runtime::Show& show);
  void positionMove(const Instr& in, const CommandDef& def, runtime::Show& show);
  void loadTexture(const Instr& in, runtime::Show& show, Host& host);
  void tv(const Instr& in, const CommandDef& def, Host& host);
  void endJitter(const Instr& in, Host& host);
  /// Applies the instruction's value (with its op) to `current`, writing `out` (both `def`'s
  /// value). False, with the line reported, when the result is not allowed.
  bool applyValue(const Instr& in, const CommandDef& def, const void* current, void* out);
  /// The part an instruction names, or nothing (reported) when the object has no such part.
  std::optional<runtime::PartId> part(const Instr& in, const runtime::Show& show);
  std::filesystem::path resolve(const Instr& in) const;
  /// Reports once per feature that `def`'s feature is stored but not rendered yet.
  void noteFeature(const Instr& in, const CommandDef& def, Host& host);
  void report(const Instr& in, Severity severity, std::string message);
  [[nodiscard]] const std::string& text(const Instr& in) const { return program_.strings[in.text]; }

  Program program_;
  std::filesystem::path folder_;
  Reporter reporter_;
  std::uint64_t budget_ = 1'000'000;

  std::size_t pc_ = 0;
  std::array<Block, kMaxNesting + 1> blocks_{};
  std::size_t depth_ = 0;
  std::int32_t jitterPass_ = -1;
  std::int32_t jitterPasses_ = 0;
  Vec2 userOffset_;
  bool quit_ = false;
  bool noFinalMove_ = false;
  bool budgetWarned_ = false;
  int currentLight_ = 0;
  int currentPlane_ = 0;
  ObjectSource object_;

  std::vector<std::uint32_t> partCache_;  // per instruction: the PartId it found last
  std::vector<std::uint8_t> reported_;    // per instruction: reported once already
  std::vector<double> moveMemory_;        // per command: the last position.* value (op-equals)
  std::array<bool, static_cast<std::size_t>(Feature::kCount)> featureNoted_{};
  std::vector<std::uint8_t> noEffectNoted_;  // per command
  runtime::Show defaults_;                   // start-up values: a feature is noted only when changed
  std::uint64_t executed_ = 0;
  std::uint64_t draws_ = 0;
  std::uint64_t problems_ = 0;
};

}  // namespace basalt::script
