#pragma once

/// \file
/// \brief Textures by name, as parts refer to them (`PartState::texture`): image files uploaded
/// once, and streams (movies, cameras) whose owners update a GL texture every frame.

#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "render/gl.h"
#include "render/output.h"
#include "runtime/error.h"
#include "runtime/image.h"

namespace basalt::render {

/// \brief What the renderer samples for a texture name. `id` is an RGBA-sampling GL_TEXTURE_2D.
///
/// Orientation: texture row 0 (t = 0) holds the image's top row, as glTexImage2D stores an image
/// read top row first; a stream that renders its frames the other way up sets `bottomUp`. The
/// renderer maps OBJ-style coordinates (v = 0 at the image's bottom) accordingly.
struct TextureView {
  GLuint id = 0;
  Size size;
  bool hasAlpha = false;
  std::uint64_t generation = 0;  ///< bumped whenever the contents change (streams: per new frame)
  bool bottomUp = false;         ///< row 0 is the image's bottom row
};

/// \brief The texture LAVA's `texture.switch = video` puts on the object: while a texture of
/// this name exists and the show's texture source is video, every part shows it (the scripts'
/// VCR and camera register it, kiosk/show/script_player.cpp).
inline constexpr std::string_view kVideoTexture = "lava:video";

/// \brief Owns image textures and refers to stream textures, by name.
///
/// Threading: the frame loop's thread, with the context current. Lookups never allocate.
class TextureRegistry {
 public:
  /// \brief Uploads an 8-bit image (1 to 4 channels) as texture `name`, with mipmaps; replaces
  /// a texture of that name.
  [[nodiscard]] Result<void> setImage(const std::string& name, const Image& image);
  /// \brief Names a texture owned elsewhere (a stream); its owner calls this again when the
  /// view changes and keeps the GL texture alive until remove().
  void setExternal(const std::string& name, const TextureView& view);
  void remove(std::string_view name);
  [[nodiscard]] const TextureView* find(std::string_view name) const;
  [[nodiscard]] std::size_t size() const { return entries_.size(); }
  /// \brief The names of every texture, sorted (allocates: for item changes, not every frame).
  [[nodiscard]] std::vector<std::string> names() const;

 private:
  struct Entry {
    TextureView view;
    gl::Texture owned;  // empty for external textures
  };
  std::map<std::string, Entry, std::less<>> entries_;
};

}  // namespace basalt::render
