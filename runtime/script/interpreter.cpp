#include "runtime/script/interpreter.h"

#include <cmath>
#include <cstring>
#include <fstream>

#include <fmt/format.h>

#include "runtime/log.h"

namespace basalt::script {

BASALT_LOG_CATEGORY(Script, "script");

using runtime::PartId;
using runtime::PartStyle;
using runtime::Show;

namespace {

constexpr std::uintmax_t kMaxScriptBytes = 64u << 20;

std::byte* bytesOf(PartStyle& s) { return reinterpret_cast<std::byte*>(&s); }
const std::byte* bytesOf(const PartStyle& s) { return reinterpret_cast<const std::byte*>(&s); }

double halton(int index, int base) {
  double f = 1;
  double r = 0;
  for (int i = index; i > 0; i /= base) {
    f /= base;
    r += f * (i % base);
  }
  return r;
}

/// `current op operand`; false for a division by zero.
bool combine(double current, double operand, AssignOp op, double& out) {
  switch (op) {
    case AssignOp::kAssign: out = operand; return true;
    case AssignOp::kAdd: out = current + operand; return true;
    case AssignOp::kSubtract: out = current - operand; return true;
    case AssignOp::kMultiply: out = current * operand; return true;
    case AssignOp::kDivide:
      if (operand == 0) return false;
      out = current / operand;
      return true;
  }
  return false;
}

std::string numberText(double v) { return fmt::format("{}", v); }

}  // namespace

Show startupShow() {
  Show show = Show::makeDefault();
  show.stopMotion();
  return show;
}

Vec2 jitterOffset(int pass) {
  return {static_cast<float>(halton(pass + 1, 2) - 0.5), static_cast<float>(halton(pass + 1, 3) - 0.5)};
}

Interpreter::Interpreter(Program program, std::filesystem::path scriptFolder)
    : program_(std::move(program)), folder_(std::move(scriptFolder)), defaults_(startupShow()) {
  partCache_.assign(program_.instrs.size(), UINT32_MAX);
  reported_.assign(program_.instrs.size(), 0);
  noEffectNoted_.assign(commands().size(), 0);
  moveMemory_.assign(commands().size(), 0.0);
  for (const CommandDef& def : commands()) {
    if (def.action == Action::kScaleLocal || def.action == Action::kScaleGlobal) {
      moveMemory_[commandIndex(def)] = 1.0;
    }
  }
}

Result<Interpreter> Interpreter::load(const std::filesystem::path& file) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(file, ec);
  if (ec) {
    return fail(ec == std::errc::no_such_file_or_directory ? Errc::kNotFound : Errc::kIo,
                fmt::format("cannot read the script: {}; check the path", ec.message()), file.string());
  }
  if (size > kMaxScriptBytes) {
    return fail(Errc::kResourceExhausted,
                fmt::format("the script is {} bytes; scripts may be at most {} MiB", size, kMaxScriptBytes >> 20),
                file.string());
  }
  std::ifstream in(file, std::ios::binary);
  if (!in) return fail(Errc::kIo, "cannot open the script for reading; check its permissions", file.string());
  std::string text(static_cast<std::size_t>(size), '\0');
  in.read(text.data(), static_cast<std::streamsize>(size));
  if (in.bad()) return fail(Errc::kIo, "reading the script failed", file.string());
  text.resize(static_cast<std::size_t>(in.gcount()));
  Program program = parseScript(text, file.string());
  std::filesystem::path folder = file.parent_path();
  if (folder.empty()) folder = ".";
  return Interpreter(std::move(program), std::move(folder));
}

