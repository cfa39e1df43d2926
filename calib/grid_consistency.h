// A corner that does not sit where its neighbours on the board say it should: a finder that put it
// on the wrong junction (OpenCV's classic finder does, on glare, by up to 9.8 px on the
// calib-board-photo capture) and a refinement that could not move it. Each seen corner is compared
// with the homography its neighbours on the board give (the 3 x 3 around it, or the 5 x 5 at the
// board's edge); over two or three squares a lens bends the grid too little to matter (measured on
// the calib-board capture's true corners through its wide lens: at most 2.1 % of a square, against
// the 10 % allowed). Used on the classic finder's boards only: the other finders check their grids
// themselves, and a fisheye lens bends two squares more than this lens does.
#pragma once

#include <vector>

#include "core/geometry/vec.h"

namespace arpipe::calib {

// How far off its neighbours' homography a corner may lie, as a share of the local square.
inline constexpr double kMaxOffGridShare = 0.1;

struct OffGridCorner {
  int index = -1;          // row * cols + col
  double share = 0;        // distance from the neighbours' prediction / the local square
};

// The seen corner (weight > 0) that lies farthest from where its seen neighbours put it, as a share
// of the square there; index -1 when no corner has enough seen neighbours (4) to be judged.
OffGridCorner farthest_off_grid(int rows, int cols, const std::vector<Vec2>& pixels, const std::vector<double>& weights);

// Drops (weight -1, mrcal's outlier convention) the corners that lie more than kMaxOffGridShare
// of a square off their neighbours' homography, worst first, judging again after each (a wrong
// corner also bends its neighbours' predictions). Returns how many it dropped.
int drop_off_grid_corners(int rows, int cols, const std::vector<Vec2>& pixels, std::vector<double>& weights);

}  // namespace arpipe::calib
