#include "kiosk/show/show_host.h"

#include <algorithm>

#include <fmt/format.h>
#include <fmt/std.h>

#include "media/image_io.h"
#include "runtime/log.h"

namespace basalt::kiosk {

BASALT_LOG_CATEGORY(ShowHost, "items");

std::vector<std::string> textureFilesOf(const runtime::Show& show) {
  std::vector<std::string> files;
  const auto add = [&files](const std::string& name) {
    if (!name.empty() && std::find(files.begin(), files.end(), name) == files.end()) files.push_back(name);
  };
  for (runtime::PartId id = 0; id < show.partCount(); ++id) {
    add(show.part(id).texture);
    add(show.part(id).reflectionTexture);
  }
  add(show.backgroundImage());
  return files;
}

void readTextureImages(const runtime::Show& show, std::string_view owner, PreparedImages& images) {
  for (const std::string& file : textureFilesOf(show)) {
    if (images.contains(file)) continue;
    auto image = media::readImage(file);
    if (!image) {
      log::warn(kLogShowHost, "{}: the texture {} is not shown: {}", owner, file, image.error().describe());
    }
    images.emplace(file, std::move(image));
  }
}

void uploadTextures(const runtime::Show& show, render::TextureRegistry& textures, const PreparedImages* images,
                    bool replace, const std::function<void(std::string)>& warn) {
  for (const std::string& file : textureFilesOf(show)) {
    if (!replace && textures.find(file) != nullptr) continue;
    Result<void> uploaded;
    const auto found = images ? images->find(file) : PreparedImages::const_iterator{};
    if (images && found != images->end()) {
      if (!found->second) continue;  // reported when it was read
      uploaded = textures.setImage(file, *found->second);
    } else {
      auto image = media::readImage(file);
      uploaded = image ? textures.setImage(file, *image) : Result<void>(std::unexpected(image.error()));
    }
    if (!uploaded && warn) warn(fmt::format("the texture {} is not shown: {}", file, uploaded.error().describe()));
  }
}

Result<void> loadObjectWithTextures(const std::filesystem::path& file, runtime::Show& show,
                                    render::TextureRegistry* textures, const PreparedContent* prepared,
                                    const std::function<void(std::string)>& warn) {
  const formats::LoadedModel* model = nullptr;
  Result<formats::LoadedModel> readNow = fail(Errc::kInternal, "not read");
  if (prepared) {
    if (const auto it = prepared->models.find(file); it != prepared->models.end()) {
      if (!it->second) return std::unexpected(it->second.error());
      model = &*it->second;
    }
  }
  if (!model) {
    readNow = formats::loadModel(file);
    if (!readNow) return std::unexpected(readNow.error());
    if (warn) {
      for (const formats::Diagnostic& w : readNow->warnings) warn(w.describe());
    }
    model = &*readNow;
  }
  if (auto r = formats::replaceObject(show, *model); !r) return r;
  // The parts name their textures by file (material maps, Extended OBJ colour and reflection
  // maps); one that cannot be read leaves its parts untextured.
  if (textures) uploadTextures(show, *textures, prepared ? &prepared->images : nullptr, false, warn);
  return {};
}

PreparedContent prepareScriptContent(const script::Program& program, const std::filesystem::path& folder) {
  PreparedContent content;
  for (const script::Instr& in : program.instrs) {
    const script::Action action = program.def(in).action;
    if (in.text == script::kNoString) continue;
    if (action != script::Action::kLoadObject && action != script::Action::kLoadTexture) continue;
    const std::filesystem::path file = (folder / program.strings[in.text]).lexically_normal();
    const std::string where = fmt::format("{}:{}", program.file, in.line);
    if (action == script::Action::kLoadTexture) {
      if (content.images.contains(file.string())) continue;
      auto image = media::readImage(file);
      if (!image) log::warn(kLogShowHost, "{}: load_texture: {}", where, image.error().describe());
      content.images.emplace(file.string(), std::move(image));
      continue;
    }
    if (content.models.contains(file)) continue;
    auto model = formats::loadModel(file);  // its warnings are logged as it reads
    if (!model) {
      log::warn(kLogShowHost, "{}: load_object: {}", where, model.error().describe());
    } else {
      runtime::Show probe;
      if (formats::replaceObject(probe, *model)) readTextureImages(probe, file.string(), content.images);
    }
    content.models.emplace(file, std::move(model));
  }
  return content;
}

bool rendererDraws(script::Feature feature) {
  // What render::Renderer draws today. As the renderer learns a feature, it moves up here, and
  // scripts stop being told that it is not rendered yet.
  using script::Feature;
  switch (feature) {
    case Feature::kRendered:
    case Feature::kRasterOp:
    case Feature::kMarkerShapes:
    case Feature::kAntialiasing:
    case Feature::kColorSelector:
    case Feature::kLineStyle:
    case Feature::kColorInterpolation:
    case Feature::kFillStyle:
    case Feature::kTransparency:
    case Feature::kEdges:
    case Feature::kDepthCue:
    case Feature::kTexture:
    case Feature::kModelClipping:
    case Feature::kStereo:
    case Feature::kFloor:
    case Feature::kShadow: return true;
    case Feature::kNurbs:
    case Feature::kPicking:
    case Feature::kAnnotation:
    case Feature::kSingleBuffering:
    case Feature::kViewMatrix:
    case Feature::kDrawNoClear:
    case Feature::kNoFinalMove:
    case Feature::kJitterDisplay:
    case Feature::kCount: return false;
  }
  return false;
}

Result<void> ShowHost::once(bool& said, std::string message) {
  if (said) return {};
  said = true;
  return fail(Errc::kUnavailable, std::move(message));
}

Result<void> ShowHost::loadObject(const std::filesystem::path& file, runtime::Show& show) {
  return loadObjectWithTextures(file, show, textures_, prepared_,
                                [](std::string message) { log::warn(kLogShowHost, "{}", message); });
}

Result<void> ShowHost::loadTexture(const std::filesystem::path& file, const std::string& name) {
  if (!textures_) {
    return fail(Errc::kUnavailable, fmt::format("a {} has no renderer to give textures to", what_));
  }
  if (prepared_) {
    if (const auto it = prepared_->images.find(file.string()); it != prepared_->images.end()) {
      if (!it->second) return std::unexpected(it->second.error());
      return textures_->setImage(name, *it->second);
    }
  }
  auto image = media::readImage(file);
  if (!image) return std::unexpected(image.error());
  return textures_->setImage(name, *image);
}

Result<void> ShowHost::saveImage(std::string_view name) {
  return once(saveSaid_,
              fmt::format("a {} has no picture of its own to save{}{}; it is skipped here and from now on (run the "
                          "script with 'basalt run SCRIPT.mdl' to save pictures)",
                          what_, name.empty() ? "" : " as ", name));
}

Result<void> ShowHost::accumulateJitterPass(int /*pass*/, int /*passes*/) {
  return once(jitterSaid_,
              fmt::format("a {} draws each jitter pass to the screen but cannot average them; the passes are "
                          "shown as they are (run the script with 'basalt run SCRIPT.mdl' for the average)",
                          what_));
}

Result<void> ShowHost::tv(const script::TvRequest& request) {
  return once(tvSaid_, fmt::format("a {} has no {} in this build; its tv commands are skipped from now on", what_,
                                   request.op == script::TvOp::kCamera ? "camera" : "VCR (movie player)"));
}

}  // namespace basalt::kiosk
