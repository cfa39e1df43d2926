// libcamera <-> arpipe pixel formats, checked against the DRM fourcc codes (drm_fourcc.h) and
// their documented memory layouts, not against the code's own table.
#include <gtest/gtest.h>

#include <libcamera/formats.h>

#include "capture/libcamera/libcamera_pixel_format.h"

namespace arpipe {
namespace {

constexpr uint32_t fourcc(char a, char b, char c, char d) {
  return uint32_t(uint8_t(a)) | uint32_t(uint8_t(b)) << 8 | uint32_t(uint8_t(c)) << 16 | uint32_t(uint8_t(d)) << 24;
}

TEST(LibcameraPixelFormat, Rgb24IsDrmBgr888) {
  // DRM_FORMAT_BGR888 = 'BG24', "[23:0] B:G:R little endian": byte 0 is R, as arpipe's RGB24.
  const auto f = libcamera_pixel_format(PixelFormat::RGB24);
  EXPECT_EQ(f.fourcc(), fourcc('B', 'G', '2', '4'));
  EXPECT_EQ(f.modifier(), 0u);
  EXPECT_EQ(pixel_format_from_libcamera(f), PixelFormat::RGB24);
  // DRM_FORMAT_RGB888 ('RG24') is B, G, R in memory: arpipe has no such format.
  EXPECT_EQ(libcamera::formats::RGB888.fourcc(), fourcc('R', 'G', '2', '4'));
  EXPECT_FALSE(pixel_format_from_libcamera(libcamera::formats::RGB888));
}

TEST(LibcameraPixelFormat, YuvAndGreyRoundTrip) {
  // YUYV and NV12 share their fourccs with V4L2; GREY is DRM's R8 ('R8  ').
  EXPECT_EQ(libcamera_pixel_format(PixelFormat::YUYV).fourcc(), pixel_format_fourcc(PixelFormat::YUYV));
  EXPECT_EQ(libcamera_pixel_format(PixelFormat::NV12).fourcc(), pixel_format_fourcc(PixelFormat::NV12));
  EXPECT_EQ(libcamera_pixel_format(PixelFormat::GREY).fourcc(), fourcc('R', '8', ' ', ' '));
  for (auto f : {PixelFormat::GREY, PixelFormat::RGB24, PixelFormat::YUYV, PixelFormat::NV12})
    EXPECT_EQ(pixel_format_from_libcamera(libcamera_pixel_format(f)), f) << pixel_format_name(f);
}

TEST(LibcameraPixelFormat, UnknownFormatsAreNotGuessed) {
  EXPECT_FALSE(pixel_format_from_libcamera(libcamera::formats::YUV420));
  // IPU3's Bayer packing (25 pixels in 32 bytes) is not MIPI's: not taken.
  EXPECT_FALSE(pixel_format_from_libcamera(libcamera::formats::SRGGB10_IPU3));
  EXPECT_FALSE(pixel_format_from_libcamera(libcamera::formats::XRGB8888));
  EXPECT_FALSE(pixel_format_from_libcamera(libcamera::PixelFormat()));
}

// Raw Bayer: DRM's unpacked Bayer fourccs ('RG10' = SRGGB10, 16 bits a pixel, little-endian) are
// V4L2's; its MIPI-packed ones are the same fourcc with the CSI2 packed modifier
// (fourcc_mod_code(MIPI, 1)), which V4L2 names with its own fourcc ('pRAA' = SRGGB10P).
TEST(LibcameraPixelFormat, RawBayerFormatsAreV4l2sOwnLayouts) {
  EXPECT_EQ(libcamera_pixel_format(PixelFormat::SRGGB10).fourcc(), fourcc('R', 'G', '1', '0'));
  EXPECT_EQ(libcamera_pixel_format(PixelFormat::SRGGB10).modifier(), 0u);
  EXPECT_EQ(libcamera_pixel_format(PixelFormat::SBGGR8).fourcc(), fourcc('B', 'A', '8', '1'));
  EXPECT_EQ(libcamera_pixel_format(PixelFormat::SGBRG16).fourcc(), fourcc('G', 'B', '1', '6'));
  const auto packed = libcamera_pixel_format(PixelFormat::SRGGB10P);
  EXPECT_EQ(packed.fourcc(), fourcc('R', 'G', '1', '0'));
  EXPECT_EQ(packed.modifier(), (uint64_t{11} << 56) | 1u);  // DRM_FORMAT_MOD_VENDOR_MIPI = 11
  EXPECT_EQ(pixel_format_from_libcamera(libcamera::formats::SGRBG12_CSI2P), PixelFormat::SGRBG12P);
  for (PixelFormat f : {PixelFormat::SRGGB8, PixelFormat::SGRBG10, PixelFormat::SBGGR12, PixelFormat::SGBRG16,
                        PixelFormat::SBGGR10P, PixelFormat::SGBRG12P})
    EXPECT_EQ(pixel_format_from_libcamera(libcamera_pixel_format(f)), f) << pixel_format_name(f);
  // Auto takes a processed format before a raw one.
  namespace fm = libcamera::formats;
  EXPECT_EQ(preferred_libcamera_format({fm::SRGGB10_CSI2P, fm::NV12}), PixelFormat::NV12);
  EXPECT_EQ(preferred_libcamera_format({fm::SRGGB10_CSI2P}), PixelFormat::SRGGB10P);
}

TEST(LibcameraPixelFormat, AutoPrefersRgb24ThenYuyvThenNv12ThenGrey) {
  namespace f = libcamera::formats;
  EXPECT_EQ(preferred_libcamera_format({f::YUV420, f::NV12, f::BGR888}), PixelFormat::RGB24);
  EXPECT_EQ(preferred_libcamera_format({f::NV12, f::YUYV}), PixelFormat::YUYV);
  EXPECT_EQ(preferred_libcamera_format({f::YUV420, f::R8, f::NV12}), PixelFormat::NV12);
  EXPECT_EQ(preferred_libcamera_format({f::R8}), PixelFormat::GREY);
  EXPECT_FALSE(preferred_libcamera_format({f::YUV420, f::RGB888}));
}

}  // namespace
}  // namespace arpipe
