// Light-probe image layouts (angular map, mirror ball, equirectangular, vertical cube cross): pixel
// <-> direction in the probe's own frame, each texel's exact solid angle, and the shape checks.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <string_view>

#include "core/config/choice_names.h"
#include "core/geometry/vec.h"

namespace arpipe {

// The probe frame P is right-handed: +x right, +y up, forward is -z, back is +z (HDRShop/OpenGL).
//
// Pixel coordinates: (px, py) with pixel centres at integers, px to the right, py down, row 0 at
// the top; pixel (x, y) covers [x - 0.5, x + 0.5] x [y - 0.5, y + 0.5]. For the two disk layouts
// the disk is inscribed in the square N x N image, with normalised coordinates
//   u = 2 (px + 0.5) / N - 1 (right),  v = 1 - 2 (py + 0.5) / N (up),  r = sqrt(u^2 + v^2) <= 1.
//
// AngularMap (Debevec), N x N: centre = forward (-z), rim = back (+z). theta = pi r is the angle
//   from forward: D = (sin(pi r) u / r, sin(pi r) v / r, -cos(pi r)). Inverse: with
//   d = sqrt(Dx^2 + Dy^2), r = acos(-Dz) / pi, (u, v) = (Dx, Dy) r / d. The exact back direction
//   (d = 0, Dz > 0) maps to the bottom of the rim, (u, v) = (0, -1).
// MirrorBall, N x N: orthographic photo of a mirror sphere from +z looking along -z, image right =
//   +x, image up = +y. Normal N = (u, v, sqrt(1 - r^2)); reflected direction R = 2 (N.V) N - V with
//   V = (0, 0, 1): R = (2 u s, 2 v s, 1 - 2 r^2), s = sqrt(1 - r^2). The centre shows +z (back,
//   towards the camera), the rim shows -z. Inverse: r = sin(theta / 2), theta = angle from +z,
//   (u, v) = (Dx, Dy) r / d; the exact -z direction maps to the bottom of the rim, (0, -1).
// Equirectangular, 2H x H: u = (px + 0.5) / W, v = (py + 0.5) / H, phi = 2 pi (u - 0.5),
//   theta = pi v (from up): D = (sin theta sin phi, cos theta, -sin theta cos phi). Inverse:
//   u = 0.5 + atan2(Dx, -Dz) / (2 pi), v = acos(Dy) / pi. The column centre is forward, turning
//   right (+x) moves right, the left and right edges (the seam) are back (+z), the top row is up.
// CubeCross (Debevec's vertical cross), 3F x 4F: faces are F x F squares at (column, row), in faces:
//   (1, 0) +y up, (0, 1) -x left, (1, 1) -z front, (2, 1) +x right, (1, 2) -y down, (1, 3) +z back.
//   Within a face, a = 2 (px - x0 + 0.5) / F - 1 (right), b = 1 - 2 (py - y0 + 0.5) / F (up), where
//   (x0, y0) is the face's top-left pixel; the direction is the normalised
//     +y: ( a,  1,  b)    -x: (-1,  b, -a)    -z: ( a,  b, -1)
//     +x: ( 1,  b,  a)    -y: ( a, -1, -b)    +z: ( a, -b,  1)
//   so the cross folds into a cube seen from inside: the front face upright, left/right/top/down
//   joined to the front along their shared image edges, the down face joined to the back along
//   theirs, and the back face upside down (its image top touches the floor), as in Debevec's files.
//   The other blank 2 x 2 face squares are outside the layout.
enum class EnvironmentLayout { AngularMap, MirrorBall, Equirectangular, CubeCross };

inline constexpr ChoiceName<EnvironmentLayout> kEnvironmentLayoutNames[] = {
    {"angular", EnvironmentLayout::AngularMap},
    {"mirror-ball", EnvironmentLayout::MirrorBall},
    {"equirect", EnvironmentLayout::Equirectangular},
    {"cube-cross", EnvironmentLayout::CubeCross}};

// The layout's name in kEnvironmentLayoutNames; parse returns nullopt for a name not in it.
inline std::string_view environment_layout_name(EnvironmentLayout layout) {
  return choice_name(kEnvironmentLayoutNames, layout);
}
inline std::optional<EnvironmentLayout> parse_environment_layout(std::string_view text) {
  return choice_value(kEnvironmentLayoutNames, text);
}

// Unit direction in P seen at pixel position (px, py); nullopt outside the layout's valid region
// (outside the image, outside the disk (r > 1), or in a blank square of the cross).
std::optional<Vec3> environment_pixel_direction(EnvironmentLayout layout, int width, int height, double px, double py);

// The inverse: continuous pixel position of a unit direction in P (inside the valid region; on the
// boundary for the rim and seam directions noted above).
Vec2 environment_direction_pixel(EnvironmentLayout layout, int width, int height, const Vec3& unit_dir_probe);

// Solid angle (sr) of pixel (x, y)'s square, clipped to the valid region:
//   equirect: (2 pi / W) (cos theta0 - cos theta1), exact;
//   cube cross: the tangent-plane formula sum +-atan2(a b, sqrt(a^2 + b^2 + 1)) over the texel's
//     corners, exact (0 in the blank squares);
//   mirror ball: 4 x (area of the texel square clipped to the unit disk, in (u, v) units), exact,
//     because R's solid-angle density is 4 everywhere in the disk;
//   angular map: integral of pi sin(pi r) / r du dv over the texel clipped to the disk: texels
//     wholly inside by tensor Gauss-Legendre (4 x 4 points when the texel is <= 0.05 wide in
//     (u, v), i.e. N >= 40, else 8 x 8); rim texels by 16-point Gauss-Legendre in u on the pieces
//     between the circle's crossings of the texel's edges (with u = end -+ L w^2 on pieces ending
//     at u = +-1) times 16-point Gauss-Legendre in v on the clipped chord. Sums to 4 pi within
//     1e-13 relative for N = 1..1000 (probe_solid_angle_test).
// Over all texels the sum is 4 pi.
double environment_texel_solid_angle(EnvironmentLayout layout, int width, int height, int x, int y);

// True when pixel (x, y)'s centre lies in the valid region: the texels a lookup may read.
bool environment_texel_valid(EnvironmentLayout layout, int width, int height, int x, int y);

// Throws AssetError naming `name` unless the size suits the layout: angular map and mirror ball
// square, equirect 2:1, cube cross 3 faces wide by 4 tall; at least 1 pixel (per face).
void check_environment_dimensions(EnvironmentLayout layout, int width, int height, const std::string& name);

// Cube cross: the face a unit direction falls on (largest |component|; ties go to x, then y), as
// its (column, row) in faces in the cross.
std::array<int, 2> cube_cross_face_cell(const Vec3& unit_dir_probe);

}  // namespace arpipe
