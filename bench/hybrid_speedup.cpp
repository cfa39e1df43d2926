// Benchmark: seed 003's protocol, the hybrid viewer against the full 3D scene. `arpipe bench hybrid
// [--scene FILE] [--config FILE] [--frames N] [--truth-views K] [--work DIR] [--viewpoint X,Y,Z]... ...`
// (the seed repeats its protocol at each viewpoint: each --viewpoint gets its own panorama and
// table, then a summary of the speedups)
//
// From a simulator scene (configs/sim/courtyard.toml: its real objects, lights, sky and virtual
// objects; the camera an equirectangular one at the viewpoint) and the hybrid's config
// (configs/courtyard.toml: the view sweep, the virtual objects, the light, the shadows), it makes
// every input: the panorama still and a video of it, the real objects as one proxy mesh (and each
// object simplified 10:1), the sky alone, and the ray-traced truth of K views of the sweep. Then
// it runs the same sweep (720 degrees at the config's rate, N frames spread over it) through
// arpiped's own pipeline (the source on its thread, the stages on theirs), for
//   (a) the full 3D scene: every real object drawn and shaded as a virtual object, with its
//       shadows, over the sky alone;
//   (b) the hybrid with the video and (c) with the still, each with the proxies whole and 10:1;
// and prints frames/s as the sinks get them (mean = frames / time, the seed's; min and max over
// stretches of 10 frames), the speedup over (a),
// the PSNR of the composited view against the truth, and the occlusion edge's mean displacement
// against the truth's coverage of the virtual objects (issue 22's measure).
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <memory>
#include <numbers>
#include <optional>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "apps/cli/command_line.h"
#include "apps/cli/number_list.h"
#include "apps/common/pipeline_assembly.h"
#include "bench/benchmarks.h"
#include "bench/pipeline_run.h"
#include "bench/proxy_comparison.h"
#include "capture/panorama/panorama_source.h"
#include "capture/recording/recording_reader.h"
#include "capture/sim/ground_truth_coverage.h"
#include "capture/sim/recording_files.h"
#include "capture/sim/scene_export.h"
#include "capture/sim/sim_scene_loader.h"
#include "capture/sim/simulator.h"
#include "capture/sinks/output_path.h"
#include "core/config/config.h"
#include "core/image/pixel_convert.h"
#include "core/log.h"
#include "core/pipeline/frame_sink.h"
#include "core/pipeline/pipeline_runner.h"
#include "core/scene/glb_writer.h"
#include "core/scene/mesh_simplify.h"

