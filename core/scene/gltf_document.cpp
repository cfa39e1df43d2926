// The checks a glTF file passes before tinygltf parses it: the GLB container, JSON nesting and
// size, counts and buffer bytes within gltf_limits.h, external buffers inside the file's folder.
#include "core/scene/gltf_document.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>
#include <string_view>

#include "core/scene/asset_error.h"
#include "core/scene/asset_file.h"
#include "core/scene/gltf_limits.h"

namespace arpipe {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr uint32_t kGlbMagic = 0x46546C67;       // "glTF"
constexpr uint32_t kJsonChunkType = 0x4E4F534A;  // "JSON"
constexpr uint32_t kBinChunkType = 0x004E4942;   // "BIN\0"
constexpr size_t kGlbHeaderBytes = 12, kChunkHeaderBytes = 8;

class DocumentReader {
 public:
  explicit DocumentReader(const fs::path& path) : path_(path) {}

  GltfDocument read() {
    std::string why;
    std::optional<std::vector<unsigned char>> bytes = read_asset_file(path_, kMaxGlbFileBytes, &why);
    if (!bytes) fail(fmt::format("cannot read the glTF file: {}", why));
    std::optional<fs::path> folder = canonical_folder(path_, &why);
    if (!folder) fail(why);
    document_.folder = std::move(*folder);
    document_.binary = bytes->size() >= 4 && read_u32(*bytes, 0) == kGlbMagic;
    if (document_.binary) {
      document_.glb = std::move(*bytes);
      read_glb();
    } else {
      if (bytes->size() > kMaxGltfJsonBytes)
        fail(fmt::format("{} bytes of glTF JSON, over the limit of {} bytes (keep large buffers in a .bin file or "
                         "a .glb)",
                         bytes->size(), kMaxGltfJsonBytes));
      document_.json = clean_json(std::string_view(reinterpret_cast<const char*>(bytes->data()), bytes->size()), 0);
    }
    return std::move(document_);
  }

 private:
  [[noreturn]] void fail(const std::string& what) const { throw AssetError(fmt::format("{}: {}", path_.string(), what)); }

  static uint32_t read_u32(const std::vector<unsigned char>& bytes, size_t at) {
    return uint32_t(bytes[at]) | uint32_t(bytes[at + 1]) << 8 | uint32_t(bytes[at + 2]) << 16 |
           uint32_t(bytes[at + 3]) << 24;
  }
  static void write_u32(std::vector<unsigned char>& bytes, size_t at, uint32_t v) {
    for (size_t i = 0; i < 4; ++i) bytes[at + i] = static_cast<unsigned char>((v >> (8 * i)) & 0xffu);
  }

