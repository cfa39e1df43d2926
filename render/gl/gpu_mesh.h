// A Mesh uploaded to GL buffers (positions at attribute 0, normals at 1, 32-bit indices, and the
// first 9 PRT transfer coefficients at 2..4 when baked), drawn part by part so each part can set
// its own base colour.
#pragma once

#include <functional>
#include <span>
#include <vector>

#include "render/gl/gl_objects.h"
#include "core/scene/mesh.h"

namespace arpipe {

class GpuMesh {
 public:
  static constexpr GLuint kPositionAttribute = 0;
  static constexpr GLuint kNormalAttribute = 1;
  // Transfer coefficients 0-3, 4-7 and 8 (render/prt/prt_transfer.h) as vec4, vec4, float.
  static constexpr GLuint kTransferAttribute = 2;

  // transfer: 9 coefficients per vertex (3 bands), or empty for a mesh without PRT.
  explicit GpuMesh(const Mesh& mesh, std::span<const float> transfer = {});
  bool has_transfer() const { return has_transfer_; }
  // Draws each part after calling before_part(part), which sets the part's uniforms.
  void draw(const std::function<void(const MeshPart&)>& before_part) const;
  // Only the parts whose index `include` says yes to (culling), with nothing set between them.
  void draw_parts(const std::function<bool(size_t part)>& include) const;
  size_t part_count() const { return parts_.size(); }

 private:
  GlVertexArray vertex_array_;
  GlBuffer positions_;
  GlBuffer normals_;
  GlBuffer indices_;
  GlBuffer transfer_;
  std::vector<MeshPart> parts_;
  bool has_transfer_ = false;
};

}  // namespace arpipe
