// arpipe bench shadows: each shadow method and map size, time per frame against the error of the
// shadow on the ground relative to the simulator's ray-traced truth (apps/bench/shadow_comparison.h),
// on probe-indoor (a lamp, PCSS penumbra from its size) and sun-outdoor (the sun's 0.53 degrees).
#include <fmt/format.h>

#include <cstdio>
#include <string>
#include <vector>

#include "apps/arpipe/commands.h"
#include "apps/bench/shadow_comparison.h"
#include "core/log.h"

namespace arpipe {
namespace {

constexpr const char* kUsage =
    "usage: arpipe bench shadows [--frames N] [--scenes DIR]\n"
    "  Draws the virtual ball of configs/sim/probe-indoor.toml and sun-outdoor.toml with every\n"
    "  render.shadows method at map sizes 512, 1024 and 2048, the shadow map redrawn every frame,\n"
    "  and prints the median shadow-map and render-stage times per frame beside the mean absolute\n"
    "  error of the shadow ratio on the ground against the simulator's ray-traced truth.\n"
    "  --frames N    frames per row (default 12)\n"
    "  --scenes DIR  where the simulator scenes are (default configs/sim)\n";

struct Row {
  std::string label, method;
  int pcf_kernel = 3;
};

}  // namespace

int run_bench_shadows(const Args& args) {
  int frames = 12;
  std::filesystem::path scenes = "configs/sim";
  for (size_t i = 0; i < args.size(); ++i) {
    const auto value = [&]() -> const std::string& {
      if (i + 1 >= args.size()) throw std::invalid_argument(fmt::format("{} needs a value", args[i]));
      return args[++i];
    };
    try {
      if (args[i] == "--frames") frames = std::stoi(value());
      else if (args[i] == "--scenes") scenes = value();
      else if (args[i] == "--help" || args[i] == "-h") {
        std::fputs(kUsage, stdout);
        return 0;
      } else {
        throw std::invalid_argument(fmt::format("unknown argument \"{}\"", args[i]));
      }
    } catch (const std::exception& e) {
      std::fprintf(stderr, "arpipe bench shadows: %s\n%s", e.what(), kUsage);
      return 2;
    }
  }
  if (frames < 1 || frames > 1000) {
    std::fprintf(stderr, "arpipe bench shadows: --frames must be in [1, 1000]\n");
    return 2;
  }
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

}  // namespace arpipe
