// Small glTF 2.0 files for the render tests, written as text with the buffer embedded as a
// base64 data URI: one triangle with a node transform and a coloured material.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace arpipe::render_test {

inline std::string base64(const std::vector<uint8_t>& bytes) {
  static const char* alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const uint32_t chunk = (uint32_t(bytes[i]) << 16) | (i + 1 < bytes.size() ? uint32_t(bytes[i + 1]) << 8 : 0) |
                           (i + 2 < bytes.size() ? uint32_t(bytes[i + 2]) : 0);
    out += alphabet[(chunk >> 18) & 63];
    out += alphabet[(chunk >> 12) & 63];
    out += i + 1 < bytes.size() ? alphabet[(chunk >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? alphabet[chunk & 63] : '=';
  }
  return out;
}

template <typename T>
inline void append(std::vector<uint8_t>& bytes, const std::vector<T>& values) {
  const size_t at = bytes.size();
  bytes.resize(at + values.size() * sizeof(T));
  std::memcpy(bytes.data() + at, values.data(), values.size() * sizeof(T));
}

// One triangle in glTF's own axes: (0,0,0), (1,0,0), (0,1,0), normal +z, indices 0 1 2.
// Buffer layout: positions at 0 (36 bytes), normals at 36 (36 bytes), indices at 72 (6 bytes).
inline std::string triangle_buffer_uri() {
  std::vector<uint8_t> bytes;
  append<float>(bytes, {0, 0, 0, 1, 0, 0, 0, 1, 0});
  append<float>(bytes, {0, 0, 1, 0, 0, 1, 0, 0, 1});
  append<uint16_t>(bytes, {0, 1, 2});
  return "data:application/octet-stream;base64," + base64(bytes);
}

struct TriangleOptions {
  bool with_normals = true;
  int position_count = 3;
  int mode = 4;  // TRIANGLES
  std::string node_transform = R"("translation": [0, 0, 2], "scale": [0.5, 0.5, 0.5])";
  int index_value_limit = -1;  // when >= 0, a second index accessor reads past the vertices
};

inline std::string triangle_gltf(const TriangleOptions& options = {}) {
  const std::string normal_attribute = options.with_normals ? R"(, "NORMAL": 1)" : "";
  return std::string(R"({
  "asset": {"version": "2.0"},
  "scene": 0,
  "scenes": [{"nodes": [0]}],
  "nodes": [{"mesh": 0, )") + options.node_transform + R"(}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0)" + normal_attribute + R"(}, "indices": 2, "material": 0, "mode": )" +
         std::to_string(options.mode) + R"(}]}],
  "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.2, 0.4, 0.6, 1.0]}}],
  "buffers": [{"byteLength": 78, "uri": ")" + triangle_buffer_uri() + R"("}],
  "bufferViews": [
    {"buffer": 0, "byteOffset": 0, "byteLength": 36},
    {"buffer": 0, "byteOffset": 36, "byteLength": 36},
    {"buffer": 0, "byteOffset": 72, "byteLength": 6}
  ],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": )" + std::to_string(options.position_count) +
         R"(, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
    {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3"},
    {"bufferView": 2, "componentType": 5123, "count": 3, "type": "SCALAR"}
  ]
})";
}

}  // namespace arpipe::render_test
