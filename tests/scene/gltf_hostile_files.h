// Hostile glTF files for the loader's hardening tests (issue 18): the one-triangle file of
// gltf_test_files.h as a JSON document to bend, node graphs, raw buffers and GLB containers.
#pragma once

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tests/scene/gltf_test_files.h"

namespace arpipe::render_test {

// The triangle of gltf_test_files.h as JSON, ready to be changed field by field.
inline nlohmann::json triangle_json(const TriangleOptions& options = {}) { return nlohmann::json::parse(triangle_gltf(options)); }

// The triangle's 78 buffer bytes (positions, normals, indices) as gltf_test_files.h lays them out.
inline std::vector<uint8_t> triangle_buffer_bytes() {
  std::vector<uint8_t> bytes;
  append<float>(bytes, {0, 0, 0, 1, 0, 0, 0, 1, 0});
  append<float>(bytes, {0, 0, 1, 0, 0, 1, 0, 0, 1});
  append<uint16_t>(bytes, {0, 1, 2});
  return bytes;
}

inline std::string data_uri(const std::vector<uint8_t>& bytes) {
  return "data:application/octet-stream;base64," + base64(bytes);
}

// Nodes 0..depth-1 each the only child of the one before; the last one holds mesh 0.
inline void make_node_chain(nlohmann::json& gltf, size_t depth) {
  nlohmann::json nodes = nlohmann::json::array();
  for (size_t i = 0; i + 1 < depth; ++i) nodes.push_back({{"children", {i + 1}}});
  nodes.push_back({{"mesh", 0}});
  gltf["nodes"] = std::move(nodes);
  gltf["scenes"] = {{{"nodes", {0}}}};
}

// A GLB container: 12-byte header, the JSON chunk (padded with spaces) and, when `bin` is not
// empty, the BIN chunk (padded with zeros); `bin_length_extra` is added to the BIN chunk's declared
// length without adding bytes (a chunk that claims to run past the file).
inline std::string glb(const std::string& json_text, const std::vector<uint8_t>& bin, uint32_t bin_length_extra = 0) {
  std::string json_chunk = json_text;
  while (json_chunk.size() % 4 != 0) json_chunk += ' ';
  std::vector<uint8_t> bin_chunk = bin;
  while (bin_chunk.size() % 4 != 0) bin_chunk.push_back(0);
  auto u32 = [](std::string& out, uint32_t v) {
    for (int i = 0; i < 4; ++i) out.push_back(char((v >> (8 * i)) & 0xffu));
  };
  const uint32_t total = uint32_t(12 + 8 + json_chunk.size() + (bin.empty() ? 0 : 8 + bin_chunk.size()));
  std::string out = "glTF";
  u32(out, 2);
  u32(out, total);
  u32(out, uint32_t(json_chunk.size()));
  u32(out, 0x4E4F534Au);  // "JSON"
  out += json_chunk;
  if (!bin.empty()) {
    u32(out, uint32_t(bin_chunk.size()) + bin_length_extra);
    u32(out, 0x004E4942u);  // "BIN\0"
    out.append(reinterpret_cast<const char*>(bin_chunk.data()), bin_chunk.size());
  }
  return out;
}

// The triangle as a GLB: its buffer is the BIN chunk (no uri).
inline std::string triangle_glb(uint32_t bin_length_extra = 0) {
  nlohmann::json gltf = triangle_json();
  gltf["buffers"][0].erase("uri");
  return glb(gltf.dump(), triangle_buffer_bytes(), bin_length_extra);
}

// The triangle file grown into an animated scene: buffer 0 is the triangle's, buffer 1 (a data
// URI made by done()) holds the keys and values each accessor call appends, each with a bufferView
// of its own. Nodes, meshes, scenes and "animations" are the caller's to write into `gltf`.
struct AnimatedGltf {
  nlohmann::json gltf = triangle_json();
  std::vector<uint8_t> data;

  // An accessor of `values` as `type` ("SCALAR", "VEC3", "VEC4") of FLOAT; its index.
  int floats(const std::vector<float>& values, const std::string& type) {
    const size_t components = type == "SCALAR" ? 1 : type == "VEC3" ? 3 : 4;
    return accessor(values, 5126, type, values.size() / components, false);
  }
  // An accessor of `values` as VEC4 of normalised SHORT (a rotation as glTF allows it); its index.
  int normalized_shorts(const std::vector<int16_t>& values) { return accessor(values, 5122, "VEC4", values.size() / 4, true); }

  // A mesh of the triangle with a material of its own of colour (r, g, b): its mesh index.
  int coloured_mesh(float r, float g, float b) {
    nlohmann::json mesh = gltf["meshes"][0];
    mesh["primitives"][0]["material"] = gltf["materials"].size();
    gltf["materials"].push_back({{"pbrMetallicRoughness", {{"baseColorFactor", {r, g, b, 1.0f}}}}});
    gltf["meshes"].push_back(mesh);
    return int(gltf["meshes"].size()) - 1;
  }

  nlohmann::json done() const {
    nlohmann::json out = gltf;
    if (!data.empty()) out["buffers"][1] = {{"byteLength", data.size()}, {"uri", data_uri(data)}};
    return out;
  }

 private:
  template <typename T>
  int accessor(const std::vector<T>& values, int component_type, const std::string& type, size_t count, bool normalized) {
    while (data.size() % 4 != 0) data.push_back(0);
    const size_t offset = data.size();
    append<T>(data, values);
    gltf["bufferViews"].push_back({{"buffer", 1}, {"byteOffset", offset}, {"byteLength", values.size() * sizeof(T)}});
    nlohmann::json accessor = {{"bufferView", gltf["bufferViews"].size() - 1},
                               {"componentType", component_type},
                               {"count", count},
                               {"type", type}};
    if (normalized) accessor["normalized"] = true;
    gltf["accessors"].push_back(accessor);
    return int(gltf["accessors"].size()) - 1;
  }
};

// One sampler and one channel: `node`'s `path` keyed by the two accessors.
inline nlohmann::json one_channel_animation(int node, const std::string& path, int input, int output,
                                            const std::string& interpolation = "LINEAR") {
  return {{"channels", {{{"sampler", 0}, {"target", {{"node", node}, {"path", path}}}}}},
          {"samplers", {{{"input", input}, {"output", output}, {"interpolation", interpolation}}}}};
}

inline void write_file(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(bytes.data(), std::streamsize(bytes.size()));
}

}  // namespace arpipe::render_test
