// The checks a glTF file passes before tinygltf parses it: the GLB container, JSON nesting and
// size, counts and buffer bytes within gltf_limits.h, external buffers inside the file's folder.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace arpipe {

struct GltfDocument {
  bool binary = false;                 // a .glb (by its magic, not its name)
  std::string json;                    // the JSON to parse, without the parts the loader never uses
  std::vector<unsigned char> glb;      // binary: a GLB holding `json` and the file's BIN chunk
  std::filesystem::path folder;        // canonical folder of the file: external buffers lie inside
};

// Reads `path` (a regular file within kMaxGltfJsonBytes, or kMaxGlbFileBytes for a GLB) and checks
// it: GLB header and chunk lengths, JSON syntax, nesting within kMaxGltfJsonDepth, top-level
// arrays within kMaxGltfArrayEntries, the buffers' declared bytes within kMaxGltfBufferBytes, every
// external buffer a regular file inside the folder of its declared byteLength. Images, textures,
// samplers, skins, cameras, "extras" and "extensions" are dropped: the loader uses none of them,
// and tinygltf would recurse over or allocate for them. The one extension kept is
// KHR_lights_punctual (within kMaxGltfLights), checked and rebuilt from its known fields: type,
// name, color, intensity, range, the spot's cone angles and each node's light index. "animations"
// are kept (GltfAnimation reads them) and checked: within kMaxGltfAnimations, each an object with
// arrays "samplers" (within kMaxGltfAnimationSamplers; "input" and "output" integer accessor
// indices in range, "interpolation" STEP, LINEAR or CUBICSPLINE) and "channels" (within
// kMaxGltfAnimationChannels; "sampler" an integer index into the animation's samplers, "target" an
// object whose "node" is an integer node index in range and whose "path" is translation, rotation,
// scale or weights), a "name" a string. A channel without a node is ignored, as glTF says (it stays,
// as an ignored weights channel, so that channel numbers in messages are the file's). Throws
// AssetError naming the file and the place (byte offset, buffer index, array, animation, channel,
// sampler).
GltfDocument read_gltf_document(const std::filesystem::path& path);

// A glTF buffer URI with its %XX escapes decoded, as tinygltf decodes it before opening the file.
std::string decode_uri(const std::string& uri);

}  // namespace arpipe
