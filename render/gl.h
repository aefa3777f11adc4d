#pragma once

/// \file
/// \brief Move-only owners of OpenGL ES objects. Each deletes its object when destroyed, so it
/// must be destroyed on the thread with the context current and before the context goes (the
/// renderer and outputs own theirs and are destroyed before their EglContext).

#include <GLES3/gl3.h>

#include <string>
#include <string_view>
#include <utility>

#include "runtime/error.h"

namespace basalt::render::gl {

/// \brief One GL object name with its deleter. `wrap()` adopts a name; `release()` gives it up.
template <typename Traits>
class Object {
 public:
  Object() = default;
  /// \brief Generates a new object.
  static Object create() {
    Object o;
    o.id_ = Traits::create();
    return o;
  }
  /// \brief Takes ownership of an existing name.
  static Object wrap(GLuint id) {
    Object o;
    o.id_ = id;
    return o;
  }
  Object(Object&& other) noexcept : id_(std::exchange(other.id_, 0)) {}
  Object& operator=(Object&& other) noexcept {
    if (this != &other) {
      reset();
      id_ = std::exchange(other.id_, 0);
    }
    return *this;
  }
  Object(const Object&) = delete;
  Object& operator=(const Object&) = delete;
  ~Object() { reset(); }

  [[nodiscard]] GLuint id() const { return id_; }
  explicit operator bool() const { return id_ != 0; }
  [[nodiscard]] GLuint release() { return std::exchange(id_, 0); }
  void reset() {
    if (id_ != 0) Traits::destroy(id_);
    id_ = 0;
  }

 private:
  GLuint id_ = 0;
};

struct BufferTraits {
  static GLuint create() {
    GLuint id = 0;
    glGenBuffers(1, &id);
    return id;
  }
  static void destroy(GLuint id) { glDeleteBuffers(1, &id); }
};
struct VertexArrayTraits {
  static GLuint create() {
    GLuint id = 0;
    glGenVertexArrays(1, &id);
    return id;
  }
  static void destroy(GLuint id) { glDeleteVertexArrays(1, &id); }
};
struct TextureTraits {
  static GLuint create() {
    GLuint id = 0;
    glGenTextures(1, &id);
    return id;
  }
  static void destroy(GLuint id) { glDeleteTextures(1, &id); }
};
struct FramebufferTraits {
  static GLuint create() {
    GLuint id = 0;
    glGenFramebuffers(1, &id);
    return id;
  }
  static void destroy(GLuint id) { glDeleteFramebuffers(1, &id); }
};
struct RenderbufferTraits {
  static GLuint create() {
    GLuint id = 0;
    glGenRenderbuffers(1, &id);
    return id;
  }
  static void destroy(GLuint id) { glDeleteRenderbuffers(1, &id); }
};
struct ProgramTraits {
  static GLuint create() { return glCreateProgram(); }
  static void destroy(GLuint id) { glDeleteProgram(id); }
};
struct ShaderTraits {
  static GLuint create() { return 0; }  // shaders are made with a type: see compileShader()
  static void destroy(GLuint id) { glDeleteShader(id); }
};

using Buffer = Object<BufferTraits>;
using VertexArray = Object<VertexArrayTraits>;
using Texture = Object<TextureTraits>;
using Framebuffer = Object<FramebufferTraits>;
using Renderbuffer = Object<RenderbufferTraits>;
using Program = Object<ProgramTraits>;
using Shader = Object<ShaderTraits>;

/// \brief Compiles one shader stage; the error carries the compiler's log and `label`.
Result<Shader> compileShader(GLenum type, std::string_view source, std::string_view label);
/// \brief Compiles and links a vertex + fragment program.
Result<Program> buildProgram(std::string_view vertexSource, std::string_view fragmentSource, std::string_view label);

/// \brief "GL_INVALID_ENUM" and friends.
std::string_view errorName(GLenum error);
/// \brief Drains glGetError(); returns the first error met, or GL_NO_ERROR.
GLenum drainErrors();

/// \brief GL_RENDERER and GL_VERSION of the current context, e.g. "llvmpipe (LLVM 15.0.6,
/// 256 bits), OpenGL ES 3.2 Mesa 22.3.6".
std::string rendererDescription();

}  // namespace basalt::render::gl