  // GLB: a 12-byte header (magic, version 2, length), a JSON chunk, an optional BIN chunk; every
  // length is checked against the bytes really there (64-bit sums: no wrap).
  void read_glb() {
    std::vector<unsigned char>& glb = document_.glb;
    const uint64_t size = glb.size();
    if (size < kGlbHeaderBytes + kChunkHeaderBytes)
      fail(fmt::format("a binary glTF (.glb) of {} bytes: the header and JSON chunk header need {}", size,
                       kGlbHeaderBytes + kChunkHeaderBytes));
    const uint32_t version = read_u32(glb, 4), length = read_u32(glb, 8);
    if (version != 2) fail(fmt::format("binary glTF (.glb) version {}, expected 2", version));
    if (length > size || length < kGlbHeaderBytes + kChunkHeaderBytes)
      fail(fmt::format("binary glTF (.glb) header (byte 8) gives a length of {} bytes, the file has {}", length, size));
    const uint64_t json_length = read_u32(glb, 12);
    if (read_u32(glb, 16) != kJsonChunkType) fail("binary glTF (.glb): the first chunk (byte 12) is not a JSON chunk");
    const uint64_t json_end = kGlbHeaderBytes + kChunkHeaderBytes + json_length;
    if (json_length == 0 || json_end > length)
      fail(fmt::format("binary glTF (.glb): the JSON chunk (byte 12) declares {} bytes, but {} remain in the file",
                       json_length, length - kGlbHeaderBytes - kChunkHeaderBytes));
    if (json_length > kMaxGltfJsonBytes)
      fail(fmt::format("binary glTF (.glb): the JSON chunk has {} bytes, over the limit of {} bytes", json_length,
                       kMaxGltfJsonBytes));
    uint64_t bin_length = 0;
    if (json_end < length) {
      if (json_end + kChunkHeaderBytes > length)
        fail(fmt::format("binary glTF (.glb): {} bytes after the JSON chunk (byte {}) are too few for a chunk header",
                         length - json_end, json_end));
      bin_length = read_u32(glb, json_end);
      if (read_u32(glb, json_end + 4) != kBinChunkType)
        fail(fmt::format("binary glTF (.glb): the chunk at byte {} is not a BIN chunk", json_end));
      if (json_end + kChunkHeaderBytes + bin_length > length)
        fail(fmt::format("binary glTF (.glb): the BIN chunk (byte {}) declares {} bytes, but {} remain in the file",
                         json_end, bin_length, length - json_end - kChunkHeaderBytes));
    }
    bin_bytes_ = bin_length;
    const std::string cleaned = clean_json(
        std::string_view(reinterpret_cast<const char*>(glb.data()) + kGlbHeaderBytes + kChunkHeaderBytes,
                         size_t(json_length)),
        kGlbHeaderBytes + kChunkHeaderBytes);
    // The GLB tinygltf parses: the cleaned JSON (space-padded) and the BIN chunk, nothing after.
    const uint64_t bin_part = bin_length > 0 ? kChunkHeaderBytes + bin_length : 0;
    if (cleaned.size() <= json_length) {
      std::memcpy(glb.data() + kGlbHeaderBytes + kChunkHeaderBytes, cleaned.data(), cleaned.size());
      std::memset(glb.data() + kGlbHeaderBytes + kChunkHeaderBytes + cleaned.size(), ' ', json_length - cleaned.size());
      glb.resize(size_t(json_end + bin_part));
    } else {  // rare: the cleaned JSON is longer (numbers written out), so the BIN chunk moves
      const uint64_t padded = (cleaned.size() + 3) / 4 * 4;
      std::vector<unsigned char> rebuilt(size_t(kGlbHeaderBytes + kChunkHeaderBytes + padded + bin_part), ' ');
      std::memcpy(rebuilt.data(), glb.data(), kGlbHeaderBytes);
      write_u32(rebuilt, 12, uint32_t(padded));
      write_u32(rebuilt, 16, kJsonChunkType);
      std::memcpy(rebuilt.data() + kGlbHeaderBytes + kChunkHeaderBytes, cleaned.data(), cleaned.size());
      if (bin_part > 0)
        std::memcpy(rebuilt.data() + kGlbHeaderBytes + kChunkHeaderBytes + padded, glb.data() + json_end, bin_part);
      glb = std::move(rebuilt);
    }
    write_u32(glb, 8, uint32_t(glb.size()));
  }

  // Array and object nesting, counted outside strings, before a parser (or tinygltf's recursion
  // over "extras") sees it.
  void check_nesting(std::string_view text, size_t file_offset) const {
    int depth = 0;
    bool in_string = false, escaped = false;
    for (size_t i = 0; i < text.size(); ++i) {
      const char c = text[i];
      if (in_string) {
        if (escaped) escaped = false;
        else if (c == '\\') escaped = true;
        else if (c == '"') in_string = false;
      } else if (c == '"') {
        in_string = true;
      } else if (c == '[' || c == '{') {
        if (++depth > kMaxGltfJsonDepth)
          fail(fmt::format("JSON nests arrays and objects more than {} levels deep (at byte {})", kMaxGltfJsonDepth,
                           file_offset + i));
      } else if (c == ']' || c == '}') {
        --depth;
      }
    }
  }

