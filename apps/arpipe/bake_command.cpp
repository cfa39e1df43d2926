// arpipe bake: precomputes a mesh's PRT transfer vectors (render/prt/prt_bake.h) into the cache
// that the renderer reads, or says that the cached bake is up to date.
#include <fmt/format.h>

#include <cstdio>
#include <exception>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "apps/arpipe/commands.h"
#include "apps/arpipe/progress_bar.h"
#include "core/sh/sh_basis.h"
#include "core/scene/asset_error.h"
#include "core/scene/builtin_meshes.h"
#include "core/scene/gltf_loader.h"
#include "render/prt/prt_bake.h"
#include "render/prt/prt_cache.h"

namespace arpipe {
namespace {

namespace fs = std::filesystem;

constexpr const char* kUsage =
    "usage: arpipe bake MODEL [--kind unshadowed|shadowed|interreflected] [--bands N] [--samples N]\n"
    "                         [--cache-dir DIR] [--force]\n"
    "  MODEL          a glTF file (.gltf, .glb) or a builtin mesh (builtin:cube, builtin:pyramid, ...)\n"
    "  --kind K       transfer: unshadowed (no rays), shadowed (default) or interreflected\n"
    "                 (shadowed plus one grey diffuse bounce)\n"
    "  --bands N      SH bands, N^2 coefficients per vertex (default 3)\n"
    "  --samples N    sphere samples per axis: N x N jittered directions (default 32)\n"
    "  --cache-dir D  the PRT cache (default $XDG_CACHE_HOME/arpipe/prt or ~/.cache/arpipe/prt)\n"
    "  --force        bake even when the cache holds an up-to-date result\n";

int parse_int(const std::string& option, const std::string& text, int lo, int hi) {
  size_t used = 0;
  int value = 0;
  try {
    value = std::stoi(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || text.empty() || value < lo || value > hi)
    throw std::invalid_argument(fmt::format("{} needs an integer in [{}, {}], got \"{}\"", option, lo, hi, text));
  return value;
}

}  // namespace

int run_bake(const Args& args) {
  std::string model;
  PrtBakeSettings settings;
  fs::path cache_dir;
  bool force = false;
  try {
    for (size_t i = 0; i < args.size(); ++i) {
      const auto value = [&]() -> const std::string& {
        if (i + 1 >= args.size()) throw std::invalid_argument(fmt::format("{} needs a value", args[i]));
        return args[++i];
      };
      const std::string& arg = args[i];
      if (arg == "--kind") {
        const std::string& name = value();
        const std::optional<TransferKind> kind = parse_transfer_kind(name);
        if (!kind)
          throw std::invalid_argument(
              fmt::format("--kind must be unshadowed, shadowed or interreflected, got \"{}\"", name));
        settings.kind = *kind;
      } else if (arg == "--bands") {
        settings.bands = parse_int(arg, value(), 1, kMaxShBands);
      } else if (arg == "--samples") {
        settings.samples_per_axis = parse_int(arg, value(), 1, 4096);
      } else if (arg == "--cache-dir") {
        cache_dir = value();
        if (cache_dir.empty()) throw std::invalid_argument("--cache-dir needs a directory");
      } else if (arg == "--force") {
        force = true;
      } else if (arg == "--help" || arg == "-h") {
        std::fputs(kUsage, stdout);
        return 0;
      } else if (arg.starts_with("--") || !model.empty()) {
        throw std::invalid_argument(fmt::format("unknown argument \"{}\"", arg));
      } else {
        model = arg;
      }
    }
    if (model.empty()) throw std::invalid_argument("which MODEL?");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "arpipe bake: %s\n%s", e.what(), kUsage);
    return 2;
  }
  if (cache_dir.empty()) cache_dir = default_prt_cache_dir();
  if (cache_dir.empty()) {
    std::fprintf(stderr, "arpipe bake: no cache directory: neither XDG_CACHE_HOME nor HOME is set; pass --cache-dir\n");
    return 2;
  }

  Mesh mesh;
  try {
    if (is_builtin_mesh_source(model)) {
      std::optional<Mesh> builtin = make_builtin_mesh(model);
      if (!builtin) {
        std::fprintf(stderr, "arpipe bake: unknown builtin mesh \"%s\" (known: %s)\n", model.c_str(),
                     std::string(kBuiltinMeshNames).c_str());
        return 1;
      }
      mesh = std::move(*builtin);
    } else {
      mesh = load_gltf_mesh(model);
    }
    validate_prt_mesh(mesh);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "arpipe bake: %s\n", e.what());
    return 1;
  }

  const std::string key = prt_cache_key(mesh, settings);
  const fs::path file = prt_cache_file(cache_dir, key);
  std::printf("model:   %s (%zu vertices, %zu triangles)\n", model.c_str(), mesh.vertex_count(), mesh.triangle_count());
  std::printf("bake:    %s, %d bands, %d x %d samples\n", std::string(transfer_kind_name(settings.kind)).c_str(),
              settings.bands, settings.samples_per_axis, settings.samples_per_axis);
  std::printf("key:     %s\n", key.c_str());
  std::printf("cache:   %s\n", file.string().c_str());
  std::string why_not;
  if (!force && read_prt_cache(file, key, &why_not)) {
    std::printf("up to date (not baked)\n");
    return 0;
  }
  std::printf("baking:  %s\n", force ? "--force" : why_not.c_str());
  std::fflush(stdout);
  try {
    ProgressBar bar("vertices");
    PrtBakeStats stats;
    const PrtTransfer transfer = bake_prt(
        mesh, settings, [&](size_t done, size_t total) { bar.update(int(done), int(total)); }, &stats);
    bar.finish();
    write_prt_cache(file, key, transfer);
    std::printf("baked in %.2f s on %d threads: %llu rays, %.2f Mrays/s\n", stats.seconds, stats.threads,
                static_cast<unsigned long long>(stats.rays),
                stats.seconds > 0 ? double(stats.rays) / stats.seconds * 1e-6 : 0.0);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "arpipe bake: %s\n", e.what());
    return 1;
  }
  return 0;
}

}  // namespace arpipe
