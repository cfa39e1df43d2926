// PixelRect's set operations and disjoint_rects, against pixel sets counted by hand.
#include <gtest/gtest.h>

#include <set>
#include <utility>
#include <vector>

#include "core/image/pixel_rect.h"

namespace arpipe {
namespace {

std::set<std::pair<int, int>> pixels_of(const std::vector<PixelRect>& rects) {
  std::set<std::pair<int, int>> out;
  for (const PixelRect& r : rects)
    for (int y = r.y; y < r.bottom(); ++y)
      for (int x = r.x; x < r.right(); ++x) out.insert({x, y});
  return out;
}

TEST(PixelRect, UnitedAndIntersected) {
  const PixelRect a{0, 0, 10, 10}, b{5, 8, 10, 4};
  EXPECT_EQ(a.united(b), (PixelRect{0, 0, 15, 12}));
  EXPECT_EQ(a.intersected(b), (PixelRect{5, 8, 5, 2}));
  EXPECT_TRUE(a.intersected(PixelRect{10, 0, 3, 3}).empty());  // touching edges share no pixel
  EXPECT_EQ(PixelRect{}.united(b), b);
}

TEST(DisjointRects, OverlappingOnesMergeAndNoPixelIsLost) {
  // Two overlapping pairs far apart, a touching neighbour (no shared pixel: stays apart) and an
  // empty one (dropped).
  const std::vector<PixelRect> in{{0, 0, 10, 10}, {8, 8, 10, 10}, {100, 0, 5, 5}, {102, 3, 6, 6}, {18, 0, 4, 4}, {50, 50, 0, 9}};
  const std::vector<PixelRect> out = disjoint_rects(in);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_EQ(out[0], (PixelRect{0, 0, 18, 18}));
  EXPECT_EQ(out[1], (PixelRect{100, 0, 8, 9}));
  EXPECT_EQ(out[2], (PixelRect{18, 0, 4, 4}));
  for (size_t i = 0; i < out.size(); ++i)
    for (size_t j = i + 1; j < out.size(); ++j) EXPECT_TRUE(out[i].intersected(out[j]).empty()) << i << " " << j;
  const std::set<std::pair<int, int>> before = pixels_of(in), after = pixels_of(out);
  for (const auto& p : before) EXPECT_TRUE(after.count(p)) << p.first << "," << p.second;
}

TEST(DisjointRects, AMergeThatReachesAThirdMergesItToo) {
  // a and b overlap; c overlaps neither, but their hull (0..10 x 0..10) it does.
  const std::vector<PixelRect> out = disjoint_rects({{0, 0, 6, 6}, {4, 4, 6, 6}, {8, 0, 4, 3}});
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0], (PixelRect{0, 0, 12, 10}));
}

}  // namespace
}  // namespace arpipe
