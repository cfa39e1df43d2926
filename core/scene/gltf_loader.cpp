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
#include <cmath>
#include <cstring>
#include <glm/glm.hpp>
#include <glm/gtc/matrix_inverse.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <limits>
#include <new>
#include <tuple>

#include "core/log.h"
#include "core/scene/asset_error.h"
#include "core/scene/asset_file.h"
#include "core/scene/gltf_document.h"
#include "core/scene/gltf_limits.h"

namespace arpipe {
namespace {

bool ignore_image(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int,
                  void*) {
  return true;
}

// tinygltf's messages, trimmed, each line cut short (a failed data URI is quoted whole).
std::string tinygltf_message(const std::string& text) {
  std::string out, line;
  auto flush = [&] {
    while (!line.empty() && line.back() == ' ') line.pop_back();
    if (line.empty()) return;
    if (line.size() > 200) line = line.substr(0, 200) + "...";
    out += (out.empty() ? "" : "; ") + line;
    line.clear();
  };
  for (char c : text) {
    if (c == '\n') flush();
    else line += c;
  }
  flush();
  return out.empty() ? "unknown error" : out;
}

// tinygltf's file system for external buffers: every path is checked again here (the document's
// checks may be stale by the time tinygltf reads), within the buffer byte budget.
struct ExternalFiles {
  std::filesystem::path folder;
  uint64_t bytes_left = kMaxGltfBufferBytes;
};

bool external_file_exists(const std::string&, void*) { return true; }  // read_external_file says what is wrong
std::string keep_file_path(const std::string& path, void*) { return path; }  // no "~" or "$VAR" expansion
bool refuse_write(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err = "writing is not allowed";
  return false;
}

bool read_external_file(std::vector<unsigned char>* out, std::string* err, const std::string& joined_path,
                        void* user_data) {
  ExternalFiles& files = *static_cast<ExternalFiles*>(user_data);
  // tinygltf joins the folder, "/" and the decoded URI; resolve what follows the folder.
  std::string prefix = files.folder.string();
  if (prefix.empty() || prefix.back() != '/') prefix += '/';  // as tinygltf's JoinPath (the root folder ends in '/')
  std::string why;
  if (joined_path.compare(0, prefix.size(), prefix) != 0) {
    if (err) *err = "not inside the glTF file's folder";
    return false;
  }
  const std::optional<std::filesystem::path> file =
      resolve_inside_folder(files.folder, joined_path.substr(prefix.size()), &why);
  std::optional<std::vector<unsigned char>> bytes;
  if (file) bytes = read_asset_file(*file, files.bytes_left, &why);
  if (!bytes) {
    if (err) *err = why;
    return false;
  }
  files.bytes_left -= bytes->size();
  *out = std::move(*bytes);
  return true;
}

bool all_finite(const std::vector<double>& values) {
  for (double v : values)
    if (!std::isfinite(v)) return false;
  return true;
}

bool all_finite(const glm::dmat4& m) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r])) return false;
  return true;
}

bool all_finite(const glm::dmat3& m) {
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r)
      if (!std::isfinite(m[c][r])) return false;
  return true;
}

// glTF's y-up axes to arpipe's z-up object frame: +y (up) becomes +z, +z (the model's front) -y.
glm::dvec3 to_object_frame(const glm::dvec3& v) { return glm::dvec3(v.x, -v.z, v.y); }

class GltfMeshCollector {
 public:
  // read_meshes false: only the lights are collected (load_gltf_lights).
  GltfMeshCollector(const tinygltf::Model& model, const std::filesystem::path& path, bool read_meshes = true)
      : model_(model), path_(path), reached_(model.nodes.size(), false), read_meshes_(read_meshes) {}

  std::vector<GltfLight> take_lights() { return std::move(lights_); }