  std::string clean_json(std::string_view text, size_t file_offset) {
    check_nesting(text, file_offset);
    json gltf;
    try {
      gltf = json::parse(text.begin(), text.end());
    } catch (const json::exception& e) {  // the message gives the line and column
      std::string what = e.what();
      if (const size_t at = what.find("] "); at != std::string::npos) what.erase(0, at + 2);
      if (what.size() > 300) what = what.substr(0, 300) + "...";
      fail(fmt::format("not a valid glTF 2.0 {} file: {}", document_.binary ? "binary (.glb)" : "JSON", what));
    }
    if (!gltf.is_object())
      fail(fmt::format("not a valid glTF 2.0 {} file: the JSON is not an object",
                       document_.binary ? "binary (.glb)" : "JSON"));
    for (const char* unused : {"images", "textures", "samplers", "skins", "cameras"}) gltf.erase(unused);
    const PunctualLights lights = take_punctual_lights(gltf);
    drop_extras_and_extensions(gltf);
    put_punctual_lights(gltf, lights);
    for (const char* name : {"nodes", "meshes", "accessors", "bufferViews", "buffers", "materials", "scenes"}) {
      const auto it = gltf.find(name);
      if (it != gltf.end() && it->is_array() && it->size() > kMaxGltfArrayEntries)
        fail(fmt::format("\"{}\" has {} entries, over the limit of {}", name, it->size(), kMaxGltfArrayEntries));
    }
    if (const auto meshes = gltf.find("meshes"); meshes != gltf.end() && meshes->is_array())
      for (size_t m = 0; m < meshes->size(); ++m) {
        const json& mesh = (*meshes)[m];
        if (!mesh.is_object()) continue;
        const auto primitives = mesh.find("primitives");
        if (primitives != mesh.end() && primitives->is_array() && primitives->size() > kMaxGltfArrayEntries)
          fail(fmt::format("mesh {} has {} primitives, over the limit of {}", m, primitives->size(),
                           kMaxGltfArrayEntries));
      }
    check_animations(gltf);
    check_buffers(gltf);
    return gltf.dump();
  }

  static std::string shown(const json& value) {
    std::string text = value.dump();
    return text.size() > 60 ? text.substr(0, 60) + "..." : text;
  }

  static size_t array_size(const json& gltf, const char* name) {
    const auto it = gltf.find(name);
    return it != gltf.end() && it->is_array() ? it->size() : 0;
  }

  // An integer index into an array of `count` entries.
  static bool is_index(const json& value, size_t count) {
    return value.is_number_integer() && value.get<int64_t>() >= 0 && uint64_t(value.get<int64_t>()) < count;
  }

  // "animations" (GltfAnimation reads them): counts within gltf_limits.h, every index an integer
  // in range, interpolation and path among glTF's. Checked here so that tinygltf, which drops a
  // channel it cannot parse and so renumbers the rest, parses each one.
  void check_animations(json& gltf) const {
    const auto animations = gltf.find("animations");
    if (animations == gltf.end()) return;
    if (!animations->is_array()) fail("\"animations\" is not an array");
    if (animations->size() > kMaxGltfAnimations)
      fail(fmt::format("\"animations\" has {} entries, over the limit of {}", animations->size(), kMaxGltfAnimations));
    const size_t nodes = array_size(gltf, "nodes"), accessors = array_size(gltf, "accessors");
    for (size_t a = 0; a < animations->size(); ++a) {
      json& animation = (*animations)[a];
      const std::string where = fmt::format("animation {}", a);
      if (!animation.is_object()) fail(where + ": not an object");
      if (const auto name = animation.find("name"); name != animation.end() && !name->is_string())
        fail(fmt::format("{}: \"name\" must be a string, not {}", where, shown(*name)));
      const size_t samplers = check_animation_samplers(animation, where, accessors);
      check_animation_channels(animation, where, samplers, nodes);
    }
  }