namespace arpipe {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = std::numbers::pi;

struct Options {
  std::string scene = "configs/sim/courtyard.toml";
  std::string config = "configs/courtyard.toml";
  std::string work = "build/bench-hybrid";
  int frames = 240;         // over the 720-degree sweep
  int truth_views = 4;      // of them, evenly spread, against the ray-traced truth
  int still_samples = 16;   // rays a pixel: the still, the truth views
  int video_frames = 30;    // the video's length (it loops)
  int video_samples = 4;    // rays a pixel of each video frame
  double ratio = 10;        // the simplified proxies' triangle ratio
  // The viewpoints ("teleport points", each measured as the seed measured its own), as "x,y,z" in
  // metres; empty: the config's source.panorama.position_m alone.
  std::vector<std::string> viewpoints;
};

// "x,y,z" in metres, or nullopt.
std::optional<Vec3> parse_point(const std::string& text) { return cli::parse_number_list<3>(text); }

// ---- The inputs -------------------------------------------------------------------------------

void write_file(const fs::path& path, const std::vector<uint8_t>& bytes) {
  if (const int error = replace_file(path, bytes))
    throw std::runtime_error(fmt::format("{}: {}", path.string(), std::strerror(error)));
}

fs::path simulate_into(const sim::SimScene& scene, const fs::path& dir) {
  fs::remove_all(dir);
  sim::SimulateOptions options;
  options.out_dir = dir;
  options.source_description = "arpipe bench hybrid";
  sim::simulate(scene, options);
  return dir;
}

sim::SimScene without_virtual_objects(sim::SimScene scene) {
  std::erase_if(scene.objects, [](const sim::SimObject& o) { return o.is_virtual; });
  return scene;
}

// The real ground: a level plane at the ground catcher's height (render.shadows.receiver_height_m),
// which the hybrid leaves to the catcher (baked, with the sky's occlusion) rather than to a proxy.
bool is_ground(const sim::SimObject& object, double receiver_height_m) {
  const Mat3& R = object.T_world_object.rotation();
  return object.shape == sim::SimObject::Shape::Plane && !object.is_virtual && std::abs(R[2][2]) > 1 - 1e-9 &&
         std::abs(object.T_world_object.translation()[2] - receiver_height_m) < 1e-3;
}

// Each real object simplified to 1/ratio of its triangles in its own frame (the seed decimated its
// proxies about 10:1), those too small to simplify (a plane, a box) kept whole.
Mesh simplified_world(const sim::SimScene& scene, double ratio) {
  return sim::real_world_mesh(scene, [&](const Mesh& mesh) {
    if (double(mesh.triangle_count()) / ratio < 12) return mesh;
    MeshSimplifySettings settings;
    settings.ratio = ratio;
    settings.normals = ProxyNormals::smooth;
    return simplify_mesh(mesh, settings).mesh;
  });
}

struct Inputs {
  fs::path still, video, sky;
  fs::path world_glb;  // every real object, for the full 3D scene to draw
  fs::path proxies_glb, proxies_simplified_glb;  // the real objects but the ground, whole and simplified
  size_t world_triangles = 0, proxy_triangles = 0, simplified_triangles = 0;
  std::vector<std::string> ground;  // the objects left to the ground catcher
};

Inputs make_inputs(const sim::SimScene& scene, const Config& config, const Options& options, const fs::path& work) {
  Inputs in;
  const sim::SimScene real = without_virtual_objects(scene);
  const Mesh world = sim::real_world_mesh(real);
  in.world_triangles = world.triangle_count();
  in.world_glb = work / "world.glb";
  write_file(in.world_glb, encode_glb(world, "arpipe bench hybrid"));
  sim::SimScene standing = real;
  for (const sim::SimObject& o : real.objects)
    if (is_ground(o, config.render.shadows.receiver_height_m)) in.ground.push_back(o.name);
  std::erase_if(standing.objects, [&](const sim::SimObject& o) { return is_ground(o, config.render.shadows.receiver_height_m); });
  const Mesh proxies = sim::real_world_mesh(standing);
  in.proxy_triangles = proxies.triangle_count();
  in.proxies_glb = work / "proxies.glb";
  write_file(in.proxies_glb, encode_glb(proxies, "arpipe bench hybrid"));
  const Mesh simplified = simplified_world(standing, options.ratio);
  in.simplified_triangles = simplified.triangle_count();
  in.proxies_simplified_glb = work / fmt::format("proxies-{}to1.glb", options.ratio);
  write_file(in.proxies_simplified_glb, encode_glb(simplified, "arpipe bench hybrid"));
  log::info("the full 3D scene: {} triangles; the proxies: {} whole, {} simplified; the ground catcher for: {}",
            in.world_triangles, in.proxy_triangles, in.simplified_triangles,
            in.ground.empty() ? std::string("nothing") : fmt::format("{}", fmt::join(in.ground, ", ")));

  sim::SimScene still = real;
  still.render.samples_per_pixel = options.still_samples;
  still.render.frames = 1;
  auto started = std::chrono::steady_clock::now();
  const fs::path still_dir = simulate_into(still, work / "still");
  sim::write_recording_as_pngs(still_dir);
  in.still = still_dir / "frame_000000.png";
  log::info("the still ({}x{}, {} rays a pixel): {:.1f} s", still.camera.model.width(), still.camera.model.height(),
            options.still_samples, std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count());

  // The video: every frame its own rays (a new seed each), so no two frames are alike.
  sim::SimScene video = real;
  video.render.samples_per_pixel = options.video_samples;
  video.render.frames = options.video_frames;
  video.camera.fps = config.source.panorama.view.fps;
  started = std::chrono::steady_clock::now();
  const fs::path video_dir = simulate_into(video, work / "video-frames");
  in.video = work / "video.mp4";
  sim::write_recording_as_video(video_dir, in.video, video.camera);
  log::info("the video ({} frames, {} rays a pixel): {:.1f} s", options.video_frames, options.video_samples,
            std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count());

  // The sky alone, for the full 3D scene's background (what it clears to): 64 x 32 is enough for
  // a sky that does not change across it; the lookup costs the same at any size.
  sim::SimScene sky = real;
  sky.objects.clear();
  sky.render.samples_per_pixel = 1;
  sky.render.frames = 1;
  sky.camera.model = CameraModel("LENSMODEL_LONLAT", {64 / (2 * kPi), 32 / kPi, 31.5, 15.5}, 64, 32);
  const fs::path sky_dir = simulate_into(sky, work / "sky");
  sim::write_recording_as_pngs(sky_dir);
  in.sky = sky_dir / "frame_000000.png";
  return in;
}

// ---- The runs ---------------------------------------------------------------------------------

struct Path {
  std::string name;
  std::string proxies;  // "whole", "10:1", or how the full 3D scene stands
  Config config;
};

struct Sample {
  cv::Mat rgb;               // the composited view
  SE3 T_cam_world;           // its pose, for the truth
  bool tracked = false;      // the pose was the source's
  std::vector<float> alpha;  // the virtual layer's alpha, drawn without shadows (edge runs only)
};

struct Run {
  std::vector<double> arrivals_s;  // when each frame after the warm-up reached the sinks
  std::vector<Sample> samples;     // at the truth views' frames
};

// The sampled frames: K directions evenly spread around the turn, (k + 1/2) 360 / K degrees past the
// sweep's start, the first half of them in the first turn and the rest in the second (so that a
// video shows other frames there too).
std::vector<size_t> truth_frames(int frames, int views) {
  std::vector<size_t> out;
  for (int k = 0; k < views; ++k) {
    const double degrees = (k + 0.5) * 360.0 / views + (2 * k >= views ? 360.0 : 0.0);
    out.push_back(size_t(kWarmupFrames) + size_t(std::lround(frames * degrees / 720.0)));
  }
  return out;
}

// Keeps when each frame reached the sinks, and the sampled frames' pictures and poses. Runs on the
// sink thread; read once the runner has finished.
class TimingSink final : public FrameSink {
 public:
  TimingSink(std::vector<size_t> samples, Run& run) : samples_(std::move(samples)), run_(run) {}
  std::string describe() const override { return "bench: frame times"; }
  void consume(const FrameContext& ctx) noexcept override {
    const double now = std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
    if (ctx.input_index >= size_t(kWarmupFrames)) run_.arrivals_s.push_back(now);
    if (std::find(samples_.begin(), samples_.end(), ctx.input_index) == samples_.end()) return;
    Sample sample;
    sample.T_cam_world = ctx.pose.T_cam_world;
    sample.tracked = ctx.pose.state == TrackState::Tracking;
    sample.rgb = cv::Mat(ctx.output.height, ctx.output.width, CV_8UC3, const_cast<uint8_t*>(ctx.output.data.data()),
                         ctx.output.bytes_per_line)
                     .clone();
    run_.samples.push_back(std::move(sample));
  }

