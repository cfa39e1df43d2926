// Where in the image an object can appear: the pixel rectangle that its bounding box projects to
// through the camera model, used to skip frames with nothing in view and to limit GL work.
#pragma once

#include <optional>
#include <span>
#include <vector>

#include "core/geometry/camera_model.h"
#include "core/geometry/se3.h"
#include "core/scene/mesh.h"
#include "core/image/pixel_rect.h"

namespace arpipe {

// box: in the object's frame (already scaled); T_cam_object maps it into the camera frame.
// Returns the bounding rectangle of the projected box, widened by margin_px and clipped to the
// image; of its part in front of the near plane when it reaches behind it (as GL clips it: an
// object beside the camera covers only the image's edge, not all of it); nullopt when it lies
// wholly behind the near plane or outside the image.
std::optional<PixelRect> projected_box_rect(const CameraModel& camera, const SE3& T_cam_object, const Bounds& box,
                                            double margin_px);

// Appends samples + 1 points along the segment a-b (camera frame), cut to its part in front of the
// near plane (none when all of it is behind). The edges of a convex shape so cut, projected, bound
// the projection of its visible part.
void append_segment_in_front(std::vector<Vec3>& points_cam, const Vec3& a, const Vec3& b, int samples);

// For the convex hull of `vertices` (camera frame), all in front of the near plane: appends
// samples + 1 points along each edge of its outline as a pinhole sees it (the 2D convex hull of
// the points (x / z, y / z)). A pinhole maps segments to segments, so that outline bounds the
// hull's projection; a lens bends it, and the samples follow the bend as an edge's would. Far
// fewer points than all the hull's edges: a box swept along the light and grown by a square has
// 64 vertices and 192 edges, and its outline about ten. Returns false (appending nothing) when a
// vertex lies at or behind the near plane or is not finite.
bool append_pinhole_outline(std::vector<Vec3>& points_cam, std::span<const Vec3> vertices, int samples);

// The same for any set of camera-frame points (a shape's edges, sampled densely enough for the
// lens's bend): their bounding rectangle, widened, clipped; the whole image when some lie behind
// the near plane and others in front; nullopt when all lie behind or it misses the image.
std::optional<PixelRect> projected_points_rect(const CameraModel& camera, const std::vector<Vec3>& points_cam,
                                               double margin_px);

}  // namespace arpipe
