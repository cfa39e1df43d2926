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
// Compiled once: a unity batch's later files (gltf_model.h among them) see only the declarations.
#undef TINYGLTF_IMPLEMENTATION

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
#include "core/scene/gltf_animation.h"
#include "core/scene/gltf_document.h"
#include "core/scene/gltf_limits.h"
#include "core/scene/gltf_model.h"

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

class GltfMeshCollector {
 public:
  // read_meshes false: only the lights are collected (load_gltf_lights).
  GltfMeshCollector(const tinygltf::Model& model, const std::filesystem::path& path, bool read_meshes = true)
      : model_(model), path_(path), read_meshes_(read_meshes) {}

  std::vector<GltfLight> take_lights() { return std::move(lights_); }

  // The meshes (and lights) of the nodes under `roots` (gltf::walk_nodes: a strict tree within
  // the depth limit). skip: per node, leave its subtree out. frame_node: a node whose own global
  // transform is left out (its subtree in its own frame).
  void add_roots(const std::vector<int>& roots, const std::vector<bool>* skip = nullptr, int frame_node = -1) {
    gltf::walk_nodes(model_, path_, roots, glm::dmat4(1.0),
                     [&](int node_index, const glm::dmat4& parent) -> std::optional<glm::dmat4> {
                       if (skip != nullptr && (*skip)[static_cast<size_t>(node_index)]) return std::nullopt;
                       const tinygltf::Node& node = model_.nodes[static_cast<size_t>(node_index)];
                       const glm::dmat4 local = gltf::rest_transform(model_, path_, node_index);  // checked even when left out
                       const glm::dmat4 transform = node_index == frame_node ? glm::dmat4(1.0) : parent * local;
                       if (!all_finite(transform))
                         fail(fmt::format("node {}: its transform combined with its parents' is not finite (overflow)",
                                          node_index));
                       if (node.mesh >= 0 && read_meshes_) add_mesh(node_index, node.mesh, transform);
                       if (std::optional<GltfLight> light = gltf::placed_light(model_, path_, node_index, transform))
                         lights_.push_back(std::move(*light));
                       return transform;
                     });
  }

  // `taken`: what of the file was loaded, for the message when it holds no triangles.
  Mesh finish(const std::string& taken = "the scene") {
    if (mesh_.indices.empty())
      fail(fmt::format("contains no triangles (no mesh with a TRIANGLES, TRIANGLE_STRIP or TRIANGLE_FAN primitive in {})",
                       taken));
    if (skipped_primitives_ > 0)
      log::warn("{}: skipped {} primitive(s) that are points or lines", path_.string(), skipped_primitives_);
    if (skipped_singular_ > 0)
      log::warn("{}: skipped {} mesh instance(s) under a singular node transform (a zero scale)", path_.string(),
                skipped_singular_);
    mesh_.source = path_.string();
    return std::move(mesh_);
  }

 private:
  [[noreturn]] void fail(const std::string& what) const { gltf::fail(path_, what); }

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

  using Span = gltf::AccessorSpan;

  Span vec3_span(int accessor_index, const std::string& where) const {
    const tinygltf::Accessor& accessor = reader_.accessor(accessor_index, where);
    if (accessor.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT || accessor.type != TINYGLTF_TYPE_VEC3)
      fail(fmt::format("{}: accessor {} must be VEC3 of FLOAT", where, accessor_index));
    return reader_.span(accessor, accessor_index, where, 12, kMaxGltfVertices, "vertices");
  }