  // The animation's samplers; their count.
  size_t check_animation_samplers(const json& animation, const std::string& where, size_t accessors) const {
    const auto samplers = animation.find("samplers");
    if (samplers == animation.end() || !samplers->is_array()) fail(where + ": \"samplers\" must be an array");
    if (samplers->size() > kMaxGltfAnimationSamplers)
      fail(fmt::format("{}: {} samplers, over the limit of {}", where, samplers->size(), kMaxGltfAnimationSamplers));
    for (size_t s = 0; s < samplers->size(); ++s) {
      const json& sampler = (*samplers)[s];
      const std::string at = fmt::format("{} sampler {}", where, s);
      if (!sampler.is_object()) fail(at + ": not an object");
      for (const char* key : {"input", "output"}) {
        const auto index = sampler.find(key);
        if (index == sampler.end() || !is_index(*index, accessors))
          fail(fmt::format("{}: \"{}\" must be an accessor index below {} (the accessors), not {}", at, key, accessors,
                           index == sampler.end() ? "missing" : shown(*index)));
      }
      if (const auto interpolation = sampler.find("interpolation"); interpolation != sampler.end())
        if (*interpolation != "STEP" && *interpolation != "LINEAR" && *interpolation != "CUBICSPLINE")
          fail(fmt::format("{}: \"interpolation\" must be \"STEP\", \"LINEAR\" or \"CUBICSPLINE\", not {}", at,
                           shown(*interpolation)));
    }
    return samplers->size();
  }

  void check_animation_channels(json& animation, const std::string& where, size_t samplers, size_t nodes) const {
    const auto channels = animation.find("channels");
    if (channels == animation.end() || !channels->is_array()) fail(where + ": \"channels\" must be an array");
    if (channels->size() > kMaxGltfAnimationChannels)
      fail(fmt::format("{}: {} channels, over the limit of {}", where, channels->size(), kMaxGltfAnimationChannels));
    for (size_t c = 0; c < channels->size(); ++c) {
      json& channel = (*channels)[c];
      const std::string at = fmt::format("{} channel {}", where, c);
      if (!channel.is_object()) fail(at + ": not an object");
      const auto sampler = channel.find("sampler");
      if (sampler == channel.end() || !is_index(*sampler, samplers))
        fail(fmt::format("{}: \"sampler\" must be an index below {} (the animation's samplers), not {}", at, samplers,
                         sampler == channel.end() ? "missing" : shown(*sampler)));
      const auto target = channel.find("target");
      if (target == channel.end() || !target->is_object()) fail(at + ": \"target\" must be an object");
      const auto node = target->find("node");
      if (node == target->end()) {
        // glTF: a channel without a node (an extension's target) is ignored. It stays, as a
        // "weights" channel (ignored too), so that the channels after it keep their indices;
        // without nodes every channel is such a one, and none stays.
        *target = {{"node", 0}, {"path", "weights"}};
        continue;
      }
      if (!is_index(*node, nodes))
        fail(fmt::format("{}: target \"node\" must be a node index below {} (the nodes), not {}", at, nodes, shown(*node)));
      const auto path = target->find("path");
      if (path == target->end() ||
          (*path != "translation" && *path != "rotation" && *path != "scale" && *path != "weights"))
        fail(fmt::format("{}: target \"path\" must be \"translation\", \"rotation\", \"scale\" or \"weights\", not {}",
                         at, path == target->end() ? "missing" : shown(*path)));
    }
    if (nodes == 0) *channels = json::array();
  }

  // KHR_lights_punctual is the one extension kept (the scene's lights, load_gltf_lights): checked
  // here and rebuilt from its known fields only, so nothing else of it reaches tinygltf.
  struct PunctualLights {
    json lights = json::array();
    std::vector<std::pair<size_t, int64_t>> node_lights;  // node index, light index
  };