StepResult Interpreter::step(Show& show, Host& host) {
  StepResult result;
  std::uint64_t spent = 0;
  while (pc_ < program_.instrs.size()) {
    const Instr& in = program_.instrs[pc_];
    if (spent++ >= budget_) {
      if (!budgetWarned_) {
        budgetWarned_ = true;
        report(in, Severity::kWarning,
               fmt::format("{} commands ran without a draw; the frame is drawn here so that the show goes on "
                           "(put a draw in the loop)",
                           budget_));
      }
      result.stop = StepStop::kBudget;
      result.line = in.line;
      result.jitterPass = jitterPass_;
      result.jitterPasses = jitterPasses_;
      result.offset = userOffset_;
      return result;
    }
    ++executed_;
    const CommandDef& def = program_.def(in);
    switch (def.action) {
      case Action::kDraw:
      case Action::kDrawNoClear: {
        ++pc_;
        ++draws_;
        if (def.action == Action::kDrawNoClear) noteFeature(in, def, host);
        result.stop = StepStop::kDraw;
        result.clear = def.action == Action::kDraw;
        result.line = in.line;
        result.jitterPass = jitterPass_;
        result.jitterPasses = jitterPasses_;
        result.offset = userOffset_;
        if (jitterPass_ >= 0) {
          const Vec2 j = jitterOffset(jitterPass_);
          result.offset = {result.offset.x + j.x, result.offset.y + j.y};
        }
        return result;
      }
      case Action::kQuit:
        quit_ = true;
        pc_ = program_.instrs.size();
        result.stop = StepStop::kQuit;
        result.line = in.line;
        return result;
      case Action::kLoop: {
        const auto n = static_cast<std::int64_t>(program_.numbers[in.values]);
        if (n <= 0 || depth_ >= blocks_.size()) {
          pc_ = static_cast<std::size_t>(in.jump) + 1;
          break;
        }
        blocks_[depth_++] = {static_cast<std::uint32_t>(pc_ + 1), n, 0, false};
        ++pc_;
        break;
      }
      case Action::kEndLoop: {
        if (depth_ == 0 || blocks_[depth_ - 1].jitter) {
          report(in, Severity::kError, "end_loop without its loop");  // the parser prevents this
          ++pc_;
          break;
        }
        Block& b = blocks_[depth_ - 1];
        if (--b.remaining > 0) {
          pc_ = b.begin;
        } else {
          --depth_;
          ++pc_;
        }
        break;
      }
      case Action::kJitter: {
        const auto n = static_cast<std::int32_t>(program_.numbers[in.values]);
        if (depth_ >= blocks_.size()) {
          pc_ = static_cast<std::size_t>(in.jump) + 1;
          break;
        }
        blocks_[depth_++] = {static_cast<std::uint32_t>(pc_ + 1), 0, n, true};
        jitterPass_ = 0;
        jitterPasses_ = n;
        ++pc_;
        break;
      }
      case Action::kEndJitter: endJitter(in, host); break;
      default:
        execute(in, show, host);
        ++pc_;
        break;
    }
  }
  result.stop = quit_ ? StepStop::kQuit : StepStop::kEnd;
  return result;
}

void Interpreter::endJitter(const Instr& in, Host& host) {
  if (depth_ == 0 || !blocks_[depth_ - 1].jitter) {
    report(in, Severity::kError, "end_jitter without its jitter");  // the parser prevents this
    ++pc_;
    return;
  }
  Block& b = blocks_[depth_ - 1];
  if (auto r = host.accumulateJitterPass(jitterPass_, b.passes); !r) {
    report(in, Severity::kError, fmt::format("end_jitter: {}", r.error().describe()));
  }
  ++jitterPass_;
  if (jitterPass_ < b.passes) {
    pc_ = b.begin;
    return;
  }
  --depth_;
  jitterPass_ = -1;
  jitterPasses_ = 0;
  if (!featureNoted_[static_cast<std::size_t>(Feature::kJitterDisplay)] && !host.renders(Feature::kJitterDisplay)) {
    featureNoted_[static_cast<std::size_t>(Feature::kJitterDisplay)] = true;
    report(in, Severity::kNote,
           fmt::format("end_jitter: the passes are averaged, but not rendered yet: {}",
                       featureName(Feature::kJitterDisplay)));
  }
  ++pc_;
}

