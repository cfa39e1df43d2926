// Loads the triangle meshes of a glTF 2.0 file (.gltf or .glb, via tinygltf) into one Mesh, with
// node transforms applied and glTF's y-up axes turned into arpipe's z-up object frame.
#include "core/scene/gltf_loader.h"

// The one translation unit that compiles tinygltf. Images are never decoded (the renderer uses
// base colours only), so stb is left out: no image decoder in the process and no clash with
// another copy of stb's symbols.
#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>

#include <fmt/format.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <glm/glm.hpp>
#include <glm/gtc/matrix_inverse.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <set>

#include "core/log.h"
#include "core/scene/asset_error.h"

namespace arpipe {
namespace {

bool ignore_image(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int,
                  void*) {
  return true;
}

std::string trimmed(std::string text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  return text;
}

glm::dmat4 node_transform(const tinygltf::Node& node) {
  if (node.matrix.size() == 16) return glm::make_mat4(node.matrix.data());  // column-major, as glTF stores it
  glm::dmat4 transform(1.0);
  if (node.translation.size() == 3)
    transform = glm::translate(transform, glm::dvec3(node.translation[0], node.translation[1], node.translation[2]));
  if (node.rotation.size() == 4)  // glTF quaternions are x, y, z, w; glm's constructor takes w first
    transform *= glm::mat4_cast(glm::dquat(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]));
  if (node.scale.size() == 3) transform = glm::scale(transform, glm::dvec3(node.scale[0], node.scale[1], node.scale[2]));
  return transform;
}

class GltfMeshCollector {
 public:
  GltfMeshCollector(const tinygltf::Model& model, const std::filesystem::path& path) : model_(model), path_(path) {}

  void add_node(int node_index, const glm::dmat4& parent, std::set<int>& ancestors) {
    if (node_index < 0 || static_cast<size_t>(node_index) >= model_.nodes.size())
      fail(fmt::format("node {} does not exist ({} nodes)", node_index, model_.nodes.size()));
    if (!ancestors.insert(node_index).second) fail(fmt::format("node {} is its own ancestor", node_index));
    const tinygltf::Node& node = model_.nodes[static_cast<size_t>(node_index)];
    const glm::dmat4 transform = parent * node_transform(node);
    if (node.mesh >= 0) {
      if (static_cast<size_t>(node.mesh) >= model_.meshes.size())
        fail(fmt::format("node {} names mesh {}, which does not exist", node_index, node.mesh));
      const tinygltf::Mesh& mesh = model_.meshes[static_cast<size_t>(node.mesh)];
      for (size_t p = 0; p < mesh.primitives.size(); ++p) add_primitive(node.mesh, p, mesh.primitives[p], transform);
    }
    for (int child : node.children) add_node(child, transform, ancestors);
    ancestors.erase(node_index);
  }

  Mesh finish() {
    if (mesh_.indices.empty()) fail("contains no triangles (no mesh with a TRIANGLES, TRIANGLE_STRIP or TRIANGLE_FAN primitive in the scene)");
    if (skipped_primitives_ > 0)
      log::warn("{}: skipped {} primitive(s) that are points or lines", path_.string(), skipped_primitives_);
    return std::move(mesh_);
  }

 private:
  [[noreturn]] void fail(const std::string& what) const { throw AssetError(fmt::format("{}: {}", path_.string(), what)); }

  // Reads a VEC3 FLOAT accessor, honouring byte strides.
  std::vector<glm::dvec3> read_vec3(int accessor_index, const std::string& where) const {
    const tinygltf::Accessor& accessor = checked_accessor(accessor_index, where);
    if (accessor.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT || accessor.type != TINYGLTF_TYPE_VEC3)
      fail(fmt::format("{}: accessor {} must be VEC3 of FLOAT", where, accessor_index));
    std::vector<glm::dvec3> values(accessor.count);
    const auto [data, stride] = element_span(accessor, accessor_index, where, 12);
    for (size_t i = 0; i < accessor.count; ++i) {
      float xyz[3];
      std::memcpy(xyz, data + i * stride, sizeof(xyz));
      values[i] = glm::dvec3(xyz[0], xyz[1], xyz[2]);
    }
    return values;
  }

