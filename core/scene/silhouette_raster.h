// A mesh's silhouette seen through a camera model, as a supersampled coverage mask drawn on the
// CPU, and the silhouette edge error between two masks: the mean displacement of the edge, pixels.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/geometry/camera_model.h"
#include "core/geometry/se3.h"
#include "core/geometry/vec.h"
#include "core/scene/mesh.h"

namespace arpipe {

// width x height pixels of samples_per_axis x samples_per_axis samples each. Pixel coordinates are
// mrcal's: pixel (i, j) is the square of side 1 centred on (i, j); its samples sit at the centres
// of its sub-squares.
class SilhouetteMask {
 public:
  // Throws std::invalid_argument unless 1 <= width, height <= 16384, 1 <= samples_per_axis <= 16
  // and the mask holds at most 2^31 samples (256 MiB).
  SilhouetteMask(int width, int height, int samples_per_axis = 4);

  int width() const { return width_; }
  int height() const { return height_; }
  int samples_per_axis() const { return samples_; }

  // Covers the samples inside the triangle (either winding; edges included, so triangles that
  // share an edge leave no gap). A triangle with a corner not finite, or of no area, covers nothing.
  void fill_triangle(const Vec2& a, const Vec2& b, const Vec2& c);
  bool covered(int sample_x, int sample_y) const;  // sample coordinates: pixel * samples_per_axis + k
  size_t covered_samples() const;
  double area_px() const;  // covered samples / samples per pixel
  // Per pixel (row-major), the fraction of its samples covered.
  std::vector<float> coverage() const;

  // Samples covered in one mask and not in the other, in pixels of area. Throws
  // std::invalid_argument when the masks' sizes or sampling differ.
  double symmetric_difference_px(const SilhouetteMask& other) const;

 private:
  int width_, height_, samples_;
  int columns_, rows_;            // samples
  size_t words_per_row_;          // 64 samples a word
  std::vector<uint64_t> bits_;
};

// Length, pixels, of the mask's edge: the 0.5 contour of its pixel coverage (marching squares
// between pixel centres, linearly interpolated). The image's border is not an edge: a silhouette
// that leaves the picture is measured up to where it leaves.
double silhouette_edge_length_px(const SilhouetteMask& mask);

struct SilhouetteEdgeError {
  double difference_px2 = 0;  // area of the symmetric difference of the two masks
  double edge_length_px = 0;  // of the reference mask's silhouette
  // difference / edge length: how far, on average, the edge moved. A straight edge shifted by d
  // across itself gives d; a shape shifted by d along x gives d times the mean |cos| of its edge
  // normals to x (d/2 for an axis-aligned square). NaN when the reference has no edge in view.
  double error_px = 0;
};
SilhouetteEdgeError silhouette_edge_error(const SilhouetteMask& reference, const SilhouetteMask& other);

// Draws the mesh, placed by T_cam_mesh, into the mask: every triangle with its corners projected
// through the camera and straight edges between them (as the renderer draws a mesh: the lens is
// applied per vertex). The mask must be the camera's size. Triangles with a corner the camera
// cannot project (behind it) are skipped; their number is returned.
size_t draw_mesh_silhouette(const Mesh& mesh, const CameraModel& camera, const SE3& T_cam_mesh, SilhouetteMask& mask);

}  // namespace arpipe
