// Sub-pixel chessboard corners by fitting a model of the blurred X-junction to the pixels around
// each corner: two straight edges through the corner, the quadrants between them alternately dark
// and bright, the whole blurred by a Gaussian. More accurate than cornerSubPix, which finds the
// point where the window's gradients are most nearly orthogonal to the rays from it and is pulled
// by noise on every gradient in the window (measured in docs/CALIBRATION.md, bench/calib_corners).
#pragma once

#include <optional>

#include "core/geometry/vec.h"

namespace cv {
class Mat;
}

namespace arpipe::calib {

struct CornerFitOptions {
  double radius_px = 5;          // pixels within this distance of the first guess take part
  int max_iterations = 30;
  int subsamples = 4;            // the model is integrated over each pixel on an n x n grid
  bool srgb_encoded = true;      // decode the grey values by the sRGB curve before the fit
  double min_contrast = 8;       // the fitted bright-dark difference must reach this (grey levels, linear when decoded)
  double max_shift_share = 0.5;  // a fit that moves farther than this share of radius_px is refused
};

// The corner near `guess` in an 8-bit grey image (pixel centres at integer coordinates, as in
// mrcal and OpenCV). edge_a and edge_b: the image directions of the two board lines through the
// corner, roughly (from the neighbouring corners); their length does not matter. nullopt when the
// fit does not converge to a credible junction (too little contrast, edges nearly parallel, the
// window leaving the image, or the corner sliding away): the caller then keeps what it had.
std::optional<Vec2> fit_chessboard_corner(const cv::Mat& grey, const Vec2& guess, const Vec2& edge_a,
                                          const Vec2& edge_b, const CornerFitOptions& options = {});

}  // namespace arpipe::calib