  // The span's VEC3 FLOAT elements, each finite.
  std::vector<glm::dvec3> read_vec3(const Span& span, int accessor_index, const std::string& where) const {
    const tinygltf::Accessor& accessor = reader_.accessor(accessor_index, where);
    const std::vector<float> xyz = reader_.read_floats(span, accessor, accessor_index, where, 3);
    std::vector<glm::dvec3> values(span.count);
    for (size_t i = 0; i < span.count; ++i) values[i] = glm::dvec3(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
    return values;
  }

  std::pair<Span, size_t> index_span(int accessor_index, const std::string& where) const {
    const tinygltf::Accessor& accessor = reader_.accessor(accessor_index, where);
    size_t size = 0;
    switch (accessor.componentType) {
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: size = 1; break;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: size = 2; break;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: size = 4; break;
      default: fail(fmt::format("{}: index accessor {} must be UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT", where, accessor_index));
    }
    if (accessor.type != TINYGLTF_TYPE_SCALAR) fail(fmt::format("{}: index accessor {} must be SCALAR", where, accessor_index));
    // A strip or fan of n indices makes n - 2 triangles.
    return {reader_.span(accessor, accessor_index, where, size, 3 * kMaxGltfTriangles + 2, "indices"), size};
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
      const glm::dvec3 placed = gltf::to_object_frame(glm::dvec3(transform * glm::dvec4(position, 1.0)));
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
        push(mesh_.normals, gltf::to_object_frame(n));
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
  gltf::AccessorReader reader_{model_, path_};
  Mesh mesh_;
  bool read_meshes_ = true;
  std::vector<GltfLight> lights_;
  int skipped_primitives_ = 0;
  int skipped_singular_ = 0;
  uint64_t elements_read_ = 0;
};

}  // namespace

namespace gltf {

void fail(const std::filesystem::path& path, const std::string& what) {
  throw AssetError(fmt::format("{}: {}", path.string(), what));
}

std::vector<int> scene_roots(const tinygltf::Model& model) {
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

tinygltf::Model load_checked_model(const std::filesystem::path& path) {
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

NodeTree scene_node_tree(const tinygltf::Model& model, const std::filesystem::path& path) {
  NodeTree tree{{}, std::vector<int>(model.nodes.size(), -1), std::vector<bool>(model.nodes.size(), false)};
  walk_nodes(model, path, scene_roots(model), -1, [&](int node, int parent) -> std::optional<int> {
    tree.order.push_back(node);
    tree.parent[static_cast<size_t>(node)] = parent;
    tree.in_scene[static_cast<size_t>(node)] = true;
    return node;
  });
  return tree;
}

std::optional<int> find_named_node(const tinygltf::Model& model, const NodeTree& tree,
                                   const std::filesystem::path& path, std::string_view name) {
  std::optional<int> found;
  for (int node : tree.order) {
    if (model.nodes[static_cast<size_t>(node)].name != name) continue;
    if (found)
      fail(path, fmt::format("nodes {} and {} are both named \"{}\" (a node must be named once to be chosen)", *found,
                             node, name));
    found = node;
  }
  return found;
}

std::vector<bool> animated_nodes(const tinygltf::Model& model) {
  std::vector<bool> animated(model.nodes.size(), false);
  for (const tinygltf::Animation& animation : model.animations)
    for (const tinygltf::AnimationChannel& channel : animation.channels)
      if (channel.target_path != "weights" && channel.target_node >= 0 &&
          static_cast<size_t>(channel.target_node) < animated.size())
        animated[static_cast<size_t>(channel.target_node)] = true;
  return animated;
}

std::string node_label(const tinygltf::Model& model, int node) {
  const std::string& name = model.nodes[static_cast<size_t>(node)].name;
  if (name.empty()) return fmt::format("node {}", node);
  return fmt::format("node {} (\"{}\")", node, name.size() > 100 ? name.substr(0, 100) + "..." : name);
}

glm::dmat4 trs_transform(const glm::dvec3& translation, const glm::dquat& rotation, const glm::dvec3& scale) {
  const double length = glm::length(rotation);
  const glm::dquat unit = length > 0 && std::isfinite(length) ? rotation / length : rotation;
  return glm::scale(glm::translate(glm::dmat4(1.0), translation) * glm::mat4_cast(unit), scale);
}

NodeTrs rest_trs(const tinygltf::Model& model, const std::filesystem::path& path, int node_index) {
  const tinygltf::Node& node = model.nodes[static_cast<size_t>(node_index)];
  for (const auto* values : {&node.matrix, &node.translation, &node.rotation, &node.scale})
    if (!all_finite(*values)) fail(path, fmt::format("node {}: its matrix or TRS has a value that is not finite", node_index));
  NodeTrs trs;
  if (node.translation.size() == 3) trs.translation = {node.translation[0], node.translation[1], node.translation[2]};
  // glTF quaternions are x, y, z, w; glm's constructor takes w first.
  if (node.rotation.size() == 4) trs.rotation = {node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]};
  if (node.scale.size() == 3) trs.scale = {node.scale[0], node.scale[1], node.scale[2]};
  return trs;
}

glm::dmat4 rest_transform(const tinygltf::Model& model, const std::filesystem::path& path, int node_index) {
  const NodeTrs trs = rest_trs(model, path, node_index);
  const tinygltf::Node& node = model.nodes[static_cast<size_t>(node_index)];
  if (node.matrix.size() == 16) return glm::make_mat4(node.matrix.data());  // column-major, as glTF stores it
  return trs_transform(trs.translation, trs.rotation, trs.scale);
}

std::optional<GltfLight> placed_light(const tinygltf::Model& model, const std::filesystem::path& path, int node_index,
                                      const glm::dmat4& global) {
  const tinygltf::Node& node = model.nodes[static_cast<size_t>(node_index)];
  const auto extension = node.extensions.find("KHR_lights_punctual");
  if (extension == node.extensions.end() || !extension->second.Has("light")) return std::nullopt;
  const int index = extension->second.Get("light").GetNumberAsInt();
  if (index < 0 || static_cast<size_t>(index) >= model.lights.size())
    fail(path, fmt::format("node {} names light {}, which does not exist", node_index, index));
  const tinygltf::Light& light = model.lights[static_cast<size_t>(index)];
  const glm::dvec3 position = to_object_frame(glm::dvec3(global * glm::dvec4(0, 0, 0, 1)));
  glm::dvec3 direction = to_object_frame(glm::dmat3(global) * glm::dvec3(0, 0, -1));
  const double length = glm::length(direction);
  if (!(length > 1e-100) || !std::isfinite(length) || !std::isfinite(position.x + position.y + position.z))
    fail(path, fmt::format("node {}: light {} has no direction or position (a zero or infinite scale)", node_index, index));
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
  return out;
}

const tinygltf::Accessor& AccessorReader::accessor(int index, const std::string& where) const {
  if (index < 0 || static_cast<size_t>(index) >= model_.accessors.size())
    fail(fmt::format("{}: accessor {} does not exist ({} accessors)", where, index, model_.accessors.size()));
  const tinygltf::Accessor& accessor = model_.accessors[static_cast<size_t>(index)];
  if (accessor.sparse.isSparse) fail(fmt::format("{}: accessor {} is sparse, which is not supported", where, index));
  return accessor;
}

AccessorSpan AccessorReader::span(const tinygltf::Accessor& accessor, int accessor_index, const std::string& where,
                                  size_t element_size, size_t max_count, const char* limit_name) const {
  if (accessor.bufferView < 0 || static_cast<size_t>(accessor.bufferView) >= model_.bufferViews.size())
    fail(fmt::format("{}: accessor {} has no valid bufferView ({})", where, accessor_index, accessor.bufferView));
  const tinygltf::BufferView& view = model_.bufferViews[static_cast<size_t>(accessor.bufferView)];
  if (view.buffer < 0 || static_cast<size_t>(view.buffer) >= model_.buffers.size())
    fail(fmt::format("{}: bufferView {} names buffer {}, which does not exist", where, accessor.bufferView, view.buffer));
  const tinygltf::Buffer& buffer = model_.buffers[static_cast<size_t>(view.buffer)];
  size_t view_end = 0;
  if (__builtin_add_overflow(view.byteOffset, view.byteLength, &view_end) || view_end > buffer.data.size())
    fail(fmt::format("{}: bufferView {} (byteOffset {}, byteLength {}) runs past the end of buffer {} ({} bytes)", where,
                     accessor.bufferView, view.byteOffset, view.byteLength, view.buffer, buffer.data.size()));
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
    fail(fmt::format("{}: accessor {} has {} elements, over the limit of {} {}", where, accessor_index, accessor.count,
                     max_count, limit_name));
  return {buffer.data.data() + view.byteOffset + accessor.byteOffset, static_cast<size_t>(stride), accessor.count};
}

size_t AccessorReader::component_bytes(int component_type) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    default: return 0;
  }
}

// One component at `at` as glTF reads it: a float as stored, a normalised integer mapped to
// [-1, 1] (signed, the most negative value clamped to -1) or [0, 1].
static float normalised_component(const unsigned char* at, int component_type) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
      float value;
      std::memcpy(&value, at, 4);
      return value;
    }
    case TINYGLTF_COMPONENT_TYPE_BYTE: return std::max(float(static_cast<int8_t>(at[0])) / 127.0f, -1.0f);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return float(at[0]) / 255.0f;
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      int16_t value;
      std::memcpy(&value, at, 2);
      return std::max(float(value) / 32767.0f, -1.0f);
    }
    default: {  // UNSIGNED_SHORT (component_bytes said which are read)
      uint16_t value;
      std::memcpy(&value, at, 2);
      return float(value) / 65535.0f;
    }
  }
}

