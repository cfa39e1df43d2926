#include "capture/image_file.h"

#include <fmt/format.h>
#include <png.h>
#include <turbojpeg.h>

#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>

#include "core/config/regular_file.h"
#include "core/image/image_header.h"
#include "core/scene/asset_error.h"

namespace arpipe {

namespace fs = std::filesystem;

namespace {

// Decoding goes to the decoder of the format read_image_header identified, never to OpenCV's
// signature probing: that handed a JPEG with "DICM" at byte 128 to its DICOM decoder, which
// aborted the process. The output is what cv::imread(IMREAD_COLOR) gave: 8-bit BGR, the same
// libpng transforms and the same libjpeg-turbo decoding (except that EXIF orientation is not applied).


[[noreturn]] void undecodable(const fs::path& path, const std::string& what, const std::string& why) {
  throw AssetError(fmt::format("{} \"{}\": cannot be decoded: {}", what, path.string(), why));
}

void check_decoded_size(int64_t width, int64_t height, const fs::path& path, const std::string& what,
                        const std::string& format, const ImageFileLimits& limits) {
  ImageHeader header{format, width, height};
  check_image_limits(header, path, what, limits.max_side, limits.max_pixels);
}

cv::Mat decode_jpeg(const std::string& bytes, const fs::path& path, const std::string& what,
                    const ImageFileLimits& limits) {
  const std::unique_ptr<void, int (*)(tjhandle)> handle(tjInitDecompress(), tjDestroy);
  if (!handle) undecodable(path, what, "JPEG: cannot start libjpeg-turbo");
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  int width = 0, height = 0, subsampling = 0, colorspace = 0;
  if (tjDecompressHeader3(handle.get(), data, bytes.size(), &width, &height, &subsampling, &colorspace) != 0)
    undecodable(path, what, fmt::format("JPEG: {}", tjGetErrorStr2(handle.get())));
  check_decoded_size(width, height, path, what, "JPEG", limits);
  cv::Mat image(height, width, CV_8UC3);
  // Flags 0: accurate integer DCT and fancy upsampling, libjpeg's defaults, as OpenCV decodes.
  // A warning (a file cut short: the rest stays grey) still yields the image, as it did in OpenCV.
  if (tjDecompress2(handle.get(), data, bytes.size(), image.data, width, static_cast<int>(image.step), height,
                    TJPF_BGR, 0) != 0 &&
      tjGetErrorCode(handle.get()) != TJERR_WARNING)
    undecodable(path, what, fmt::format("JPEG: {}", tjGetErrorStr2(handle.get())));
  return image;
}

// libpng reports errors by longjmp: the functions that call setjmp hold only trivially
// destructible locals, and the C++ objects live in decode_png.
struct PngSource {
  const std::string* bytes;
  size_t at = 0;
  char error[256] = {};
};

void png_read_from_memory(png_structp png, png_bytep out, size_t count) {
  auto* source = static_cast<PngSource*>(png_get_io_ptr(png));
  if (source->bytes->size() - source->at < count) png_error(png, "the file ends inside the image");
  std::memcpy(out, source->bytes->data() + source->at, count);
  source->at += count;
}

void png_keep_error(png_structp png, png_const_charp message) {
  auto* source = static_cast<PngSource*>(png_get_error_ptr(png));
  std::snprintf(source->error, sizeof source->error, "%s", message);
  png_longjmp(png, 1);
}

void png_ignore_warning(png_structp, png_const_charp) {}

// OpenCV's PngDecoder transforms for IMREAD_COLOR: 16 bits to their high byte, alpha dropped,
// palette and low-bit grey expanded, colour to BGR, grey to three channels.
bool png_read_header_and_set_transforms(png_structp png, png_infop info) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_info(png, info);
  const int bit_depth = png_get_bit_depth(png, info), color_type = png_get_color_type(png, info);
  if (bit_depth > 8) png_set_strip_16(png);
  png_set_strip_alpha(png);
  if (color_type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if ((color_type & PNG_COLOR_MASK_COLOR) == 0 && bit_depth < 8) png_set_expand_gray_1_2_4_to_8(png);
  if (color_type & PNG_COLOR_MASK_COLOR)
    png_set_bgr(png);
  else
    png_set_gray_to_rgb(png);
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  return true;
}

bool png_read_rows(png_structp png, png_bytepp rows) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_image(png, rows);
  png_read_end(png, nullptr);
  return true;
}

cv::Mat decode_png(const std::string& bytes, const fs::path& path, const std::string& what,
                   const ImageFileLimits& limits) {
  PngSource source{&bytes};
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &source, png_keep_error, png_ignore_warning);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  const auto destroy = [&] { png_destroy_read_struct(&png, info ? &info : nullptr, nullptr); };
  if (!png || !info) {
    destroy();
    undecodable(path, what, "PNG: cannot start libpng");
  }
  png_set_read_fn(png, &source, png_read_from_memory);
  if (!png_read_header_and_set_transforms(png, info)) {
    destroy();
    undecodable(path, what, fmt::format("PNG: {}", source.error));
  }
  const auto width = png_get_image_width(png, info), height = png_get_image_height(png, info);
  const auto row_bytes = png_get_rowbytes(png, info);
  try {
    check_decoded_size(width, height, path, what, "PNG", limits);
  } catch (...) {
    destroy();
    throw;
  }
  cv::Mat image(static_cast<int>(height), static_cast<int>(width), CV_8UC3);
  if (row_bytes != image.step) {
    destroy();
    undecodable(path, what, fmt::format("PNG: {} bytes a row after the transforms, expected {}", row_bytes, image.step));
  }
  std::vector<png_bytep> rows(height);
  for (size_t row = 0; row < rows.size(); ++row) rows[row] = image.ptr<uint8_t>(static_cast<int>(row));
  const bool read = png_read_rows(png, rows.data());
  destroy();
  if (!read) undecodable(path, what, fmt::format("PNG: {}", source.error));
  return image;
}

// The file's bytes (a regular file, at most limits.max_file_bytes), decoded as `header.format`.
cv::Mat read_image(const fs::path& path, const ImageHeader& header, const std::string& what,
                   const ImageFileLimits& limits) {
  std::string bytes;
  try {
    bytes = read_regular_file(path, what, limits.max_file_bytes);
  } catch (const FileAccessError& e) {
    throw AssetError(fmt::format("{} \"{}\": {}", what, path.string(), e.action_and_reason()));
  }
  if (header.format == "PNG") return decode_png(bytes, path, what, limits);
  if (header.format == "JPEG") return decode_jpeg(bytes, path, what, limits);
  undecodable(path, what, fmt::format("no decoder for the format \"{}\"", header.format));
}

// The size the file declares, checked before OpenCV decodes it: a few KB of PNG can declare
// 30000 x 30000 pixels (13 GB once decoded and turned into floats).
ImageHeader checked_header(const fs::path& path, const std::string& what, const ImageFileLimits& limits) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw AssetError(fmt::format("{} \"{}\": no such file", what, path.string()));
  ImageHeader header;
  try {
    header = read_image_header(path);
  } catch (const AssetError& e) {
    throw AssetError(fmt::format("{}: {}", what, e.what()));
  }
  check_image_limits(header, path, what, limits.max_side, limits.max_pixels);
  return header;
}

}  // namespace

cv::Mat read_image_file(const fs::path& path, const std::string& what, const ImageFileLimits& limits) {
  const ImageHeader header = checked_header(path, what, limits);
  return read_image(path, header, what, limits);
}

}  // namespace arpipe
