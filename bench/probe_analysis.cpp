// Benchmark: the light-probe analyses per frame (ProbeLightEstimator::update: region, decode and
// method) on the probe-indoor capture, run time against light-direction error to the true key light.
// `arpipe bench probe [--capture DIR] [--repeats N]` prints markdown tables for docs/BENCHMARKS.md.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "apps/cli/command_line.h"
#include "bench/benchmarks.h"
#include "capture/recording/recording_reader.h"
#include "core/image/pixel_convert.h"
#include "core/probe/probe_light_estimator.h"
#include "core/log.h"

namespace arpipe {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
  return v[v.size() / 2];
}

double angle_deg(const Vec3& a, const Vec3& b) {
  return std::atan2(norm(cross(a, b)), dot(a, b)) * 180 / std::numbers::pi;
}

struct Row {
  std::string probe;
  ProbeMethod method = ProbeMethod::Auto;
  double light_distance_m = 0;  // < 0: unknown, and a diffuse fit takes the light as far
  // The method's name, and for a fit without a distance "(far light)".
  std::string label() const {
    return std::string(probe_method_name(method)) + (light_distance_m < 0 ? " (far light)" : "");
  }
};

int run_probe_benchmark(const std::string& capture, int repeats) {
  try {
    RecordingReader reader(capture);
    const auto& truth = reader.ground_truth();
    if (truth.size() != reader.frame_count()) {
      log::error("{}: no ground truth", capture);
      return 1;
    }
    std::vector<Frame> frames(reader.frame_count());
    for (size_t i = 0; i < frames.size(); ++i) reader.read(i, frames[i]);
    const CameraModel& model = reader.camera_model();
    fmt::print("capture: {} ({} frames, {}x{} {}), {} repeats\n\n", capture, frames.size(), reader.info().width,
               reader.info().height, pixel_format_name(reader.info().pixel_format), repeats);

    // What the design choices rest on: converting the whole frame versus the probe's rect, and
    // mrcal's unproject per pixel (why the rays are cached).
    {
      std::vector<uint8_t> rgb;
      std::vector<double> t;
      for (int r = 0; r < repeats; ++r) {
        const auto t0 = Clock::now();
        to_rgb24(frames[0], rgb);
        t.push_back(ms_since(t0));
      }
      std::vector<Vec2> px;
      for (int y = 200; y < 290; ++y)
        for (int x = 100; x < 190; ++x) px.push_back({double(x), double(y)});
      std::vector<Vec3> rays;
      const auto t0 = Clock::now();
      model.unproject(px, rays);
      const double unproject_ms = ms_since(t0);
      fmt::print("to_rgb24 of the whole frame: {:.3f} ms; mrcal unproject of a 90x90 rect ({}): {:.3f} ms\n\n",
                 median(t), model.lensmodel(), unproject_ms);
    }

    const ProbeSphere mirror{ProbeSphere::Kind::Mirror, {-0.15, 0.10, 0.0395}, 0.04, 0.9};
    const ProbeSphere diffuse{ProbeSphere::Kind::Diffuse, {0.15, 0.16, 0.0395}, 0.04, 0.7};
    const std::vector<Row> rows = {
        {"mirror", ProbeMethod::Environment, 0},      {"mirror", ProbeMethod::Environment, 0.5},
        {"mirror", ProbeMethod::BrightestImage, 0},   {"mirror", ProbeMethod::BrightestSphere, 0},
        {"diffuse", ProbeMethod::Fit, 0},             {"diffuse", ProbeMethod::Fit, -1},
        {"diffuse", ProbeMethod::BrightestImage, 0},  {"diffuse", ProbeMethod::BrightestSphere, 0},
    };
    fmt::print("| probe | method | lamp distance given | ms per frame (median) | first frame ms (cold ray cache) | "
               "direction error median / max (deg) | key irradiance / truth (green) |\n");
    fmt::print("|---|---|---|---|---|---|---|\n");
    for (const Row& row : rows) {
      ProbeLightConfig config;
      config.sphere = row.probe == "mirror" ? mirror : diffuse;
      config.method = row.method;
      config.light_distance_m = std::max(0.0, row.light_distance_m);
      config.fit_light_distance = row.light_distance_m >= 0;
      config.smoothing_s = 0;  // raw per-frame errors
      std::vector<double> times, errors, ratio;
      double first_ms = 0;
      for (int r = 0; r < repeats; ++r) {
        ProbeLightEstimator est;
        est.configure(config);
        for (size_t i = 0; i < frames.size(); ++i) {
          const auto t0 = Clock::now();
          const LightEstimate e = est.update(frames[i], model, truth[i].T_cam_world_mid, true);
          const double ms = ms_since(t0);
          if (r == 0 && i == 0) first_ms = ms;
          else times.push_back(ms);
          if (r > 0 || e.lights.empty()) continue;
          const GroundTruthLight* key = nullptr;
          for (const GroundTruthLight& l : truth[i].lights)
            if (l.name == "key") key = &l;
          if (key == nullptr) continue;
          const Vec3 d = key->position - config.sphere.center_world;
          errors.push_back(angle_deg(e.lights[0].direction_world, normalized(d)));
          const double e_true = key->strength / dot(d, d) * 100 * key->color[1];  // sensitivity 100
          ratio.push_back(e.lights[0].irradiance[1] / e_true);
        }
      }
      const std::string given = row.light_distance_m > 0 ? fmt::format("{} m", row.light_distance_m) : "no";
      fmt::print("| {} | {} | {} | {:.3f} | {:.2f} | {:.2f} / {:.2f} | {} |\n", row.probe, row.label(), given,
                 median(times), first_ms, median(errors), errors.empty() ? NAN : *std::max_element(errors.begin(), errors.end()),
                 ratio.empty() || std::isnan(median(ratio)) ? std::string("-") : fmt::format("{:.3f}", median(ratio)));
    }
  } catch (const std::exception& e) {
    log::error("{}", e.what());
    return 1;
  }
  return 0;
}

}  // namespace

void add_probe_benchmark(CLI::App& bench) {
  CLI::App* command = bench.add_subcommand(
      "probe", "the light-probe analyses per frame: run time against light-direction error to the true key light");
  struct Options {
    std::string capture = "build/probe-indoor-capture";
    int repeats = 20;
  };
  auto options = std::make_shared<Options>();
  command->add_option("--capture", options->capture, "the probe-indoor capture (or one like it)")->type_name("DIR");
  command->add_option("--repeats", options->repeats, "runs over the capture per row")->check(CLI::PositiveNumber);
  cli::on_run(command, [options] { return run_probe_benchmark(options->capture, options->repeats); }, cli::Failure{});
}

}  // namespace arpipe
