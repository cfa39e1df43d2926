// Calibration image sets: files from a glob decoded by OpenCV, or a recording's frames turned into
// full-range 8-bit luma, each decoded when asked for.
#include "calib/calibration_images.h"

#include <fmt/format.h>
#include <glob.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <opencv2/imgcodecs.hpp>

#include "capture/recording/recording_reader.h"
#include "core/config/regular_file.h"
#include "core/image/image_header.h"
#include "core/scene/asset_error.h"
#include "core/image/pixel_convert.h"

namespace arpipe::calib {

namespace {

// Photographs are hostile input: a FIFO matched by the glob must not block imread, and a PNG or
// JPEG that declares 30000 x 30000 pixels in a small file is refused before it is decoded.
constexpr int64_t kMaxImageSide = 16384;
constexpr int64_t kMaxImagePixels = int64_t{1} << 27;  // 128 Mpixel; a 9x6 board photo is a few Mpixel

bool has_png_or_jpeg_signature(int fd) {
  unsigned char magic[4] = {};
  const ssize_t n = ::pread(fd, magic, sizeof magic, 0);
  return (n >= 4 && magic[0] == 0x89 && magic[1] == 'P' && magic[2] == 'N' && magic[3] == 'G') ||
         (n >= 2 && magic[0] == 0xff && magic[1] == 0xd8);
}

void check_image_file(const std::string& file) {
  try {
    const int fd = open_regular_file(file, "image");
    const bool checkable = has_png_or_jpeg_signature(fd);
    ::close(fd);
    // Other formats (TIFF, BMP, ...) are left to OpenCV's own limit (CV_IO_MAX_IMAGE_PIXELS).
    if (checkable) check_image_limits(read_image_header(file), file, "calibration image", kMaxImageSide, kMaxImagePixels);
  } catch (const FileAccessError& e) {
    throw CalibrationInputError(e.what());
  } catch (const AssetError& e) {
    throw CalibrationInputError(e.what());
  }
}

class GlobImages final : public CalibrationImages {
 public:
  GlobImages(std::string pattern, std::vector<std::string> files)
      : pattern_(std::move(pattern)), files_(std::move(files)) {}

  size_t count() const override { return files_.size(); }
  std::string name(size_t index) const override { return files_.at(index); }

  GreyImage load(size_t index) const override {
    if (index >= files_.size())
      throw CalibrationInputError(fmt::format("'{}': no image {} (the pattern matched {})", pattern_, index, files_.size()));
    const std::string& file = files_[index];
    std::error_code ec;
    if (!std::filesystem::exists(file, ec))  // gone since the glob; imread would only log a warning
      throw CalibrationInputError(fmt::format("{}: cannot read image: it no longer exists", file));
    check_image_file(file);
    cv::Mat image;
    try {
      // The sensor's own pixel grid: an EXIF rotation would make some images a different camera.
      image = cv::imread(file, cv::IMREAD_GRAYSCALE | cv::IMREAD_IGNORE_ORIENTATION);
    } catch (const cv::Exception& e) {
      throw CalibrationInputError(fmt::format("{}: cannot read image: {}", file, e.what()));
    }
    if (image.empty())
      throw CalibrationInputError(
          fmt::format("{}: cannot read image: not a readable image file (OpenCV could not decode it)", file));
    GreyImage out;
    out.name = file;
    out.width = image.cols;
    out.height = image.rows;
    out.pixels.resize(static_cast<size_t>(image.cols) * static_cast<size_t>(image.rows));
    for (int row = 0; row < image.rows; ++row)
      std::copy_n(image.ptr<unsigned char>(row), image.cols, out.pixels.data() + static_cast<size_t>(row) * image.cols);
    return out;
  }

 private:
  std::string pattern_;
  std::vector<std::string> files_;
};

class RecordingImages final : public CalibrationImages {
 public:
  explicit RecordingImages(const std::filesystem::path& dir) : reader_(dir), dir_(dir.string()) {}

  size_t count() const override { return reader_.frame_count(); }
  std::string name(size_t index) const override { return fmt::format("{} frame {}", dir_, index); }

  GreyImage load(size_t index) const override {
    if (index >= count())
      throw CalibrationInputError(fmt::format("{}: no frame {} (the recording has {})", dir_, index, count()));
    Frame frame;
    try {
      reader_.read(index, frame);
    } catch (const std::exception& e) {
      throw CalibrationInputError(fmt::format("{}: cannot read frame {}: {}", dir_, index, e.what()));
    }
    GreyImage out;
    out.name = name(index);
    out.width = frame.width;
    out.height = frame.height;
    to_grey(frame, out.pixels);
    // YUV luma is limited range (16..235); the detectors' thresholds and the tag refiner's sRGB
    // decoding expect full-range grey, as image files give it.
    if (frame.format == PixelFormat::YUYV || frame.format == PixelFormat::NV12) {
      for (unsigned char& v : out.pixels)
        v = static_cast<unsigned char>(std::clamp(std::lround((v - 16) * 255.0 / 219.0), 0L, 255L));
    }
    return out;
  }

 private:
  RecordingReader reader_;
  std::string dir_;
};

}  // namespace

std::unique_ptr<CalibrationImages> images_from_glob(const std::string& pattern) {
  glob_t matches{};
  // GLOB_MARK: directories end in '/', so "dir/*" skips subdirectories rather than failing on them.
  errno = 0;
  const int result = glob(pattern.c_str(), GLOB_ERR | GLOB_MARK | GLOB_TILDE_CHECK, nullptr, &matches);
  const int glob_errno = errno;
  std::vector<std::string> files;
  if (result == 0)
    for (size_t i = 0; i < matches.gl_pathc; ++i) {
      const std::string path = matches.gl_pathv[i];
      if (!path.empty() && path.back() != '/') files.push_back(path);
    }
  globfree(&matches);
  if (result == GLOB_NOMATCH || (result == 0 && files.empty()))
    throw CalibrationInputError(fmt::format("'{}': no file matches this pattern", pattern));
  if (result == GLOB_ABORTED)
    throw CalibrationInputError(fmt::format("'{}': cannot list a directory of this pattern: {}", pattern,
                                            glob_errno != 0 ? std::strerror(glob_errno) : "read error"));
  if (result != 0) throw CalibrationInputError(fmt::format("'{}': cannot expand this pattern (out of memory)", pattern));
  std::sort(files.begin(), files.end());  // glob sorts by the locale's collation; make it bytewise
  return std::make_unique<GlobImages>(pattern, std::move(files));
}

std::unique_ptr<CalibrationImages> images_from_recording(const std::filesystem::path& dir) {
  try {
    return std::make_unique<RecordingImages>(dir);
  } catch (const std::exception& e) {  // RecordingError, or a camera model that does not load
    throw CalibrationInputError(fmt::format("{}: cannot open the recording: {}", dir.string(), e.what()));
  }
}

}  // namespace arpipe::calib
