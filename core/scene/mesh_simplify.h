// Reduces a proxy mesh (an occluder and collider standing for real geometry, seed 003 sections
// 2.6-2.8) to a fraction of its triangles with meshoptimizer: welded by position, simplified, given
// new normals.
#pragma once

#include <cstddef>
#include <string_view>

#include "core/scene/mesh.h"

namespace arpipe {

enum class ProxyNormals {
  flat,    // per triangle: every triangle gets its own three vertices (a box stays a box)
  smooth,  // per welded vertex: the area-weighted mean of its triangles' normals
};

// How the target was reached, in the order they are tried.
enum class SimplifyMethod {
  within_error_bound,  // meshopt_simplify within MeshSimplifySettings::max_error
  error_bound_raised,  // meshopt_simplify, only once the error bound was lifted (topology kept)
  sloppy,              // meshopt_simplifySloppy: meshopt_simplify stopped short; topology not kept
};
std::string_view simplify_method_name(SimplifyMethod method);  // "meshopt_simplify within the error bound", ...

struct MeshSimplifySettings {
  // At most floor(triangles / ratio) triangles are left; the seed's proxies are simplified 10:1.
  double ratio = 10;
  // meshopt's target error for the first try, as a fraction of the mesh's size (its largest
  // extent, meshopt_simplifyScale): 0.01 lets the surface move by 1 % of the mesh.
  double max_error = 0.01;
  ProxyNormals normals = ProxyNormals::flat;
  // Vertices closer than this fraction of the mesh's size are welded before simplifying (seams of
  // split normals, a builtin sphere's seam and poles).
  double weld_tolerance = 1e-6;
};

struct MeshSimplifyResult {
  Mesh mesh;  // the simplified mesh; Mesh::source kept, parts by colour (below)
  size_t input_triangles = 0;
  size_t input_vertices = 0;
  size_t welded_vertices = 0;   // distinct positions after the weld
  size_t welded_triangles = 0;  // after the weld, less the triangles it made degenerate
  size_t input_unpaired_edges = 0;   // count_unpaired_edges of the welded input: 0 when closed
  size_t output_unpaired_edges = 0;  // the same of the simplified triangles
  size_t target_triangles = 0;       // floor(input_triangles / ratio)
  double error = 0;    // meshopt's result error, a fraction of scale_m
  double scale_m = 0;  // the mesh's size as meshopt measures it (meshopt_simplifyScale)
  SimplifyMethod method = SimplifyMethod::within_error_bound;
  // Distinct base colours among the input's parts. With more than one, each simplified triangle
  // takes the colour that most of its corners had in the input (a corner: the colour of the first
  // input triangle that used it), and the output has one part per colour.
  size_t colours = 1;
  double seconds = 0;  // weld, simplify and normals
};

// Throws AssetError naming Mesh::source for a mesh that is not one (weld_by_position's checks),
// std::invalid_argument for settings out of range (ratio not a finite number above 1 or leaving
// fewer than 4 triangles, the smallest closed solid; max_error or weld_tolerance not finite and
// positive) and std::runtime_error when even meshopt_simplifySloppy cannot reach the target.
MeshSimplifyResult simplify_mesh(const Mesh& mesh, const MeshSimplifySettings& settings);

// As far as meshopt_simplify goes while the surface moves by at most max_error (a fraction of the
// mesh's size, as above), with no triangle target: an occluder's coarser levels of detail. The
// result's target_triangles is what it reached; its method is within_error_bound. Throws as above.
MeshSimplifyResult simplify_mesh_within_error(const Mesh& mesh, double max_error,
                                              ProxyNormals normals = ProxyNormals::flat, double weld_tolerance = 1e-6);

}  // namespace arpipe
