#include "render/texture_registry.h"

#include <fmt/format.h>

namespace basalt::render {

Result<void> TextureRegistry::setImage(const std::string& name, const Image& image) {
  if (image.empty() || image.type != ChannelType::kU8 || image.channels < 1 || image.channels > 4) {
    return fail(Errc::kUnsupported, fmt::format("texture '{}' must be an 8-bit image with 1 to 4 channels", name));
  }
  GLint maxSize = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &maxSize);
  if (image.width > static_cast<std::uint32_t>(maxSize) || image.height > static_cast<std::uint32_t>(maxSize)) {
    return fail(Errc::kUnsupported, fmt::format("texture '{}' is {}x{}, larger than this renderer's limit of {}", name,
                                                image.width, image.height, maxSize));
  }
  static constexpr GLenum kFormats[] = {GL_LUMINANCE, GL_LUMINANCE_ALPHA, GL_RGB, GL_RGBA};
  const GLenum format = kFormats[image.channels - 1];
  gl::Texture texture = gl::Texture::create();
  glBindTexture(GL_TEXTURE_2D, texture.id());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, static_cast<GLint>(format), static_cast<GLsizei>(image.width),
               static_cast<GLsizei>(image.height), 0, format, GL_UNSIGNED_BYTE, image.pixels.data());
  glGenerateMipmap(GL_TEXTURE_2D);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
  glBindTexture(GL_TEXTURE_2D, 0);
  if (const GLenum e = gl::drainErrors(); e != GL_NO_ERROR) {
    return fail(Errc::kUnavailable, fmt::format("uploading texture '{}': {}", name, gl::errorName(e)));
  }
  auto it = entries_.find(name);
  const std::uint64_t generation = it != entries_.end() ? it->second.view.generation + 1 : 1;
  Entry entry;
  entry.view =
      TextureView{texture.id(), {image.width, image.height}, image.channels == 2 || image.channels == 4, generation};
  entry.owned = std::move(texture);
  entries_.insert_or_assign(name, std::move(entry));
  return {};
}

void TextureRegistry::setExternal(const std::string& name, const TextureView& view) {
  auto it = entries_.find(name);
  if (it == entries_.end()) {
    entries_.emplace(name, Entry{view, gl::Texture{}});
    return;
  }
  it->second.owned.reset();
  it->second.view = view;
}

void TextureRegistry::remove(std::string_view name) {
  auto it = entries_.find(name);
  if (it != entries_.end()) entries_.erase(it);
}

std::vector<std::string> TextureRegistry::names() const {
  std::vector<std::string> out;
  out.reserve(entries_.size());
  for (const auto& [name, entry] : entries_) out.push_back(name);
  return out;
}

const TextureView* TextureRegistry::find(std::string_view name) const {
  auto it = entries_.find(name);
  return it == entries_.end() ? nullptr : &it->second.view;
}

}  // namespace basalt::render
