// Where a proxy's silhouette is compared with its original's: cameras on the faces, edges and
// corners of a cube around the mesh, looking at its centre, and the comparison over those views.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/geometry/camera_model.h"
#include "core/geometry/se3.h"
#include "core/scene/mesh.h"
#include "core/scene/silhouette_raster.h"

namespace arpipe {

struct SilhouetteView {
  std::string name;  // "+x", "+x-y", "+x+y+z", ... (the direction from the centre to the camera), or "--pose"
  SE3 T_cam_mesh;
};

// The camera at `eye` looking at `target` (camera frame: x right, y down, z forward), the image's
// up towards the mesh's +z, or towards +y when looking straight along z.
SE3 look_at(const Vec3& eye, const Vec3& target);

// 26 views at distance_m from the bounding box's centre, one per direction (a, b, c) in
// {-1, 0, 1}^3 other than 0: the faces, edges and corners of a cube.
std::vector<SilhouetteView> cube_views_around(const Bounds& box, double distance_m);

// The radius of the sphere about the box's centre that holds the box: half its diagonal.
double bounding_radius_m(const Bounds& box);

// The distance at which the bounding sphere spans about half the image's smaller side,
// 4 f r / min(width, height) with f the camera's focal length (fx or fy, the smaller); nullopt
// for a lens model without fx, fy, cx, cy.
std::optional<double> default_view_distance_m(const Bounds& box, const CameraModel& camera);

// The camera the comparison uses without a camera model: 640 x 480 pixels, a pinhole with a 60
// degree horizontal field of view, centred.
CameraModel default_silhouette_camera();

struct SilhouetteViewResult {
  std::string name;
  SilhouetteEdgeError error;
  size_t skipped_triangles = 0;  // of both meshes: a corner behind the camera
};

struct SilhouetteComparison {
  std::vector<SilhouetteViewResult> views;
  size_t views_measured = 0;  // views where the reference has a silhouette edge in the picture
  double mean_error_px = 0;   // over the views measured (NaN when none)
  double max_error_px = 0;
  std::string worst_view;
  double seconds = 0;
};

// Draws both meshes from each view through the camera (draw_mesh_silhouette) and measures the
// silhouette edge error of `other` against `reference`.
SilhouetteComparison compare_silhouettes(const Mesh& reference, const Mesh& other, const CameraModel& camera,
                                         const std::vector<SilhouetteView>& views, int samples_per_axis = 4);

}  // namespace arpipe
