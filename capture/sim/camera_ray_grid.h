// The camera's viewing rays for any sub-pixel position: mrcal unprojection on a regular grid,
// interpolated bilinearly, so millions of samples per frame cost no iterative unprojection.
#pragma once

#include <array>
#include <vector>

#include "core/geometry/camera_model.h"

namespace arpipe::sim {

class CameraRayGrid {
 public:
  // Unprojects a grid over the whole image (pixel centres at integer coordinates, so the image
  // spans [-0.5, width - 0.5]) with the spacing halved until interpolation agrees with a direct
  // unprojection to within max_error_px (checked on cell midpoints, reprojected). Throws
  // std::invalid_argument for a lens mrcal cannot unproject.
  explicit CameraRayGrid(const CameraModel& model, double max_error_px = 0.002);

  // Unit camera-frame direction (x right, y down, z forward) through pixel position (x, y);
  // false where the lens cannot unproject (then dir is untouched).
  bool ray(double x, double y, std::array<double, 3>& dir) const;

  double spacing_px() const { return spacing_; }
  double measured_error_px() const { return measured_error_px_; }

 private:
  void build(const CameraModel& model, double spacing);
  double check(const CameraModel& model) const;

  double spacing_ = 1.0;
  int columns_ = 0;  // grid nodes across
  int rows_ = 0;
  std::vector<std::array<float, 3>> nodes_;  // NaN where unprojection failed
  double measured_error_px_ = 0;
};

}  // namespace arpipe::sim
