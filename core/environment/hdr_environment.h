// HdrEnvironment: an HDR light-probe image placed in the world (layout, rotation, radiance scale),
// answering radiance by direction and listing every texel with its direction and solid angle.
#pragma once

#include <filesystem>
#include <functional>
#include <string>

#include "core/geometry/vec.h"
#include "core/image/hdr_image.h"
#include "core/environment/environment_layout.h"

namespace arpipe {

// The usual placement of a probe in arpipe's z-up world: probe up (+y) -> world +z, probe forward
// (-z) -> world +y, probe right (+x) -> world +x, then turned by yaw_rad about world +z
// (counter-clockwise seen from above). Columns are the world images of the probe's axes.
Mat3 default_world_from_probe(double yaw_rad);

class HdrEnvironment {
 public:
  // Checks the image's shape for the layout, its texels (finite, >= 0), the scale (finite, >= 0)
  // and that R_world_probe is a rotation; throws AssetError naming `name`.
  HdrEnvironment(HdrImage image, EnvironmentLayout layout, const Mat3& R_world_probe, double scale, std::string name);

  // Reads the file (Radiance .hdr or OpenEXR) and places it; the name is the file's path.
  static HdrEnvironment load(const std::filesystem::path& file, EnvironmentLayout layout, const Mat3& R_world_probe,
                             double scale);

  // Bilinear lookup times scale. Equirect wraps in u and clamps rows; cube faces clamp to the
  // face's own texels (no filtering across face edges); the disk layouts replace a tap whose
  // centre is outside the disk by the valid texel nearest to it, so no blank texel is ever read.
  Vec3 radiance(const Vec3& unit_dir_world) const;

  // Every texel with a non-zero solid angle: its centre's world direction, its radiance (times
  // scale) and its exact solid angle (environment_texel_solid_angle); the solid angles sum to 4 pi.
  // A disk texel whose centre is just outside the disk (but whose square overlaps it) reports the
  // rim direction (back for the angular map, -z for the mirror ball) and the nearest valid
  // texel's radiance.
  void for_each_texel(
      const std::function<void(const Vec3& unit_dir_world, const Vec3& radiance, double solid_angle)>& visit) const;

  int width() const { return image_.width; }
  int height() const { return image_.height; }
  EnvironmentLayout layout() const { return layout_; }
  const std::string& name() const { return name_; }
  const Mat3& R_world_probe() const { return R_world_probe_; }
  double scale() const { return scale_; }
  const HdrImage& image() const { return image_; }

 private:
  Vec3 texel(int x, int y) const;          // a valid texel's value times scale
  Vec3 disk_texel(int x, int y) const;     // the nearest valid texel's value for a disk layout

  HdrImage image_;
  EnvironmentLayout layout_;
  Mat3 R_world_probe_;
  double scale_;
  std::string name_;
};

}  // namespace arpipe
