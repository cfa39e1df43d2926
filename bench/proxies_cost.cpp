// arpipe bench proxies: what the phantom proxies cost and how exactly they hide, on the capture of
// configs/sim/proxies.toml (a real box and cylinder in front of a virtual cube): the render stage's
// time per frame and the occlusion edge's displacement against the simulator's visible coverage,
// for no proxies, the builtin proxies, the same shapes as 10k-triangle glTF meshes, and those
// simplified 10:1 with `arpipe proxy simplify`'s code. The rows come from one run: compare them.
#include <fmt/format.h>

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "apps/cli/command_line.h"
#include "bench/benchmarks.h"
#include "bench/proxy_comparison.h"
#include "core/log.h"
#include "core/scene/builtin_meshes.h"
#include "core/scene/glb_writer.h"
#include "core/scene/mesh_simplify.h"

namespace arpipe {
namespace {

namespace fs = std::filesystem;

struct ProxyVariant {
  std::string label;
  std::vector<SceneProxy> proxies;
  size_t triangles = 0;
  std::optional<double> lod_px;  // render.occluder_lod_px for this row; none: the config's
};

void write_glb(const Mesh& mesh, const fs::path& path) {
  const std::vector<uint8_t> bytes = encode_glb(mesh, "arpipe bench proxies");
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  if (!out) throw std::runtime_error(fmt::format("cannot write {}", path.string()));
}

// The config's proxies with their meshes replaced by glTF files of the same shapes: the box with
// faces split into n x n squares, the cylinder with many segments: about 10k triangles each.
std::vector<ProxyVariant> variants(const Config& config, const fs::path& work) {
  std::vector<ProxyVariant> out;
  out.push_back({"no proxies (the cube drawn whole)", {}, 0, {}});
  ProxyVariant builtin{"builtin proxies (a box, a 48-gon cylinder)", config.render.proxies, 0, {}};
  for (const SceneProxy& p : config.render.proxies)  // as render/uploaded_objects.cpp makes them
    builtin.triangles += make_builtin_mesh(p.mesh, p.size_m, config.render.lens == LensMode::Vertex ? 8 : 1)->triangle_count();
  out.push_back(builtin);
  ProxyVariant fine{"10k-triangle glTF proxies", config.render.proxies, 0, {}};
  ProxyVariant simplified{"the same simplified 10:1 (meshoptimizer)", config.render.proxies, 0, {}};
  for (size_t i = 0; i < fine.proxies.size(); ++i) {
    SceneProxy& p = fine.proxies[i];
    Mesh mesh = p.mesh == "builtin:box" ? make_box_mesh(p.size_m, 29)            // 6 x 29^2 x 2 = 10092
                : p.mesh == "builtin:cylinder" ? make_cylinder_mesh(p.size_m, 420, 4)  // 420 x (8 + 14) = 9240
                                                : *make_builtin_mesh(p.mesh, p.size_m);
    const fs::path full = work / fmt::format("proxy{}-full.glb", i), reduced = work / fmt::format("proxy{}-10to1.glb", i);
    write_glb(mesh, full);
    MeshSimplifySettings settings;
    settings.ratio = 10;
    const MeshSimplifyResult result = simplify_mesh(mesh, settings);
    write_glb(result.mesh, reduced);
    fine.triangles += mesh.triangle_count();
    simplified.triangles += result.mesh.triangle_count();
    p.mesh = full.string();
    simplified.proxies[i].mesh = reduced.string();
  }
  out.push_back(fine);
  ProxyVariant fine_full = fine;
  fine_full.label = "10k-triangle glTF proxies, no occluder levels (render.occluder_lod_px = 0)";
  fine_full.lod_px = 0;
  out.push_back(fine_full);
  out.push_back(simplified);
  return out;
}

int run_proxies_benchmark(const fs::path& capture, const fs::path& config_path, int repeats) {
  log::set_max_level(log::Level::Warning);
  try {
    const Config base = load_config(config_path);
    const fs::path work = fs::temp_directory_path() / fmt::format("arpipe-bench-proxies-{}", ::getpid());
    fs::create_directories(work);
    const std::vector<ProxyVariant> rows = variants(base, work);
    std::printf("%s with %s: every frame drawn %d times, ground-truth camera motion\n\n", capture.string().c_str(),
                config_path.string().c_str(), repeats);
    std::printf("| proxies | triangles | render ms, no shadows | render ms, shadows | render ms, occluders only | "
                "the occluders' share | of which the hidden-share report | edge error, still frames (mean / worst) | "
                "edge error, blurred frames (mean / worst) |\n");
    std::printf("|---|---|---|---|---|---|---|---|---|\n");
    for (const ProxyVariant& row : rows) {
      Config config = base;
      config.render.proxies = row.proxies;
      if (row.lod_px) config.render.occluder_lod_px = *row.lod_px;
      const bench::ProxyCaptureRun lit = bench::run_proxy_capture(capture, config, repeats);
      // The occluder pass alone: the same proxies with the one role, the config's shadows on,
      // against no proxies, in alternating runs so that the machine's drift cancels.
      Config occluding = config, without = config;
      without.render.proxies.clear();
      for (SceneProxy& proxy : occluding.render.proxies) {
        proxy.roles.occlude = true;
        proxy.roles.receive_shadows = proxy.roles.cast_shadows = false;
      }
      std::vector<double> hiding_ms, shares;
      if (!row.proxies.empty())
        for (int k = 0; k < std::max(3, repeats); ++k) {
          const double none = bench::run_proxy_capture(capture, without, 1).render_ms;
          hiding_ms.push_back(bench::run_proxy_capture(capture, occluding, 1).render_ms);
          shares.push_back((hiding_ms.back() - none) / hiding_ms.back());
        }
      config.render.shadows.method = ShadowMethod::Off;
      const bench::ProxyCaptureRun plain = bench::run_proxy_capture(capture, config, repeats);
      const std::string share = shares.empty() ? std::string("-") : fmt::format("{:.0f} %", 100.0 * bench::median_of(shares));
      const double hiding = hiding_ms.empty() ? lit.render_ms : bench::median_of(hiding_ms);
      std::printf("| %s | %zu | %.2f | %.2f | %.2f | %s | %.2f | %.3f / %.3f px | %.3f / %.3f px |\n", row.label.c_str(),
                  row.triangles, plain.render_ms, lit.render_ms, hiding, share.c_str(), lit.occlusion_ms,
                  plain.mean_still_px, plain.worst_still_px, plain.mean_blurred_px, plain.worst_blurred_px);
      std::fflush(stdout);
    }
    fs::remove_all(work);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "arpipe bench proxies: %s\n", e.what());
    return 1;
  }
  return 0;
}

}  // namespace

void add_proxies_benchmark(CLI::App& bench) {
  CLI::App* command = bench.add_subcommand(
      "proxies", "phantom proxies: render time against the occlusion edge's error, full and simplified proxies");
  command->footer(
      "Draws every frame of the proxies capture (configs/sim/proxies.toml) with the ground-truth camera motion and\n"
      "prints, per set of proxies, the median render-stage time per frame (with and without shadows) and the mean\n"
      "displacement of the occlusion edge against the simulator's visible coverage, on frames under and over 1 px\n"
      "of motion blur.");
  struct Options {
    fs::path capture = fs::path(ARPIPE_BINARY_DIR) / "proxies-capture";
    fs::path config = "configs/proxies.toml";
    int repeats = 3;
  };
  auto options = std::make_shared<Options>();
  command->add_option("--capture", options->capture, "a capture with ground_truth_coverage/")->type_name("DIR");
  command->add_option("--config", options->config, "the config with the proxies")->type_name("FILE");
  command->add_option("--repeats", options->repeats, "times each capture is drawn for the timings")->check(CLI::Range(1, 100));
  cli::on_run(command, [options] { return run_proxies_benchmark(options->capture, options->config, options->repeats); }, cli::Failure{});
}

}  // namespace arpipe