  std::vector<uint32_t> read_indices(int accessor_index, const std::string& where) const {
    const tinygltf::Accessor& accessor = checked_accessor(accessor_index, where);
    size_t size = 0;
    switch (accessor.componentType) {
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: size = 1; break;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: size = 2; break;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: size = 4; break;
      default: fail(fmt::format("{}: index accessor {} must be UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT", where, accessor_index));
    }
    if (accessor.type != TINYGLTF_TYPE_SCALAR) fail(fmt::format("{}: index accessor {} must be SCALAR", where, accessor_index));
    const auto [data, stride] = element_span(accessor, accessor_index, where, size);
    std::vector<uint32_t> indices(accessor.count);
    for (size_t i = 0; i < accessor.count; ++i) {
      const unsigned char* element = data + i * stride;
      if (size == 1) {
        indices[i] = element[0];
      } else if (size == 2) {
        uint16_t value;
        std::memcpy(&value, element, 2);
        indices[i] = value;
      } else {
        std::memcpy(&indices[i], element, 4);
      }
    }
    return indices;
  }

  const tinygltf::Accessor& checked_accessor(int accessor_index, const std::string& where) const {
    if (accessor_index < 0 || static_cast<size_t>(accessor_index) >= model_.accessors.size())
      fail(fmt::format("{}: accessor {} does not exist ({} accessors)", where, accessor_index, model_.accessors.size()));
    const tinygltf::Accessor& accessor = model_.accessors[static_cast<size_t>(accessor_index)];
    if (accessor.sparse.isSparse) fail(fmt::format("{}: accessor {} is sparse, which is not supported", where, accessor_index));
    return accessor;
  }

  // Start of the accessor's first element and the byte step between elements, after checking that
  // every element lies inside its buffer view and the view inside its buffer.
  std::pair<const unsigned char*, size_t> element_span(const tinygltf::Accessor& accessor, int accessor_index,
                                                       const std::string& where, size_t element_size) const {
    if (accessor.bufferView < 0 || static_cast<size_t>(accessor.bufferView) >= model_.bufferViews.size())
      fail(fmt::format("{}: accessor {} has no valid bufferView ({})", where, accessor_index, accessor.bufferView));
    const tinygltf::BufferView& view = model_.bufferViews[static_cast<size_t>(accessor.bufferView)];
    if (view.buffer < 0 || static_cast<size_t>(view.buffer) >= model_.buffers.size())
      fail(fmt::format("{}: bufferView {} names buffer {}, which does not exist", where, accessor.bufferView, view.buffer));
    const tinygltf::Buffer& buffer = model_.buffers[static_cast<size_t>(view.buffer)];
    if (view.byteOffset > buffer.data.size() || view.byteLength > buffer.data.size() - view.byteOffset)
      fail(fmt::format("{}: bufferView {} (offset {}, length {}) runs past the end of buffer {} ({} bytes)", where,
                       accessor.bufferView, view.byteOffset, view.byteLength, view.buffer, buffer.data.size()));
    const int stride = accessor.ByteStride(view);
    if (stride <= 0 || static_cast<size_t>(stride) < element_size)
      fail(fmt::format("{}: accessor {} has an invalid byte stride", where, accessor_index));
    if (accessor.count > 0) {
      const size_t needed = accessor.byteOffset + static_cast<size_t>(stride) * (accessor.count - 1) + element_size;
      if (needed > view.byteLength)
        fail(fmt::format("{}: accessor {} ({} elements from offset {}) needs {} bytes but bufferView {} has {}", where,
                         accessor_index, accessor.count, accessor.byteOffset, needed, accessor.bufferView, view.byteLength));
    }
    return {buffer.data.data() + view.byteOffset + accessor.byteOffset, static_cast<size_t>(stride)};
  }

