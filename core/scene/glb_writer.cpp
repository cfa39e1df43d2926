// A Mesh as a binary glTF 2.0 file (.glb) in memory: what `arpipe proxy simplify` writes, and what
// load_gltf_mesh (gltf_loader.h) reads back to the same triangles, positions and colours.
#include "core/scene/glb_writer.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

namespace arpipe {
namespace {

static_assert(std::endian::native == std::endian::little, "the .glb's binary chunk is written as the host stores it");

constexpr uint32_t kGlbWriterMagic = 0x46546C67;      // "glTF"
constexpr uint32_t kGlbWriterJsonChunk = 0x4E4F534A;  // "JSON"
constexpr uint32_t kGlbWriterBinChunk = 0x004E4942;   // "BIN\0"
constexpr int kGlbWriterFloat = 5126, kGlbWriterUnsignedInt = 5125;
constexpr int kGlbWriterArrayBuffer = 34962, kGlbWriterElementArrayBuffer = 34963;

// The BIN chunk as it grows, and the bufferViews and accessors that describe it.
class GlbBinaryBuilder {
 public:
  // A tightly packed bufferView of `bytes`, 4-byte aligned; its index. target 0: none (animation data).
  size_t add_view(const void* bytes, size_t size, int target) {
    const size_t offset = bin_.size();
    bin_.resize(offset + size);
    if (size > 0) std::memcpy(bin_.data() + offset, bytes, size);
    bin_.resize((bin_.size() + 3) / 4 * 4, 0);
    views_.push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", size}});
    if (target != 0) views_.back()["target"] = target;
    return views_.size() - 1;
  }
  // Animation data: floats, `type` ("SCALAR", "VEC3", "VEC4") of `components` each.
  size_t add_float_accessor(const std::vector<float>& values, const char* type, size_t components) {
    return add_accessor({{"bufferView", add_view(values.data(), values.size() * sizeof(float), 0)},
                         {"componentType", kGlbWriterFloat},
                         {"count", values.size() / components},
                         {"type", type}});
  }
  size_t add_accessor(nlohmann::json accessor) {
    accessors_.push_back(std::move(accessor));
    return accessors_.size() - 1;
  }
  // float3 per vertex in glTF's axes; POSITION accessors carry min and max (the spec asks for them).
  size_t add_vec3_accessor(const std::vector<float>& xyz, bool with_bounds) {
    const size_t count = xyz.size() / 3;
    nlohmann::json accessor = {{"bufferView", add_view(xyz.data(), xyz.size() * sizeof(float), kGlbWriterArrayBuffer)},
                               {"componentType", kGlbWriterFloat},
                               {"count", count},
                               {"type", "VEC3"}};
    if (with_bounds) {
      std::array<float, 3> low{}, high{};
      for (size_t axis = 0; axis < 3; ++axis) {
        low[axis] = high[axis] = xyz[axis];
        for (size_t i = axis; i < xyz.size(); i += 3) {
          low[axis] = std::min(low[axis], xyz[i]);
          high[axis] = std::max(high[axis], xyz[i]);
        }
      }
      accessor["min"] = low;
      accessor["max"] = high;
    }
    return add_accessor(std::move(accessor));
  }
  const std::vector<uint8_t>& bin() const { return bin_; }
  nlohmann::json& views() { return views_; }
  nlohmann::json& accessors() { return accessors_; }

 private:
  std::vector<uint8_t> bin_;
  nlohmann::json views_ = nlohmann::json::array();
  nlohmann::json accessors_ = nlohmann::json::array();
};

// `label`: how messages name the mesh ("": by its source).
void check_glb_encodable(const Mesh& mesh, const std::string& label = "") {
  const std::string name = !label.empty() ? label : mesh.source.empty() ? std::string("the mesh") : mesh.source;
  auto fail = [&](const std::string& what) { throw std::invalid_argument(fmt::format("{}: {}", name, what)); };
  if (mesh.positions.size() % 3 != 0 || mesh.indices.size() % 3 != 0 || mesh.indices.empty())
    fail(fmt::format("not a triangle mesh ({} position floats, {} indices)", mesh.positions.size(), mesh.indices.size()));
  if (!mesh.normals.empty() && mesh.normals.size() != mesh.positions.size())
    fail(fmt::format("{} normal floats for {} position floats", mesh.normals.size(), mesh.positions.size()));
  for (const std::vector<float>* values : {&mesh.positions, &mesh.normals})
    for (size_t i = 0; i < values->size(); ++i)
      if (!std::isfinite((*values)[i]))
        fail(fmt::format("vertex {} has a {} that is not finite", i / 3, values == &mesh.positions ? "position" : "normal"));
  for (size_t i = 0; i < mesh.indices.size(); ++i)
    if (mesh.indices[i] >= mesh.vertex_count())
      fail(fmt::format("index {} is {}, past the last vertex ({} vertices)", i, mesh.indices[i], mesh.vertex_count()));
  for (size_t p = 0; p < mesh.parts.size(); ++p)
    if (mesh.parts[p].first_index % 3 != 0 || mesh.parts[p].index_count % 3 != 0 ||
        uint64_t{mesh.parts[p].first_index} + mesh.parts[p].index_count > mesh.indices.size())
      fail(fmt::format("part {} is not whole triangles of the {} indices", p, mesh.indices.size()));
  for (const MeshPart& part : mesh.parts)
    for (float c : part.base_color)
      if (!std::isfinite(c)) fail("a part's base colour is not finite");
}

void append_glb_u32(std::vector<uint8_t>& out, uint32_t value) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<uint8_t>(value >> (8 * i)));
}

}  // namespace