void Interpreter::execute(const Instr& in, Show& show, Host& host) {
  const CommandDef& def = program_.def(in);
  switch (def.action) {
    case Action::kStore:
      // A setting at its start-up value changes nothing on screen: only a change is noted.
      if (store(in, def, show)) noteFeature(in, def, host);
      break;
    case Action::kPartSelect:
    case Action::kPartDeselect: {
      const bool select = def.action == Action::kPartSelect;
      if (text(in) == "Global") {
        report(in, Severity::kError,
               fmt::format("Global is not a part to {}; use {}", select ? "display" : "hide",
                           select ? "part.select_all" : "part.deselect_all"));
        break;
      }
      if (auto id = part(in, show)) show.setPartSelected(*id, select);
      break;
    }
    case Action::kSelectAll: show.selectAll(true); break;
    case Action::kDeselectAll: show.selectAll(false); break;
    case Action::kPartColor: partColor(in, show); break;
    case Action::kLoadObject: {
      if (auto r = host.loadObject(resolve(in), show); !r) {
        report(in, Severity::kError, fmt::format("load_object: {}", r.error().describe()));
        break;
      }
      object_ = {false, text(in), {}};
      object_.textures.reserve(show.partCount());
      for (PartId id = 0; id < show.partCount(); ++id) object_.textures.push_back(show.part(id).texture);
      break;
    }
    case Action::kLoadColorCube:
      show = startupShow();
      object_ = {};
      break;
    case Action::kLoadTexture: loadTexture(in, show, host); break;
    case Action::kNoFinalMove:
      noFinalMove_ = true;
      noteFeature(in, def, host);
      break;
    case Action::kUpdateMenus:
    case Action::kNoOp: {
      std::uint8_t& noted = noEffectNoted_[in.command];
      if (!noted) {
        noted = 1;
        report(in, Severity::kNote, fmt::format("{} has no effect in Basalt: {}", def.name, def.noEffect));
      }
      break;
    }
    case Action::kJitterOffset: {
      float next[2];
      float current[2] = {userOffset_.x, userOffset_.y};
      if (applyValue(in, def, current, next)) userOffset_ = {next[0], next[1]};
      break;
    }
    case Action::kSaveImage: {
      const std::string_view name = in.text == kNoString ? std::string_view{} : std::string_view(text(in));
      if (auto r = host.saveImage(name); !r) {
        report(in, Severity::kError, fmt::format("save_image: {}", r.error().describe()));
      }
      break;
    }
    case Action::kResetGlobalSettings: show.resetGlobalSettings(); break;
    case Action::kResetTransforms: show.resetTransforms(); break;
    case Action::kMotionStop: show.stopMotion(); break;
    case Action::kMotionStart: show.startMotion(); break;
    case Action::kGlobalFreeRun: show.motion().globalFreeRun = true; break;
    case Action::kLocalFreeRun: show.motion().localFreeRun = true; break;
    case Action::kGlobalStop:
      // LAVA: "If the local matrix is not in free run mode, this also stops all automatic motion."
      show.motion().globalFreeRun = false;
      if (!show.motion().localFreeRun) show.stopMotion();
      break;
    case Action::kLocalStop:
      show.motion().localFreeRun = false;
      if (!show.motion().globalFreeRun) show.stopMotion();
      break;
    case Action::kTranslateLocal:
    case Action::kTranslateGlobal:
    case Action::kRotateLocal:
    case Action::kRotateGlobal:
    case Action::kScaleLocal:
    case Action::kScaleGlobal: positionMove(in, def, show); break;
    case Action::kTv: tv(in, def, host); break;
    // Control flow is step()'s.
    case Action::kDraw:
    case Action::kDrawNoClear:
    case Action::kLoop:
    case Action::kEndLoop:
    case Action::kJitter:
    case Action::kEndJitter:
    case Action::kQuit: break;
  }
}

