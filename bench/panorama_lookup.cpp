// Benchmark: the panorama source's per-pixel background lookup (capture/panorama/panorama_view.h),
// time against error. `arpipe bench panorama [--frames N] [--size WxH]`
// For views of 640x480, 1280x720 and 1920x1080 (90 degrees across) of a WxH panorama (4096x2048 by
// default) at the horizon, 60 degrees up and at the zenith, prints ms per frame (the median frame), the same against
// a memcpy of the frame (measured in the same run), and the looked-up positions' error against a
// double-precision remap (mrcal's unprojection, the rotation, environment_direction_pixel), as an
// angle in texels: mean and largest over the frames' pixels. With --video FILE: the video's decoding
// to RGB and the pyramid of each frame, ms per frame.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <memory>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "apps/cli/command_line.h"
#include "bench/benchmarks.h"
#include "bench/proxy_comparison.h"
#include "capture/panorama/equirect_image.h"
#include "capture/panorama/panorama_light.h"
#include "capture/panorama/panorama_video.h"
#include "capture/panorama/panorama_view.h"
#include "core/environment/environment_layout.h"
#include "core/environment/hdr_environment.h"

namespace arpipe {
namespace {

constexpr double kPi = std::numbers::pi;

// A panorama with detail at every scale: smooth colour plus texel noise.
EquirectImage test_panorama(int width, int height) {
  std::vector<uint8_t> rgb(size_t(width) * size_t(height) * 3);
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> noise(-20, 20);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const Vec3 d = *environment_pixel_direction(EnvironmentLayout::Equirectangular, width, height, x, y);
      for (size_t c = 0; c < 3; ++c)
        rgb[(size_t(y) * size_t(width) + size_t(x)) * 3 + c] =
            uint8_t(std::clamp(128 + int(90 * d[c]) + noise(rng), 0, 255));
    }
  return EquirectImage(std::move(rgb), width, height, "benchmark panorama");
}

struct Row {
  int width, height;
  double pitch_deg;
  double lookup_ms, memcpy_ms, mean_texels, max_texels;
};

// Frames at one pitch, the yaw a golden turn further each frame.
Row measure(EquirectImage& panorama, int width, int height, double pitch_deg, int frames) {
  const double fx = 0.5 * width;  // 90 degrees across
  const auto camera =
      std::make_shared<const CameraModel>(CameraModel::pinhole(fx, fx, 0.5 * (width - 1), 0.5 * (height - 1), width, height));
  const PanoramaView view(camera);
  std::vector<uint8_t> out(size_t(width) * size_t(height) * 3), copy(out.size());
  std::vector<double> lookup_ms, memcpy_ms;
  double error_sum = 0, error_max = 0;
  size_t error_count = 0;
  std::vector<std::array<float, 2>> positions;
  for (int f = 0; f < frames; ++f) {
    const Mat3 R = panorama_view_rotation(f * 2.399963, pitch_deg * kPi / 180);
    auto start = std::chrono::steady_clock::now();
    view.render(panorama, R, out.data(), size_t(width) * 3);
    lookup_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    start = std::chrono::steady_clock::now();
    std::memcpy(copy.data(), out.data(), out.size());
    memcpy_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    // The positions against double precision, on every 7th pixel.
    view.lookup_positions(panorama, R, positions);
    for (size_t i = 0; i < positions.size(); i += 7) {
      const Vec3 ray = normalized(*camera->unproject({double(i % size_t(width)), double(i / size_t(width))}));
      const Vec3 truth = mat_mul(R, ray);
      const Vec3 looked = *environment_pixel_direction(EnvironmentLayout::Equirectangular, panorama.width(),
                                                       panorama.height(), positions[i][0], positions[i][1]);
      const double texels = std::atan2(norm(cross(truth, looked)), dot(truth, looked)) / (kPi / panorama.height());
      error_sum += texels;
      error_max = std::max(error_max, texels);
      ++error_count;
    }
  }
  return {width, height, pitch_deg, bench::median_of(lookup_ms), bench::median_of(memcpy_ms), error_sum / double(error_count), error_max};
}

// Decoding a video to RGB frames, and the whole pyramid of each (what a view at a pole needs):
// ms per frame (means). Also how many levels the hybrid example's view (configs/panorama.toml:
// 1280 x 720, 75 degrees across) builds at its pitch and at the horizon: 1 is none past the frame.
int run_video_benchmark(const std::string& file) {
  PanoramaVideo video(file);
  PanoramaVideoFrame frame;
  std::vector<double> decode_ms, pyramid_ms, light_ms;
  std::unique_ptr<PanoramaLight> light;
  int width = 0, height = 0;
  for (;;) {
    auto start = std::chrono::steady_clock::now();
    if (!video.next(frame)) break;
    decode_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    width = frame.width;
    height = frame.height;
    start = std::chrono::steady_clock::now();
    EquirectImage image(std::move(frame.rgb), frame.width, frame.height, file);
    image.build_levels(image.levels());
    pyramid_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    if (!light) light = std::make_unique<PanoramaLight>(width, height, default_world_from_probe(0));
    start = std::chrono::steady_clock::now();
    const ShRgb9 sh = light->project(image, 4);  // as the source does for light.source = "panorama"
    light_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    if (!std::isfinite(sh[0][0])) throw std::runtime_error(file + ": the light is not finite");
  }
  if (decode_ms.empty()) throw std::runtime_error(file + ": no frame decodes");
  const double rate = double(video.rate_num()) / double(video.rate_den());
  // Means, not medians: FFmpeg's frame threads decode ahead, so one call's time says little.
  const auto mean = [](const std::vector<double>& v) {
    double sum = 0;
    for (double x : v) sum += x;
    return sum / double(v.size());
  };
  const double fx = 640 / std::tan(37.5 * kPi / 180);
  const PanoramaView view(std::make_shared<const CameraModel>(CameraModel::pinhole(fx, fx, 639.5, 359.5, 1280, 720)));
  const EquirectImage shape(std::vector<uint8_t>(size_t(width) * size_t(height) * 3), width, height, file);
  const auto levels_at = [&](double pitch_deg) { return view.levels_needed(shape, panorama_view_rotation(0, pitch_deg * kPi / 180)); };
  const double decode = mean(decode_ms), pyramid = mean(pyramid_ms), light_cost = mean(light_ms);
  fmt::print("| video | frames | decode to RGB, ms/frame (mean) | whole pyramid, ms/frame (mean) | frames/s decoded | frames/s with the whole pyramid "
             "| levels a 720p 75° view builds at pitch 0, -32, 80 | the panorama's light (SH), ms/frame | the video's rate |\n");
  fmt::print("|---|---:|---:|---:|---:|---:|---|---:|---:|\n");
  fmt::print("| {} | {} | {:.1f} | {:.1f} | {:.1f} | {:.1f} | {}, {}, {} of {} | {:.2f} | {:.2f} |\n", video.describe(), decode_ms.size(), decode,
             pyramid, 1000 / decode, 1000 / (decode + pyramid), levels_at(0), levels_at(-32), levels_at(80), shape.levels(), light_cost, rate);
  return 0;
}

int run_panorama_benchmark(int frames, int width, int height) {
  EquirectImage panorama = test_panorama(width, height);
  fmt::print("panorama {} x {} ({} pyramid levels), {} frames a row, the yaw a golden turn further each frame\n\n", width,
             height, panorama.levels(), frames);
  fmt::print("| view | pitch | lookup ms/frame (median) | memcpy of the frame, ms | lookup / memcpy | mean error, texels | max error, texels |\n");
  fmt::print("|---|---:|---:|---:|---:|---:|---:|\n");
  for (const auto& [w, h] : std::vector<std::pair<int, int>>{{640, 480}, {1280, 720}, {1920, 1080}})
    for (const double pitch : {0.0, 60.0, 90.0}) {
      const Row row = measure(panorama, w, h, pitch, frames);
      fmt::print("| {}x{} | {:.0f} | {:.2f} | {:.3f} | {:.0f} | {:.5f} | {:.4f} |\n", row.width, row.height, row.pitch_deg,
                 row.lookup_ms, row.memcpy_ms, row.lookup_ms / row.memcpy_ms, row.mean_texels, row.max_texels);
    }
  return 0;
}

}  // namespace

void add_panorama_benchmark(CLI::App& bench) {
  CLI::App* command = bench.add_subcommand(
      "panorama", "the panorama source's per-pixel background lookup: ms per frame against its error in texels");
  struct Options {
    int frames = 10;
    std::string size = "4096x2048";
    std::string video;
  };
  auto options = std::make_shared<Options>();
  command->add_option("--frames", options->frames, "frames a row")->check(CLI::PositiveNumber);
  command->add_option("--size", options->size, "the panorama's size, WxH (2:1, even height)")->type_name("WxH");
  command->add_option("--video", options->video, "instead: decode this panorama video, ms per frame")->type_name("FILE");
  cli::on_run(command, [options] {
    if (!options->video.empty()) return run_video_benchmark(options->video);
    int width = 0, height = 0;
    if (std::sscanf(options->size.c_str(), "%dx%d", &width, &height) != 2)
      throw std::invalid_argument(fmt::format("--size {}: expected WxH", options->size));
    if (const std::string why = EquirectImage::shape_problem(width, height); !why.empty())
      throw std::invalid_argument(fmt::format("--size {}: {}", options->size, why));
    return run_panorama_benchmark(options->frames, width, height);
  }, cli::Failure{});
}

}  // namespace arpipe
