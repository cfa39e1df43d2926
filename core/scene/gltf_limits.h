// The limits the glTF loader declares up front for untrusted files (docs/ARCHITECTURE.md,
// "Untrusted input"): each is checked before the memory or work it bounds, and named in the message.
#pragma once

#include <cstddef>
#include <cstdint>

namespace arpipe {

// JSON text: a .gltf file, or a .glb's JSON chunk. Parsing takes up to ~30x its size in the worst
// case (tiny JSON objects), so 32 MiB stays under 1 GB; larger models keep their buffers in a .bin
// file or a .glb's BIN chunk.
inline constexpr size_t kMaxGltfJsonBytes = size_t{32} << 20;
// All buffers together (their declared byteLength: data URIs, .bin files and the GLB BIN chunk).
inline constexpr uint64_t kMaxGltfBufferBytes = uint64_t{1} << 30;
// A .glb file: its header, the JSON chunk and the BIN chunk at their limits.
inline constexpr uint64_t kMaxGlbFileBytes = kMaxGltfJsonBytes + kMaxGltfBufferBytes + 64;
// Nesting of JSON arrays and objects (tinygltf recurses over "extras" and "extensions").
inline constexpr int kMaxGltfJsonDepth = 64;
// Entries of each top-level array (nodes, meshes, accessors, bufferViews, buffers, materials,
// scenes) and primitives per mesh.
inline constexpr size_t kMaxGltfArrayEntries = 1'000'000;
// KHR_lights_punctual lights (the scene's lights, gltf_loader.h load_gltf_lights).
inline constexpr size_t kMaxGltfLights = 1024;
// Node hierarchy depth (the walk is iterative; the limit keeps the walk's own stack small).
inline constexpr size_t kMaxGltfNodeDepth = 1024;
// The one mesh the loader returns (every node's instance of a mesh counts again).
inline constexpr size_t kMaxGltfTriangles = 4'000'000;
inline constexpr size_t kMaxGltfVertices = 12'000'000;
// Animations ("animations": an array of its own, under kMaxGltfArrayEntries too), and each one's
// channels and samplers: a rig of 20,000 moving nodes with three channels each fits.
inline constexpr size_t kMaxGltfAnimations = 4096;
inline constexpr size_t kMaxGltfAnimationChannels = 65'536;
inline constexpr size_t kMaxGltfAnimationSamplers = 65'536;
// Keys of one sampler (its input accessor's elements; a CUBICSPLINE output holds three per key):
// over four hours at 60 keys a second.
inline constexpr size_t kMaxGltfAnimationKeys = 1'000'000;
// Accessor elements one GltfAnimation::load reads (each accessor once, however many samplers share
// it): kept as floats, at most 16 bytes an element, so 256 MiB at the limit.
inline constexpr uint64_t kMaxGltfAnimationElementsRead = 16'000'000;
// Accessor elements read over the whole load: a mesh instanced by many nodes is read once per
// node, so this bounds the work even for primitives that add no triangles.
inline constexpr uint64_t kMaxGltfElementsRead = 64'000'000;

}  // namespace arpipe
