// An object's pose in the camera as a function of the image row, at one instant of each row's
// exposure: what the vertex shaders use so that a rolling-shutter frame's virtual layer skews like
// the picture, and what the blur methods evaluate at several instants of the exposure.
#pragma once

#include <cstdint>
#include <functional>
#include <string_view>
#include <vector>

#include "core/geometry/se3.h"
#include "core/motion/shutter_motion.h"
#include "render/gl/gl_program.h"

namespace arpipe {

// Which image row a camera-frame point falls on, by the pinhole part of the lens (a few rows of
// distortion change the pose by a negligible fraction of a row's motion).
struct RowProjection {
  double fy = 1;
  double cy = 0;
  int rows = 1;

  double row_of(const Vec3& p_cam) const;  // clamped to [0, rows - 1]; rows / 2 behind the camera
};

struct RowPoses {
  static constexpr int kMaxEntries = 9;
  // One entry: the same pose for every row. More: entry i belongs to row i (rows - 1) / (n - 1),
  // and rows between take the blend of the neighbouring entries' camera-frame points (exact up to
  // the rotation's curvature, since the motion within an exposure is piecewise constant velocity).
  std::vector<SE3> T_cam_object;

  // The camera-frame position of an object-frame point: with one entry its transform; else found
  // by placing the point with the middle entry, reading its row, and blending there, twice (the
  // same steps as row_poses_glsl(), so CPU and GPU agree).
  Vec3 camera_point(const Vec3& p_object, const RowProjection& rows) const;
};

// The object's poses for the instant `exposure_fraction` (0 = start, 1 = end) of each row's own
// exposure. With a global shutter, no rolling-shutter correction asked for, or an invalid motion,
// a single entry (the motion's pose at that instant, or T_cam_world_fallback without motion).
// T_world_object_at: an object that moves itself (physics), its pose at each row's instant; empty:
// fixed at T_world_object (which is also what a frame without motion uses).
RowPoses row_poses(const ShutterMotion& motion, const SE3& T_cam_world_fallback, const SE3& T_world_object,
                   double exposure_fraction, bool rolling_shutter,
                   const std::function<SE3(int64_t)>& T_world_object_at = {});

// GLSL ES 3.00 (no #version line) declaring, for a pose table named `name`:
//   uniform int <name>_count; uniform mat3 <name>_linear[9]; uniform vec3 <name>_translation[9];
//   vec3 <name>_camera_point(vec3 p_object);
// and once per program (with_row_projection = true) `uniform vec3 u_row_projection;` (fy, cy, rows).
// The linear parts carry the object's scale. set_row_poses() uploads them.
std::string row_poses_glsl(std::string_view name, bool with_row_projection);
// Uploads a table to a bound program made with row_poses_glsl(name, ...); scale multiplies the
// linear parts (the object's uniform scale).
void set_row_poses(const GlProgram& program, std::string_view name, const RowPoses& poses, double scale);
void set_row_projection(const GlProgram& program, const RowProjection& rows);

}  // namespace arpipe