  // The node hierarchy under `roots`, walked depth-first with an explicit stack (no recursion over
  // the file's graph). glTF nodes form strict trees: a node reached a second time (two parents,
  // a cycle, a scene root that is also a child) is an error, so every node is visited at most once.
  void add_roots(const std::vector<int>& roots) {
    struct Pending {
      int node;
      glm::dmat4 parent;
      size_t depth;
    };
    std::vector<Pending> stack;
    for (auto root = roots.rbegin(); root != roots.rend(); ++root) stack.push_back({*root, glm::dmat4(1.0), 1});
    while (!stack.empty()) {
      const Pending pending = stack.back();
      stack.pop_back();
      const int node_index = pending.node;
      if (node_index < 0 || static_cast<size_t>(node_index) >= model_.nodes.size())
        fail(fmt::format("node {} does not exist ({} nodes)", node_index, model_.nodes.size()));
      if (reached_[static_cast<size_t>(node_index)])
        fail(fmt::format("node {} is reached more than once: it has more than one parent, is its own ancestor or "
                         "is both a scene root and a child (glTF nodes form strict trees)",
                         node_index));
      reached_[static_cast<size_t>(node_index)] = true;
      if (pending.depth > kMaxGltfNodeDepth)
        fail(fmt::format("node {} is {} levels deep in the node hierarchy, over the depth limit of {}", node_index,
                         pending.depth, kMaxGltfNodeDepth));
      const tinygltf::Node& node = model_.nodes[static_cast<size_t>(node_index)];
      const glm::dmat4 transform = pending.parent * node_transform(node_index, node);
      if (!all_finite(transform))
        fail(fmt::format("node {}: its transform combined with its parents' is not finite (overflow)", node_index));
      if (node.mesh >= 0 && read_meshes_) add_mesh(node_index, node.mesh, transform);
      add_light(node_index, node, transform);
      for (auto child = node.children.rbegin(); child != node.children.rend(); ++child)
        stack.push_back({*child, transform, pending.depth + 1});
    }
  }

  Mesh finish() {
    if (mesh_.indices.empty()) fail("contains no triangles (no mesh with a TRIANGLES, TRIANGLE_STRIP or TRIANGLE_FAN primitive in the scene)");
    if (skipped_primitives_ > 0)
      log::warn("{}: skipped {} primitive(s) that are points or lines", path_.string(), skipped_primitives_);
    if (skipped_singular_ > 0)
      log::warn("{}: skipped {} mesh instance(s) under a singular node transform (a zero scale)", path_.string(),
                skipped_singular_);
    mesh_.source = path_.string();
    return std::move(mesh_);
  }

 private:
  [[noreturn]] void fail(const std::string& what) const { throw AssetError(fmt::format("{}: {}", path_.string(), what)); }