 private:
  std::vector<size_t> samples_;
  Run& run_;
};

// The sweep through the daemon's own pipeline (the source on its thread, the stages on theirs, as
// arpiped runs them): when each frame reaches the sinks, and the sampled frames.
Run run_timed(const Config& config, const std::vector<size_t>& samples) {
  Run run;
  std::vector<std::unique_ptr<FrameSink>> sinks;
  sinks.push_back(std::make_unique<TimingSink>(samples, run));
  PipelineRunner runner(make_source(config), make_stage_factory(), std::move(sinks), config);
  runner.start();
  runner.wait();
  if (run.samples.size() != samples.size())
    throw std::runtime_error(fmt::format("{} of the {} sampled frames came through", run.samples.size(), samples.size()));
  for (const Sample& sample : run.samples)
    if (!sample.tracked) throw std::runtime_error("a sampled frame has no pose");
  return run;
}

// The sampled frames alone through the stages on this thread (the source still gives every frame,
// so that a video's index and the sweep advance as in the timed run), with the virtual layer's
// alpha read back: that needs the stages' GL context current.
Run run_sampled_with_alpha(const Config& config, const std::vector<size_t>& samples) {
  PanoramaSource source(config.source);
  std::vector<std::unique_ptr<Stage>> stages = make_stage_factory()();
  for (auto& stage : stages) stage->configure(config);
  for (auto& stage : stages) stage->prepare(source.camera_model());
  Run run;
  const size_t total = size_t(config.source.panorama.view.frames);
  for (size_t i = 0; i < total; ++i) {
    FrameContext ctx;
    if (source.next(ctx.camera) != SourceStatus::Frame)
      throw std::runtime_error(fmt::format("{}: no frame {}", source.describe(), i));
    if (std::find(samples.begin(), samples.end(), i) == samples.end()) continue;
    ctx.camera_model = source.camera_model();
    ctx.input_index = i;
    for (auto& stage : stages) stage->process(ctx);
    Sample sample;
    if (ctx.virtual_layer_drawn) sample.alpha = bench::layer_alpha(ctx.virtual_layer);
    run.samples.push_back(std::move(sample));
  }
  return run;
}

// ---- The truth ---------------------------------------------------------------------------------

struct Truth {
  cv::Mat rgb;
  sim::CoverageImage coverage;
};

// The simulator's picture of the view at this pose, with the virtual objects and their shadows.
Truth simulate_truth(const sim::SimScene& scene, const CameraModel& view, const SE3& T_cam_world, int samples,
                     const fs::path& dir) {
  sim::SimScene truth = scene;
  truth.camera.model = view;
  truth.camera.stereo = {};
  truth.render.samples_per_pixel = samples;
  truth.render.frames = 1;
  const SE3 T_world_cam = T_cam_world.inverse();
  const Vec3 centre = T_world_cam.translation();
  const Mat3& R = T_world_cam.rotation();
  sim::SimKeyframe key;
  key.position = centre;
  key.look_at = centre + mat_mul(R, Vec3{0, 0, 1});
  key.up = mat_mul(R, Vec3{0, -1, 0});
  truth.trajectory = {};
  truth.trajectory.keyframes = {key};
  simulate_into(truth, dir);
  const RecordingReader reader(dir / sim::kGroundTruthCompositeDir);
  Frame frame;
  reader.read(0, frame);
  std::vector<uint8_t> rgb;
  to_rgb24(frame, rgb);
  Truth out;
  out.rgb = cv::Mat(frame.height, frame.width, CV_8UC3, rgb.data()).clone();
  out.coverage = sim::read_coverage_frame(dir, 0);
  return out;
}

// ---- The report --------------------------------------------------------------------------------

struct Row {
  std::string path, proxies;
  double fps_min = 0, fps_mean = 0, fps_max = 0;
  double psnr_db = 0;
  double edge_px = -1;  // -1: not measured
  std::string edge_note;
};

// Frames/s: the mean over the sweep (frames / time, the seed's), and the slowest and fastest
// stretch of kFpsWindow frames (single intervals jitter with the threads' hand-overs).
constexpr size_t kFpsWindow = 10;

Row summarise(const Path& path, const Run& run, const std::vector<Truth>& truths) {
  Row row;
  row.path = path.name;
  row.proxies = path.proxies;
  const std::vector<double>& t = run.arrivals_s;
  if (t.size() > kFpsWindow) {
    row.fps_mean = double(t.size() - 1) / (t.back() - t.front());
    row.fps_min = INFINITY;
    for (size_t i = kFpsWindow; i < t.size(); ++i) {
      const double fps = double(kFpsWindow) / (t[i] - t[i - kFpsWindow]);
      row.fps_min = std::min(row.fps_min, fps);
      row.fps_max = std::max(row.fps_max, fps);
    }
  }
  double mse = 0;
  for (size_t k = 0; k < truths.size(); ++k) {
    cv::Mat a, b;
    run.samples[k].rgb.convertTo(a, CV_64F);
    truths[k].rgb.convertTo(b, CV_64F);
    const cv::Mat d = a - b;
    const cv::Scalar channel_mse = cv::mean(d.mul(d));
    mse += (channel_mse[0] + channel_mse[1] + channel_mse[2]) / 3;
  }
  mse /= double(truths.size());
  row.psnr_db = 10 * std::log10(255.0 * 255.0 / std::max(mse, 1e-12));
  return row;
}

// Over the truth views that show a virtual object (from another viewpoint a sampled frame may face
// none); -1 when none does.
double mean_edge_error(const Run& run, const std::vector<Truth>& truths) {
  double sum = 0, length = 0;
  for (size_t k = 0; k < truths.size(); ++k) {
    if (run.samples[k].alpha.empty()) continue;
    const bench::EdgeError e = bench::occlusion_edge_error(run.samples[k].alpha, truths[k].coverage);
    sum += e.displacement_px * e.edge_length_px;  // weighted by the edge's length: the mean over all edges
    length += e.edge_length_px;
  }
  return length > 0 ? sum / length : -1;
}

// One viewpoint: its inputs made in `work`, every path run over the sweep, the table printed.
std::vector<Row> measure_viewpoint(const sim::SimScene& scene, const Config& base, const Options& options,
                                   const fs::path& work) {
  fs::create_directories(work);
  const Inputs in = make_inputs(scene, base, options, work);

  std::vector<Path> paths;
  {
    Path full{"full 3D scene", fmt::format("drawn ({} triangles)", in.world_triangles), base};
    full.config.source.panorama.file = in.sky;
    full.config.render.proxies.clear();
    // It draws the ground itself: the catcher goes under it, out of sight.
    full.config.render.shadows.receiver_height_m -= 0.01;
    SceneObject world;
    world.mesh = in.world_glb.string();
    world.scale = 1;
    world.prt = ObjectPrt::Off;
    full.config.render.objects.push_back(world);
    paths.push_back(std::move(full));
  }
  for (const auto& [name, file] : {std::pair{"hybrid, video", in.video}, std::pair{"hybrid, still", in.still}})
    for (const auto& [proxies, glb] :
         {std::pair{fmt::format("whole ({})", in.proxy_triangles), in.proxies_glb},
          std::pair{fmt::format("{}:1 ({})", options.ratio, in.simplified_triangles), in.proxies_simplified_glb}}) {
      Path hybrid{name, proxies, base};
      hybrid.config.source.panorama.file = file;
      if (hybrid.config.render.proxies.empty())
        throw std::invalid_argument(fmt::format("{}: the hybrid needs a [[render.proxies]] for the scene", options.config));
      hybrid.config.render.proxies.resize(1);
      hybrid.config.render.proxies[0].mesh = glb.string();
      hybrid.config.render.proxies[0].position_m = {0, 0, 0};
      hybrid.config.render.proxies[0].scale = 1;
      paths.push_back(std::move(hybrid));
    }

  const std::vector<size_t> samples = truth_frames(options.frames, options.truth_views);
  std::vector<Run> runs;
  for (const Path& path : paths) {
    log::info("{}, proxies {}: {} frames", path.name, path.proxies, options.frames);
    runs.push_back(run_timed(path.config, samples));
  }

  // The truth at the sampled frames' poses (the last path's: every path has the same sweep).
  const auto view_model = PanoramaSource(paths.back().config.source).camera_model();
  std::vector<Truth> truths;
  for (size_t k = 0; k < samples.size(); ++k)
    truths.push_back(simulate_truth(scene, *view_model, runs.back().samples[k].T_cam_world, options.still_samples,
                                    work / fmt::format("truth-{}", k)));
  for (size_t p = 0; p < paths.size(); ++p)
    for (size_t k = 0; k < samples.size(); ++k) {
      cv::Mat bgr;
      cv::cvtColor(runs[p].samples[k].rgb, bgr, cv::COLOR_RGB2BGR);
      cv::imwrite((work / fmt::format("view-{}-{}.png", k, p)).string(), bgr);
      if (p == 0) {
        cv::cvtColor(truths[k].rgb, bgr, cv::COLOR_RGB2BGR);
        cv::imwrite((work / fmt::format("view-{}-truth.png", k)).string(), bgr);
      }
    }

  // The occlusion edges: the sampled frames again without shadows, so that the layer's alpha is
  // the virtual objects' coverage alone; the proxies decide them, not the background.
  std::vector<Row> rows;
  for (size_t p = 0; p < paths.size(); ++p) rows.push_back(summarise(paths[p], runs[p], truths));
  for (size_t p = 1; p < 3; ++p) {
    Config edges = paths[p + 2].config;  // the still's, whole then simplified
    edges.render.shadows.method = ShadowMethod::Off;
    const double px = mean_edge_error(run_sampled_with_alpha(edges, samples), truths);
    rows[p].edge_px = rows[p + 2].edge_px = px;
  }
  // The full 3D scene hides the virtual objects behind the same triangles, drawn into the same
  // depth buffer, as the whole proxies (and the ground, which hides nothing standing on it): its
  // edges are theirs.
  rows[0].edge_px = rows[1].edge_px;
  rows[0].edge_note = " (the whole proxies')";

  fmt::print("Seed 003's protocol on {} ({} at {}): a 720-degree sweep as {} frames of {}x{} through arpiped's\n"
             "pipeline (frames/s as its sinks get them; min and max over {}-frame stretches); PSNR and edges over {}\n"
             "views against the ray-traced truth.\n"
             "The hybrid leaves the ground ({}) to the ground catcher, the full 3D scene draws it.\n\n",
             options.scene, options.config, fmt::format("({:.2f}, {:.2f}, {:.2f})", base.source.panorama.position_m[0],
                                                        base.source.panorama.position_m[1], base.source.panorama.position_m[2]),
             options.frames, view_model->width(), view_model->height(), kFpsWindow, samples.size(),
             in.ground.empty() ? std::string("none at render.shadows.receiver_height_m") : fmt::format("{}", fmt::join(in.ground, ", ")));
  fmt::print("| path | proxies (triangles) | frames/s min | mean | max | speedup | PSNR (dB) | occlusion edge (px) |\n");
  fmt::print("|---|---|---:|---:|---:|---:|---:|---:|\n");
  for (const Row& row : rows)
    fmt::print("| {} | {} | {:.1f} | {:.1f} | {:.1f} | {:.2f} | {:.2f} | {}{} |\n", row.path, row.proxies, row.fps_min,
               row.fps_mean, row.fps_max, row.fps_mean / rows[0].fps_mean, row.psnr_db,
               row.edge_px < 0 ? std::string("-") : fmt::format("{:.3f}", row.edge_px), row.edge_note);
  return rows;
}

int run_hybrid_benchmark(const Options& options) {
  const sim::SimScene scene = sim::load_sim_scene(options.scene);
  // Its proxies and its full 3D scene are the objects at rest: a scene that moves would be measured
  // against geometry that stands still (render.objects do not follow a glTF animation).
  for (const sim::SimObject& object : scene.objects)
    if (!object.keyframes.empty())
      throw std::invalid_argument(fmt::format("{}: object \"{}\" moves ([[object.keyframe]]); the benchmark's proxies and "
                                              "full 3D scene stand still, so it takes static scenes only",
                                              options.scene, object.name));
  Config base = load_config(options.config);
  if (base.source.type != SourceType::Panorama)
    throw std::invalid_argument(fmt::format("{}: source.type must be \"panorama\"", options.config));
  if (scene.camera.model.lensmodel() != "LENSMODEL_LONLAT" || scene.camera.stereo.enabled)
    throw std::invalid_argument(fmt::format("{}: the camera must be a mono LENSMODEL_LONLAT (the panorama)", options.scene));
  if (scene.trajectory.keyframes.empty() ||
      norm(scene.trajectory.keyframes.front().position - base.source.panorama.position_m) > 1e-3)
    throw std::invalid_argument(fmt::format("{}: the scene's first keyframe must be at source.panorama.position_m of {}",
                                            options.scene, options.config));
  if (!base.source.panorama.viewpoints.empty())
    throw std::invalid_argument(fmt::format(
        "{}: no [[source.panorama.viewpoints]] here; give the benchmark's viewpoints as --viewpoint X,Y,Z", options.config));
  const fs::path work = options.work;

  // The sweep: 720 degrees at the config's rate, as N frames at its frame rate (so a video shows a
  // new frame each): every frame costs what it would, the yaw steps 720 / N degrees.
  PanoramaViewConfig& view = base.source.panorama.view;
  if (view.yaw_rad_per_s == 0) view.yaw_rad_per_s = 12 * kPi / 180;
  const double sweep_rad = std::copysign(4 * kPi, view.yaw_rad_per_s);
  view.yaw_rad_per_s = sweep_rad * view.fps / options.frames;
  view.frames = options.frames + kWarmupFrames;
  view.yaw_rad -= kWarmupFrames * view.yaw_rad_per_s / view.fps;  // the measured frames start at the config's yaw
  view.track.clear();
  view.dwell_s = 0;
  base.render.blur.method = BlurMethod::Off;  // a panorama's frames are instants

  std::vector<Vec3> viewpoints;
  for (const std::string& text : options.viewpoints) viewpoints.push_back(*parse_point(text));  // checked by the option
  if (viewpoints.empty()) viewpoints.push_back(base.source.panorama.position_m);

  // Each viewpoint: the scene's camera and the config's panorama moved there together (the
  // camera's orientation kept), its own inputs in its own folder.
  std::vector<std::vector<Row>> tables;
  for (size_t v = 0; v < viewpoints.size(); ++v) {
    const Vec3 offset = viewpoints[v] - base.source.panorama.position_m;
    sim::SimScene moved = scene;
    for (sim::SimKeyframe& keyframe : moved.trajectory.keyframes) {
      keyframe.position = keyframe.position + offset;
      keyframe.look_at = keyframe.look_at + offset;
    }
    Config at = base;
    at.source.panorama.position_m = viewpoints[v];
    tables.push_back(measure_viewpoint(moved, at, options, viewpoints.size() == 1 ? work : work / fmt::format("viewpoint-{}", v)));
  }
  if (viewpoints.size() > 1) {
    // The seed's summary: each path's frames/s and speedup at every viewpoint, and their means.
    fmt::print("\nAll {} viewpoints (frames/s mean over the sweep; speedup over the full 3D scene at the same viewpoint):\n\n",
               viewpoints.size());
    fmt::print("| path | proxies |");
    for (const Vec3& p : viewpoints) fmt::print(" ({:.2f}, {:.2f}, {:.2f}) |", p[0], p[1], p[2]);
    fmt::print(" mean speedup |\n|---|---|");
    for (size_t v = 0; v < viewpoints.size(); ++v) fmt::print("---:|");
    fmt::print("---:|\n");
    for (size_t r = 0; r < tables[0].size(); ++r) {
      fmt::print("| {} | {} |", tables[0][r].path, tables[0][r].proxies);
      double sum = 0;
      for (const auto& rows : tables) {
        const double speedup = rows[r].fps_mean / rows[0].fps_mean;
        sum += speedup;
        fmt::print(" {:.1f} ({:.2f}x) |", rows[r].fps_mean, speedup);
      }
      fmt::print(" {:.2f} |\n", sum / double(tables.size()));
    }
  }
  return 0;
}

}  // namespace

