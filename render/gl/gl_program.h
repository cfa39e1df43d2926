// A linked GLSL ES program built from named vertex and fragment sources; compile and link errors
// throw RenderError with the shader's name and the driver's log.
#pragma once

#include <GLES3/gl3.h>

#include <string>
#include <string_view>
#include <vector>

namespace arpipe {

class GlProgram {
 public:
  GlProgram() = default;
  // name: what messages call it ("object shading"). transform_feedback_varyings: outputs to capture
  // (interleaved), set before linking; empty for ordinary drawing.
  GlProgram(std::string name, std::string_view vertex_source, std::string_view fragment_source,
            const std::vector<std::string>& transform_feedback_varyings = {});
  ~GlProgram();
  GlProgram(GlProgram&& other) noexcept;
  GlProgram& operator=(GlProgram&& other) noexcept;
  GlProgram(const GlProgram&) = delete;
  GlProgram& operator=(const GlProgram&) = delete;

  GLuint id() const { return program_; }
  const std::string& name() const { return name_; }
  // Location of a uniform that the program must have; throws RenderError naming it otherwise
  // (the GLSL compiler drops unused uniforms, so a missing one is a bug worth hearing about).
  GLint uniform(const char* uniform_name) const;

 private:
  std::string name_;
  GLuint program_ = 0;
};

}  // namespace arpipe
