// A linked GLSL ES program built from named vertex and fragment sources; compile and link errors
// throw RenderError with the shader's name and the driver's log.
#include "render/gl/gl_program.h"

#include <fmt/format.h>

#include <algorithm>
#include <utility>

#include "render/gl/render_errors.h"

namespace arpipe {
namespace {

// The info log of a shader or a program (glGetShaderiv and glGetShaderInfoLog, or the program
// ones), without its terminating NUL.
template <class GetIv, class GetInfoLog>
std::string info_log(GLuint object, GetIv get_iv, GetInfoLog get_info_log) {
  GLint length = 0;
  get_iv(object, GL_INFO_LOG_LENGTH, &length);
  std::string log(static_cast<size_t>(std::max(length, 1)), '\0');
  get_info_log(object, length, nullptr, log.data());
  log.resize(log.find('\0') == std::string::npos ? log.size() : log.find('\0'));
  return log;
}

std::string shader_log(GLuint shader) { return info_log(shader, glGetShaderiv, glGetShaderInfoLog); }
std::string program_log(GLuint program) { return info_log(program, glGetProgramiv, glGetProgramInfoLog); }

GLuint compile(GLenum type, std::string_view source, const std::string& program_name) {
  const char* stage = type == GL_VERTEX_SHADER ? "vertex" : "fragment";
  GLuint shader = glCreateShader(type);
  if (shader == 0) throw RenderError(fmt::format("{} {} shader: glCreateShader failed", program_name, stage));
  const char* text = source.data();
  const GLint length = static_cast<GLint>(source.size());
  glShaderSource(shader, 1, &text, &length);
  glCompileShader(shader);
  GLint ok = GL_FALSE;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok != GL_TRUE) {
    std::string log = shader_log(shader);
    glDeleteShader(shader);
    throw RenderError(fmt::format("{} {} shader failed to compile:\n{}", program_name, stage, log));
  }
  return shader;
}

}  // namespace

GlProgram::GlProgram(std::string name, std::string_view vertex_source, std::string_view fragment_source,
                     const std::vector<std::string>& transform_feedback_varyings)
    : name_(std::move(name)) {
  GLuint vertex = compile(GL_VERTEX_SHADER, vertex_source, name_);
  GLuint fragment = 0;
  try {
    fragment = compile(GL_FRAGMENT_SHADER, fragment_source, name_);
  } catch (...) {
    glDeleteShader(vertex);
    throw;
  }
  program_ = glCreateProgram();
  glAttachShader(program_, vertex);
  glAttachShader(program_, fragment);
  if (!transform_feedback_varyings.empty()) {
    std::vector<const char*> names;
    for (const std::string& varying : transform_feedback_varyings) names.push_back(varying.c_str());
    glTransformFeedbackVaryings(program_, static_cast<GLsizei>(names.size()), names.data(), GL_INTERLEAVED_ATTRIBS);
  }
  glLinkProgram(program_);
  glDeleteShader(vertex);
  glDeleteShader(fragment);
  GLint ok = GL_FALSE;
  glGetProgramiv(program_, GL_LINK_STATUS, &ok);
  if (ok != GL_TRUE) {
    std::string log = program_log(program_);
    glDeleteProgram(program_);
    program_ = 0;
    throw RenderError(fmt::format("{} program failed to link:\n{}", name_, log));
  }
}

GlProgram::~GlProgram() {
  if (program_ != 0) glDeleteProgram(program_);
}

GlProgram::GlProgram(GlProgram&& other) noexcept
    : name_(std::move(other.name_)), program_(std::exchange(other.program_, 0)) {}

GlProgram& GlProgram::operator=(GlProgram&& other) noexcept {
  if (this != &other) {
    if (program_ != 0) glDeleteProgram(program_);
    name_ = std::move(other.name_);
    program_ = std::exchange(other.program_, 0);
  }
  return *this;
}

GLint GlProgram::uniform(const char* uniform_name) const {
  const GLint location = glGetUniformLocation(program_, uniform_name);
  if (location < 0) throw RenderError(fmt::format("{} program has no uniform \"{}\"", name_, uniform_name));
  return location;
}

}  // namespace arpipe