bool Interpreter::store(const Instr& in, const CommandDef& def, Show& show) {
  if (def.attr != runtime::AttrId::kCount) {
    std::optional<PartId> id;
    if (in.text != kNoString) {
      id = part(in, show);
      if (!id) return false;
    }
    const PartStyle& current = id ? show.resolvedStyle(*id) : show.globalStyle();
    PartStyle next = current;
    const std::size_t offset = runtime::attrField(def.attr).offset;
    if (!applyValue(in, def, bytesOf(current) + offset, bytesOf(next) + offset)) return false;
    const auto copy = [&](PartStyle& s) { runtime::copyAttr(def.attr, next, s); };
    if (id) {
      show.editPartStyle(*id, def.attr, copy);
    } else {
      show.editGlobalStyle(copy);
    }
    const PartStyle initial;
    return std::memcmp(bytesOf(next) + offset, bytesOf(initial) + offset, valueBytes(def)) != 0;
  }
  if (!def.slot) return false;
  int index = in.index;
  int& current = def.indexCount == runtime::kMaxLights ? currentLight_ : currentPlane_;
  if (def.scope == Scope::kIndexed) {
    // Without [N] a command addresses the light (or plane) named last, as LAVA's menu keeps a
    // current light number.
    if (index < 0) index = current;
    current = index;
  }
  void* storage = def.slot(show, index);
  alignas(16) std::byte next[16 * sizeof(float)];
  if (!applyValue(in, def, storage, next)) return false;
  std::memcpy(storage, next, valueBytes(def));
  return std::memcmp(next, def.slot(defaults_, index), valueBytes(def)) != 0;
}

void Interpreter::partColor(const Instr& in, Show& show) {
  const CommandDef& def = program_.def(in);
  std::optional<PartId> id;
  if (in.text != kNoString) {
    id = part(in, show);
    if (!id) return;
  }
  const runtime::Color3 current = id ? show.resolvedStyle(*id).front.color : show.globalStyle().front.color;
  runtime::Color3 next;
  if (!applyValue(in, def, &current, &next)) return;
  if (id) {
    show.editPartStyle(*id, runtime::AttrId::kFrontColor, [&](PartStyle& s) { s.front.color = next; });
    show.editPartStyle(*id, runtime::AttrId::kLinesColor, [&](PartStyle& s) { s.lines.color = next; });
    show.editPartStyle(*id, runtime::AttrId::kMarkersColor, [&](PartStyle& s) { s.markers.color = next; });
  } else {
    show.editGlobalStyle([&](PartStyle& s) {
      s.front.color = next;
      s.lines.color = next;
      s.markers.color = next;
    });
  }
}

bool Interpreter::applyValue(const Instr& in, const CommandDef& def, const void* current, void* out) {
  const double* values = program_.numbers.data() + in.values;
  switch (def.kind) {
    case ValueKind::kBool: {
      const bool b = values[0] != 0;
      std::memcpy(out, &b, 1);
      return true;
    }
    case ValueKind::kEnum:
    case ValueKind::kFlags: {
      const auto v = static_cast<std::uint8_t>(values[0]);
      std::memcpy(out, &v, 1);
      return true;
    }
    case ValueKind::kInt: {
      std::int32_t cur = 0;
      std::memcpy(&cur, current, sizeof cur);
      double r = 0;
      if (!combine(cur, values[0], in.op, r)) {
        report(in, Severity::kError,
               fmt::format("{} {} 0: division by zero; it stays {}", def.name, assignOpText(in.op), cur));
        return false;
      }
      r = std::trunc(r);
      if (r < def.min || r > def.max) {
        report(in, Severity::kError,
               fmt::format("{} would become {}, outside {} to {}; it stays {}", def.name, numberText(r),
                           numberText(def.min), numberText(def.max), cur));
        return false;
      }
      const auto v = static_cast<std::int32_t>(r);
      std::memcpy(out, &v, sizeof v);
      return true;
    }
    case ValueKind::kFloat: {
      float result[16];
      for (std::uint8_t i = 0; i < def.count; ++i) {
        if (in.op == AssignOp::kAssign) {
          result[i] = program_.floats[in.values + i];
          continue;
        }
        float cur = 0;
        std::memcpy(&cur, static_cast<const std::byte*>(current) + i * sizeof(float), sizeof cur);
        double r = 0;
        if (!combine(static_cast<double>(cur), values[in.count == 1 ? 0 : i], in.op, r)) {
          report(in, Severity::kError,
                 fmt::format("{} {} 0: division by zero; the value stays as it was", def.name, assignOpText(in.op)));
          return false;
        }
        const auto f = static_cast<float>(r);
        if (!std::isfinite(f)) {
          report(in, Severity::kError, fmt::format("{} would overflow; the value stays as it was", def.name));
          return false;
        }
        if (r < def.min || r > def.max) {
          report(in, Severity::kError,
                 fmt::format("{} would become {}, outside {} to {}; it stays {}", def.name, numberText(r),
                             numberText(def.min), numberText(def.max), numberText(static_cast<double>(cur))));
          return false;
        }
        result[i] = f;
      }
      std::memcpy(out, result, sizeof(float) * def.count);
      return true;
    }
    case ValueKind::kNone:
    case ValueKind::kFile:
    case ValueKind::kPartName: break;
  }
  return false;
}

