// Internal to core/scene (gltf_loader.cpp, gltf_animation.cpp): a glTF file as tinygltf parses it
// after gltf_document.cpp's checks, and the loader's rules on it written once: the scene's nodes
// as a strict tree within kMaxGltfNodeDepth, walked without recursion; a node's rest transform;
// overflow-checked accessor spans; a light placed by its node; glTF's y-up axes turned to z-up.
// Defined in gltf_loader.cpp, the one unit that compiles tinygltf.
#pragma once

// tinygltf's declarations with the macros gltf_loader.cpp compiles its implementation with, so that
// they read alike in every unit. In a unity batch after gltf_loader.cpp they are already in (and
// gltf_loader.cpp undefines TINYGLTF_IMPLEMENTATION after it, so none compiles it twice).
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>

#include <fmt/format.h>

#include <cstddef>
#include <filesystem>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <new>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "core/scene/asset_error.h"
#include "core/scene/gltf_limits.h"
#include "core/scene/gltf_loader.h"

namespace arpipe::gltf {

// AssetError "<file>: <what>".
[[noreturn]] void fail(const std::filesystem::path& path, const std::string& what);

// Reads and checks the file (gltf_document.h) and parses it; buffers are read through the same
// checks (inside the file's folder, within kMaxGltfBufferBytes).
tinygltf::Model load_checked_model(const std::filesystem::path& path);

// Every failure an AssetError naming the file: the limits keep allocations small, and this is the
// last line for what they do not foresee.
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

// glTF's y-up axes to arpipe's z-up object frame (C): +y (up) becomes +z, +z (the model's front) -y.
inline glm::dvec3 to_object_frame(const glm::dvec3& v) { return glm::dvec3(v.x, -v.z, v.y); }

// The scene's root nodes: the default scene's, else the first scene's, else every node that is
// nobody's child.
std::vector<int> scene_roots(const tinygltf::Model& model);

// The node hierarchy under `roots`, depth-first with an explicit stack (no recursion over the
// file's graph), each node after its parent and before its siblings' subtrees. glTF nodes form
// strict trees: a node reached a second time (two parents, a cycle, a scene root that is also a
// child) is an error, so every node is visited at most once; so is a node past kMaxGltfNodeDepth or
// an index that names no node. visit(node, value) gets the value its parent returned (`root_value`
// for a root) and returns its children's, or nullopt to leave its subtree out (then not walked).
template <class T, class Visit>
void walk_nodes(const tinygltf::Model& model, const std::filesystem::path& path, const std::vector<int>& roots,
                const T& root_value, Visit&& visit) {
  struct Pending {
    int node;
    T parent_value;
    size_t depth;
  };
  std::vector<bool> reached(model.nodes.size(), false);
  std::vector<Pending> stack;
  for (auto root = roots.rbegin(); root != roots.rend(); ++root) stack.push_back({*root, root_value, 1});
  while (!stack.empty()) {
    const Pending pending = std::move(stack.back());
    stack.pop_back();
    const int node = pending.node;
    if (node < 0 || static_cast<size_t>(node) >= model.nodes.size())
      fail(path, fmt::format("node {} does not exist ({} nodes)", node, model.nodes.size()));
    if (reached[static_cast<size_t>(node)])
      fail(path, fmt::format("node {} is reached more than once: it has more than one parent, is its own ancestor or "
                             "is both a scene root and a child (glTF nodes form strict trees)",
                             node));
    reached[static_cast<size_t>(node)] = true;
    if (pending.depth > kMaxGltfNodeDepth)
      fail(path, fmt::format("node {} is {} levels deep in the node hierarchy, over the depth limit of {}", node,
                             pending.depth, kMaxGltfNodeDepth));
    std::optional<T> value = visit(node, pending.parent_value);
    if (!value) continue;
    const std::vector<int>& children = model.nodes[static_cast<size_t>(node)].children;
    for (auto child = children.rbegin(); child != children.rend(); ++child)
      stack.push_back({*child, *value, pending.depth + 1});
  }
}

// The scene's nodes (the walk above from scene_roots): their order and their parents.
struct NodeTree {
  std::vector<int> order;   // parents before children, as the loader places them
  std::vector<int> parent;  // per node of the file: its parent, -1 for a root
  std::vector<bool> in_scene;
};
NodeTree scene_node_tree(const tinygltf::Model& model, const std::filesystem::path& path);

// The scene's node named `name`; nullopt when none is. AssetError when two are.
std::optional<int> find_named_node(const tinygltf::Model& model, const NodeTree& tree,
                                   const std::filesystem::path& path, std::string_view name);

// Per node of the file: whether a translation, rotation or scale channel of any animation targets it.
std::vector<bool> animated_nodes(const tinygltf::Model& model);

// "node 3" or "node 3 (\"name\")", for messages.
std::string node_label(const tinygltf::Model& model, int node);

// A node's local transform from translation, rotation (x, y, z, w; normalised unless of zero
// length, as glTF asks for unit quaternions) and scale, in glTF's order T * R * S.
glm::dmat4 trs_transform(const glm::dvec3& translation, const glm::dquat& rotation, const glm::dvec3& scale);
// Its TRS at rest (glTF's defaults where absent); AssetError when a value is not finite.
struct NodeTrs {
  glm::dvec3 translation{0.0};
  glm::dquat rotation{1.0, 0.0, 0.0, 0.0};  // glm: w first
  glm::dvec3 scale{1.0};
};
NodeTrs rest_trs(const tinygltf::Model& model, const std::filesystem::path& path, int node);
// The rest transform: its matrix, else its TRS. AssetError when a value is not finite.
glm::dmat4 rest_transform(const tinygltf::Model& model, const std::filesystem::path& path, int node);

// The node's KHR_lights_punctual light placed by the node's global transform (glTF axes): at its
// origin, shining along its -z, in the z-up frame. nullopt when the node has none.
std::optional<GltfLight> placed_light(const tinygltf::Model& model, const std::filesystem::path& path, int node,
                                      const glm::dmat4& global);

// An accessor's elements: where the first starts, the byte step to the next, how many.
struct AccessorSpan {
  const unsigned char* data;
  size_t stride;
  size_t count;
};

// The model's accessors read with every offset and size checked first (overflow-checked), each
// error naming the file, `where` (the caller's place: "mesh 0 primitive 1 POSITION") and the accessor.
class AccessorReader {
 public:
  AccessorReader(const tinygltf::Model& model, const std::filesystem::path& path) : model_(model), path_(path) {}

  // The accessor, not sparse.
  const tinygltf::Accessor& accessor(int index, const std::string& where) const;
  // Checks that every element lies inside the accessor's buffer view and the view inside its
  // buffer, and that the count is within `max_count` (`limit_name` names it in the message): all
  // before any element is read or any memory is allocated for them.
  AccessorSpan span(const tinygltf::Accessor& accessor, int index, const std::string& where, size_t element_size,
                    size_t max_count, const char* limit_name) const;
  // Its elements' `components` components as floats: FLOAT as stored, and the normalised integer
  // types (BYTE, UNSIGNED_BYTE, SHORT, UNSIGNED_SHORT) as glTF maps them to [-1, 1] or [0, 1].
  // AssetError for another component type, or a float that is not finite.
  std::vector<float> read_floats(const AccessorSpan& span, const tinygltf::Accessor& accessor, int index,
                                 const std::string& where, size_t components) const;
  // The size of one component of that type; 0 for a type read_floats does not read.
  static size_t component_bytes(int component_type);

  [[noreturn]] void fail(const std::string& what) const { gltf::fail(path_, what); }

 private:
  const tinygltf::Model& model_;
  const std::filesystem::path& path_;
};

}  // namespace arpipe::gltf
