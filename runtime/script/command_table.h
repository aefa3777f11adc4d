#pragma once

/// \file
/// \brief Every command of the LAVA script language (LAVA manual §10) with its value forms, in
/// one table: the parser, the interpreter, Save Model, `basalt check` and the generated
/// reference page (docs/script-reference.md) all read it, so they cannot disagree.
///
/// Per-part attributes are stored through the Show's attribute table (`runtime::attrFields()`,
/// addressed by `AttrId`); global-only settings through a slot function that returns the field
/// in the Show; everything else is an action the interpreter carries out.

#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "runtime/show/attributes.h"
#include "runtime/show/show.h"

namespace basalt::script {

/// \brief What follows a command's name.
enum class Syntax : std::uint8_t {
  kAction,            ///< nothing: `draw`
  kArgument,          ///< one argument without '=': `loop 3`, `part.select "face 1"`
  kOptionalArgument,  ///< an argument that may be left out: `save_image ["name"]`
  kAssignment,        ///< `= VALUES` (or an op-equals sign)
};

/// \brief Where an assignment applies.
enum class Scope : std::uint8_t {
  kGlobal,   ///< the whole show; no part name may be given
  kPart,     ///< the five per-part forms: no name or `Global` (global), or a part name
  kIndexed,  ///< `[N]` before the sign picks a light or a clip plane
};

/// \brief The type of a command's value (or argument).
enum class ValueKind : std::uint8_t {
  kNone,      ///< an action without a value
  kBool,      ///< off | on
  kEnum,      ///< exactly one of `choices`
  kFlags,     ///< zero or more of `choices` (bit i for choice i)
  kFloat,     ///< `count` floating-point numbers
  kInt,       ///< one whole number
  kFile,      ///< a file name, in double quotes or bare
  kPartName,  ///< a part name, in double quotes or bare (case-sensitive)
};

/// \brief What the interpreter does with a command. `kStore` writes the value into the Show (a
/// per-part attribute or a global slot); the others are actions.
enum class Action : std::uint8_t {
  kStore,
  kPartSelect,
  kPartDeselect,
  kSelectAll,
  kDeselectAll,
  kPartColor,  ///< obj_colors.part_color: surface, line and marker colour together
  kLoadObject,
  kLoadColorCube,
  kLoadTexture,
  kDraw,
  kDrawNoClear,
  kNoFinalMove,
  kUpdateMenus,
  kLoop,
  kEndLoop,
  kJitter,
  kEndJitter,
  kJitterOffset,
  kQuit,
  kSaveImage,
  kResetGlobalSettings,
  kResetTransforms,
  kMotionStop,
  kMotionStart,
  kGlobalFreeRun,
  kGlobalStop,
  kLocalFreeRun,
  kLocalStop,
  kTranslateLocal,  ///< position.local_{x,y,z}_translate; `axis` says which
  kTranslateGlobal,
  kRotateLocal,
  kRotateGlobal,
  kScaleLocal,
  kScaleGlobal,
  kNoOp,  ///< accepted and reported once as having no effect (texture.binding, ...)
  kTv,    ///< the VCR and camera; `tv` says which operation
};

/// \brief The VCR remote (LAVA §7.1) and the camera switch, as scripts drive them.
enum class TvOp : std::uint8_t {
  kMovie,        ///< tv.movie = "file": load a movie
  kUnload,       ///< tv.unload
  kPlay,         ///< tv.play
  kPause,        ///< tv.pause
  kStop,         ///< tv.stop
  kStepForward,  ///< tv.step_forward: one frame on
  kStepReverse,  ///< tv.step_reverse: one frame back
  kRewind,       ///< tv.rewind: to the first frame
  kFastForward,  ///< tv.fast_forward: ten frames on
  kShuttle,      ///< tv.shuttle = N: N frames on (back when negative)
  kRepeat,       ///< tv.repeat = on|off: loop the movie
  kCamera,       ///< tv.camera = on|off: the live camera
};

/// \brief A part of the picture that a command changes. The kiosk's host says which of these
/// the renderer draws today; a command whose feature is not drawn yet is stored and reported
/// once ("stored, but ... not rendered yet").
enum class Feature : std::uint8_t {
  kRendered,  ///< always in effect (geometry, colours, lighting, view, motion, selection)
  kRasterOp,
  kMarkerShapes,
  kAntialiasing,
  kColorSelector,
  kLineStyle,
  kColorInterpolation,
  kFillStyle,
  kTransparency,
  kEdges,
  kNurbs,
  kPicking,
  kDepthCue,
  kTexture,
  kModelClipping,
  kAnnotation,
  kSingleBuffering,
  kStereo,
  kFloor,
  kShadow,
  kViewMatrix,
  kDrawNoClear,
  kNoFinalMove,
  kJitterDisplay,
  kCount
};

/// \brief "edges", "depth cueing", ...: what the message about an unrendered feature names.
std::string_view featureName(Feature feature);

/// \brief Where a command comes from.
enum class Origin : std::uint8_t {
  kManual,      ///< listed in LAVA manual §10
  kManualMenu,  ///< a control of LAVA's menus (§6-§8) that §10 does not list; Basalt adds it
  kBasalt,      ///< Basalt's own (the VCR and camera commands)
};

/// \brief Returns the storage of a global-only setting in `show` for index `index`.
using SlotFn = void* (*)(runtime::Show& show, int index);

/// \brief One command of the language.
struct CommandDef {
  std::string_view name;  ///< lower case, as the manual writes it: "render.prim_type"
  Syntax syntax = Syntax::kAction;
  Scope scope = Scope::kGlobal;
  ValueKind kind = ValueKind::kNone;
  std::uint8_t count = 0;                                 ///< numbers in a value (kFloat); 1 for kInt
  std::span<const std::string_view> choices;              ///< kBool, kEnum, kFlags
  double min = -std::numeric_limits<double>::infinity();  ///< smallest allowed number
  double max = std::numeric_limits<double>::infinity();   ///< largest allowed number
  bool noOpEquals = false;                                ///< refuses += -= *= /= (LAVA: rotations)
  std::uint8_t indexCount = 0;                            ///< kIndexed: indices 0 .. indexCount-1
  Action action = Action::kStore;
  runtime::AttrId attr = runtime::AttrId::kCount;  ///< per-part storage (kPart scope)
  SlotFn slot = nullptr;                           ///< global-only storage
  std::uint8_t axis = 0;                           ///< 0 x, 1 y, 2 z for translate and rotate actions
  TvOp tv = TvOp::kPlay;                           ///< for Action::kTv
  Feature feature = Feature::kRendered;
  Origin origin = Origin::kManual;
  std::string_view noEffect;  ///< why the command changes nothing in Basalt ("" when it does)
  std::string_view summary;   ///< one line for the reference page

