// Move-only owners of GL object names (textures, buffers, framebuffers...), so that GL resources
// follow C++ lifetimes. They must be destroyed while their context is current.
#pragma once

#include <GLES3/gl3.h>

#include <utility>

namespace arpipe {

template <void (*Generate)(GLsizei, GLuint*), void (*Delete)(GLsizei, const GLuint*)>
class GlObject {
 public:
  GlObject() = default;
  static GlObject create() {
    GlObject object;
    Generate(1, &object.name_);
    return object;
  }
  ~GlObject() { reset(); }
  GlObject(GlObject&& other) noexcept : name_(std::exchange(other.name_, 0)) {}
  GlObject& operator=(GlObject&& other) noexcept {
    if (this != &other) {
      reset();
      name_ = std::exchange(other.name_, 0);
    }
    return *this;
  }
  GlObject(const GlObject&) = delete;
  GlObject& operator=(const GlObject&) = delete;

  GLuint get() const { return name_; }
  explicit operator bool() const { return name_ != 0; }
  void reset() {
    if (name_ != 0) Delete(1, &name_);
    name_ = 0;
  }

 private:
  GLuint name_ = 0;
};

using GlTexture = GlObject<glGenTextures, glDeleteTextures>;
using GlBuffer = GlObject<glGenBuffers, glDeleteBuffers>;
using GlFramebuffer = GlObject<glGenFramebuffers, glDeleteFramebuffers>;
using GlRenderbuffer = GlObject<glGenRenderbuffers, glDeleteRenderbuffers>;
using GlVertexArray = GlObject<glGenVertexArrays, glDeleteVertexArrays>;

// A 2D texture of fixed size and format read texel for texel: one level, nearest filtering (a
// texture without mipmaps is only complete with a non-mipmap filter). Leaves it bound.
inline GlTexture create_texel_texture(GLenum internal_format, int width, int height) {
  GlTexture texture = GlTexture::create();
  glBindTexture(GL_TEXTURE_2D, texture.get());
  glTexStorage2D(GL_TEXTURE_2D, 1, internal_format, width, height);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  return texture;
}

// A framebuffer whose colour attachment 0 is level 0 of `texture`. Leaves it bound.
inline GlFramebuffer create_framebuffer_for(GLuint texture) {
  GlFramebuffer framebuffer = GlFramebuffer::create();
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer.get());
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, texture, 0);
  return framebuffer;
}

}  // namespace arpipe
