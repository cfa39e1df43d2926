// arpipe bench blur: run time against error of the motion-blur methods on a simulated pan
// (configs/sim/blur-bench.toml): each method and sample count against the converged "accumulate"
// reference (PSNR and SSIM over the object's footprint), and the whole pipeline's output against
// the simulator's ray-traced, physically blurred picture of the same virtual object.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <limits>
#include <memory>
#include <mutex>
#include <numbers>
#include <numeric>
#include <optional>
#include <string>
#include <vector>

#include "apps/cli/command_line.h"
#include "apps/cli/progress_bar.h"
#include "apps/common/pipeline_assembly.h"
#include "bench/benchmarks.h"
#include "capture/recording/recording_reader.h"
#include "capture/sim/sim_scene_loader.h"
#include "capture/sim/simulator.h"
#include "core/image/image_quality.h"
#include "core/image/pixel_convert.h"
#include "core/log.h"
#include "render/gl_stages.h"

namespace arpipe {
namespace {

namespace fs = std::filesystem;

struct Variant {
  BlurMethod method = BlurMethod::Off;
  int samples = 0;  // 0: from the motion
  std::string label() const {
    return samples > 0 ? fmt::format("{} {}", blur_method_name(method), samples) : fmt::format("{} auto", blur_method_name(method));
  }
};

// Keeps what tracking and motion found for each frame (pass 1), to draw it again per variant.
class KeepContexts : public FrameSink {
 public:
  std::string describe() const override { return "bench: keep frames"; }
  void consume(const FrameContext& ctx) noexcept override {
    std::lock_guard lock(mutex_);
    frames.push_back(ctx);
  }
  std::mutex mutex_;
  std::vector<FrameContext> frames;
};

struct Rendered {
  std::vector<uint8_t> rgb;  // the composite, empty when not drawn
  double render_ms = 0;
  std::string blur_method;
  int blur_samples = 0;
};

// The render and composite stages configured for one variant, kept to draw frames again.
class VariantRenderer {
 public:
  VariantRenderer(const Config& base, const Variant& variant, const std::shared_ptr<const CameraModel>& camera_model)
      : stages_(make_gl_stages()) {
    Config config = base;
    config.render.blur.method = variant.method;
    config.render.blur.samples = variant.samples;
    for (auto& stage : stages_) stage->configure(config);
    for (auto& stage : stages_) stage->prepare(camera_model);
  }

  Rendered draw(const FrameContext& frame) {
    FrameContext ctx;
    ctx.camera = frame.camera;
    ctx.camera_model = frame.camera_model;
    ctx.pose = frame.pose;
    ctx.motion = frame.motion;
    ctx.input_index = frame.input_index;
    for (auto& stage : stages_) stage->process(ctx);
    Rendered r;
    if (ctx.virtual_layer_drawn) r.rgb = std::move(ctx.output.data);
    for (const StageTiming& t : ctx.timings)
      if (t.stage == "render") r.render_ms = t.ms;
    r.blur_method = ctx.blur_method;
    r.blur_samples = ctx.blur_samples;
    return r;
  }