  static std::vector<uint32_t> triangle_list(int mode, const std::vector<uint32_t>& indices) {
    std::vector<uint32_t> triangles;
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      triangles.assign(indices.begin(), indices.end() - static_cast<std::ptrdiff_t>(indices.size() % 3));
    } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
      for (size_t i = 2; i < indices.size(); ++i) {
        // Every second triangle of a strip is wound the other way round.
        if (i % 2 == 0) triangles.insert(triangles.end(), {indices[i - 2], indices[i - 1], indices[i]});
        else triangles.insert(triangles.end(), {indices[i - 1], indices[i - 2], indices[i]});
      }
    } else if (mode == TINYGLTF_MODE_TRIANGLE_FAN) {
      for (size_t i = 2; i < indices.size(); ++i) triangles.insert(triangles.end(), {indices[0], indices[i - 1], indices[i]});
    }
    return triangles;
  }

  void add_primitive(int mesh_index, size_t primitive_index, const tinygltf::Primitive& primitive,
                     const glm::dmat4& transform) {
    if (primitive.mode != TINYGLTF_MODE_TRIANGLES && primitive.mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
        primitive.mode != TINYGLTF_MODE_TRIANGLE_FAN) {
      ++skipped_primitives_;
      return;
    }
    const std::string where = fmt::format("mesh {} primitive {}", mesh_index, primitive_index);
    const auto position_attribute = primitive.attributes.find("POSITION");
    if (position_attribute == primitive.attributes.end()) fail(where + " has no POSITION attribute");
    const std::vector<glm::dvec3> positions = read_vec3(position_attribute->second, where + " POSITION");

    std::vector<glm::dvec3> normals;
    const auto normal_attribute = primitive.attributes.find("NORMAL");
    if (normal_attribute != primitive.attributes.end()) {
      normals = read_vec3(normal_attribute->second, where + " NORMAL");
      if (normals.size() != positions.size())
        fail(fmt::format("{}: NORMAL has {} elements but POSITION has {}", where, normals.size(), positions.size()));
    }

    std::vector<uint32_t> indices;
    if (primitive.indices >= 0) {
      indices = read_indices(primitive.indices, where + " indices");
    } else {
      indices.resize(positions.size());
      for (size_t i = 0; i < indices.size(); ++i) indices[i] = static_cast<uint32_t>(i);
    }
    for (size_t i = 0; i < indices.size(); ++i)
      if (indices[i] >= positions.size())
        fail(fmt::format("{}: index {} (element {}) is past the last vertex ({} vertices)", where, indices[i], i,
                         positions.size()));
    const std::vector<uint32_t> triangles = triangle_list(primitive.mode, indices);

    std::array<float, 4> color{1, 1, 1, 1};
    if (primitive.material >= 0) {
      if (static_cast<size_t>(primitive.material) >= model_.materials.size())
        fail(fmt::format("{}: material {} does not exist", where, primitive.material));
      const std::vector<double>& factor =
          model_.materials[static_cast<size_t>(primitive.material)].pbrMetallicRoughness.baseColorFactor;
      if (factor.size() == 4)
        for (size_t c = 0; c < 4; ++c) color[c] = static_cast<float>(factor[c]);
    }

    const glm::dmat3 normal_matrix = glm::inverseTranspose(glm::dmat3(transform));
    // glTF is y-up with the model's front towards +z; the object frame is z-up (x stays x).
    auto to_object_frame = [](const glm::dvec3& v) { return glm::dvec3(v.x, -v.z, v.y); };
    auto push = [&](std::vector<float>& out, const glm::dvec3& v) {
      out.insert(out.end(), {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)});
    };
    const bool mirrored = glm::determinant(glm::dmat3(transform)) < 0;  // a mirroring node turns the winding over
    MeshPart part;
    part.first_index = static_cast<uint32_t>(mesh_.indices.size());
    part.base_color = color;
    if (!normals.empty()) {
      const uint32_t base = static_cast<uint32_t>(mesh_.vertex_count());
      for (size_t i = 0; i < positions.size(); ++i) {
        push(mesh_.positions, to_object_frame(glm::dvec3(transform * glm::dvec4(positions[i], 1.0))));
        glm::dvec3 n = normal_matrix * normals[i];
        if (glm::length(n) > 0) n = glm::normalize(n);
        push(mesh_.normals, to_object_frame(n));
      }
      for (size_t i = 0; i < triangles.size(); i += 3) {
        const uint32_t a = base + triangles[i], b = base + triangles[i + 1], c = base + triangles[i + 2];
        mesh_.indices.insert(mesh_.indices.end(), mirrored ? std::initializer_list<uint32_t>{a, c, b}
                                                           : std::initializer_list<uint32_t>{a, b, c});
      }
    } else {
      // Flat normals: every triangle gets its own three vertices.
      for (size_t i = 0; i < triangles.size(); i += 3) {
        glm::dvec3 corner[3];
        for (size_t k = 0; k < 3; ++k)
          corner[k] = to_object_frame(glm::dvec3(transform * glm::dvec4(positions[triangles[i + k]], 1.0)));
        if (mirrored) std::swap(corner[1], corner[2]);
        glm::dvec3 n = glm::cross(corner[1] - corner[0], corner[2] - corner[0]);
        if (glm::length(n) > 0) n = glm::normalize(n);
        for (size_t k = 0; k < 3; ++k) {
          mesh_.indices.push_back(static_cast<uint32_t>(mesh_.vertex_count()));
          push(mesh_.positions, corner[k]);
          push(mesh_.normals, n);
        }
      }
    }
    part.index_count = static_cast<uint32_t>(mesh_.indices.size()) - part.first_index;
    if (part.index_count > 0) mesh_.parts.push_back(part);
  }

  const tinygltf::Model& model_;
  const std::filesystem::path& path_;
  Mesh mesh_;
  int skipped_primitives_ = 0;
};

