// Where calibration images come from: a glob of image files, or the frames of a recording.
// Each is decoded to 8-bit grey on demand, so a 100-image set never sits in memory at once.
#pragma once

#include <cstddef>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace arpipe::calib {

class CalibrationInputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct GreyImage {
  std::string name;           // the file path, or "DIR frame N"
  int width = 0;
  int height = 0;
  std::vector<unsigned char> pixels;  // width*height, tightly packed
};

class CalibrationImages {
 public:
  virtual ~CalibrationImages() = default;
  virtual size_t count() const = 0;
  virtual std::string name(size_t index) const = 0;
  // Decodes image `index`. Throws CalibrationInputError naming the file when it cannot be read.
  // Safe to call from several threads at once.
  virtual GreyImage load(size_t index) const = 0;
};

// Files matching a shell glob (sorted by name; directories skipped), in any format OpenCV's imread
// reads, in the sensor's orientation (EXIF rotation ignored).
// Throws CalibrationInputError when the glob matches nothing.
std::unique_ptr<CalibrationImages> images_from_glob(const std::string& pattern);
// Every frame of a format-v1 recording (any pixel format the recording reader decodes). YUV
// frames give their luma, stretched from limited range (16-235) to 0-255 as image files have it.
// Throws CalibrationInputError naming the directory when it cannot be opened.
std::unique_ptr<CalibrationImages> images_from_recording(const std::filesystem::path& dir);

}  // namespace arpipe::calib