namespace {

// The rotation (glTF's x, y, z, w) that turns a node's -z onto the unit vector d (glTF axes).
std::array<double, 4> rotation_onto(const Vec3& d) {
  const Vec3 a{0, 0, -1};
  const double c = dot(a, d);
  if (c < -1 + 1e-12) return {1, 0, 0, 0};  // opposite: half a turn about x
  const Vec3 axis = cross(a, d);
  const double w = 1 + c, length = std::sqrt(dot(axis, axis) + w * w);
  return {axis[0] / length, axis[1] / length, axis[2] / length, w / length};
}

}  // namespace

namespace {

// The materials of a file's meshes, one per distinct base colour.
struct GlbMaterials {
  nlohmann::json materials = nlohmann::json::array();
  std::vector<std::array<float, 4>> colours;

  size_t index_of(const std::array<float, 4>& colour) {
    const auto found = std::find(colours.begin(), colours.end(), colour);
    if (found != colours.end()) return size_t(found - colours.begin());
    colours.push_back(colour);
    materials.push_back({{"name", fmt::format("colour {}", colours.size() - 1)},
                         {"pbrMetallicRoughness", {{"baseColorFactor", colour}, {"metallicFactor", 0.0}, {"roughnessFactor", 1.0}}}});
    return colours.size() - 1;
  }
};

// The mesh as a glTF mesh: a primitive per part, each with the part's own vertices in glTF's axes.
nlohmann::json glb_mesh(const Mesh& mesh, GlbBinaryBuilder& builder, GlbMaterials& materials) {
  std::vector<MeshPart> parts = mesh.parts;
  if (parts.empty()) parts.push_back(MeshPart{0, static_cast<uint32_t>(mesh.indices.size()), {1, 1, 1, 1}});
  nlohmann::json primitives = nlohmann::json::array();
  std::vector<uint32_t> local(mesh.vertex_count());
  std::vector<bool> seen(mesh.vertex_count());
  for (const MeshPart& part : parts) {
    if (part.index_count == 0) continue;
    // The part's own vertices, in the order its triangles first use them, in glTF's axes.
    std::fill(seen.begin(), seen.end(), false);
    std::vector<float> positions, normals;
    std::vector<uint32_t> indices;
    indices.reserve(part.index_count);
    for (uint32_t i = part.first_index; i < part.first_index + part.index_count; ++i) {
      const uint32_t v = mesh.indices[i];
      if (!seen[v]) {
        seen[v] = true;
        local[v] = static_cast<uint32_t>(positions.size() / 3);
        const float* p = &mesh.positions[3 * size_t{v}];
        positions.insert(positions.end(), {p[0], p[2], -p[1]});
        if (!mesh.normals.empty()) {
          const float* n = &mesh.normals[3 * size_t{v}];
          normals.insert(normals.end(), {n[0], n[2], -n[1]});
        }
      }
      indices.push_back(local[v]);
    }
    nlohmann::json attributes = {{"POSITION", builder.add_vec3_accessor(positions, true)}};
    if (!normals.empty()) attributes["NORMAL"] = builder.add_vec3_accessor(normals, false);
    const size_t index_view =
        builder.add_view(indices.data(), indices.size() * sizeof(uint32_t), kGlbWriterElementArrayBuffer);
    const size_t index_accessor = builder.add_accessor(
        {{"bufferView", index_view}, {"componentType", kGlbWriterUnsignedInt}, {"count", indices.size()}, {"type", "SCALAR"}});
    primitives.push_back({{"attributes", std::move(attributes)},
                          {"indices", index_accessor},
                          {"material", materials.index_of(part.base_color)},
                          {"mode", 4}});
  }
  return {{"primitives", std::move(primitives)}};
}

void check_animated_nodes(const std::vector<GlbAnimatedNode>& animated) {
  for (size_t n = 0; n < animated.size(); ++n) {
    const GlbAnimatedNode& node = animated[n];
    const auto fail = [&](const std::string& what) {
      throw std::invalid_argument(fmt::format("animated node {} (\"{}\"): {}", n, node.name, what));
    };
    if (node.name.empty()) fail("no name");
    for (size_t other = 0; other < n; ++other)
      if (animated[other].name == node.name) fail(fmt::format("the name of animated node {} too", other));
    check_glb_encodable(node.mesh, fmt::format("animated node \"{}\"'s mesh", node.name));
    if (node.keys.empty()) fail("no keys");
    for (size_t k = 0; k < node.keys.size(); ++k) {
      const GlbAnimatedNode::Key& key = node.keys[k];
      if (!std::isfinite(key.t_s) || key.t_s < 0) fail(fmt::format("key {} at {} s (times are finite and >= 0)", k, key.t_s));
      // Stored as floats: two keys one float apart would be one time.
      if (k > 0 && !(float(key.t_s) > float(node.keys[k - 1].t_s)))
        fail(fmt::format("key {} at {} s is not after key {} at {} s (as floats)", k, key.t_s, k - 1, node.keys[k - 1].t_s));
      const Vec3& t = key.T_world_node.translation();
      if (!std::isfinite(t[0] + t[1] + t[2] + norm(key.T_world_node.rotation_vector())))
        fail(fmt::format("key {} has a pose that is not finite", k));
    }
  }
}

// A pose's rotation as glTF's unit quaternion (x, y, z, w) in glTF's axes: the rotation C^-1 R C has
// the quaternion of R with its axis turned, (w, C^-1 v), and glTF (x, y, z) = object (x, z, -y).
std::array<double, 4> glb_rotation(const SE3& pose) {
  const Vec3 r = pose.rotation_vector();
  const double angle = norm(r);
  const double k = angle > 1e-12 ? std::sin(angle / 2) / angle : 0.5;
  return {k * r[0], k * r[2], -k * r[1], std::cos(angle / 2)};
}

// Each animated node's keys as a LINEAR translation and a LINEAR rotation channel, the quaternions
// on one hemisphere (each flipped when it disagrees in sign with the one before), so that glTF's
// slerp takes the short way; the node's rest TRS is its first key. `nodes[i]`: node i's index.
nlohmann::json glb_animation(const std::vector<GlbAnimatedNode>& animated, const std::vector<size_t>& nodes,
                             std::string_view name, GlbBinaryBuilder& builder, nlohmann::json& gltf_nodes) {
  nlohmann::json channels = nlohmann::json::array(), samplers = nlohmann::json::array();
  for (size_t n = 0; n < animated.size(); ++n) {
    std::vector<float> times, translations, rotations;
    std::array<double, 4> previous{0, 0, 0, 1};
    for (size_t k = 0; k < animated[n].keys.size(); ++k) {
      const GlbAnimatedNode::Key& key = animated[n].keys[k];
      times.push_back(float(key.t_s));
      const Vec3& t = key.T_world_node.translation();
      translations.insert(translations.end(), {float(t[0]), float(t[2]), float(-t[1])});
      std::array<double, 4> q = glb_rotation(key.T_world_node);
      if (k > 0 && q[0] * previous[0] + q[1] * previous[1] + q[2] * previous[2] + q[3] * previous[3] < 0)
        for (double& c : q) c = -c;
      previous = q;
      rotations.insert(rotations.end(), {float(q[0]), float(q[1]), float(q[2]), float(q[3])});
    }
    const size_t input = builder.add_float_accessor(times, "SCALAR", 1);
    builder.accessors()[input]["min"] = {times.front()};  // glTF asks for an input's bounds
    builder.accessors()[input]["max"] = {times.back()};
    nlohmann::json& node = gltf_nodes[nodes[n]];
    node["translation"] = {translations[0], translations[1], translations[2]};
    node["rotation"] = {rotations[0], rotations[1], rotations[2], rotations[3]};
    for (const auto& [path, values] : {std::pair{"translation", &translations}, std::pair{"rotation", &rotations}}) {
      const bool rotation = std::string_view(path) == "rotation";
      channels.push_back({{"sampler", samplers.size()}, {"target", {{"node", nodes[n]}, {"path", path}}}});
      samplers.push_back({{"input", input},
                          {"interpolation", "LINEAR"},
                          {"output", builder.add_float_accessor(*values, rotation ? "VEC4" : "VEC3", rotation ? 4 : 3)}});
    }
  }
  return {{"name", std::string(name)}, {"channels", std::move(channels)}, {"samplers", std::move(samplers)}};
}

// The lights as KHR_lights_punctual, each on a node of its own appended to `nodes` and `scene_nodes`.
nlohmann::json glb_lights(const std::vector<GltfLight>& lights, nlohmann::json& nodes, nlohmann::json& scene_nodes) {
  using nlohmann::json;
  json defined = json::array();
  for (const GltfLight& light : lights) {
    if (light.type != "directional" && light.type != "point")
      throw std::invalid_argument(fmt::format("light \"{}\": a {} light, not directional or point", light.name, light.type));
    json entry = {{"type", light.type}, {"color", {light.color[0], light.color[1], light.color[2]}}, {"intensity", light.intensity}};
    if (!light.name.empty()) entry["name"] = light.name;
    if (light.range > 0) entry["range"] = light.range;
    defined.push_back(std::move(entry));
    // Object (x, y, z) is glTF (x, z, -y).
    const Vec3 d = normalized(light.direction);
    const std::array<double, 4> q = rotation_onto({d[0], d[2], -d[1]});
    json light_node = {{"rotation", {q[0], q[1], q[2], q[3]}},
                       {"extensions", {{"KHR_lights_punctual", {{"light", defined.size() - 1}}}}}};
    if (light.type == "point") light_node["translation"] = {light.position[0], light.position[2], -light.position[1]};
    if (!light.name.empty()) light_node["name"] = light.name;
    scene_nodes.push_back(nodes.size());
    nodes.push_back(std::move(light_node));
  }
  return defined;
}

std::vector<uint8_t> glb_container(const std::string& json, const std::vector<uint8_t>& bin, const Mesh& mesh) {
  std::string json_text = json;
  json_text.resize((json_text.size() + 3) / 4 * 4, ' ');
  const uint64_t total = 12 + 8 + uint64_t{json_text.size()} + 8 + uint64_t{bin.size()};
  if (total > std::numeric_limits<uint32_t>::max())
    throw std::invalid_argument(
        fmt::format("{}: {} bytes, over the 4 GiB a .glb can hold", mesh.source.empty() ? "the mesh" : mesh.source, total));
  std::vector<uint8_t> out;
  out.reserve(static_cast<size_t>(total));
  append_glb_u32(out, kGlbWriterMagic);
  append_glb_u32(out, 2);
  append_glb_u32(out, static_cast<uint32_t>(total));
  append_glb_u32(out, static_cast<uint32_t>(json_text.size()));
  append_glb_u32(out, kGlbWriterJsonChunk);
  out.insert(out.end(), json_text.begin(), json_text.end());
  append_glb_u32(out, static_cast<uint32_t>(bin.size()));
  append_glb_u32(out, kGlbWriterBinChunk);
  out.insert(out.end(), bin.begin(), bin.end());
  return out;
}

}  // namespace

