// FrameRenderer: the per-pixel sampling loop, spread over threads by rows.
#include "capture/sim/frame_renderer.h"

#include <algorithm>
#include <atomic>
#include <thread>

#include "capture/sim/exposure_control.h"

namespace arpipe::sim {

uint64_t sample_stream(uint64_t frame_index, uint64_t pixel_index, SampleStream purpose) {
  // 2^40 pixels per frame is far beyond any sensor; the low bit picks the purpose.
  return (((frame_index << 40u) + pixel_index) << 1u) | uint64_t(purpose);
}

FrameRenderer::FrameRenderer(const CameraRayGrid& rays, int width, int height, int samples_per_pixel, uint64_t seed,
                             int threads)
    : rays_(rays),
      width_(width),
      height_(height),
      samples_per_pixel_(samples_per_pixel),
      samples_per_axis_(samples_per_axis(samples_per_pixel)),
      seed_(seed),
      threads_(threads > 0 ? threads : int(std::clamp(std::thread::hardware_concurrency(), 1u, 64u))) {}

void FrameRenderer::render(const SceneShader& shader, const ShutterPoseTable& poses, const FrameMetadata& meta,
                           double trajectory_time_s, uint64_t frame_index, RadianceImage& out,
                           std::vector<float>* coverage, Eye eye, const OdsRig& rig) const {
  out.width = width_;
  out.height = height_;
  out.rgb.assign(size_t(width_) * height_ * 3, 0.0f);
  if (coverage != nullptr) coverage->assign(size_t(width_) * height_, 0.0f);
  const double exposure_s = meta.exposure_ns * 1e-9;
  const int spp = samples_per_pixel_, n = samples_per_axis_;
  const uint64_t first_pixel = eye == Eye::Right ? uint64_t(width_) * uint64_t(height_) : 0;
  const Vec3 up_cam{0, -1, 0};  // the camera's rows run down its y axis

  std::atomic<int> next_row{0};
  auto worker = [&] {
    std::vector<int> time_stratum(size_t(spp), 0);
    for (int y = next_row++; y < height_; y = next_row++) {
      const double row_start_s = trajectory_time_s + row_exposure_start_s(meta, y, height_);
      for (int x = 0; x < width_; ++x) {
        const uint64_t pixel = uint64_t(y) * uint64_t(width_) + uint64_t(x);
        SampleRng rng(seed_, sample_stream(frame_index, first_pixel + pixel, SampleStream::Shading));
        // Time strata in a random order, so that position and time strata are not correlated.
        for (int i = 0; i < spp; ++i) time_stratum[size_t(i)] = i;
        for (int i = spp - 1; i > 0; --i) std::swap(time_stratum[size_t(i)], time_stratum[rng.next_u32() % uint32_t(i + 1)]);
        double sum[3] = {0, 0, 0};
        int covered = 0;
        for (int i = 0; i < spp; ++i) {
          const double px = x - 0.5 + ((i % n) + rng.uniform()) / n;
          const double py = y - 0.5 + ((i / n) + rng.uniform()) / n;
          const double t = row_start_s + exposure_s * (time_stratum[size_t(i)] + rng.uniform()) / spp;
          std::array<double, 3> d{};
          if (!rays_.ray(px, py, d)) continue;  // outside what the lens can see: black
          const RayPose pose = poses.at(t);
          const auto& R = pose.R_world_cam;
          const Vec3 dir{R[0][0] * d[0] + R[0][1] * d[1] + R[0][2] * d[2],
                         R[1][0] * d[0] + R[1][1] * d[1] + R[1][2] * d[2],
                         R[2][0] * d[0] + R[2][1] * d[1] + R[2][2] * d[2]};
          Vec3 origin{pose.centre[0], pose.centre[1], pose.centre[2]};
          if (eye != Eye::Mono) {
            const Vec3 o = ods_eye_origin(rig, eye, up_cam, {d[0], d[1], d[2]});
            origin = origin + Vec3{R[0][0] * o[0] + R[0][1] * o[1] + R[0][2] * o[2], R[1][0] * o[0] + R[1][1] * o[1] + R[1][2] * o[2],
                                   R[2][0] * o[0] + R[2][1] * o[1] + R[2][2] * o[2]};
          }
          bool virtual_hit = false;
          const Rgb radiance = shader.radiance(origin, dir, rng, virtual_hit);
          covered += virtual_hit ? 1 : 0;
          for (int c = 0; c < 3; ++c) sum[c] += radiance[size_t(c)];
        }
        for (int c = 0; c < 3; ++c) out.rgb[pixel * 3 + size_t(c)] = float(sum[c] / spp);
        if (coverage != nullptr) (*coverage)[pixel] = float(double(covered) / spp);
      }
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads_; ++t) pool.emplace_back(worker);
  worker();
  for (auto& thread : pool) thread.join();
}

}  // namespace arpipe::sim