  /// \brief True for numeric values that accept += -= *= /=.
  [[nodiscard]] bool acceptsOpEquals() const {
    return (kind == ValueKind::kFloat || kind == ValueKind::kInt) && syntax == Syntax::kAssignment && !noOpEquals;
  }
  /// \brief The command's form for messages and the reference: `render.prim_type [PART] = ...`.
  [[nodiscard]] std::string form() const;
  /// \brief The values part of the form: "wireframe | markers | solid", "<float> <float>".
  [[nodiscard]] std::string valueForm() const;
};

/// \brief Every command, grouped as the manual lists them.
std::span<const CommandDef> commands();

/// \brief The command named `name` (any case), including the manual's other spellings
/// (`render.hlshr_mode`), or nullptr.
const CommandDef* findCommand(std::string_view name);
/// \brief The index of `def` in commands().
std::uint16_t commandIndex(const CommandDef& def);

/// \brief Other spellings the parser accepts: alias → command name.
struct CommandAlias {
  std::string_view alias;
  std::string_view name;
  std::string_view why;
};
std::span<const CommandAlias> commandAliases();

/// \brief Longest word closestMatch() compares: a longer word (or candidate) gets no suggestion,
/// so that a command from the network costs the same small work whatever its length.
inline constexpr std::size_t kMaxSuggestedLength = 64;

/// \brief The most likely intended word among `candidates` for a misspelt `word` (compared
/// without case), or nothing when none is close. Bounded: words and candidates longer than
/// kMaxSuggestedLength are not compared, nor candidates whose length differs too much to be close.
std::optional<std::string_view> closestMatch(std::string_view word, std::span<const std::string_view> candidates);
/// \brief The command a misspelt name most likely meant.
std::optional<std::string_view> suggestCommand(std::string_view name);

// ---- Values in storage, shared by the interpreter, Save Model and the reference ----------

/// \brief The storage of `def` for the global value (per-part attributes: in `style`; slots: in
/// `show` at `index`). Null for actions.
void* globalStorage(const CommandDef& def, runtime::Show& show, runtime::PartStyle& style, int index);
/// \brief Writes the value at `storage` as the script writes it: "solid", "0.2 0.8 1", "on",
/// "ambient specular". Floats are written so that they read back exactly.
std::string formatValue(const CommandDef& def, const void* storage);
/// \brief Bytes the value occupies in storage.
std::size_t valueBytes(const CommandDef& def);

}  // namespace basalt::script
