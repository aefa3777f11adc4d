#pragma once

/// \file
/// \brief What a script needs from the program that runs it: files, media, devices and the
/// picture. `runtime/` cannot load models, decode images or read the framebuffer, so the
/// interpreter asks its Host; the kiosk implements it with media/ and render/ (and, as they land,
/// the model loaders, the movie player and the cameras).

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "runtime/error.h"
#include "runtime/script/command_table.h"
#include "runtime/show/show.h"

namespace basalt::script {

/// \brief One VCR or camera command with its value.
struct TvRequest {
  TvOp op = TvOp::kPlay;
  std::filesystem::path file;  ///< kMovie: the movie, resolved against the script's folder
  std::int32_t frames = 0;     ///< kShuttle: frames to move (negative: back)
  bool on = false;             ///< kRepeat, kCamera
};

/// \brief The services a script uses. Calls come from the frame loop's thread, inside
/// Interpreter::step(); none may block on a device.
class Host {
 public:
  virtual ~Host() = default;

  /// \brief `load_object`: replaces the Show's object with the model in `file` (resolved
  /// against the script's folder). LAVA: "all attributes get reset whenever a new object is
  /// loaded". On failure the Show must be unchanged.
  [[nodiscard]] virtual Result<void> loadObject(const std::filesystem::path& file, runtime::Show& show) = 0;
  /// \brief `load_texture`: makes the image in `file` available as texture `name` (the name
  /// parts refer to in `PartState::texture`).
  [[nodiscard]] virtual Result<void> loadTexture(const std::filesystem::path& file, const std::string& name) = 0;
  /// \brief `save_image`: writes the current picture (the last frame drawn, or the average of
  /// the jitter loop that just ended) to `name` in the output folder; "" for the default name.
  /// Called right after a frame was drawn and before it is presented, so that the framebuffer
  /// still holds it.
  [[nodiscard]] virtual Result<void> saveImage(std::string_view name) = 0;
  /// \brief `end_jitter`: adds the last frame drawn as pass `pass` (from 0) of `passes`; after
  /// the last pass the average becomes the current picture. Called as saveImage() is.
  [[nodiscard]] virtual Result<void> accumulateJitterPass(int pass, int passes) = 0;
  /// \brief The VCR remote and the camera.
  [[nodiscard]] virtual Result<void> tv(const TvRequest& request) = 0;
  /// \brief Whether the renderer draws `feature` today. Commands whose feature it does not draw
  /// are stored and reported once as not rendered yet.
  [[nodiscard]] virtual bool renders(Feature feature) const = 0;
};

/// \brief A host with no files, media or picture: every service answers that it is unavailable
/// and nothing beyond the basics is rendered. For checking scripts and for tests to build on.
class OfflineHost : public Host {
 public:
  [[nodiscard]] Result<void> loadObject(const std::filesystem::path& file, runtime::Show& show) override;
  [[nodiscard]] Result<void> loadTexture(const std::filesystem::path& file, const std::string& name) override;
  [[nodiscard]] Result<void> saveImage(std::string_view name) override;
  [[nodiscard]] Result<void> accumulateJitterPass(int pass, int passes) override;
  [[nodiscard]] Result<void> tv(const TvRequest& request) override;
  [[nodiscard]] bool renders(Feature feature) const override { return feature == Feature::kRendered; }
};

}  // namespace basalt::script
