#include "render/gl.h"

#include <vector>

#include <fmt/format.h>

namespace basalt::render::gl {

Result<Shader> compileShader(GLenum type, std::string_view source, std::string_view label) {
  Shader shader = Shader::wrap(glCreateShader(type));
  if (!shader) return fail(Errc::kInternal, fmt::format("glCreateShader failed for {}", label));
  const char* text = source.data();
  const auto length = static_cast<GLint>(source.size());
  glShaderSource(shader.id(), 1, &text, &length);
  glCompileShader(shader.id());
  GLint ok = GL_FALSE;
  glGetShaderiv(shader.id(), GL_COMPILE_STATUS, &ok);
  if (ok != GL_TRUE) {
    GLint logLength = 0;
    glGetShaderiv(shader.id(), GL_INFO_LOG_LENGTH, &logLength);
    std::string log(static_cast<std::size_t>(std::max(logLength, 1)), '\0');
    glGetShaderInfoLog(shader.id(), logLength, nullptr, log.data());
    return fail(Errc::kInternal, fmt::format("shader {} does not compile: {}", label, log.c_str()));
  }
  return shader;
}

Result<Program> buildProgram(std::string_view vertexSource, std::string_view fragmentSource, std::string_view label) {
  auto vs = compileShader(GL_VERTEX_SHADER, vertexSource, fmt::format("{} (vertex)", label));
  if (!vs) return std::unexpected(vs.error());
  auto fs = compileShader(GL_FRAGMENT_SHADER, fragmentSource, fmt::format("{} (fragment)", label));
  if (!fs) return std::unexpected(fs.error());
  Program program = Program::create();
  glAttachShader(program.id(), vs->id());
  glAttachShader(program.id(), fs->id());
  glLinkProgram(program.id());
  GLint ok = GL_FALSE;
  glGetProgramiv(program.id(), GL_LINK_STATUS, &ok);
  if (ok != GL_TRUE) {
    GLint logLength = 0;
    glGetProgramiv(program.id(), GL_INFO_LOG_LENGTH, &logLength);
    std::string log(static_cast<std::size_t>(std::max(logLength, 1)), '\0');
    glGetProgramInfoLog(program.id(), logLength, nullptr, log.data());
    return fail(Errc::kInternal, fmt::format("program {} does not link: {}", label, log.c_str()));
  }
  glDetachShader(program.id(), vs->id());
  glDetachShader(program.id(), fs->id());
  return program;
}

std::string_view errorName(GLenum error) {
  switch (error) {
    case GL_NO_ERROR: return "GL_NO_ERROR";
    case GL_INVALID_ENUM: return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE: return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION: return "GL_INVALID_OPERATION";
    case GL_INVALID_FRAMEBUFFER_OPERATION: return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_OUT_OF_MEMORY: return "GL_OUT_OF_MEMORY";
    default: return "unknown GL error";
  }
}

GLenum drainErrors() {
  GLenum first = GL_NO_ERROR;
  for (GLenum e = glGetError(); e != GL_NO_ERROR; e = glGetError()) {
    if (first == GL_NO_ERROR) first = e;
  }
  return first;
}

std::string rendererDescription() {
  const auto* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  const auto* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
  return fmt::format("{}, {}", renderer ? renderer : "unknown renderer", version ? version : "unknown version");
}

}  // namespace basalt::render::gl
