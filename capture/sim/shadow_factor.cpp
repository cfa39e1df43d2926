// Ray-traced shadow factor (see shadow_factor.h).
#include "capture/sim/shadow_factor.h"

#include <algorithm>
#include <atomic>
#include <thread>

#include "capture/sim/camera_ray_grid.h"
#include "capture/sim/frame_renderer.h"
#include "capture/sim/sample_rng.h"
#include "capture/sim/scene_shader.h"

namespace arpipe::sim {

ShadowFactorImage render_shadow_factor(const SimScene& scene, const CameraModel& camera, const SE3& T_cam_world,
                                       int samples, const PixelRegion& region, int threads) {
  const SceneShader real(scene, false), with_virtual(scene, true);
  const CameraRayGrid rays(camera);
  const SE3 T_world_cam = T_cam_world.inverse();
  const Vec3 centre = T_world_cam.translation();
  ShadowFactorImage out;
  out.width = camera.width();
  out.height = camera.height();
  out.ratio.assign(size_t(out.width) * size_t(out.height), 1.0f);
  out.valid.assign(out.ratio.size(), 0);
  const int x0 = std::max(0, region.x0), x1 = std::min(out.width, region.x1);
  std::atomic<int> next_row{std::max(0, region.y0)};
  const int y1 = std::min(out.height, region.y1);
  auto worker = [&] {
    for (int y = next_row++; y < y1; y = next_row++) {
      for (int x = x0; x < x1; ++x) {
        std::array<double, 3> d{};
        if (!rays.ray(x, y, d)) continue;
        const Vec3 dir = T_world_cam.rotate({d[0], d[1], d[2]});
        if (with_virtual.sees_virtual_object(centre, dir)) continue;
        const uint64_t pixel = uint64_t(y) * uint64_t(out.width) + uint64_t(x);
        double lit = 0, shadowed = 0;
        for (int i = 0; i < samples; ++i) {
          // The same stream for both: the same light samples, so the noise cancels in the ratio.
          const uint64_t stream = sample_stream(uint64_t(i), pixel, SampleStream::Shading);
          SampleRng a(1, stream), b(1, stream);
          const Rgb without = real.radiance(centre, dir, a), with = with_virtual.radiance(centre, dir, b);
          lit += 0.2126 * without[0] + 0.7152 * without[1] + 0.0722 * without[2];
          shadowed += 0.2126 * with[0] + 0.7152 * with[1] + 0.0722 * with[2];
        }
        if (lit <= 0) continue;
        out.ratio[pixel] = static_cast<float>(shadowed / lit);
        out.valid[pixel] = 1;
      }
    }
  };
  const int n = threads > 0 ? threads : std::max(1, int(std::thread::hardware_concurrency()));
  std::vector<std::thread> pool;
  for (int t = 1; t < n; ++t) pool.emplace_back(worker);
  worker();
  for (auto& thread : pool) thread.join();
  return out;
}

}  // namespace arpipe::sim
