// The one camera model of the project: an mrcal lens model plus intrinsics and imager size.
// Every projection of a 3D point into a camera image goes through here (docs/DESIGN.md "Space").
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/geometry/vec.h"

namespace arpipe {

// Bad camera-model input; what() names the file and what was wrong.
class CameraModelError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Immutable once made; copies share the mrcal state. The const methods may run on several threads
// at once (mrcal's project/unproject keep no global state).
class CameraModel {
 public:
  // lensmodel: an mrcal name such as "LENSMODEL_OPENCV8"; intrinsics: fx, fy, cx, cy, then distortion
  // in mrcal's order. Throws CameraModelError when the name is unknown or the count is wrong.
  CameraModel(const std::string& lensmodel, std::vector<double> intrinsics, int width, int height);

  static CameraModel pinhole(double fx, double fy, double cx, double cy, int width, int height);
  // Reads an mrcal .cameramodel file (mrcal's own reader). Throws CameraModelError naming the file.
  static CameraModel load(const std::filesystem::path& path);
  static CameraModel parse(const std::string& text, const std::string& source_name);
  // Writes a .cameramodel at full precision (%.17g; mrcal's C writer rounds with %f), readable by mrcal.
  void save(const std::filesystem::path& path) const;
  // Writes a model's text (to_string(), or one with more in it) as save() does: to a temporary
  // file renamed into place, so a crash never leaves half a model. Throws CameraModelError.
  static void save_text(const std::filesystem::path& path, const std::string& text);
  std::string to_string() const;

  const std::string& lensmodel() const { return lensmodel_; }
  const std::vector<double>& intrinsics() const { return intrinsics_; }
  int width() const { return width_; }
  int height() const { return height_; }
  double fx() const { return intrinsics_[0]; }
  double fy() const { return intrinsics_[1]; }
  double cx() const { return intrinsics_[2]; }
  double cy() const { return intrinsics_[3]; }
  bool is_pinhole() const;
  bool has_core() const;  // fx, fy, cx, cy are the first four intrinsics (true for PINHOLE, OPENCVn, splined)

  // Pixel of a point in the camera frame (x right, y down, z forward). nullopt when the model
  // cannot project it (behind a non-wrapping camera, or mrcal failed).
  std::optional<Vec2> project(const Vec3& p_cam) const;
  // Batch form: out[i] is NaN,NaN where projection is impossible.
  void project(const std::vector<Vec3>& p_cam, std::vector<Vec2>& out) const;
  // Direction (unit, z > 0 for forward-looking models) of the ray through a pixel.
  std::optional<Vec3> unproject(const Vec2& pixel) const;
  void unproject(const std::vector<Vec2>& pixels, std::vector<Vec3>& out) const;
  // Undistorts a pixel to normalised pinhole coordinates (x/z, y/z).
  std::optional<Vec2> normalize(const Vec2& pixel) const;
  // The same, by Newton's method on the projection from `near`, the normalised coordinates of a
  // pixel a few pixels away: about ten times cheaper than mrcal's unprojection, which solves each
  // pixel from scratch. It converges to 1e-9 px or falls back to normalize().
  std::optional<Vec2> normalize_near(const Vec2& pixel, const Vec2& near) const;

 private:
  struct Mrcal;  // the mrcal lens-model struct, kept out of this header
  std::string lensmodel_;
  std::vector<double> intrinsics_;
  int width_ = 0;
  int height_ = 0;
  std::shared_ptr<const Mrcal> mrcal_;
};

}  // namespace arpipe
