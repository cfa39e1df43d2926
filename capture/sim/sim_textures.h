// The simulator's images: plane reflectance textures (AprilTags from the family's bit pattern,
// chessboards, sRGB image files) and the sky (equirectangular HDR or constant), sampled per ray.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "capture/sim/sim_scene.h"
#include "core/geometry/vec.h"

namespace arpipe::sim {

// Image textures: at most 16384 pixels a side and 2^25 pixels (an 8192 x 4096 photo) in all, 400 MB
// as floats; checked on the file's header before it is decoded.
inline constexpr int64_t kMaxTextureSide = 16384;
inline constexpr int64_t kMaxTexturePixels = int64_t{1} << 25;

// Linear reflectance over a plane's texture coordinates (u left to right, v top to bottom, both
// in [0, 1], as sim_scene.h defines them). Two-tone textures are sampled nearest-texel (crisp
// edges: the camera's area sampling anti-aliases them); image files bilinearly.
class PlaneTexture {
 public:
  // Throws AssetError naming the file for an unreadable image or one over the size limits above
  // (with the limit), std::invalid_argument naming
  // `object_name` for an unknown tag family, a tag id outside it or a board without squares.
  PlaneTexture(const SimMaterial& material, const std::string& object_name);

  Rgb reflectance(double u, double v) const;

 private:
  SimTexture::Kind kind_;
  Rgb albedo_;
  Rgb dark_, light_;
  int width_ = 0, height_ = 0;                           // texels (AprilTag cells or image pixels)
  std::vector<uint8_t> paper_;                           // AprilTag: 1 where the cell is paper (white), row 0 on top
  std::vector<float> rgb_;                               // Image: linear RGB reflectance, albedo applied, row 0 on top
  double board_cols_ = 0, board_rows_ = 0, margin_ = 0;  // Chessboard, in squares
};

// Where a world direction lands in the equirectangular sky: u = (atan2(y, x) + rotation) / 2 pi
// wrapped to [0, 1), v = acos(z) / pi (sim_scene.h, SimEnvironment).
Vec2 equirect_uv(const Vec3& unit_dir, double rotation_rad);

// The sky's radiance per direction: the HDR image times `radiance`, bilinear with wrap-around in
// u, or the constant `radiance`.
class EnvironmentMap {
 public:
  // Throws AssetError naming the HDR file when it is missing, cannot be decoded, is not a
  // floating-point image or holds a negative or non-finite value.
  explicit EnvironmentMap(const SimEnvironment& environment);

  Rgb radiance(const Vec3& unit_dir) const;
  bool is_black() const { return black_; }

 private:
  Rgb constant_{0, 0, 0};
  double rotation_ = 0;
  int width_ = 0, height_ = 0;  // 0: constant
  std::vector<float> rgb_;      // linear RGB radiance, multiplier applied, row 0 = straight up
  bool black_ = true;
};

}  // namespace arpipe::sim