void Interpreter::positionMove(const Instr& in, const CommandDef& def, Show& show) {
  double& memory = moveMemory_[in.command];
  double next = 0;
  if (!combine(memory, program_.numbers[in.values], in.op, next)) {
    report(in, Severity::kError, fmt::format("{} /= 0: division by zero; nothing moved", def.name));
    return;
  }
  const float v = in.op == AssignOp::kAssign ? program_.floats[in.values] : static_cast<float>(next);
  if (!std::isfinite(v)) {
    report(in, Severity::kError, fmt::format("{} would overflow; nothing moved", def.name));
    return;
  }
  memory = next;
  const runtime::Position before = show.position();
  Vec3 axis{};
  (def.axis == 0 ? axis.x : def.axis == 1 ? axis.y : axis.z) = v;
  switch (def.action) {
    case Action::kTranslateLocal: show.translateLocal(axis); break;
    case Action::kTranslateGlobal: show.translateGlobal(axis); break;
    case Action::kRotateLocal: show.rotateLocal(axis); break;
    case Action::kRotateGlobal: show.rotateGlobal(axis); break;
    case Action::kScaleLocal: show.scaleLocal(v); break;
    case Action::kScaleGlobal: show.scaleGlobal(v); break;
    default: break;
  }
  for (float f : show.position().global.m) {
    if (std::isfinite(f)) continue;
    show.position() = before;
    report(in, Severity::kError, fmt::format("{} = {} overflows the matrix; nothing moved", def.name, v));
    return;
  }
  for (float f : show.position().local.m) {
    if (std::isfinite(f)) continue;
    show.position() = before;
    report(in, Severity::kError, fmt::format("{} = {} overflows the matrix; nothing moved", def.name, v));
    return;
  }
}

void Interpreter::loadTexture(const Instr& in, Show& show, Host& host) {
  const std::string& name = text(in);
  if (auto r = host.loadTexture(resolve(in), name); !r) {
    report(in, Severity::kError, fmt::format("load_texture: {}", r.error().describe()));
    return;
  }
  std::size_t mapped = 0;
  for (PartId id = 0; id < show.partCount(); ++id) {
    if (!show.part(id).selected) continue;
    show.setPartTexture(id, name);
    ++mapped;
  }
  if (mapped == 0) {
    report(in, Severity::kWarning, "load_texture: no part is displayed, so the texture is on none; select parts first");
  }
  if (show.texture().source == runtime::TextureSource::kOff) show.texture().source = runtime::TextureSource::kImage;
  if (!host.renders(Feature::kTexture) && !featureNoted_[static_cast<std::size_t>(Feature::kTexture)]) {
    featureNoted_[static_cast<std::size_t>(Feature::kTexture)] = true;
    report(in, Severity::kNote,
           fmt::format("load_texture: loaded and mapped, but not rendered yet: {}", featureName(Feature::kTexture)));
  }
}

