// arpipe bake: precomputes a mesh's PRT transfer vectors (render/prt/prt_bake.h) into the cache
// that the renderer reads, or says that the cached bake is up to date.
#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "apps/arpipe/commands.h"
#include "apps/cli/command_line.h"
#include "apps/cli/progress_bar.h"
#include "core/sh/sh_basis.h"
#include "core/scene/asset_error.h"
#include "core/scene/builtin_meshes.h"
#include "core/scene/gltf_loader.h"
#include "render/prt/prt_bake.h"
#include "render/prt/prt_cache.h"

namespace arpipe {
namespace {

namespace fs = std::filesystem;

struct BakeOptions {
  std::string model, kind = "shadowed";
  PrtBakeSettings settings;
  fs::path cache_dir;
  bool force = false;
};

int bake(BakeOptions options) {
  const std::string& model = options.model;
  PrtBakeSettings& settings = options.settings;
  settings.kind = *parse_transfer_kind(options.kind);  // checked when read
  fs::path& cache_dir = options.cache_dir;
  const bool force = options.force;
  if (cache_dir.empty()) cache_dir = default_prt_cache_dir();
  if (cache_dir.empty()) {
    std::fprintf(stderr, "arpipe bake: no cache directory: neither XDG_CACHE_HOME nor HOME is set; pass --cache-dir\n");
    return 2;
  }

  Mesh mesh;
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
  ProgressBar bar("vertices");
  PrtBakeStats stats;
  const PrtTransfer transfer = bake_prt(
      mesh, settings, [&](size_t done, size_t total) { bar.update(int(done), int(total)); }, &stats);
  bar.finish();
  write_prt_cache(file, key, transfer);
  std::printf("baked in %.2f s on %d threads: %llu rays, %.2f Mrays/s\n", stats.seconds, stats.threads,
              static_cast<unsigned long long>(stats.rays),
              stats.seconds > 0 ? double(stats.rays) / stats.seconds * 1e-6 : 0.0);
  return 0;
}

}  // namespace

void add_bake_command(CLI::App& arpipe) {
  CLI::App* command =
      arpipe.add_subcommand("bake", "precompute a mesh's radiance transfer (PRT) into the cache the renderer reads");
  auto options = std::make_shared<BakeOptions>();
  command->add_option("MODEL", options->model, "a glTF file (.gltf, .glb) or a builtin mesh (builtin:cube, builtin:pyramid, ...)")
      ->required();
  command->add_option("--kind", options->kind,
                      "transfer: unshadowed (no rays), shadowed or interreflected (shadowed plus one grey diffuse bounce)")
      ->type_name("K")
      ->check(cli::accepted_by([](const std::string& t) { return parse_transfer_kind(t).has_value(); },
                               "unshadowed, shadowed or interreflected"));
  command->add_option("--bands", options->settings.bands, "SH bands, N^2 coefficients per vertex")
      ->check(CLI::Range(1, kMaxShBands));
  command->add_option("--samples", options->settings.samples_per_axis, "sphere samples per axis: N x N jittered directions")
      ->check(CLI::Range(1, 4096));
  command->add_option("--cache-dir", options->cache_dir, "the PRT cache")
      ->type_name("DIR")
      ->default_str("$XDG_CACHE_HOME/arpipe/prt or ~/.cache/arpipe/prt")
      ->check(cli::accepted_by([](const std::string& t) { return !t.empty(); }, "a directory"));
  command->add_flag("--force", options->force, "bake even when the cache holds an up-to-date result");
  cli::on_run(command, [options] { return bake(*options); },
              cli::Failure{.status = 1, .message = cli::Failure::Message::after_command_name});
}

}  // namespace arpipe