std::vector<float> AccessorReader::read_floats(const AccessorSpan& span, const tinygltf::Accessor& accessor, int index,
                                               const std::string& where, size_t components) const {
  const size_t bytes = component_bytes(accessor.componentType);
  if (bytes == 0) fail(fmt::format("{}: accessor {} has component type {}, not one read here", where, index, accessor.componentType));
  std::vector<float> values(span.count * components);
  for (size_t i = 0; i < span.count; ++i) {
    for (size_t c = 0; c < components; ++c)
      values[i * components + c] = normalised_component(span.data + i * span.stride + c * bytes, accessor.componentType);
    for (size_t c = 0; c < components; ++c)
      if (!std::isfinite(values[i * components + c]))
        fail(fmt::format("{}: accessor {} element {} is not finite ({})", where, index, i,
                         fmt::join(values.begin() + std::ptrdiff_t(i * components),
                                   values.begin() + std::ptrdiff_t((i + 1) * components), ", ")));
  }
  return values;
}

}  // namespace gltf

namespace {

// What load_gltf_mesh takes of the file, for the message when that holds no triangles.
std::string selection_label(const tinygltf::Model& model, const GltfMeshSelection& selection, int node) {
  std::string taken = node >= 0 ? fmt::format("the subtree of {}", gltf::node_label(model, node)) : "the scene";
  if (selection.skip_animated) taken += " without the nodes its animations move";
  return taken;
}

}  // namespace

