// Show items read by runtime/formats and runtime/script, prepared on the show loader's thread
// and put on the Show on the frame loop's thread.

#include "kiosk/show/readers.h"

#include <algorithm>
#include <optional>

#include <fmt/format.h>
#include <fmt/std.h>

#include "kiosk/show/show_host.h"
#include "media/image_io.h"
#include "runtime/formats/model.h"
#include "runtime/formats/scene.h"
#include "runtime/log.h"
#include "runtime/script/interpreter.h"

namespace basalt::kiosk {

BASALT_LOG_CATEGORY(Items, "items");

namespace {

/// A resumed script steps forward at most this many draws (ten minutes at 60 fps), so that
/// resuming stays within one frame's time.
constexpr std::int64_t kMaxResumeDraws = 36000;

std::string entryWhere(const EntrySpec& entry, const Manifest& show) {
  return fmt::format("{}:{}", show.file.string(), entry.line);
}

/// Parts and backgrounds name image files; where the manifest has a texture for that file (by
/// its name in the show folder, or by its file), they show the manifest's texture instead, so
/// that a model's `usemap screens.png` shows the movie bound to "screens.png".
void useManifestTextures(runtime::Show& show, const Manifest& manifest) {
  if (manifest.textures.empty()) return;
  const std::filesystem::path folder = manifest.file.parent_path();
  const auto rename = [&](const std::string& file) -> std::optional<std::string> {
    if (file.empty()) return std::nullopt;
    const std::filesystem::path path = std::filesystem::path(file).lexically_normal();
    const std::string relative = path.lexically_relative(folder).generic_string();
    for (const TextureSpec& t : manifest.textures) {
      if (t.name == relative || (!t.file.empty() && t.file.lexically_normal() == path)) return t.name;
    }
    return std::nullopt;
  };
  for (runtime::PartId id = 0; id < show.partCount(); ++id) {
    if (auto name = rename(show.part(id).texture)) show.setPartTexture(id, *name);
    if (auto name = rename(show.part(id).reflectionTexture)) show.setPartReflectionTexture(id, *name);
  }
  if (auto name = rename(show.backgroundImage())) show.backgroundImage() = *name;
}

/// Images the prepared Show names that the manifest does not provide, read now. The manifest's
/// textures are marked as not the item's, so that starting the item leaves them to the director.
void readOwnTextures(const runtime::Show& show, const Manifest& manifest, std::string_view owner,
                     PreparedImages& images) {
  for (const TextureSpec& t : manifest.textures) {
    images.emplace(t.name, fail(Errc::kUnavailable, "shown by the manifest's [textures]"));
  }
  readTextureImages(show, owner, images);
}

/// A model or a scene: a Show prepared on the loader's thread, copied in at start.
class PreparedItem final : public ItemPlayer {
 public:
  PreparedItem(runtime::Show show, PreparedImages images) : show_(std::move(show)), images_(std::move(images)) {}

  void useTextures(render::TextureRegistry& textures) override { textures_ = &textures; }

  Result<void> start(runtime::Show& show, Nanos /*position*/, double /*fps*/) override {
    show = show_;
    if (textures_) {
      // The first start uploads the item's images (a reload may have changed them); later
      // starts only what another item replaced or removed.
      uploadTextures(show, *textures_, &images_, !uploaded_,
                     [](std::string message) { log::warn(kLogItems, "{}", message); });
      uploaded_ = true;
    }
    return {};
  }

 private:
  runtime::Show show_;
  PreparedImages images_;
  render::TextureRegistry* textures_ = nullptr;
  bool uploaded_ = false;
};

}  // namespace

Result<std::unique_ptr<ItemPlayer>> makeModelItem(const EntrySpec& entry, const Manifest& manifest) {
  auto model = formats::loadModel(entry.path);  // warnings are logged with file:line:column
  if (!model) return std::unexpected(model.error().at(entryWhere(entry, manifest)));
  runtime::Show show = script::startupShow();
  if (auto r = formats::replaceObject(show, *model); !r) return std::unexpected(r.error());
  // `view = "scene"`: the model in its own units, seen from the thesis' default camera (F.1).
  if (entry.view == EntryView::kScene) show.viewer().framing = runtime::Framing::kScene;
  useManifestTextures(show, manifest);
  PreparedImages images;
  readOwnTextures(show, manifest, entry.path.string(), images);
  const formats::ModelCounts counts = formats::countModel(*model);
  log::info(kLogItems, "{}: model {}: {} objects, {} triangles, {} warnings", entryWhere(entry, manifest), entry.text,
            counts.objects, counts.triangles, model->warnings.size());
  return std::make_unique<PreparedItem>(std::move(show), std::move(images));
}

Result<std::unique_ptr<ItemPlayer>> makeSceneItem(const EntrySpec& entry, const Manifest& manifest) {
  formats::LoadOptions options;
  options.decodeImage = [](const std::filesystem::path& file) { return media::readImage(file); };
  auto scene = formats::loadScene(entry.path, options);  // warnings are logged with file:line:column
  if (!scene) return std::unexpected(scene.error().at(entryWhere(entry, manifest)));
  const std::size_t sources = scene->description.sources.size();
  if (sources > 0 && scene->models.empty() && scene->terrains.empty()) {
    return fail(Errc::kParse,
                fmt::format("scene {} has nothing to show: none of its {} imports could be loaded (the warnings "
                            "above say why)",
                            entry.text, sources),
                entryWhere(entry, manifest));
  }
  runtime::Show show = script::startupShow();
  std::vector<formats::Diagnostic> warnings;
  formats::applyScene(show, *scene, &warnings);
  if (entry.view == EntryView::kFit) formats::useFitFraming(show);
  for (const formats::Diagnostic& w : warnings) log::warn(kLogItems, "{}", w.describe());
  useManifestTextures(show, manifest);
  PreparedImages images;
  readOwnTextures(show, manifest, entry.path.string(), images);
  log::info(kLogItems, "{}: scene {}: {} models, {} terrains, {} warnings", entryWhere(entry, manifest), entry.text,
            scene->models.size(), scene->terrains.size(), scene->warnings.size() + warnings.size());
  return std::make_unique<PreparedItem>(std::move(show), std::move(images));
}

namespace {

/// A LAVA script: the interpreter steps to the next `draw` in each frame's beforeDraw.
class ScriptItem final : public ItemPlayer {
 public:
  ScriptItem(script::Interpreter prototype, PreparedContent content)
      : prototype_(std::move(prototype)), content_(std::move(content)), host_("show item", &content_) {}