  PunctualLights take_punctual_lights(const json& gltf) const {
    PunctualLights out;
    const auto number = [](const json& v) { return v.is_number() && std::isfinite(v.get<double>()); };
    if (const auto extensions = gltf.find("extensions"); extensions != gltf.end() && extensions->is_object())
      if (const auto khr = extensions->find("KHR_lights_punctual"); khr != extensions->end() && khr->is_object())
        if (const auto lights = khr->find("lights"); lights != khr->end() && lights->is_array()) {
          if (lights->size() > kMaxGltfLights)
            fail(fmt::format("KHR_lights_punctual has {} lights, over the limit of {}", lights->size(), kMaxGltfLights));
          for (size_t i = 0; i < lights->size(); ++i) {
            const json& light = (*lights)[i];
            const auto bad = [&](const std::string& what) { fail(fmt::format("KHR_lights_punctual light {}: {}", i, what)); };
            if (!light.is_object()) bad("not an object");
            json kept = json::object();
            const auto type = light.find("type");
            if (type == light.end() || !type->is_string() ||
                (*type != "directional" && *type != "point" && *type != "spot"))
              bad("\"type\" must be \"directional\", \"point\" or \"spot\"");
            kept["type"] = *type;
            if (const auto name = light.find("name"); name != light.end() && name->is_string())
              kept["name"] = name->get<std::string>().substr(0, 200);
            if (const auto color = light.find("color"); color != light.end()) {
              if (!color->is_array() || color->size() != 3 || !std::all_of(color->begin(), color->end(), [&](const json& c) {
                    return number(c) && c.get<double>() >= 0;
                  }))
                bad("\"color\" must be 3 numbers >= 0");
              kept["color"] = *color;
            }
            if (const auto intensity = light.find("intensity"); intensity != light.end()) {
              if (!number(*intensity) || intensity->get<double>() < 0) bad("\"intensity\" must be a number >= 0");
              kept["intensity"] = *intensity;
            }
            if (const auto range = light.find("range"); range != light.end()) {
              if (!number(*range) || range->get<double>() <= 0) bad("\"range\" must be a number > 0");
              kept["range"] = *range;
            }
            if (*type == "spot") {
              json cone = json::object();
              if (const auto spot = light.find("spot"); spot != light.end() && spot->is_object())
                for (const char* key : {"innerConeAngle", "outerConeAngle"})
                  if (const auto angle = spot->find(key); angle != spot->end()) {
                    if (!number(*angle)) bad(fmt::format("\"spot\".\"{}\" must be a number", key));
                    cone[key] = *angle;
                  }
              kept["spot"] = cone;
            }
            out.lights.push_back(std::move(kept));
          }
        }
    if (const auto nodes = gltf.find("nodes"); nodes != gltf.end() && nodes->is_array())
      for (size_t n = 0; n < nodes->size(); ++n) {
        const json& node = (*nodes)[n];
        if (!node.is_object()) continue;
        const auto extensions = node.find("extensions");
        if (extensions == node.end() || !extensions->is_object()) continue;
        const auto khr = extensions->find("KHR_lights_punctual");
        if (khr == extensions->end() || !khr->is_object()) continue;
        const auto light = khr->find("light");
        if (light == khr->end()) continue;
        if (!light->is_number_integer() || light->get<int64_t>() < 0 || light->get<int64_t>() >= int64_t(out.lights.size()))
          fail(fmt::format("node {}: its KHR_lights_punctual light {} does not exist ({} lights)", n, light->dump(),
                           out.lights.size()));
        out.node_lights.emplace_back(n, light->get<int64_t>());
      }
    return out;
  }