Mesh load_gltf_mesh(const std::filesystem::path& path) { return load_gltf_mesh(path, GltfMeshSelection{}); }

Mesh load_gltf_mesh(const std::filesystem::path& path, const GltfMeshSelection& selection) {
  return gltf::as_asset_errors(path, [&] {
    const tinygltf::Model model = gltf::load_checked_model(path);
    std::vector<int> roots = gltf::scene_roots(model);
    int frame_node = -1;
    if (!selection.node.empty()) {
      // The whole scene's tree is checked first, as without a selection.
      const std::optional<int> node = gltf::find_named_node(model, gltf::scene_node_tree(model, path), path, selection.node);
      if (!node) gltf::fail(path, fmt::format("no node of the scene is named \"{}\"", selection.node));
      frame_node = *node;
      roots = {*node};
    } else if (selection.skip_animated) {
      gltf::scene_node_tree(model, path);  // the nodes left out are checked too
    }
    std::vector<bool> animated;
    if (selection.skip_animated) animated = gltf::animated_nodes(model);
    GltfMeshCollector collector(model, path);
    collector.add_roots(roots, selection.skip_animated ? &animated : nullptr, frame_node);
    return collector.finish(selection_label(model, selection, frame_node));
  });
}

std::vector<GltfLight> load_gltf_lights(const std::filesystem::path& path) {
  return gltf::as_asset_errors(path, [&] {
    const tinygltf::Model model = gltf::load_checked_model(path);
    GltfMeshCollector collector(model, path, false);
    collector.add_roots(gltf::scene_roots(model));
    return collector.take_lights();
  });
}

}  // namespace arpipe
