// arpipe bench shadows: each shadow method and map size, time per frame against the error of the
// shadow on the ground relative to the simulator's ray-traced truth (bench/shadow_comparison.h),
// on probe-indoor (a lamp, PCSS penumbra from its size) and sun-outdoor (the sun's 0.53 degrees).
#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "apps/cli/command_line.h"
#include "bench/benchmarks.h"
#include "bench/shadow_comparison.h"
#include "core/log.h"

namespace arpipe {
namespace {

struct Row {
  std::string label, method;
  int pcf_kernel = 3;
};

int run_shadows_benchmark(int frames, const std::filesystem::path& scenes) {
  log::set_max_level(log::Level::Warning);
  const std::vector<Row> rows{{"hard (the seed's SM)", "hard"},   {"pcf 3x3", "pcf", 3}, {"pcf 8x8", "pcf", 8},
                              {"pcss", "pcss"},                   {"vsm (7-tap blur)", "vsm"},
                              {"vsm-packed (RGBA8)", "vsm-packed"}};
  const std::vector<bench::ShadowScene> setups{bench::probe_indoor_shadow_scene(), bench::sun_outdoor_shadow_scene()};
  try {
    for (const bench::ShadowScene& setup : setups) {
      bench::shadow_truth(scenes, setup);  // ray traced once, before the timings
      std::printf("\n%s (%s)\n\n", setup.file.c_str(),
                  norm(setup.light_position) > 0 ? "a lamp: perspective map" : "the sun: orthographic map");
      std::printf("| method | map | shadow map ms | render ms (map included) | MAE vs ray traced | pixels |\n");
      std::printf("|---|---|---|---|---|---|\n");
      // The same stages without shadows: the cost that is not the shadow's.
      const bench::ShadowComparison none = bench::compare_shadow(scenes, setup, "off", 1024, frames);
      std::printf("| off | - | - | %.2f | %.4f | %d |\n", none.render_ms, none.mae, none.pixels);
      for (const Row& row : rows)
        for (int size : {512, 1024, 2048}) {
          bench::ShadowComparison c;
          if (row.pcf_kernel != 3) {
            // The seed's 8x8 window: set through the config the comparison builds.
            c = bench::compare_shadow(scenes, setup, row.method + ":8", size, frames);
          } else {
            c = bench::compare_shadow(scenes, setup, row.method, size, frames);
          }
          std::printf("| %s | %d | %.2f | %.2f | %.4f | %d |\n", row.label.c_str(), size, c.shadow_ms, c.render_ms,
                      c.mae, c.pixels);
          std::fflush(stdout);
        }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "arpipe bench shadows: %s\n", e.what());
    return 1;
  }
  return 0;
}

}  // namespace

void add_shadows_benchmark(CLI::App& bench) {
  CLI::App* command = bench.add_subcommand(
      "shadows", "shadow methods and map sizes: time against the error of the shadow on the ground vs ray tracing");
  command->footer(
      "Draws the virtual ball of configs/sim/probe-indoor.toml and sun-outdoor.toml with every render.shadows\n"
      "method at map sizes 512, 1024 and 2048, the shadow map redrawn every frame, and prints the median\n"
      "shadow-map and render-stage times per frame beside the mean absolute error of the shadow ratio on the\n"
      "ground against the simulator's ray-traced truth.");
  struct Options {
    int frames = 12;
    std::filesystem::path scenes = "configs/sim";
  };
  auto options = std::make_shared<Options>();
  command->add_option("--frames", options->frames, "frames per row")->check(CLI::Range(1, 1000));
  command->add_option("--scenes", options->scenes, "where the simulator scenes are")->type_name("DIR");
  cli::on_run(command, [options] { return run_shadows_benchmark(options->frames, options->scenes); }, cli::Failure{});
}

}  // namespace arpipe
