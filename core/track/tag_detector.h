// AprilTag detection: a thin owner of a libapriltag detector for one tag family chosen by name,
// run over an 8-bit grey image with any row stride.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "core/config/config.h"
#include "core/pipeline/frame_context.h"

namespace arpipe {

class TagDetector {
 public:
  // Builds the detector for config.track (family, quad_decimate, quad_sigma, threads, max_hamming).
  // Throws ConfigError naming config.file and the key when the family is unknown or a setting is out
  // of range (including a max_hamming whose decode table would need hundreds of MB for the family).
  explicit TagDetector(const Config& config);
  ~TagDetector();
  TagDetector(const TagDetector&) = delete;
  TagDetector& operator=(const TagDetector&) = delete;

  const std::string& family() const;
  // Number of distinct ids in the family (valid ids are 0 .. code_count()-1).
  int code_count() const;
  // Code cells across the detected square (libapriltag's width_at_border: 8 for tag36h11).
  int border_cells() const;

  // Detects tags in a grey image of width x height pixels whose rows are `stride` bytes apart.
  // Fills out with every detection of the family (corners in pixels, AprilTag order: bottom-left,
  // bottom-right, top-right, top-left of the printed tag). Never throws: failure yields no tags.
  void detect(const uint8_t* grey, int width, int height, size_t stride,
              std::vector<TagObservation>& out) noexcept;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace arpipe
