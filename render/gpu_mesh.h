// A Mesh uploaded to GL buffers (positions at attribute 0, normals at 1, 32-bit indices), drawn
// part by part so each part can set its own base colour.
#pragma once

#include <functional>
#include <vector>

#include "render/gl_objects.h"
#include "core/scene/mesh.h"

namespace arpipe {

class GpuMesh {
 public:
  static constexpr GLuint kPositionAttribute = 0;
  static constexpr GLuint kNormalAttribute = 1;

  explicit GpuMesh(const Mesh& mesh);
  // Draws each part after calling before_part(part), which sets the part's uniforms.
  void draw(const std::function<void(const MeshPart&)>& before_part) const;

 private:
  GlVertexArray vertex_array_;
  GlBuffer positions_;
  GlBuffer normals_;
  GlBuffer indices_;
  std::vector<MeshPart> parts_;
};

}  // namespace arpipe
