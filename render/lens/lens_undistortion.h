// render.lens = "undistort": the camera frame warped to its lens model's pinhole core (same size),
// through a per-pixel map built once with mrcal and bilinear filtering in linear light. CPU only.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "core/frame.h"
#include "core/geometry/camera_model.h"

namespace arpipe {

// Throws RenderError naming the model when it has no pinhole core (fx, fy, cx, cy) to undistort to.
void check_lens_undistortable(const CameraModel& model);

class LensUndistortion {
 public:
  // Projects the ray of every pixel of the pinhole core's image through the lens with mrcal.
  // Throws RenderError (check_lens_undistortable).
  explicit LensUndistortion(const CameraModel& model);

  // The camera model of the undistorted picture: LENSMODEL_PINHOLE with the lens's fx, fy, cx, cy.
  const std::shared_ptr<const CameraModel>& pinhole_core() const { return pinhole_core_; }
  // source and out: RGB24 at the model's size, sRGB-encoded. Each output pixel is the camera
  // frame sampled bilinearly (decoded to linear light, weighted, encoded again) where the lens
  // sees its ray; black where the lens does not see it. A pinhole lens copies the bytes.
  void apply(const Frame& source, Frame& out) const;

 private:
  struct Tap {
    int16_t x0 = -1;   // left/top source pixel; -1: nothing seen here
    int16_t y0 = -1;
    uint8_t dx = 0;    // 1 when the right/bottom neighbour is a different pixel (0 at the border)
    uint8_t dy = 0;
    float fx = 0;      // weights of the right/bottom neighbour
    float fy = 0;
  };
  int width_;
  int height_;
  bool identity_;
  std::shared_ptr<const CameraModel> pinhole_core_;
  std::vector<Tap> taps_;  // per output pixel, row-major
};

}  // namespace arpipe