  glm::dmat4 node_transform(int node_index, const tinygltf::Node& node) const {
    for (const auto* values : {&node.matrix, &node.translation, &node.rotation, &node.scale})
      if (!all_finite(*values)) fail(fmt::format("node {}: its matrix or TRS has a value that is not finite", node_index));
    if (node.matrix.size() == 16) return glm::make_mat4(node.matrix.data());  // column-major, as glTF stores it
    glm::dmat4 transform(1.0);
    if (node.translation.size() == 3)
      transform = glm::translate(transform, glm::dvec3(node.translation[0], node.translation[1], node.translation[2]));
    if (node.rotation.size() == 4)  // glTF quaternions are x, y, z, w; glm's constructor takes w first
      transform *= glm::mat4_cast(glm::dquat(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]));
    if (node.scale.size() == 3) transform = glm::scale(transform, glm::dvec3(node.scale[0], node.scale[1], node.scale[2]));
    return transform;
  }

  // The node's KHR_lights_punctual light (gltf_document.cpp checked its index), placed: at the
  // node's origin, shining along its -z, in the z-up frame.
  void add_light(int node_index, const tinygltf::Node& node, const glm::dmat4& transform) {
    const auto extension = node.extensions.find("KHR_lights_punctual");
    if (extension == node.extensions.end() || !extension->second.Has("light")) return;
    const int index = extension->second.Get("light").GetNumberAsInt();
    if (index < 0 || static_cast<size_t>(index) >= model_.lights.size())
      fail(fmt::format("node {} names light {}, which does not exist", node_index, index));
    const tinygltf::Light& light = model_.lights[static_cast<size_t>(index)];
    const glm::dvec3 position = to_object_frame(glm::dvec3(transform * glm::dvec4(0, 0, 0, 1)));
    glm::dvec3 direction = to_object_frame(glm::dmat3(transform) * glm::dvec3(0, 0, -1));
    const double length = glm::length(direction);
    if (!(length > 1e-100) || !std::isfinite(length) || !std::isfinite(position.x + position.y + position.z))
      fail(fmt::format("node {}: light {} has no direction or position (a zero or infinite scale)", node_index, index));
    direction /= length;
    GltfLight out;
    out.name = light.name;
    out.type = light.type;
    if (light.color.size() == 3) out.color = {light.color[0], light.color[1], light.color[2]};
    out.intensity = light.intensity;
    out.range = light.range;
    out.position = {position.x, position.y, position.z};
    out.direction = {direction.x, direction.y, direction.z};
    out.node = node_index;
    lights_.push_back(std::move(out));
  }

  void add_mesh(int node_index, int mesh_index, const glm::dmat4& transform) {
    if (static_cast<size_t>(mesh_index) >= model_.meshes.size())
      fail(fmt::format("node {} names mesh {}, which does not exist", node_index, mesh_index));
    const glm::dmat3 normal_matrix = glm::inverseTranspose(glm::dmat3(transform));
    if (!all_finite(normal_matrix)) {  // a zero scale: nothing to see, and no normals to turn
      ++skipped_singular_;
      return;
    }
    const tinygltf::Mesh& mesh = model_.meshes[static_cast<size_t>(mesh_index)];
    for (size_t p = 0; p < mesh.primitives.size(); ++p)
      add_primitive(node_index, mesh_index, p, mesh.primitives[p], transform, normal_matrix);
  }

  // An accessor's elements: where the first starts, the byte step to the next, how many.
  struct Span {
    const unsigned char* data;
    size_t stride;
    size_t count;
  };

  const tinygltf::Accessor& checked_accessor(int accessor_index, const std::string& where) const {
    if (accessor_index < 0 || static_cast<size_t>(accessor_index) >= model_.accessors.size())
      fail(fmt::format("{}: accessor {} does not exist ({} accessors)", where, accessor_index, model_.accessors.size()));
    const tinygltf::Accessor& accessor = model_.accessors[static_cast<size_t>(accessor_index)];
    if (accessor.sparse.isSparse) fail(fmt::format("{}: accessor {} is sparse, which is not supported", where, accessor_index));
    return accessor;
  }

  // Checks, with overflow-checked arithmetic, that every element lies inside the accessor's buffer
  // view and the view inside its buffer, and that the count is within `max_count`: all before any
  // element is read or any memory is allocated for them.
  Span element_span(const tinygltf::Accessor& accessor, int accessor_index, const std::string& where,
                    size_t element_size, size_t max_count, const char* limit_name) const {
    if (accessor.bufferView < 0 || static_cast<size_t>(accessor.bufferView) >= model_.bufferViews.size())
      fail(fmt::format("{}: accessor {} has no valid bufferView ({})", where, accessor_index, accessor.bufferView));
    const tinygltf::BufferView& view = model_.bufferViews[static_cast<size_t>(accessor.bufferView)];
    if (view.buffer < 0 || static_cast<size_t>(view.buffer) >= model_.buffers.size())
      fail(fmt::format("{}: bufferView {} names buffer {}, which does not exist", where, accessor.bufferView, view.buffer));
    const tinygltf::Buffer& buffer = model_.buffers[static_cast<size_t>(view.buffer)];
    size_t view_end = 0;
    if (__builtin_add_overflow(view.byteOffset, view.byteLength, &view_end) || view_end > buffer.data.size())
      fail(fmt::format("{}: bufferView {} (byteOffset {}, byteLength {}) runs past the end of buffer {} ({} bytes)",
                       where, accessor.bufferView, view.byteOffset, view.byteLength, view.buffer, buffer.data.size()));
    // glTF: byteStride is 4..252 and a multiple of 4 (tinygltf checks it too); 0 means packed.
    if (view.byteStride != 0 && (view.byteStride < 4 || view.byteStride > 252 || view.byteStride % 4 != 0))
      fail(fmt::format("{}: bufferView {} has byteStride {} (must be 4 to 252, a multiple of 4)", where,
                       accessor.bufferView, view.byteStride));
    const int stride = accessor.ByteStride(view);
    if (stride <= 0 || static_cast<size_t>(stride) < element_size)
      fail(fmt::format("{}: accessor {} has an invalid byte stride {} for {}-byte elements (bufferView {})", where,
                       accessor_index, stride, element_size, accessor.bufferView));
    if (accessor.count > 0) {
      size_t last_start = 0, end = 0;
      if (__builtin_mul_overflow(static_cast<size_t>(stride), accessor.count - 1, &last_start) ||
          __builtin_add_overflow(last_start, accessor.byteOffset, &last_start) ||
          __builtin_add_overflow(last_start, element_size, &end) || end > view.byteLength)
        fail(fmt::format("{}: accessor {} ({} elements of {} bytes, stride {}, from byteOffset {}) does not fit in "
                         "bufferView {} ({} bytes)",
                         where, accessor_index, accessor.count, element_size, stride, accessor.byteOffset,
                         accessor.bufferView, view.byteLength));
    }
    if (accessor.count > max_count)
      fail(fmt::format("{}: accessor {} has {} elements, over the limit of {} {}", where, accessor_index,
                       accessor.count, max_count, limit_name));
    return {buffer.data.data() + view.byteOffset + accessor.byteOffset, static_cast<size_t>(stride), accessor.count};
  }

  Span vec3_span(int accessor_index, const std::string& where) const {
    const tinygltf::Accessor& accessor = checked_accessor(accessor_index, where);
    if (accessor.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT || accessor.type != TINYGLTF_TYPE_VEC3)
      fail(fmt::format("{}: accessor {} must be VEC3 of FLOAT", where, accessor_index));
    return element_span(accessor, accessor_index, where, 12, kMaxGltfVertices, "vertices");
  }

  // The span's VEC3 FLOAT elements, each finite.
  std::vector<glm::dvec3> read_vec3(const Span& span, int accessor_index, const std::string& where) const {
    std::vector<glm::dvec3> values(span.count);
    for (size_t i = 0; i < span.count; ++i) {
      float xyz[3];
      std::memcpy(xyz, span.data + i * span.stride, sizeof(xyz));
      if (!std::isfinite(xyz[0]) || !std::isfinite(xyz[1]) || !std::isfinite(xyz[2]))
        fail(fmt::format("{}: accessor {} element {} is not finite ({}, {}, {})", where, accessor_index, i, xyz[0],
                         xyz[1], xyz[2]));
      values[i] = glm::dvec3(xyz[0], xyz[1], xyz[2]);
    }
    return values;
  }

  std::pair<Span, size_t> index_span(int accessor_index, const std::string& where) const {
    const tinygltf::Accessor& accessor = checked_accessor(accessor_index, where);
    size_t size = 0;
    switch (accessor.componentType) {
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: size = 1; break;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: size = 2; break;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: size = 4; break;
      default: fail(fmt::format("{}: index accessor {} must be UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT", where, accessor_index));
    }
    if (accessor.type != TINYGLTF_TYPE_SCALAR) fail(fmt::format("{}: index accessor {} must be SCALAR", where, accessor_index));
    // A strip or fan of n indices makes n - 2 triangles.
    return {element_span(accessor, accessor_index, where, size, 3 * kMaxGltfTriangles + 2, "indices"), size};
  }

  static std::vector<uint32_t> read_indices(const Span& span, size_t size) {
    std::vector<uint32_t> indices(span.count);
    for (size_t i = 0; i < span.count; ++i) {
      const unsigned char* element = span.data + i * span.stride;
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

  static size_t triangle_count(int mode, size_t index_count) {
    if (mode == TINYGLTF_MODE_TRIANGLES) return index_count / 3;
    return index_count >= 3 ? index_count - 2 : 0;  // strips and fans
  }

  static std::vector<uint32_t> triangle_list(int mode, const std::vector<uint32_t>& indices) {
    std::vector<uint32_t> triangles;
    triangles.reserve(3 * triangle_count(mode, indices.size()));
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

  // The output limits, and the elements-read budget, checked before a primitive is read.
  void reserve_output(const std::string& where, size_t new_vertices, size_t new_triangles, size_t elements_read) {
    size_t vertices = 0, triangles = 0;
    if (__builtin_add_overflow(mesh_.vertex_count(), new_vertices, &vertices) || vertices > kMaxGltfVertices)
      fail(fmt::format("{}: the mesh would have more than {} vertices, the limit (every instance of a mesh counts)",
                       where, kMaxGltfVertices));
    if (__builtin_add_overflow(mesh_.triangle_count(), new_triangles, &triangles) || triangles > kMaxGltfTriangles)
      fail(fmt::format("{}: the mesh would have more than {} triangles, the limit (every instance of a mesh counts)",
                       where, kMaxGltfTriangles));
    if (__builtin_add_overflow(elements_read_, elements_read, &elements_read_) || elements_read_ > kMaxGltfElementsRead)
      fail(fmt::format("{}: loading reads more than {} accessor elements, the limit (every instance of a mesh "
                       "counts)",
                       where, kMaxGltfElementsRead));
  }

  void add_primitive(int node_index, int mesh_index, size_t primitive_index, const tinygltf::Primitive& primitive,
                     const glm::dmat4& transform, const glm::dmat3& normal_matrix) {
    if (primitive.mode != TINYGLTF_MODE_TRIANGLES && primitive.mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
        primitive.mode != TINYGLTF_MODE_TRIANGLE_FAN) {
      ++skipped_primitives_;
      return;
    }
    const std::string where = fmt::format("mesh {} primitive {}", mesh_index, primitive_index);
    const auto position_attribute = primitive.attributes.find("POSITION");
    if (position_attribute == primitive.attributes.end()) fail(where + " has no POSITION attribute");
    const Span positions_span = vec3_span(position_attribute->second, where + " POSITION");

    const auto normal_attribute = primitive.attributes.find("NORMAL");
    const bool has_normals = normal_attribute != primitive.attributes.end();
    Span normals_span{nullptr, 0, 0};
    if (has_normals) {
      normals_span = vec3_span(normal_attribute->second, where + " NORMAL");
      if (normals_span.count != positions_span.count)
        fail(fmt::format("{}: NORMAL has {} elements but POSITION has {}", where, normals_span.count,
                         positions_span.count));
    }
    Span indices_span{nullptr, 0, positions_span.count};  // without indices: the vertices in order
    size_t index_size = 0;
    if (primitive.indices >= 0) std::tie(indices_span, index_size) = index_span(primitive.indices, where + " indices");

    const size_t triangles_out = triangle_count(primitive.mode, indices_span.count);
    reserve_output(where, has_normals ? positions_span.count : 3 * triangles_out, triangles_out,
                   positions_span.count + normals_span.count + (index_size > 0 ? indices_span.count : 0));

    const std::vector<glm::dvec3> positions = read_vec3(positions_span, position_attribute->second, where + " POSITION");
    std::vector<glm::dvec3> normals;
    if (has_normals) normals = read_vec3(normals_span, normal_attribute->second, where + " NORMAL");
    std::vector<uint32_t> indices;
    if (index_size > 0) {
      indices = read_indices(indices_span, index_size);
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
        for (size_t c = 0; c < 4; ++c) color[c] = static_cast<float>(std::isfinite(factor[c]) ? factor[c] : 1.0);
    }

    // glTF is y-up with the model's front towards +z; the object frame is z-up (x stays x).
    auto place = [&](const glm::dvec3& position, size_t vertex) {
      const glm::dvec3 placed = to_object_frame(glm::dvec3(transform * glm::dvec4(position, 1.0)));
      for (int axis = 0; axis < 3; ++axis)
        if (!std::isfinite(static_cast<float>(placed[axis])))
          fail(fmt::format("node {} {}: vertex {} is ({}, {}, {}) after the node's transform, beyond float range",
                           node_index, where, vertex, placed.x, placed.y, placed.z));
      return placed;
    };
    auto push = [&](std::vector<float>& out, const glm::dvec3& v) {
      out.insert(out.end(), {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)});
    };
    const bool mirrored = glm::determinant(glm::dmat3(transform)) < 0;  // a mirroring node turns the winding over
    MeshPart part;
    part.first_index = static_cast<uint32_t>(mesh_.indices.size());
    part.base_color = color;
    if (has_normals) {
      const uint32_t base = static_cast<uint32_t>(mesh_.vertex_count());
      for (size_t i = 0; i < positions.size(); ++i) {
        push(mesh_.positions, place(positions[i], i));
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
        for (size_t k = 0; k < 3; ++k) corner[k] = place(positions[triangles[i + k]], triangles[i + k]);
        if (mirrored) std::swap(corner[1], corner[2]);
        glm::dvec3 n = glm::cross(corner[1] - corner[0], corner[2] - corner[0]);
        const double length = glm::length(n);
        n = length > 0 && std::isfinite(length) ? n / length : glm::dvec3(0.0);
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
  std::vector<bool> reached_;  // per node: already placed once
  Mesh mesh_;
  bool read_meshes_ = true;
  std::vector<GltfLight> lights_;
  int skipped_primitives_ = 0;
  int skipped_singular_ = 0;
  uint64_t elements_read_ = 0;
};

// The scene's root nodes: the default scene's, else the first scene's, else every node that is
// nobody's child.
std::vector<int> root_nodes(const tinygltf::Model& model) {
  if (model.defaultScene >= 0 && static_cast<size_t>(model.defaultScene) < model.scenes.size())
    return model.scenes[static_cast<size_t>(model.defaultScene)].nodes;
  if (!model.scenes.empty()) return model.scenes.front().nodes;
  std::vector<bool> is_child(model.nodes.size(), false);
  for (const tinygltf::Node& node : model.nodes)
    for (int child : node.children)
      if (child >= 0 && static_cast<size_t>(child) < is_child.size()) is_child[static_cast<size_t>(child)] = true;
  std::vector<int> roots;
  for (size_t i = 0; i < model.nodes.size(); ++i)
    if (!is_child[i]) roots.push_back(static_cast<int>(i));
  return roots;
}

tinygltf::Model load_checked_gltf_model(const std::filesystem::path& path) {
  GltfDocument document = read_gltf_document(path);
  ExternalFiles external{document.folder, kMaxGltfBufferBytes};
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(ignore_image, nullptr);
  loader.SetFsCallbacks({external_file_exists, keep_file_path, read_external_file, refuse_write, &external});
  tinygltf::Model model;
  std::string error, warning;
  const std::string base_dir = document.folder.string();
  const bool ok =
      document.binary
          ? loader.LoadBinaryFromMemory(&model, &error, &warning, document.glb.data(),
                                        static_cast<unsigned int>(document.glb.size()), base_dir)
          : loader.LoadASCIIFromString(&model, &error, &warning, document.json.data(),
                                       static_cast<unsigned int>(document.json.size()), base_dir);
  const bool binary = document.binary;
  document = {};  // the parsed model holds what is needed
  if (!ok)
    throw AssetError(fmt::format("{}: not a valid glTF 2.0 {} file: {}", path.string(),
                                 binary ? "binary (.glb)" : "JSON", tinygltf_message(error)));
  if (!warning.empty()) log::debug("{}: tinygltf: {}", path.string(), tinygltf_message(warning));
  return model;
}

// Every failure an AssetError naming the file: the limits above keep allocations small, and this is
// the last line for what they do not foresee.
template <class F>
auto as_asset_errors(const std::filesystem::path& path, F load) {
  try {
    return load();
  } catch (const AssetError&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw AssetError(fmt::format("{}: out of memory while loading the glTF file", path.string()));
  } catch (const std::exception& e) {
    throw AssetError(fmt::format("{}: cannot load the glTF file: {}", path.string(), e.what()));
  }
}

}  // namespace

Mesh load_gltf_mesh(const std::filesystem::path& path) {
  return as_asset_errors(path, [&] {
    const tinygltf::Model model = load_checked_gltf_model(path);
    GltfMeshCollector collector(model, path);
    collector.add_roots(root_nodes(model));
    return collector.finish();
  });
}

std::vector<GltfLight> load_gltf_lights(const std::filesystem::path& path) {
  return as_asset_errors(path, [&] {
    const tinygltf::Model model = load_checked_gltf_model(path);
    GltfMeshCollector collector(model, path, false);
    collector.add_roots(root_nodes(model));
    return collector.take_lights();
  });
}

}  // namespace arpipe