void Interpreter::tv(const Instr& in, const CommandDef& def, Host& host) {
  TvRequest request;
  request.op = def.tv;
  switch (def.tv) {
    case TvOp::kMovie: request.file = resolve(in); break;
    case TvOp::kShuttle: request.frames = static_cast<std::int32_t>(program_.numbers[in.values]); break;
    case TvOp::kRepeat:
    case TvOp::kCamera: request.on = program_.numbers[in.values] != 0; break;
    default: break;
  }
  if (def.tv == TvOp::kShuttle && in.op != AssignOp::kAssign) {
    // op-equals on the shuttle works from the last value given.
    double& memory = moveMemory_[in.command];
    double next = 0;
    if (!combine(memory, program_.numbers[in.values], in.op, next) || std::fabs(next) > 2147483647.0) {
      report(in, Severity::kError, fmt::format("{}: the shuttle value would be out of range", def.name));
      return;
    }
    request.frames = static_cast<std::int32_t>(next);
  }
  if (def.tv == TvOp::kShuttle) moveMemory_[in.command] = request.frames;
  if (auto r = host.tv(request); !r)
    report(in, Severity::kError, fmt::format("{}: {}", def.name, r.error().describe()));
}

std::optional<PartId> Interpreter::part(const Instr& in, const Show& show) {
  const std::size_t at = static_cast<std::size_t>(&in - program_.instrs.data());
  const std::string& name = text(in);
  std::uint32_t& cached = partCache_[at];
  if (cached < show.partCount() && show.part(cached).name == name) return cached;
  if (auto found = show.findPart(name)) {
    cached = *found;
    return found;
  }
  // Not found: say what there is.
  std::vector<std::string_view> names;
  names.reserve(show.partCount() + 1);
  names.emplace_back("Global");
  std::string caseHint;
  for (PartId id = 0; id < show.partCount(); ++id) {
    names.emplace_back(show.part(id).name);
    if (equalsIgnoreCase(show.part(id).name, name)) {
      caseHint = fmt::format(" (part names are case-sensitive: '{}')", show.part(id).name);
    }
  }
  std::string message = fmt::format("{}: the object has no part '{}'", program_.def(in).name, name);
  if (!caseHint.empty()) {
    message += caseHint;
  } else if (auto guess = closestMatch(name, names)) {
    message += fmt::format("; did you mean '{}'?", *guess);
  }
  if (show.partCount() > 0) {
    message += " The object's parts:";
    for (PartId id = 0; id < show.partCount() && id < 8; ++id) message += fmt::format(" '{}'", show.part(id).name);
    if (show.partCount() > 8) message += fmt::format(" and {} more", show.partCount() - 8);
  }
  report(in, Severity::kError, std::move(message));
  return std::nullopt;
}

std::filesystem::path Interpreter::resolve(const Instr& in) const { return (folder_ / text(in)).lexically_normal(); }

void Interpreter::noteFeature(const Instr& in, const CommandDef& def, Host& host) {
  if (def.feature == Feature::kRendered) return;
  const auto f = static_cast<std::size_t>(def.feature);
  if (featureNoted_[f] || host.renders(def.feature)) return;
  featureNoted_[f] = true;
  report(in, Severity::kNote, fmt::format("{}: stored, but not rendered yet: {}", def.name, featureName(def.feature)));
}

void Interpreter::report(const Instr& in, Severity severity, std::string message) {
  const std::size_t at = static_cast<std::size_t>(&in - program_.instrs.data());
  if (at < reported_.size()) {
    if (reported_[at]) return;
    reported_[at] = 1;
  }
  if (severity != Severity::kNote) ++problems_;
  const Diagnostic d{severity, program_.file, in.line, std::move(message)};
  if (reporter_) {
    reporter_(d);
    return;
  }
  if (severity == Severity::kNote) {
    log::info(kLogScript, "{}", d.describe());
  } else {
    log::warn(kLogScript, "{}", d.describe());
  }
}

}  // namespace basalt::script
