// A Mesh uploaded to GL buffers (positions at attribute 0, normals at 1, 32-bit indices), drawn
// part by part so each part can set its own base colour.
#include "render/gl/gpu_mesh.h"

#include <cstdint>
#include <stdexcept>

#include "render/gl/gl_error.h"

namespace arpipe {
namespace {

template <typename T>
void upload(GLenum target, const GlBuffer& buffer, const std::vector<T>& data) {
  glBindBuffer(target, buffer.get());
  glBufferData(target, static_cast<GLsizeiptr>(data.size() * sizeof(T)), data.data(), GL_STATIC_DRAW);
}

}  // namespace

GpuMesh::GpuMesh(const Mesh& mesh, std::span<const float> transfer)
    : vertex_array_(GlVertexArray::create()),
      positions_(GlBuffer::create()),
      normals_(GlBuffer::create()),
      indices_(GlBuffer::create()),
      transfer_(GlBuffer::create()),
      parts_(mesh.parts),
      has_transfer_(!transfer.empty()) {
  if (has_transfer_ && transfer.size() != 9 * mesh.vertex_count())
    throw std::invalid_argument("GpuMesh: the transfer needs 9 coefficients per vertex");
  glBindVertexArray(vertex_array_.get());
  upload(GL_ARRAY_BUFFER, positions_, mesh.positions);
  glEnableVertexAttribArray(kPositionAttribute);
  glVertexAttribPointer(kPositionAttribute, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
  upload(GL_ARRAY_BUFFER, normals_, mesh.normals);
  glEnableVertexAttribArray(kNormalAttribute);
  glVertexAttribPointer(kNormalAttribute, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
  if (has_transfer_) {
    glBindBuffer(GL_ARRAY_BUFFER, transfer_.get());
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(transfer.size_bytes()), transfer.data(), GL_STATIC_DRAW);
    constexpr GLsizei stride = 9 * sizeof(float);
    const GLint sizes[3] = {4, 4, 1};
    for (GLuint k = 0; k < 3; ++k) {
      glEnableVertexAttribArray(kTransferAttribute + k);
      glVertexAttribPointer(kTransferAttribute + k, sizes[k], GL_FLOAT, GL_FALSE, stride,
                            reinterpret_cast<const void*>(uintptr_t{4 * k} * sizeof(float)));
    }
  }
  upload(GL_ELEMENT_ARRAY_BUFFER, indices_, mesh.indices);  // recorded in the vertex array
  glBindVertexArray(0);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  check_gl("uploading a mesh");
}

void GpuMesh::draw(const std::function<void(const MeshPart&)>& before_part) const {
  glBindVertexArray(vertex_array_.get());
  for (const MeshPart& part : parts_) {
    before_part(part);
    glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(part.index_count), GL_UNSIGNED_INT,
                   reinterpret_cast<const void*>(uintptr_t{part.first_index} * sizeof(uint32_t)));
  }
  glBindVertexArray(0);
}

void GpuMesh::draw_parts(const std::function<bool(size_t part)>& include) const {
  // Consecutive parts go in one call (culling clusters come in runs along their Morton curve).
  glBindVertexArray(vertex_array_.get());
  size_t i = 0;
  while (i < parts_.size()) {
    if (!include(i)) {
      ++i;
      continue;
    }
    const uint32_t first = parts_[i].first_index;
    uint32_t end = first + parts_[i].index_count;
    for (++i; i < parts_.size() && parts_[i].first_index == end && include(i); ++i) end += parts_[i].index_count;
    glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(end - first), GL_UNSIGNED_INT,
                   reinterpret_cast<const void*>(uintptr_t{first} * sizeof(uint32_t)));
  }
  glBindVertexArray(0);
}

}  // namespace arpipe
