// simulate(): the frame loop. Per frame: exposure setting → metadata → radiance (camera scene, and
// the scene with virtual objects for the composite) → sensor → recording, ground truth, linear image.
#include "capture/sim/simulator.h"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <numbers>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>

#include "capture/recording/recording_writer.h"
#include "capture/sim/camera_ray_grid.h"
#include "capture/sim/camera_trajectory.h"
#include "capture/sim/exposure_control.h"
#include "capture/sim/frame_renderer.h"
#include "capture/sim/ground_truth_coverage.h"
#include "capture/sim/jpeg_round_trip.h"
#include "capture/sim/lens_optics.h"
#include "capture/sim/raw_exposure.h"
#include "capture/sim/scene_shader.h"
#include "capture/sim/sensor_model.h"
#include "capture/sim/shutter_pose_table.h"
#include "core/image/pixel_convert.h"

namespace arpipe::sim {

namespace fs = std::filesystem;

namespace {

constexpr int kGroundTruthRowStride = 16;  // rolling shutter: a pose every 16 rows, and the last row

double trajectory_time_s(const SimCamera& camera, int64_t time_ns) {
  return double(time_ns - camera.first_exposure_start_ns) * 1e-9;
}

std::vector<GroundTruthLight> ground_truth_lights(const SimScene& scene) {
  std::vector<GroundTruthLight> lights;
  for (const SimLight& light : scene.lights) {
    GroundTruthLight& out = lights.emplace_back();
    out.name = light.name;
    out.color = light.color;
    out.kind = choice_name<SimLight::Kind>(kSimLightKindNames, light.kind);
    switch (light.kind) {
      case SimLight::Kind::Directional:
        out.direction_to_light = light.direction_to_light;
        out.strength = light.irradiance;
        out.angular_diameter_rad = light.angular_diameter_rad;
        break;
      case SimLight::Kind::Point:
        out.position = light.position;
        out.strength = light.intensity;
        break;
      case SimLight::Kind::Sphere:
        out.position = light.position;
        out.strength = light.intensity;
        out.radius_m = light.radius_m;
        break;
    }
  }
  return lights;
}

GroundTruthFrame ground_truth(const SimScene& scene, const CameraTrajectory& trajectory, const FrameMetadata& meta,
                              const std::vector<GroundTruthLight>& lights) {
  const SimCamera& camera = scene.camera;
  const double start = trajectory_time_s(camera, meta.exposure_start_ns);
  GroundTruthFrame truth;
  truth.sequence = meta.sequence;
  truth.T_cam_world_start = trajectory.T_cam_world(start);
  truth.T_cam_world_mid = trajectory.T_cam_world(trajectory_time_s(camera, meta.exposure_mid_ns()));
  truth.T_cam_world_end = trajectory.T_cam_world(start + (meta.exposure_ns + meta.readout_ns) * 1e-9);
  if (meta.readout_ns > 0) {
    const int height = camera.model.height();
    std::vector<int> rows;
    for (int row = 0; row < height; row += kGroundTruthRowStride) rows.push_back(row);
    if (rows.back() != height - 1) rows.push_back(height - 1);
    for (int row : rows) {
      const double mid = start + row_exposure_start_s(meta, row, height) + meta.exposure_ns * 0.5e-9;
      truth.rows.push_back({row, trajectory.T_cam_world(mid)});
    }
  }
  truth.lights = lights;
  if (scene.sun) truth.sun = GroundTruthSun{scene.sun->azimuth_rad, scene.sun->elevation_rad};
  truth.exposure_ns = meta.exposure_ns;
  truth.analogue_gain = meta.analogue_gain;
  truth.digital_gain = meta.digital_gain;
  return truth;
}

// The sensor's output of a radiance image, as packed RGB24; noise from each pixel's own stream.
std::vector<uint8_t> expose(const RadianceImage& radiance, const SensorModel& sensor, const SensorExposure& exposure,
                            uint64_t seed, uint64_t frame_index) {
  std::vector<uint8_t> rgb(radiance.rgb.size());
  const size_t pixels = size_t(radiance.width) * radiance.height;
  for (size_t p = 0; p < pixels; ++p) {
    SampleRng rng(seed, sample_stream(frame_index, p, SampleStream::SensorNoise));
    for (size_t c = 0; c < 3; ++c)
      rgb[p * 3 + c] = SensorModel::quantize(sensor.encode(sensor.noisy_value(radiance.rgb[p * 3 + c], exposure, rng)));
  }
  return rgb;
}

// Mean noise-free linear value (after gains, before clipping): what auto-exposure meters.
double mean_linear_value(const RadianceImage& radiance, const SensorModel& sensor, const SensorExposure& exposure) {
  double sum = 0;
  for (float value : radiance.rgb) sum += sensor.expected_value(value, exposure);
  return radiance.rgb.empty() ? 0.0 : sum / double(radiance.rgb.size());
}

// The noise-free linear image as float RGB PFM (1.0 = full scale).
void write_linear_image(const fs::path& path, const RadianceImage& radiance, const SensorModel& sensor,
                        const SensorExposure& exposure) {
  cv::Mat image(radiance.height, radiance.width, CV_32FC3);
  for (int y = 0; y < radiance.height; ++y)
    for (int x = 0; x < radiance.width; ++x) {
      const size_t p = (size_t(y) * radiance.width + x) * 3;
      // OpenCV images are BGR.
      image.at<cv::Vec3f>(y, x) = cv::Vec3f(float(sensor.expected_value(radiance.rgb[p + 2], exposure)),
                                            float(sensor.expected_value(radiance.rgb[p + 1], exposure)),
                                            float(sensor.expected_value(radiance.rgb[p], exposure)));
    }
  bool written = false;
  try {
    written = cv::imwrite(path.string(), image);
  } catch (const cv::Exception& e) {
    throw RecordingError(fmt::format("{}: cannot write the linear image: {}", path.string(), e.what()));
  }
  if (!written) throw RecordingError(fmt::format("{}: cannot write the linear image", path.string()));
}

// The sensor's 8-bit RGB in the recording's format. With jpeg_quality > 0 the camera sends JPEG:
// RGB (4:2:0) through a JPEG round trip before the format's conversion, or for GREY the grey
// plane through a one-component JPEG.
Frame to_frame(std::vector<uint8_t> rgb, int width, int height, PixelFormat format, const FrameMetadata& meta,
               int jpeg_quality = 0) {
  if (jpeg_quality > 0 && format != PixelFormat::GREY)
    jpeg_round_trip(rgb.data(), width, height, size_t(width) * 3, 3, jpeg_quality);
  Frame frame = from_rgb24(rgb.data(), width, height, format);
  if (jpeg_quality > 0 && format == PixelFormat::GREY)
    jpeg_round_trip(frame.data.data(), width, height, frame.bytes_per_line, 1, jpeg_quality);
  frame.meta = meta;
  return frame;
}

// Rows of `eye` (channels values a pixel) placed in the pair's image: below or right of the first.
void place_eye(const std::vector<float>& eye, int width, int height, int channels, bool top_bottom, int which,
               std::vector<float>& pair) {
  const size_t row = size_t(width) * size_t(channels);
  const size_t pair_row = top_bottom ? row : 2 * row;
  pair.resize(pair_row * size_t(top_bottom ? 2 * height : height));
  for (int y = 0; y < height; ++y) {
    const size_t to = top_bottom ? size_t(which * height + y) * pair_row : size_t(y) * pair_row + size_t(which) * row;
    std::copy_n(eye.data() + size_t(y) * row, row, pair.data() + to);
  }
}

// One frame's radiance (and coverage) as the camera sees it: a mono image, or the stereo pair's
// two eyes in their places; each eye through the lens's defocus and vignetting when it has them
// (the coverage is the geometric one, left alone).
void render_frame(const FrameRenderer& renderer, const SimCamera& camera, const SceneShader& shader,
                  const ShutterPoseTable& poses, const FrameMetadata& meta, double start_s, uint64_t index,
                  const LensOptics& optics, RadianceImage& out, std::vector<float>* coverage) {
  if (!camera.stereo.enabled) {
    renderer.render(shader, poses, meta, start_s, index, out, coverage);
    if (optics.active()) optics.apply(out);
    return;
  }
  RadianceImage eye;
  std::vector<float> eye_coverage;
  for (int which = 0; which < 2; ++which) {
    renderer.render(shader, poses, meta, start_s, index, eye, coverage ? &eye_coverage : nullptr,
                    which == 0 ? Eye::Left : Eye::Right, camera.stereo.rig);
    if (optics.active()) optics.apply(eye);
    place_eye(eye.rgb, eye.width, eye.height, 3, camera.stereo.top_bottom, which, out.rgb);
    if (coverage) place_eye(eye_coverage, eye.width, eye.height, 1, camera.stereo.top_bottom, which, *coverage);
  }
  out.width = camera.frame_width();
  out.height = camera.frame_height();
}

// The shaders a frame is rendered with: the camera's world (real objects) and, when the scene
// has virtual objects, the composite's (all of them). A static one is built once; one whose
// objects move is placed anew at each frame's exposure start (objects do not move within an
// exposure). Built here first (at trajectory time 0, the first frame's), so that a bad asset
// throws before anything is written.
class FrameWorlds {
 public:
  explicit FrameWorlds(const SimScene& scene)
      : scene_(scene), animated_(scene.has_animated_objects()), with_virtual_(scene.has_virtual_objects()) {
    build(animated_ ? scene_at_time(scene, posed_at_s_) : scene);
  }
  // Places the objects at trajectory time t_s (a no-op for a static scene).
  void pose(double t_s) {
    if (!animated_ || t_s == posed_at_s_) return;
    camera_.reset();  // one Embree scene at a time
    composite_.reset();
    build(scene_at_time(scene_, t_s));
    posed_at_s_ = t_s;
  }
  bool has_composite() const { return with_virtual_; }
  const SceneShader& camera() const { return *camera_; }
  const SceneShader& composite() const { return *composite_; }

