// arpipe simulate: renders a simulator scene (configs/sim/*.toml) into a recording with ground truth.
#include <fmt/format.h>

#include <charconv>
#include <cstdio>
#include <exception>
#include <new>
#include <stdexcept>

#include "apps/arpipe/commands.h"
#include "apps/arpipe/progress_bar.h"
#include "capture/sim/sim_scene_loader.h"
#include "capture/sim/simulator.h"
#include "core/log.h"

namespace arpipe {

namespace {
constexpr const char* kUsage =
    "usage: arpipe simulate --scene FILE --out DIR [--frames N] [--seed S] [--threads N] [--samples N]\n"
    "  Renders the scene (docs/SIMULATOR.md) into a recording at DIR (which must not hold one),\n"
    "  with ground truth, and DIR/ground_truth_composite when the scene has virtual objects.\n"
    "  --samples overrides the scene's render.samples_per_pixel (a square number).\n";

template <typename T>
bool parse_number(const std::string& text, T& out) {
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), out);
  return ec == std::errc() && end == text.data() + text.size();
}
}  // namespace

int run_simulate(const Args& args) {
  std::string scene_path;
  sim::SimulateOptions options;
  int samples = 0;
  for (size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--help" || args[i] == "-h") {
      std::fputs(kUsage, stdout);
      return 0;
    }
    if (i + 1 >= args.size()) {
      fmt::print(stderr, "arpipe simulate: {} needs a value\n{}", args[i], kUsage);
      return 2;
    }
    const std::string& key = args[i];
    const std::string& value = args[++i];
    bool ok = true;
    if (key == "--scene") scene_path = value;
    else if (key == "--out") options.out_dir = value;
    else if (key == "--frames") ok = parse_number(value, options.frames) && options.frames > 0;
    else if (key == "--seed") {
      uint64_t seed = 0;
      ok = parse_number(value, seed);
      options.seed = seed;
    } else if (key == "--threads") ok = parse_number(value, options.threads) && options.threads > 0;
    else if (key == "--samples") ok = parse_number(value, samples) && sim::samples_per_axis(samples) > 0;
    else {
      fmt::print(stderr, "arpipe simulate: unknown option {}\n{}", key, kUsage);
      return 2;
    }
    if (!ok) {
      fmt::print(stderr, "arpipe simulate: bad value '{}' for {}\n{}", value, key, kUsage);
      return 2;
    }
  }
  if (scene_path.empty() || options.out_dir.empty()) {
    fmt::print(stderr, "arpipe simulate: --scene and --out are required\n{}", kUsage);
    return 2;
  }
  sim::SimScene scene;
  try {
    scene = sim::load_sim_scene(scene_path);
  } catch (const std::bad_alloc&) {  // the loaders cap what they allocate; this names the file if one did not
    log::error("{}: out of memory while loading the scene and its assets", scene_path);
    return 2;
  } catch (const std::length_error& e) {
    log::error("{}: a size in the scene or its assets is too large ({})", scene_path, e.what());
    return 2;
  } catch (const std::exception& e) {
    log::error("{}", e.what());
    return 2;
  }
  if (samples > 0) scene.render.samples_per_pixel = samples;
  ProgressBar progress("frames");
  options.on_frame = [&progress](int done, int total) { progress.update(done, total); };
  try {
    const sim::SimulateSummary summary = sim::simulate(scene, options);
    progress.finish();
    log::info("wrote {} frames to {} in {:.1f} s ({:.1f} s setup, {:.2f} s per frame{})", summary.frames,
              options.out_dir.string(), summary.seconds, summary.setup_seconds,
              (summary.seconds - summary.setup_seconds) / summary.frames,
              summary.wrote_composite ? ", with the ground-truth composite" : "");
    return 0;
  } catch (const std::bad_alloc&) {
    progress.finish();
    log::error("{}: out of memory while simulating into {}", scene_path, options.out_dir.string());
    return 1;
  } catch (const std::exception& e) {
    progress.finish();
    log::error("{}", e.what());
    return 1;
  }
}

}  // namespace arpipe
