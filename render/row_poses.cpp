// An object's pose in the camera as a function of the image row (see row_poses.h).
#include "render/row_poses.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

namespace arpipe {

double RowProjection::row_of(const Vec3& p_cam) const {
  const double last = std::max(0, rows - 1);
  if (!(p_cam[2] > 1e-9)) return 0.5 * last;
  return std::clamp(fy * p_cam[1] / p_cam[2] + cy, 0.0, last);
}

Vec3 RowPoses::camera_point(const Vec3& p_object, const RowProjection& rows) const {
  const int n = static_cast<int>(T_cam_object.size());
  if (n == 1) return T_cam_object[0] * p_object;
  Vec3 p_cam = T_cam_object[n / 2] * p_object;
  const double rows_per_entry = std::max(1, rows.rows - 1) / double(n - 1);
  // Two rounds: the row moves by the motion of one row's worth of time, so the second is exact
  // to a small fraction of a pixel (same steps as the shader).
  for (int round = 0; round < 2; ++round) {
    const double f = rows.row_of(p_cam) / rows_per_entry;
    const int i = std::min(static_cast<int>(f), n - 2);
    const double w = f - i;
    const Vec3 a = T_cam_object[i] * p_object, b = T_cam_object[i + 1] * p_object;
    p_cam = {a[0] + w * (b[0] - a[0]), a[1] + w * (b[1] - a[1]), a[2] + w * (b[2] - a[2])};
  }
  return p_cam;
}

RowPoses row_poses(const ShutterMotion& motion, const SE3& T_cam_world_fallback, const SE3& T_world_object,
                   double exposure_fraction, bool rolling_shutter, const std::function<SE3(int64_t)>& T_world_object_at) {
  RowPoses out;
  const auto object_at = [&](int64_t t) { return T_world_object_at ? T_world_object_at(t) : T_world_object; };
  if (!motion.valid()) {
    out.T_cam_object.push_back(T_cam_world_fallback * T_world_object);
    return out;
  }
  const ShutterTiming& timing = motion.timing;
  const auto instant = [&](double row) {
    return timing.row_start_ns(row) + std::llround(exposure_fraction * double(timing.exposure_ns));
  };
  if (!rolling_shutter || timing.readout_ns <= 0 || timing.rows <= 1) {
    // A global shutter: every row's exposure is row 0's.
    out.T_cam_object.push_back(motion.T_cam_world_at(instant(0)) * object_at(instant(0)));
    return out;
  }
  const int n = RowPoses::kMaxEntries;
  out.T_cam_object.reserve(n);
  for (int i = 0; i < n; ++i) {
    const double row = double(timing.rows - 1) * i / (n - 1);
    const int64_t t = instant(row);
    out.T_cam_object.push_back(motion.T_cam_world_at(t) * object_at(t));
  }
  return out;
}

std::string row_poses_glsl(std::string_view name, bool with_row_projection) {
  std::string out;
  if (with_row_projection)
    out += "uniform vec3 u_row_projection;  // fy, cy, rows: which row a camera-frame point lies on\n";
  out += fmt::format(R"glsl(
uniform int {0}_count;
uniform mat3 {0}_linear[{1}];
uniform vec3 {0}_translation[{1}];
vec3 {0}_camera_point(vec3 p) {{
  if ({0}_count <= 1) return {0}_linear[0] * p + {0}_translation[0];
  int middle = {0}_count / 2;
  vec3 c = {0}_linear[middle] * p + {0}_translation[middle];
  float last_row = max(u_row_projection.z - 1.0, 0.0);
  float rows_per_entry = max(last_row, 1.0) / float({0}_count - 1);
  for (int round = 0; round < 2; ++round) {{
    float row = c.z > 1e-9 ? clamp(u_row_projection.x * c.y / c.z + u_row_projection.y, 0.0, last_row) : 0.5 * last_row;
    float f = row / rows_per_entry;
    int i = min(int(f), {0}_count - 2);
    float w = f - float(i);
    c = mix({0}_linear[i] * p + {0}_translation[i], {0}_linear[i + 1] * p + {0}_translation[i + 1], w);
  }}
  return c;
}}
)glsl",
                     name, RowPoses::kMaxEntries);
  return out;
}

void set_row_poses(const GlProgram& program, std::string_view name, const RowPoses& poses, double scale) {
  const int n = std::min<int>(static_cast<int>(poses.T_cam_object.size()), RowPoses::kMaxEntries);
  std::array<float, 9 * RowPoses::kMaxEntries> linear{};
  std::array<float, 3 * RowPoses::kMaxEntries> translation{};
  for (int i = 0; i < n; ++i) {
    const SE3& pose = poses.T_cam_object[i];
    for (size_t col = 0; col < 3; ++col)  // column-major, as glUniformMatrix3fv wants it untransposed
      for (size_t row = 0; row < 3; ++row) linear[i * 9 + col * 3 + row] = static_cast<float>(pose.rotation()[row][col] * scale);
    for (size_t k = 0; k < 3; ++k) translation[i * 3 + k] = static_cast<float>(pose.translation()[k]);
  }
  const std::string prefix(name);
  glUniform1i(program.uniform((prefix + "_count").c_str()), n);
  glUniformMatrix3fv(program.uniform((prefix + "_linear").c_str()), n, GL_FALSE, linear.data());
  glUniform3fv(program.uniform((prefix + "_translation").c_str()), n, translation.data());
}

void set_row_projection(const GlProgram& program, const RowProjection& rows) {
  glUniform3f(program.uniform("u_row_projection"), static_cast<float>(rows.fy), static_cast<float>(rows.cy),
              static_cast<float>(rows.rows));
}

}  // namespace arpipe
