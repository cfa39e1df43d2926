// PRT against Lambert shading at run time (see prt_runtime_cost.h).
#include "bench/prt_runtime_cost.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "core/config/config.h"
#include "core/geometry/camera_model.h"
#include "core/pipeline/frame_context.h"
#include "core/scene/builtin_meshes.h"
#include "render/gl_stages.h"

namespace arpipe {
namespace {

constexpr int kWidth = 640, kHeight = 480;

// T_cam_world of a camera at `eye` looking at `target`, image up towards world +z.
SE3 look_at(const Vec3& eye, const Vec3& target) {
  const Vec3 forward = normalized(target - eye);
  const Vec3 down = normalized(dot(Vec3{0, 0, 1}, forward) * forward - Vec3{0, 0, 1});
  const Vec3 right = cross(down, forward);
  const Mat3 R{{{right[0], right[1], right[2]}, {down[0], down[1], down[2]}, {forward[0], forward[1], forward[2]}}};
  return SE3(R, -1.0 * mat_mul(R, eye));
}

// A 3 x 3 grid of the mesh filling most of the view, lit by the fixed light and an SH ambient.
Config scene(const std::string& mesh, ObjectPrt prt, const std::filesystem::path& cache_dir) {
  Config config;
  config.render.objects.clear();
  for (int j = -1; j <= 1; ++j)
    for (int i = -1; i <= 1; ++i) {
      SceneObject object;
      object.mesh = mesh;
      object.position_m = {0.08 * i, 0.08 * j, 0};
      object.yaw_rad = 0.3 * (i + 3 * j);
      object.prt = prt;
      config.render.objects.push_back(object);
    }
  config.render.shadows.method = ShadowMethod::Off;
  config.render.blur.method = BlurMethod::Off;
  config.render.prt.cache_dir = cache_dir;
  return config;
}

struct Variant {
  ObjectPrt prt;
  std::vector<std::unique_ptr<Stage>> stages;
  std::vector<double> render_ms;
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

}  // namespace

void print_prt_runtime_cost(int frames) {
  const auto camera = std::make_shared<const CameraModel>(CameraModel::pinhole(520, 520, 319.5, 239.5, kWidth, kHeight));
  const SE3 pose = look_at({0.16, -0.24, 0.26}, {0, 0, 0.02});
  const std::filesystem::path cache_dir = std::filesystem::temp_directory_path() / "arpipe-bench-prt-cache";
  Frame background = Frame::allocate(PixelFormat::RGB24, kWidth, kHeight);
  std::fill(background.data.begin(), background.data.end(), uint8_t{90});
  fmt::print("\nrun-time cost, {}x{}, 9 objects, shadows and blur off, MSAA 4; median render-stage ms over {} "
             "frames, interleaved:\n\n| mesh | vertices | Lambert + SH irradiance (prt = off) | PRT (shadowed) | PRT / "
             "Lambert |\n|---|---|---|---|---|\n",
             kWidth, kHeight, frames);
  for (const std::string mesh : {"builtin:sphere", "builtin:cup"}) {
    Variant variants[2] = {{ObjectPrt::Off, make_gl_stages(), {}}, {ObjectPrt::Shadowed, make_gl_stages(), {}}};
    for (Variant& v : variants)
      for (auto& stage : v.stages) stage->configure(scene(mesh, v.prt, cache_dir));
    for (int frame = -3; frame < frames; ++frame)
      for (Variant& v : variants) {
        FrameContext ctx;
        ctx.camera = background;
        ctx.camera.meta.exposure_ns = 10'000'000;
        ctx.camera_model = camera;
        ctx.pose.state = TrackState::Tracking;
        ctx.pose.T_cam_world = pose;
        for (auto& stage : v.stages) stage->process(ctx);
        for (const StageTiming& t : ctx.timings)
          if (t.stage == "render" && frame >= 0) v.render_ms.push_back(t.ms);
      }
    const double lambert = median(variants[0].render_ms), prt = median(variants[1].render_ms);
    fmt::print("| {} | {} | {:.2f} | {:.2f} | {:.2f} |\n", mesh, make_builtin_mesh(mesh)->vertex_count(), lambert, prt,
               lambert > 0 ? prt / lambert : 0.0);
  }
  std::filesystem::remove_all(cache_dir);
}

}  // namespace arpipe