 private:
  std::vector<std::unique_ptr<Stage>> stages_;
};

std::vector<Rendered> draw_all(const Config& base, const Variant& variant, const std::vector<FrameContext>& frames) {
  VariantRenderer renderer(base, variant, frames.front().camera_model);
  std::vector<Rendered> out;
  for (const FrameContext& frame : frames) out.push_back(renderer.draw(frame));
  return out;
}

double median(std::vector<double> values) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

// Pixels where a composite differs from the camera frame: where the virtual layer drew something.
std::vector<uint8_t> drawn_mask(const std::vector<uint8_t>& composite, const std::vector<uint8_t>& background) {
  std::vector<uint8_t> mask(composite.size() / 3, 0);
  for (size_t i = 0; i < mask.size(); ++i)
    mask[i] = composite[3 * i] != background[3 * i] || composite[3 * i + 1] != background[3 * i + 1] ||
              composite[3 * i + 2] != background[3 * i + 2];
  return mask;
}

struct Score {
  double psnr_db = 0;
  double ssim = 0;
};

// Pooled PSNR (one MSE over every masked pixel of every frame) and the mean of the frames' SSIM.
Score score(const std::vector<std::vector<uint8_t>>& got, const std::vector<std::vector<uint8_t>>& want,
            const std::vector<std::vector<uint8_t>>& masks, int width, int height) {
  double squared = 0, samples = 0, ssim_sum = 0;
  int frames = 0;
  for (size_t i = 0; i < got.size(); ++i) {
    const RgbView a{got[i], width, height}, b{want[i], width, height};
    const double psnr = masked_psnr(a, b, masks[i]);
    if (std::isnan(psnr)) continue;
    const double count = 3.0 * double(std::count(masks[i].begin(), masks[i].end(), uint8_t{1}));
    if (std::isfinite(psnr)) squared += count * 255.0 * 255.0 / std::pow(10.0, psnr / 10);
    samples += count;
    ssim_sum += masked_ssim(a, b, masks[i]);
    ++frames;
  }
  if (frames == 0) return {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
  const double mse = squared / samples;
  return {mse > 0 ? 10 * std::log10(255.0 * 255.0 / mse) : std::numeric_limits<double>::infinity(), ssim_sum / frames};
}

// The simulator's first directional light and constant sky, through its sensor (radiance x exposure
// x sensitivity x gains, docs/SIMULATOR.md), as the renderer's light and ambient: what light
// estimation will supply; without it the comparison with the simulator would measure the
// difference in shading rather than in blur. The ambient is the sky seen by an upward face (the
// renderer's ambient does not fall off on the sides as the simulator's sky does).
void light_as_the_simulator(const sim::SimScene& scene, RenderConfig& render) {
  const double scale = double(scene.camera.exposure_ns.front()) * 1e-9 * scene.camera.sensor.sensitivity *
                       scene.camera.analogue_gain * scene.camera.digital_gain;
  for (const sim::SimLight& light : scene.lights) {
    if (light.kind != sim::SimLight::Kind::Directional) continue;
    render.light_direction = light.direction_to_light;
    for (size_t c = 0; c < 3; ++c) render.light_color[c] = scale * light.irradiance / std::numbers::pi * light.color[c];
    break;
  }
  if (scene.environment.hdr_path.empty())
    for (size_t c = 0; c < 3; ++c) render.ambient[c] = scale * scene.environment.radiance[c];
}

Config bench_config(const fs::path& config_path, const std::vector<std::string>& overrides, const fs::path& capture) {
  std::vector<std::string> all = overrides;
  Config config = config_path.empty() ? parse_config("", "arpipe bench blur", all) : load_config(config_path, all);
  if (config_path.empty()) {
    // configs/arpipe.toml's object, lit as the simulator lights the virtual cube (below).
    config.render.objects = {SceneObject{}};
    if (fs::exists(capture / "scene.toml")) light_as_the_simulator(sim::load_sim_scene(capture / "scene.toml"), config.render);
  }
  config.source.type = SourceType::Replay;
  config.source.path = capture;
  config.source.pacing = ReplayPacing::Fast;
  config.source.loop = false;
  // Interpolated motion: the best estimate the pipeline can make (one frame of latency).
  config.motion.latency_frames = 1;
  config.sinks = SinksConfig{};
  config.sinks.png.enabled = config.sinks.y4m.enabled = config.sinks.results.enabled = false;
  config.sinks.recording.enabled = false;
  return config;
}

struct BlurOptions {
  fs::path capture, scene_path = "configs/sim/blur-bench.toml", out_dir = "out/bench-blur", config_path;
  int frames_limit = 0, reference_samples = 256;
  std::vector<std::string> overrides;
};

int run_blur_benchmark(BlurOptions options) {
  fs::path& capture = options.capture;
  const fs::path& scene_path = options.scene_path;
  const fs::path& out_dir = options.out_dir;
  const fs::path& config_path = options.config_path;
  const int frames_limit = options.frames_limit, reference_samples = options.reference_samples;
  const std::vector<std::string>& overrides = options.overrides;
  try {
    if (capture.empty()) {
      capture = out_dir / "capture";
      if (fs::exists(capture / "frames.jsonl")) {
        log::info("reusing the capture in {} (delete it to simulate again)", capture.string());
      } else {
        sim::SimulateOptions options;
        options.out_dir = capture;
        options.frames = frames_limit;
        ProgressBar progress("simulating");
        options.on_frame = [&progress](int done, int total) { progress.update(done, total); };
        const sim::SimulateSummary summary = sim::simulate(sim::load_sim_scene(scene_path), options);
        progress.finish();
        log::info("simulated {} frames of {} in {:.0f} s", summary.frames, scene_path.string(), summary.seconds);
      }
    }
    const fs::path truth_dir = capture / "ground_truth_composite";
    if (!fs::exists(truth_dir / "frames.jsonl"))
      throw std::runtime_error(fmt::format("{}: no ground_truth_composite/ (the scene needs a virtual object)", capture.string()));

    // Pass 1: tracking and motion, as the daemon runs them.
    Config config = bench_config(config_path, overrides, capture);
    Config track_only = config;
    track_only.render.blur.method = BlurMethod::Off;  // rendering stays on: tracking runs only for something to draw
    auto keep = std::make_unique<KeepContexts>();
    KeepContexts* kept = keep.get();
    std::vector<std::unique_ptr<FrameSink>> sinks;
    sinks.push_back(std::move(keep));
    PipelineRunner runner(make_source(track_only), make_stage_factory(), std::move(sinks), track_only);
    runner.start();
    runner.wait();
    std::vector<FrameContext> frames = std::move(kept->frames);
    std::sort(frames.begin(), frames.end(), [](const auto& a, const auto& b) { return a.input_index < b.input_index; });
    int tracked = 0;
    for (const FrameContext& f : frames) tracked += f.pose.state == TrackState::Tracking || f.pose.state == TrackState::Predicted;
    log::info("tracking: {} of {} frames with a pose", tracked, frames.size());
    if (frames.empty()) throw std::runtime_error(capture.string() + ": no frames");
    const int width = frames.front().camera.width, height = frames.front().camera.height;

    // The variants, the converged reference first.
    std::vector<Variant> variants{{BlurMethod::Accumulate, reference_samples}, {BlurMethod::Off, 0}};
    for (int n : {4, 8, 16, 32, 64}) variants.push_back({BlurMethod::Accumulate, n});
    variants.push_back({BlurMethod::Accumulate, 0});
    for (int n : {4, 8, 16, 32, 50}) variants.push_back({BlurMethod::IntraframeWarp, n});
    variants.push_back({BlurMethod::IntraframeWarp, 0});
    for (int n : {4, 8, 16, 32}) variants.push_back({BlurMethod::Velocity, n});
    variants.push_back({BlurMethod::Velocity, 0});

    std::vector<std::vector<Rendered>> results;
    ProgressBar progress("variants");
    for (size_t v = 0; v < variants.size(); ++v) {
      results.push_back(draw_all(config, variants[v], frames));
      progress.update(int(v + 1), int(variants.size()));
    }
    progress.finish();

    // Which frames count: drawn by the reference with blur (moving) or sharp (still).
    const RecordingReader truth(truth_dir);
    std::vector<size_t> moving, still;
    for (size_t i = 0; i < frames.size(); ++i) {
      if (results[0][i].rgb.empty()) continue;
      (results[0][i].blur_method == "off" ? still : moving).push_back(i);
    }
    std::vector<std::vector<uint8_t>> backgrounds(frames.size()), truths(frames.size());
    std::vector<std::vector<uint8_t>> footprint(frames.size());
    for (size_t i : moving) {
      to_rgb24(frames[i].camera, backgrounds[i]);
      Frame truth_frame;
      truth.read(size_t(frames[i].input_index), truth_frame);
      to_rgb24(truth_frame, truths[i]);
      footprint[i] = dilate_mask(drawn_mask(results[0][i].rgb, backgrounds[i]), width, height, 2);
    }

    fmt::print("\n# arpipe bench blur: {} ({} frames: {} with motion >= {} px, {} still; reference: accumulate {})\n\n",
               capture.string(), frames.size(), moving.size(), config.render.blur.min_motion_px, still.size(),
               reference_samples);
    fmt::print("| method | samples (median) | render ms/frame (median, moving) | time vs reference | PSNR dB vs reference | SSIM vs reference | PSNR dB vs simulator | SSIM vs simulator |\n");
    fmt::print("|---|---|---|---|---|---|---|---|\n");
    const double reference_ms = [&] {
      std::vector<double> ms;
      for (size_t i : moving) ms.push_back(results[0][i].render_ms);
      return median(ms);
    }();
    for (size_t v = 0; v < variants.size(); ++v) {
      std::vector<std::vector<uint8_t>> got, want, want_truth, masks;
      std::vector<double> ms, samples;
      for (size_t i : moving) {
        const Rendered& r = results[v][i];
        if (r.rgb.empty()) continue;
        got.push_back(r.rgb);
        want.push_back(results[0][i].rgb);
        want_truth.push_back(truths[i]);
        // The footprint of both: where either drew.
        std::vector<uint8_t> mask = footprint[i];
        const std::vector<uint8_t> mine = drawn_mask(r.rgb, backgrounds[i]);
        for (size_t k = 0; k < mask.size(); ++k) mask[k] = mask[k] || mine[k];
        masks.push_back(std::move(mask));
        ms.push_back(r.render_ms);
        samples.push_back(r.blur_samples);
      }
      const Score vs_reference = score(got, want, masks, width, height);
      const Score vs_truth = score(got, want_truth, masks, width, height);
      const double t = median(ms);
      fmt::print("| {} | {:.0f} | {:.2f} | {:.3f} | {:.2f} | {:.4f} | {:.2f} | {:.4f} |\n",
                 v == 0 ? variants[v].label() + " (reference)" : variants[v].label(), median(samples), t,
                 t / reference_ms, vs_reference.psnr_db, vs_reference.ssim, vs_truth.psnr_db, vs_truth.ssim);
    }
    // Frames without motion: each method's default against the no-blur path on the same frames,
    // interleaved and repeated, so that the comparison does not depend on when each ran.
    constexpr int kStillRepeats = 30;
    const std::vector<Variant> still_variants{{BlurMethod::Off, 0}, {BlurMethod::Accumulate, 0}, {BlurMethod::IntraframeWarp, 0}, {BlurMethod::Velocity, 0}};
    std::vector<VariantRenderer> renderers;
    for (const Variant& variant : still_variants) renderers.emplace_back(config, variant, frames.front().camera_model);
    std::vector<std::vector<double>> still_ms(still_variants.size());
    for (int repeat = 0; repeat < kStillRepeats; ++repeat)
      for (size_t v = 0; v < still_variants.size(); ++v)
        for (size_t i : still) still_ms[v].push_back(renderers[v].draw(frames[i]).render_ms);
    fmt::print("\nStill frames (motion below {} px): render ms/frame, median over {} frames x {} interleaved repeats\n\n"
               "| method | ms | vs off |\n|---|---|---|\n",
               config.render.blur.min_motion_px, still.size(), kStillRepeats);
    for (size_t v = 0; v < still_variants.size(); ++v)
      fmt::print("| {} | {:.2f} | {:.2f} |\n", still_variants[v].label(), median(still_ms[v]),
                 median(still_ms[v]) / median(still_ms[0]));
    return 0;
  } catch (const std::exception& e) {
    log::error("{}", e.what());
    return 1;
  }
}

}  // namespace

void add_blur_benchmark(CLI::App& bench) {
  CLI::App* command = bench.add_subcommand(
      "blur", "motion-blur methods: time against error (PSNR, SSIM) vs the converged reference and the simulator's truth");
  auto options = std::make_shared<BlurOptions>();
  command->add_option("--capture", options->capture, "a recording with ground_truth_composite/")
      ->type_name("DIR")
      ->default_str("simulate --scene into --out");
  command->add_option("--scene", options->scene_path, "the simulator scene")->type_name("FILE");
  command->add_option("--out", options->out_dir, "where the simulated capture goes (reused when present)")
      ->type_name("DIR");
  command->add_option("--frames", options->frames_limit, "simulate only the first N frames (0: all)")
      ->check(CLI::NonNegativeNumber);
  command->add_option("--reference-samples", options->reference_samples, "renders of the accumulate reference")
      ->check(CLI::Range(2, 1024));
  command->add_option("--config", options->config_path, "pipeline config for the objects, light and lens")
      ->type_name("FILE")
      ->default_str("configs/arpipe.toml's cube");
  command->add_option("--set", options->overrides, "override one config key (VALUE in TOML syntax); repeatable")
      ->type_name("KEY=VALUE")
      ->allow_extra_args(false);
  cli::on_run(command, [options] { return run_blur_benchmark(*options); }, cli::Failure{});
}

}  // namespace arpipe
