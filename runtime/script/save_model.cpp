#include "runtime/script/save_model.h"

#include <map>
#include <vector>

#include <fmt/format.h>

#include "runtime/script/command_table.h"

namespace basalt::script {

using runtime::PartId;
using runtime::PartStyle;
using runtime::Show;

namespace {

std::string quotedName(const std::string& name) { return fmt::format("\"{}\"", name); }

/// The command that stores attribute `attr` per part (obj_colors.part_color, which sets three,
/// is not one of them).
const CommandDef* storeCommandFor(runtime::AttrId attr) {
  for (const CommandDef& def : commands()) {
    if (def.action == Action::kStore && def.attr == attr) return &def;
  }
  return nullptr;
}

/// "name = value"; "name =" for an empty set of flags.
std::string assignment(std::string_view target, const std::string& value) {
  return value.empty() ? fmt::format("{} =", target) : fmt::format("{} = {}", target, value);
}

void line(std::string& out, std::string_view text) {
  out += text;
  out += '\n';
}

}  // namespace

std::string saveModel(const Show& original, const ObjectSource& object) {
  // The slot functions address fields of a mutable Show; they only read here.
  Show show = original;
  PartStyle global = show.globalStyle();
  std::string out;
  line(out, "! Basalt Save Model (LAVA manual section 8): every setting of the show.");
  line(out, "! Run it with `basalt run FILE.mdl`; edit it to taste.");
  line(out, "");

  // The object first: loading one resets every attribute.
  if (object.colorCube) {
    line(out, "load_color_cube");
  } else {
    line(out, fmt::format("load_object {}", quotedName(object.file)));
  }

  // Textures go on the displayed parts, so display exactly the parts of each texture in turn.
  // A part showing the texture its object's materials gave it gets it again from load_object:
  // that one is left to the model (its name is the material's resolved path, which a script
  // may not name: absolute, or relative to the model's folder rather than the script's).
  std::map<std::string, std::vector<PartId>> textured;
  for (PartId id = 0; id < show.partCount(); ++id) {
    const std::string& texture = show.part(id).texture;
    if (texture.empty()) continue;
    if (!object.colorCube && id < object.textures.size() && object.textures[id] == texture) continue;
    textured[texture].push_back(id);
  }
  if (!textured.empty()) {
    line(out, "");
    line(out, "! Textures");
    for (const auto& [texture, parts] : textured) {
      line(out, "part.deselect_all");
      for (PartId id : parts) line(out, fmt::format("part.select {}", quotedName(show.part(id).name)));
      line(out, fmt::format("load_texture {}", quotedName(texture)));
    }
  }

  line(out, "");
  line(out, "! Global attributes (each part's own settings below win over these)");
  for (const CommandDef& def : commands()) {
    if (def.action != Action::kStore || def.scope != Scope::kPart) continue;
    line(out, assignment(def.name, formatValue(def, globalStorage(def, show, global, 0))));
  }

  bool anyOwn = false;
  for (PartId id = 0; id < show.partCount(); ++id) {
    const runtime::PartState& part = show.part(id);
    if (part.mask.none()) continue;
    if (!anyOwn) {
      line(out, "");
      line(out, "! Attributes parts set for themselves");
      anyOwn = true;
    }
    PartStyle own = part.own;
    for (std::size_t bit = 0; bit < runtime::kAttrCount; ++bit) {
      if (!part.mask.test(bit)) continue;
      const CommandDef* def = storeCommandFor(static_cast<runtime::AttrId>(bit));
      if (!def) continue;
      line(out, assignment(fmt::format("{} {}", def->name, quotedName(part.name)),
                           formatValue(*def, globalStorage(*def, show, own, 0))));
    }
  }

  line(out, "");
  line(out, "! Settings of the whole show");
  for (const CommandDef& def : commands()) {
    if (def.action != Action::kStore || def.scope == Scope::kPart || !def.slot) continue;
    if (def.scope == Scope::kIndexed) {
      for (int i = 0; i < def.indexCount; ++i) {
        line(out, assignment(fmt::format("{} [{}]", def.name, i), formatValue(def, def.slot(show, i))));
      }
    } else {
      line(out, assignment(def.name, formatValue(def, def.slot(show, 0))));
    }
  }

  // Motion that is running: motion.start counts num_frames from now, so start it with the frames
  // left, then put num_frames back; then each matrix's free run as it is.
  const runtime::Motion& motion = show.motion();
  line(out, "");
  line(out, "! Motion");
  if (motion.framesLeft > 0) {
    line(out, fmt::format("motion.num_frames = {}", motion.framesLeft));
    line(out, "motion.start");
    line(out, fmt::format("motion.num_frames = {}", motion.numFrames));
  }
  line(out, motion.globalFreeRun ? "motion.global_free_run" : "motion.global_stop");
  line(out, motion.localFreeRun ? "motion.local_free_run" : "motion.local_stop");

  line(out, "");
  line(out, "! Displayed parts");
  line(out, "part.select_all");
  for (PartId id = 0; id < show.partCount(); ++id) {
    if (!show.part(id).selected) line(out, fmt::format("part.deselect {}", quotedName(show.part(id).name)));
  }

  const Show fresh;
  std::vector<std::string_view> unsaved;
  if (show.fog() != fresh.fog()) unsaved.emplace_back("fog");
  if (show.earthSky() != fresh.earthSky()) unsaved.emplace_back("the earth-sky");
  if (show.backgroundKind() != fresh.backgroundKind() || show.backgroundImage() != fresh.backgroundImage()) {
    unsaved.emplace_back("the background image or sky");
  }
  if (!unsaved.empty()) {
    line(out, "");
    std::string list;
    for (std::size_t i = 0; i < unsaved.size(); ++i) list += fmt::format("{}{}", i ? ", " : "", unsaved[i]);
    line(out, fmt::format("! Not saved (no script command sets them; the scene file does): {}", list));
  }
  return out;
}

}  // namespace basalt::script