bool starts_with_glb_magic(const std::filesystem::path& path) {
  std::ifstream file(path, std::ios::binary);
  char magic[4] = {};
  file.read(magic, 4);
  return file.gcount() == 4 && std::memcmp(magic, "glTF", 4) == 0;
}

}  // namespace

Mesh load_gltf_mesh(const std::filesystem::path& path) {
  {
    std::ifstream probe(path, std::ios::binary);
    if (!probe) throw AssetError(fmt::format("{}: cannot open glTF file: {}", path.string(), std::strerror(errno)));
  }
  if (std::filesystem::is_directory(path)) throw AssetError(fmt::format("{}: is a directory, not a glTF file", path.string()));

  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(ignore_image, nullptr);
  tinygltf::Model model;
  std::string error, warning;
  const bool binary = starts_with_glb_magic(path);
  const bool ok = binary ? loader.LoadBinaryFromFile(&model, &error, &warning, path.string())
                         : loader.LoadASCIIFromFile(&model, &error, &warning, path.string());
  if (!ok) {
    if (error.empty()) error = "unknown error";
    throw AssetError(fmt::format("{}: not a valid glTF 2.0 {} file: {}", path.string(), binary ? "binary (.glb)" : "JSON",
                                 trimmed(error)));
  }
  if (!warning.empty()) log::debug("{}: tinygltf: {}", path.string(), trimmed(warning));

  GltfMeshCollector collector(model, path);
  std::vector<int> roots;
  if (model.defaultScene >= 0 && static_cast<size_t>(model.defaultScene) < model.scenes.size()) {
    roots = model.scenes[static_cast<size_t>(model.defaultScene)].nodes;
  } else if (!model.scenes.empty()) {
    roots = model.scenes.front().nodes;
  } else {
    std::vector<bool> is_child(model.nodes.size(), false);
    for (const tinygltf::Node& node : model.nodes)
      for (int child : node.children)
        if (child >= 0 && static_cast<size_t>(child) < is_child.size()) is_child[static_cast<size_t>(child)] = true;
    for (size_t i = 0; i < model.nodes.size(); ++i)
      if (!is_child[i]) roots.push_back(static_cast<int>(i));
  }
  std::set<int> ancestors;
  for (int root : roots) collector.add_node(root, glm::dmat4(1.0), ancestors);
  return collector.finish();
}

}  // namespace arpipe