  void useTextures(render::TextureRegistry& textures) override { host_.setTextures(&textures); }

  Result<void> start(runtime::Show& show, Nanos position, double fps) override {
    interpreter_.emplace(prototype_);
    ended_ = false;
    show = script::startupShow();
    // A resumed script runs forward to where it was, one draw per frame of the time passed.
    const auto draws = std::min<std::int64_t>(static_cast<std::int64_t>(toSeconds(position) * fps), kMaxResumeDraws);
    for (std::int64_t i = 0; i < draws && !ended_; ++i) step(show);
    return {};
  }

  Result<void> beforeDraw(const FrameContext& /*frame*/, runtime::Show& show) override {
    if (!ended_) step(show);
    return {};
  }

  [[nodiscard]] bool ended() const override { return ended_; }

 private:
  void step(runtime::Show& show) {
    const script::StepResult r = interpreter_->step(show, host_);
    if (r.stop == script::StepStop::kEnd || r.stop == script::StepStop::kQuit) ended_ = true;
  }

  script::Interpreter prototype_;
  PreparedContent content_;
  ShowHost host_;
  std::optional<script::Interpreter> interpreter_;
  bool ended_ = false;
};

}  // namespace

Result<std::unique_ptr<ItemPlayer>> makeScriptItem(const EntrySpec& entry, const Manifest& manifest) {
  auto interpreter = script::Interpreter::load(entry.path);
  if (!interpreter) return std::unexpected(interpreter.error().at(entryWhere(entry, manifest)));
  const script::Program& program = interpreter->program();
  for (const script::Diagnostic& d : program.diagnostics) {
    if (d.severity == script::Severity::kNote) {
      log::info(kLogItems, "{}", d.describe());
    } else {
      log::warn(kLogItems, "{}{}", d.describe(),
                d.severity == script::Severity::kError ? " (the line is skipped)" : "");
    }
  }
  if (program.instrs.empty()) {
    return fail(Errc::kParse, fmt::format("script {} has no command that can run", entry.text),
                entryWhere(entry, manifest));
  }
  const std::filesystem::path folder = entry.path.parent_path().empty() ? "." : entry.path.parent_path();
  PreparedContent content = prepareScriptContent(program, folder);
  return std::make_unique<ScriptItem>(std::move(*interpreter), std::move(content));
}

namespace {

std::string_view trimmed(std::string_view s) {
  const auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; };
  while (!s.empty() && blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && blank(s.back())) s.remove_suffix(1);
  return s;
}

}  // namespace

Result<std::string> runControlCommand(std::string_view command, const CommandTarget& target) {
  command = trimmed(command);
  if (command.empty()) {
    return fail(Errc::kInvalidArgument,
                "no command given; send one LAVA script command, such as 'render.prim_type = wireframe'");
  }
  if (command.find('\n') != std::string_view::npos) {
    return fail(Errc::kInvalidArgument, "one command at a time, please: the body has more than one line");
  }
  script::Program program = script::parseScript(command, "command");
  std::string problems;
  for (const script::Diagnostic& d : program.diagnostics) {
    if (d.severity != script::Severity::kError) continue;
    problems += fmt::format("{}{}", problems.empty() ? "" : "; ", d.message);
  }
  if (!problems.empty()) return fail(Errc::kParse, problems);
  if (program.instrs.empty()) return fail(Errc::kInvalidArgument, "nothing to run: the line has no command");
  const script::Action action = program.def(program.instrs.front()).action;
  if (action == script::Action::kQuit) {
    return fail(Errc::kInvalidArgument, fmt::format("'{}' cannot be run on its own from the control server",
                                                    program.def(program.instrs.front()).name));
  }
  script::Interpreter interpreter(std::move(program), target.folder.empty() ? "." : target.folder);
  std::vector<script::Diagnostic> reported;
  interpreter.setReporter([&reported](const script::Diagnostic& d) { reported.push_back(d); });
  ShowHost host("control command", nullptr);
  host.setTextures(target.textures);
  while (!interpreter.finished()) {
    const script::StepResult r = interpreter.step(target.show, host);
    if (r.stop == script::StepStop::kEnd || r.stop == script::StepStop::kQuit) break;
  }
  std::string errors;
  std::string notes;
  for (const script::Diagnostic& d : reported) {
    std::string& into = d.severity == script::Severity::kError ? errors : notes;
    into += fmt::format("{}{}{}", into.empty() ? "" : "; ", d.severity == script::Severity::kWarning ? "warning: " : "",
                        d.message);
  }
  if (!errors.empty()) return fail(Errc::kInvalidArgument, errors);
  log::info(kLogItems, "control command run: {}", command);
  return notes.empty() ? fmt::format("ran: {}", command) : fmt::format("ran: {} ({})", command, notes);
}

}  // namespace basalt::kiosk