 private:
  void build(const SimScene& posed) {
    camera_.emplace(posed, false);
    if (has_composite()) composite_.emplace(posed, true);
  }

  const SimScene& scene_;
  bool animated_;
  bool with_virtual_;
  double posed_at_s_ = 0;
  std::optional<SceneShader> camera_, composite_;
};

}  // namespace

SimulateSummary simulate(const SimScene& scene, const SimulateOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  const SimCamera& camera = scene.camera;
  const int frames = options.frames > 0 ? options.frames : scene.render.frames;
  if (frames <= 0) throw std::invalid_argument(fmt::format("simulate: frames must be positive, got {}", frames));
  const uint64_t seed = options.seed.value_or(scene.render.seed);
  const int width = camera.frame_width(), height = camera.frame_height();
  if (width > kMaxFrameSide || height > kMaxFrameSide || int64_t{width} * height > kMaxFramePixels)
    throw std::invalid_argument(fmt::format("simulate: a {}x{} frame exceeds the limit of {} pixels a side and {} "
                                            "pixels in all (rendering holds about 80 bytes a pixel)",
                                            width, height, kMaxFrameSide, kMaxFramePixels));

  int64_t longest_exposure_ns = 0;
  for (int64_t e : camera.exposure_ns) longest_exposure_ns = std::max(longest_exposure_ns, e);
  const double duration_s = frames / camera.fps + (longest_exposure_ns + camera.readout_ns) * 1e-9;
  const CameraTrajectory trajectory(scene.trajectory, camera, duration_s, seed);
  const SensorModel sensor(camera.sensor);
  const CameraRayGrid rays(camera.model);
  // A stereo pair's recording carries the left eye's lens over the whole pair's frame: exact for
  // the left eye's half, which starts at the frame's top left corner.
  const CameraModel recorded_model =
      camera.stereo.enabled ? CameraModel(camera.model.lensmodel(), camera.model.intrinsics(), width, height) : camera.model;
  if (camera.jpeg_quality > 0 && is_bayer(camera.pixel_format))
    throw std::invalid_argument(fmt::format("simulate: camera.jpeg_quality applies to RGB24, YUYV, GREY and NV12 frames, "
                                            "not to the raw Bayer format {}",
                                            pixel_format_name(camera.pixel_format)));
  const LensOptics optics(camera.optics, rays, camera.model.width(), camera.model.height());
  const FrameRenderer renderer(rays, camera.model.width(), camera.model.height(), scene.render.samples_per_pixel, seed,
                               options.threads);
  FrameWorlds worlds(scene);  // a moving world is placed again for each frame (FrameWorlds::pose)

  const std::string source = options.source_description.empty()
                                 ? fmt::format("arpipe simulate {} (seed {})", scene.source_file.string(), seed)
                                 : options.source_description;
  RecordingWriter writer(options.out_dir, RecordingInfo{kRecordingFormatVersion, camera.pixel_format, width, height, 0,
                                                        source, ""},
                         recorded_model);
  std::optional<RecordingWriter> composite_writer, coverage_writer;
  if (worlds.has_composite()) {
    composite_writer.emplace(options.out_dir / kGroundTruthCompositeDir,
                             RecordingInfo{kRecordingFormatVersion, PixelFormat::RGB24, width, height, 0,
                                           source + ": ground-truth composite", ""},
                             recorded_model);
    coverage_writer.emplace(options.out_dir / kGroundTruthCoverageDir,
                            RecordingInfo{kRecordingFormatVersion, PixelFormat::GREY, width, height, 0,
                                          source + ": ground-truth coverage of the virtual objects", ""},
                            recorded_model);
  }
  if (!scene.source_file.empty() && fs::is_regular_file(scene.source_file)) {
    std::error_code ignored;  // a copy for reproducibility; the recording does not need it
    fs::copy_file(scene.source_file, options.out_dir / kSceneCopyFile, fs::copy_options::overwrite_existing, ignored);
  }

  const double setup_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  const std::vector<GroundTruthLight> lights = ground_truth_lights(scene);
  ExposureControl exposure_control(camera);
  RadianceImage radiance, composite_radiance;
  std::vector<float> coverage;
  for (int k = 0; k < frames; ++k) {
    const auto index = uint64_t(k);
    const ExposureSetting setting = exposure_control.setting(index);
    const FrameMetadata meta = simulated_frame_metadata(camera, index, setting);
    const SensorExposure exposure{meta.exposure_ns * 1e-9, meta.analogue_gain, meta.digital_gain};
    const double start_s = trajectory_time_s(camera, meta.exposure_start_ns);

    const ShutterPoseTable poses(trajectory, start_s, start_s + (meta.exposure_ns + meta.readout_ns) * 1e-9);
    worlds.pose(start_s);
    render_frame(renderer, camera, worlds.camera(), poses, meta, start_s, index, optics, radiance, nullptr);
    GroundTruthFrame truth = ground_truth(scene, trajectory, meta, lights);
    if (scene.render.write_linear) {
      truth.linear_image = fmt::format("linear_{:06d}.pfm", k);
      write_linear_image(options.out_dir / truth.linear_image, radiance, sensor, exposure);
    }
    // A raw camera's frame is the mosaic (raw_exposure.h); every other format encodes the RGB.
    Frame frame = is_bayer(camera.pixel_format)
                      ? expose_bayer(radiance, sensor, exposure, seed, index, camera.pixel_format, camera.sensor.black_level)
                      : to_frame(expose(radiance, sensor, exposure, seed, index), width, height, camera.pixel_format, meta,
                               camera.jpeg_quality);
    frame.meta = meta;
    // The simulated sensor's raw values are neutral: what its black level is, and unit gains.
    if (is_bayer(camera.pixel_format)) {
      frame.meta.raw.black_level.emplace().fill(double(camera.sensor.black_level));
      frame.meta.raw.gains = std::array<double, 3>{1, 1, 1};
    }
    writer.append(frame, truth);
    if (worlds.has_composite()) {
      render_frame(renderer, camera, worlds.composite(), poses, meta, start_s, index, optics, composite_radiance,
                   &coverage);
      composite_writer->append(
          to_frame(expose(composite_radiance, sensor, exposure, seed, index), width, height, PixelFormat::RGB24, meta,
                   camera.jpeg_quality),
          truth);
      coverage_writer->append(coverage_frame(coverage, width, height, meta), truth);
    }
    exposure_control.update(mean_linear_value(radiance, sensor, exposure));
    if (options.on_frame) options.on_frame(k + 1, frames);
  }
  writer.flush();
  if (composite_writer) composite_writer->flush();
  if (coverage_writer) coverage_writer->flush();

  SimulateSummary summary;
  summary.frames = frames;
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  summary.setup_seconds = setup_seconds;
  summary.wrote_composite = worlds.has_composite();
  return summary;
}

}  // namespace arpipe::sim
