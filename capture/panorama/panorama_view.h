// The camera that looks at a panorama: its lens (any mrcal model), where it looks at each time, and
// the background it sees, looked up per pixel from its viewing ray (no sphere mesh: no seam, no
// pinched poles, the same sharpness in every direction).
//
// Frames: the panorama's (core/environment/environment_layout.h: x right, y up, -z the image's
// centre) and the view camera's (x right, y down, z forward). Yaw turns right about the panorama's
// up, then pitch tilts up: yaw 0, pitch 0 look at the centre with its top up; pitch 90 at the zenith.
#pragma once

#include <array>
#include <memory>
#include <vector>

#include "capture/panorama/equirect_image.h"
#include "core/geometry/camera_model.h"
#include "core/geometry/se3.h"
#include "core/geometry/vec.h"

namespace arpipe {

// The view camera's axes in the panorama's frame (columns: right, down, forward). Roll > 0 then tilts
// the camera about its forward axis to the right (its right side down: the picture turns anticlockwise).
Mat3 panorama_view_rotation(double yaw_rad, double pitch_rad, double roll_rad = 0);

class PanoramaView {
 public:
  // Unprojects every pixel of the camera once. Throws CameraModelError when a pixel cannot be
  // unprojected (the lens must see every pixel).
  explicit PanoramaView(std::shared_ptr<const CameraModel> camera);

  const std::shared_ptr<const CameraModel>& camera() const { return camera_; }

  // Writes the background seen with the camera turned by R_pano_cam into rgb (RGB24, rows of
  // `stride` bytes): per pixel, the ray's panorama pixel, sampled at the pyramid level and with the
  // taps across that the pixel's footprint there needs (wider towards the poles). First builds the
  // pyramid levels the view can ask for at this turn (levels_needed); bands of rows then run on one
  // thread a core.
  void render(EquirectImage& panorama, const Mat3& R_pano_cam, uint8_t* rgb, size_t stride) const;

  // The pyramid levels (from level 0) that some pixel may ask for with the camera turned by
  // R_pano_cam: a bound from the largest footprint and the view's nearest approach to a pole.
  int levels_needed(const EquirectImage& panorama, const Mat3& R_pano_cam) const;

  // The level-0 panorama position each pixel's ray meets (row-major), as render computes it.
  void lookup_positions(const EquirectImage& panorama, const Mat3& R_pano_cam, std::vector<std::array<float, 2>>& out) const;

  // Whether render and lookup_positions take this turn from the yaw-free table (below).
  bool uses_yaw_table(const EquirectImage& panorama, const Mat3& R_pano_cam) const;

 private:
  // A turn split into a yaw about the panorama's up and the rest: R_pano_cam = Ry(-yaw) rest, with
  // rest's forward axis at longitude 0. A yaw moves every pixel's longitude by the same amount and
  // leaves its latitude, level and taps as they were.
  struct Turn {
    double yaw_texels = 0;  // the longitude shift, in level-0 texels
    Mat3 rest{};
  };
  static Turn split_turn(const Mat3& R_pano_cam, int panorama_width);
  // Per pixel at yaw 0: the level-0 position, the footprint across at the pixel's level, the level
  // and the taps. Made on the second frame in a row with the same rest (a sweep, a still head),
  // then each frame costs a shift and the sampling: the rotation and both atan2 are done once.
  struct TableEntry {
    float u = 0, v = 0, wide_scaled = 0;
    uint8_t level = 0, taps = 1;
  };
  struct YawTable {
    Mat3 rest{};
    int width = 0, height = 0, levels = 0;  // the panorama's size, and the levels the table may pick
    std::vector<TableEntry> entries;        // empty: `rest` was last frame's, the table not made yet
  };
  bool table_matches(const EquirectImage& panorama, const Mat3& rest) const;
  void make_table_rows(const EquirectImage& panorama, int first_row, int end_row) const;
  void render_rows_from_table(const EquirectImage& panorama, double yaw_texels, uint8_t* rgb, size_t stride,
                              int first_row, int end_row) const;
  void render_rows(const EquirectImage& panorama, const Mat3& R_pano_cam, uint8_t* rgb, size_t stride, int first_row,
                   int end_row) const;
  // render() is called from one thread at a time (the source's), which alone changes the table.
  mutable YawTable table_;
  std::shared_ptr<const CameraModel> camera_;
  // Per pixel: the unit ray (camera frame) and the angle to its neighbours (radians).
  std::vector<std::array<float, 4>> rays_;
  double widest_footprint_rad_ = 0;  // the largest such angle
  double widest_ray_rad_ = 0;        // the largest angle of a ray from the camera's +z
};

}  // namespace arpipe
