// Direction sampling for the simulator's lighting: orthonormal frames, directions uniform in a cone
// (light discs and spheres) and cosine-weighted over a hemisphere (sky light), from uniform numbers.
#pragma once

#include "core/geometry/vec.h"

namespace arpipe::sim {

// A right-handed orthonormal frame (tangent, bitangent, normal) around a unit normal.
struct Frame3 {
  Vec3 t{1, 0, 0};
  Vec3 b{0, 1, 0};
  Vec3 n{0, 0, 1};

  Vec3 to_world(double x, double y, double z) const {
    return {x * t[0] + y * b[0] + z * n[0], x * t[1] + y * b[1] + z * n[1], x * t[2] + y * b[2] + z * n[2]};
  }
};

// Continuous in n except where n.z flips sign (Duff et al., "Building an orthonormal basis, revisited").
Frame3 frame_around(const Vec3& unit_normal);

// 1 - cos(half_angle), computed as 2 sin^2(half_angle / 2) so that tiny cones (the sun) keep
// their precision.
double one_minus_cos(double half_angle_rad);
// Solid angle of a cone given 1 - cos(half angle): 2 pi (1 - cos).
double cone_solid_angle(double one_minus_cos_half_angle);

// A direction uniform in solid angle within the cone around frame.n of the given 1 - cos(half
// angle) (0: frame.n itself). u1, u2 uniform in [0, 1).
Vec3 sample_cone(const Frame3& frame, double one_minus_cos_half_angle, double u1, double u2);

// A direction over the hemisphere around frame.n with density cos(theta) / pi. u1, u2 in [0, 1).
Vec3 sample_cosine_hemisphere(const Frame3& frame, double u1, double u2);

// The cone of directions in which a sphere (centre, radius) is seen from a point outside it.
struct SphereCone {
  Vec3 axis{0, 0, 1};        // unit, towards the centre
  double distance = 0;       // to the centre
  double one_minus_cos = 0;  // of the half angle alpha, sin(alpha) = radius / distance
  bool outside = false;      // false: the point is inside or on the sphere (no cone)
};
SphereCone sphere_cone(const Vec3& point, const Vec3& centre, double radius);

}  // namespace arpipe::sim