  static void put_punctual_lights(json& gltf, const PunctualLights& lights) {
    if (lights.lights.empty()) return;
    gltf["extensions"] = {{"KHR_lights_punctual", {{"lights", lights.lights}}}};
    for (const auto& [node, light] : lights.node_lights)
      gltf["nodes"][node]["extensions"] = {{"KHR_lights_punctual", {{"light", light}}}};
  }

  // "extras" and "extensions" anywhere: iteratively, with a stack of the objects still to visit.
  static void drop_extras_and_extensions(json& root) {
    std::vector<json*> pending{&root};
    while (!pending.empty()) {
      json* value = pending.back();
      pending.pop_back();
      if (value->is_object()) {
        value->erase("extras");
        value->erase("extensions");
      }
      if (value->is_structured())
        for (json& child : *value) pending.push_back(&child);
    }
  }

  // The declared bytes of all buffers against the limit; each external one resolved inside the
  // folder, a regular file of its byteLength (tinygltf then reads it through the loader's checked
  // callbacks, which apply the same rules again).
  void check_buffers(const json& gltf) const {
    const auto buffers = gltf.find("buffers");
    if (buffers == gltf.end() || !buffers->is_array()) return;
    uint64_t total = 0;
    for (size_t b = 0; b < buffers->size(); ++b) {
      const json& buffer = (*buffers)[b];
      if (!buffer.is_object()) continue;
      const auto length = buffer.find("byteLength");
      if (length == buffer.end() || !length->is_number_unsigned()) continue;  // tinygltf says what is wrong
      const uint64_t bytes = length->get<uint64_t>();
      if (__builtin_add_overflow(total, bytes, &total) || total > kMaxGltfBufferBytes)
        fail(fmt::format("buffer {} brings the buffers' byteLength to more than the limit of {} bytes", b,
                         kMaxGltfBufferBytes));
      const auto uri = buffer.find("uri");
      if (uri == buffer.end() || !uri->is_string()) {
        if (document_.binary && b == 0 && bytes > bin_bytes_)
          fail(fmt::format("buffer 0 declares {} bytes, but the BIN chunk has {}", bytes, bin_bytes_));
        continue;
      }
      const std::string& text = uri->get_ref<const std::string&>();
      if (text.rfind("data:", 0) == 0) continue;  // embedded: bounded by the JSON's size
      std::string why;
      const std::optional<fs::path> file = resolve_inside_folder(document_.folder, decode_uri(text), &why);
      const std::string shown = text.size() > 200 ? text.substr(0, 200) + "..." : text;
      if (!file) fail(fmt::format("buffer {} (uri \"{}\"): {}", b, shown, why));
      std::error_code error;
      const fs::file_status status = fs::status(*file, error);
      if (error || !fs::is_regular_file(status))
        fail(fmt::format("buffer {} (uri \"{}\"): not a regular file", b, shown));
      const uintmax_t size = fs::file_size(*file, error);
      if (error) fail(fmt::format("buffer {} (uri \"{}\"): cannot read its size: {}", b, shown, error.message()));
      if (size != bytes)
        fail(fmt::format("buffer {} (uri \"{}\"): the file has {} bytes, byteLength says {}", b, shown, size, bytes));
    }
  }

  const fs::path& path_;
  GltfDocument document_;
  uint64_t bin_bytes_ = 0;
};

}  // namespace

std::string decode_uri(const std::string& uri) {
  // tinygltf's own decoding (dlib's urldecode): '+' is a space, %XX a byte.
  auto hex = [](char c) -> int {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return 0;
  };
  std::string out;
  for (size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '+') {
      out += ' ';
    } else if (uri[i] == '%' && uri.size() > i + 2) {
      out += static_cast<char>((hex(uri[i + 1]) << 4) | hex(uri[i + 2]));
      i += 2;
    } else {
      out += uri[i];
    }
  }
  return out;
}

GltfDocument read_gltf_document(const fs::path& path) { return DocumentReader(path).read(); }

}  // namespace arpipe
