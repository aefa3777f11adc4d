#pragma once

/// \file
/// \brief The script::Host of scripts that play on the kiosk's Show (show items and the control
/// server's commands), and the model and texture loading it shares with ScriptPlayer.
///
/// Files an item names are read on the show loader's thread (PreparedContent) and only put into
/// the Show and the texture registry on the frame loop's thread, so that starting an item does
/// not wait for a disk or a decoder.

#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <string_view>

#include "render/texture_registry.h"
#include "runtime/error.h"
#include "runtime/formats/model.h"
#include "runtime/image.h"
#include "runtime/script/host.h"
#include "runtime/script/program.h"
#include "runtime/show/show.h"

namespace basalt::kiosk {

/// \brief Images read ahead, by the file name a part, a background or a script names them by.
/// A file that could not be read holds its error (reported when it was read).
using PreparedImages = std::map<std::string, Result<Image>, std::less<>>;

/// \brief Models and images a script or item names, read off the frame loop's thread.
struct PreparedContent {
  std::map<std::filesystem::path, Result<formats::LoadedModel>> models;  ///< by resolved path
  PreparedImages images;
};

/// \brief The image files `show` names as textures: each part's colour and reflection map and
/// the background image or skybox, each once, in order.
std::vector<std::string> textureFilesOf(const runtime::Show& show);

/// \brief Reads every image textureFilesOf(show) names that `images` does not hold yet.
/// Each one that cannot be read is logged once, naming `owner` (the model or scene file).
void readTextureImages(const runtime::Show& show, std::string_view owner, PreparedImages& images);

/// \brief Uploads the textures `show` names: from `images` when it holds them, else read now.
/// With `replace` false, names the registry already has are left as they are. Each texture
/// that cannot be shown is passed to `warn` (once per call), and the show goes on without it.
void uploadTextures(const runtime::Show& show, render::TextureRegistry& textures, const PreparedImages* images,
                    bool replace, const std::function<void(std::string)>& warn);

/// \brief LAVA `load_object` in the kiosk: the model (from `prepared` when it holds it, else
/// read now) replaces the Show's object, and its parts' textures are uploaded. On failure the
/// Show is unchanged.
[[nodiscard]] Result<void> loadObjectWithTextures(const std::filesystem::path& file, runtime::Show& show,
                                                  render::TextureRegistry* textures, const PreparedContent* prepared,
                                                  const std::function<void(std::string)>& warn);

/// \brief Reads ahead what `program`'s load_object and load_texture commands name (resolved
/// against `folder`, as the interpreter resolves them). Problems are logged and kept.
PreparedContent prepareScriptContent(const script::Program& program, const std::filesystem::path& folder);

/// \brief Whether render::Renderer draws `feature` today (ScriptPlayer and show items agree).
[[nodiscard]] bool rendererDraws(script::Feature feature);

/// \brief A Host for scripts that play on the kiosk's Show without a picture of their own: show
/// items and control commands. Objects and textures load (from PreparedContent when given);
/// save_image, jitter and the VCR are reported once each as unavailable, with the line that
/// asked, and then ignored, so that the show goes on.
///
/// Threading: the frame loop's thread.
class ShowHost final : public script::Host {
 public:
  /// \param what   names the script's player in messages ("show item", "control command")
  ShowHost(std::string what, const PreparedContent* prepared) : what_(std::move(what)), prepared_(prepared) {}

  /// \brief The registry textures go to; null: load_texture fails and models show no maps.
  void setTextures(render::TextureRegistry* textures) { textures_ = textures; }

  [[nodiscard]] Result<void> loadObject(const std::filesystem::path& file, runtime::Show& show) override;
  [[nodiscard]] Result<void> loadTexture(const std::filesystem::path& file, const std::string& name) override;
  [[nodiscard]] Result<void> saveImage(std::string_view name) override;
  [[nodiscard]] Result<void> accumulateJitterPass(int pass, int passes) override;
  [[nodiscard]] Result<void> tv(const script::TvRequest& request) override;
  [[nodiscard]] bool renders(script::Feature feature) const override { return rendererDraws(feature); }

 private:
  /// The first time: the error that the interpreter reports with the line; later: nothing.
  Result<void> once(bool& said, std::string message);

  std::string what_;
  const PreparedContent* prepared_;
  render::TextureRegistry* textures_ = nullptr;
  bool saveSaid_ = false;
  bool jitterSaid_ = false;
  bool tvSaid_ = false;
};

}  // namespace basalt::kiosk