void add_hybrid_benchmark(CLI::App& bench) {
  CLI::App* command = bench.add_subcommand(
      "hybrid", "seed 003's protocol: the hybrid (video, still; proxies whole and 10:1) against the full 3D scene: "
                "frames/s, speedup, PSNR and occlusion edges against the ray-traced truth");
  auto options = std::make_shared<Options>();
  command->add_option("--scene", options->scene, "the simulator scene (its camera the panorama's)")->type_name("FILE");
  command->add_option("--config", options->config, "the hybrid's config for it")->type_name("FILE");
  command->add_option("--work", options->work, "where the inputs, truth views and sampled frames go")->type_name("DIR");
  command->add_option("--frames", options->frames, "frames over the 720-degree sweep (the seed's 12 degrees/s at 30 "
                                                   "frames/s: 1800)")
      ->check(CLI::Range(8, 100000));
  command->add_option("--truth-views", options->truth_views, "sampled frames measured against the truth")
      ->check(CLI::Range(1, 64));
  const auto square = cli::accepted_by([](const std::string& text) {
    try {
      return sim::samples_per_axis(std::stoi(text)) > 0;
    } catch (const std::exception&) {
      return false;
    }
  }, "a square number");
  command->add_option("--still-samples", options->still_samples, "rays a pixel of the still and the truth views (a square)")
      ->check(CLI::Range(1, 1024))
      ->check(square);
  command->add_option("--video-frames", options->video_frames, "the video's length in frames (it loops)")
      ->check(CLI::Range(1, 100000));
  command->add_option("--video-samples", options->video_samples, "rays a pixel of each video frame (a square)")
      ->check(CLI::Range(1, 1024))
      ->check(square);
  command->add_option("--ratio", options->ratio, "the simplified proxies' triangle ratio")->check(CLI::Range(2.0, 1000.0));
  command->add_option("--viewpoint", options->viewpoints,
                      "a viewpoint X,Y,Z (metres, world), repeatable: each measured in turn with its own panorama, "
                      "then a summary (default: the config's source.panorama.position_m)")
      ->type_name("X,Y,Z")
      ->check(cli::accepted_by([](const std::string& text) { return parse_point(text).has_value(); }, "X,Y,Z in metres"));
  cli::on_run(command, [options] { return run_hybrid_benchmark(*options); }, cli::Failure{});
}

}  // namespace arpipe
