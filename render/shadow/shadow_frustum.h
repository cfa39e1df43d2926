// The directional light's view for a shadow map: an orthographic box fitted tightly around the
// virtual objects that cast shadows and the patch of ground their shadows fall on.
#pragma once

#include <array>
#include <optional>
#include <span>

#include "core/geometry/se3.h"
#include "core/scene/mesh.h"

namespace arpipe {

struct ShadowCaster {
  Bounds bounds;        // object frame, already scaled
  SE3 T_world_object;
};

// The rectangle of the receiver plane (world z = height) that the casters' shadows can reach,
// widened by the penumbra: where the shadow catcher is drawn.
struct ReceiverPatch {
  double height = 0;
  std::array<double, 2> min{0, 0};
  std::array<double, 2> max{0, 0};
};

// A directional light's view is an orthographic box; a local light's (a lamp at a known place)
// a perspective cone from its position. Depth is linear in both: distance along the light's axis,
// 0 at the near end and 1 at the far end of the range the casters and the receiver span.
struct ShadowFrustum {
  // Rows: the light's x and y axes and its z axis: towards the light (directional), or along its
  // axis away from it into the scene (local).
  Mat3 R_light_world{};
  std::array<double, 3> min{0, 0, 0};  // directional: light-frame box; x, y across, z along
  std::array<double, 3> max{0, 0, 0};
  bool local = false;
  Vec3 light_position{0, 0, 0};  // local: where the light is
  double tan_half_angle = 0;     // local: half the cone's width at unit distance
  double near_m = 0, far_m = 0;  // local: distances along the axis
  ReceiverPatch receiver;

  // World point -> (u, v, depth) in [0, 1]: u, v across the map, depth 0 nearest the light.
  Vec3 map_coordinates(const Vec3& world) const;
  // World to clip space as a GL matrix (column-major); u, v = clip.xy / clip.w * 0.5 + 0.5.
  std::array<float, 16> clip_from_world() const;
  // The plane whose value at a world point (x, y, z, 1) is its depth.
  std::array<float, 4> depth_plane() const;
  // Across the map at the far end of the range (directional: everywhere).
  double width_m() const { return local ? 2 * far_m * tan_half_angle : max[0] - min[0]; }
  double depth_range_m() const { return local ? far_m - near_m : max[2] - min[2]; }
};

// towards_light: world frame, unit. receiver_height: the world z of the ground plane.
// margin_m widens the box across the light (filter kernels and penumbrae reach past the casters)
// and the receiver patch. The box is square across the light (square texels).
// nullopt when there is nothing to cast or the light is not above the receiver plane
// (towards_light.z below min_elevation_sin): then no shadow falls on it.
// A directional frustum's depth range grown to hold the part of a caster inside its column of
// light (the box across the light, along it without end): where a real caster fitted for the
// virtual objects alone must still be drawn. world_box: the caster's (or one of its clusters')
// world-frame axis-aligned box. Conservative: it takes the box's part within the column's own box,
// in 8 slabs of the caster's height. Whether anything of it was inside.
bool extend_depth_over(ShadowFrustum& frustum, const Bounds& world_box);

std::optional<ShadowFrustum> fit_shadow_frustum(const Vec3& towards_light, std::span<const ShadowCaster> casters,
                                                double receiver_height, double margin_m,
                                                double min_elevation_sin = 0.02);
// A local light at light_position: nullopt when it is not above every caster (a lamp among the
// objects would need a cube map) or there is nothing to cast.
std::optional<ShadowFrustum> fit_local_shadow_frustum(const Vec3& light_position, std::span<const ShadowCaster> casters,
                                                      double receiver_height, double margin_m);

}  // namespace arpipe