std::vector<uint8_t> encode_glb(const Mesh& mesh, std::string_view generator, const std::vector<GltfLight>& lights) {
  return encode_glb(mesh, generator, lights, {});
}

std::vector<uint8_t> encode_glb(const Mesh& mesh, std::string_view generator, const std::vector<GltfLight>& lights,
                                const std::vector<GlbAnimatedNode>& animated, std::string_view animation_name) {
  using nlohmann::json;
  const bool with_static = animated.empty() || !mesh.indices.empty() || !mesh.positions.empty();
  if (with_static) check_glb_encodable(mesh);
  check_animated_nodes(animated);

  GlbBinaryBuilder builder;
  GlbMaterials materials;
  json meshes = json::array(), nodes = json::array(), scene_nodes = json::array();
  if (with_static) {
    meshes.push_back(glb_mesh(mesh, builder, materials));
    json node = {{"mesh", 0}};
    if (!mesh.source.empty()) node["name"] = mesh.source;
    scene_nodes.push_back(nodes.size());
    nodes.push_back(std::move(node));
  }
  json document = json::object();
  document["asset"] = {{"version", "2.0"}, {"generator", std::string(generator)}};
  if (!lights.empty()) {
    document["extensions"] = {{"KHR_lights_punctual", {{"lights", glb_lights(lights, nodes, scene_nodes)}}}};
    document["extensionsUsed"] = json::array({"KHR_lights_punctual"});
  }
  std::vector<size_t> animated_indices;
  for (const GlbAnimatedNode& node : animated) {
    animated_indices.push_back(nodes.size());
    scene_nodes.push_back(nodes.size());
    nodes.push_back({{"name", node.name}, {"mesh", meshes.size()}});
    meshes.push_back(glb_mesh(node.mesh, builder, materials));
  }
  if (!animated.empty())
    document["animations"] = json::array({glb_animation(animated, animated_indices, animation_name, builder, nodes)});
  document["scene"] = 0;
  document["scenes"] = json::array({json{{"nodes", std::move(scene_nodes)}}});
  document["nodes"] = std::move(nodes);
  document["meshes"] = std::move(meshes);
  document["materials"] = std::move(materials.materials);
  document["accessors"] = std::move(builder.accessors());
  document["bufferViews"] = std::move(builder.views());
  document["buffers"] = json::array({json{{"byteLength", builder.bin().size()}}});
  return glb_container(document.dump(), builder.bin(), mesh);
}

}  // namespace arpipe
