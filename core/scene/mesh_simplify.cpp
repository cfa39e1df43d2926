// Reduces a proxy mesh (an occluder and collider standing for real geometry, seed 003 sections
// 2.6-2.8) to a fraction of its triangles with meshoptimizer: welded by position, simplified, given
// new normals.
#include "core/scene/mesh_simplify.h"

#include <fmt/format.h>
#include <meshoptimizer.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "core/scene/mesh_weld.h"

namespace arpipe {
namespace {

// meshopt's error bound for the retries: far beyond any mesh (errors are fractions of its size),
// so only the target count stops the simplifier.
constexpr float kUnboundedSimplifyError = 1e6f;

using SimplifyRgba = std::array<float, 4>;

// Per input part (and one more for triangles in none): its colour's number among the distinct
// colours, which are listed in `colours`.
std::vector<uint32_t> colour_of_parts(const Mesh& mesh, std::vector<SimplifyRgba>& colours) {
  std::vector<uint32_t> colour_index;
  auto index_of = [&](const SimplifyRgba& rgba) {
    const auto found = std::find(colours.begin(), colours.end(), rgba);
    if (found != colours.end()) return static_cast<uint32_t>(found - colours.begin());
    colours.push_back(rgba);
    return static_cast<uint32_t>(colours.size() - 1);
  };
  for (const MeshPart& part : mesh.parts) colour_index.push_back(index_of(part.base_color));
  colour_index.push_back(index_of(SimplifyRgba{1, 1, 1, 1}));  // a triangle in no part: white, as the loader's default
  return colour_index;
}

// The simplified triangles' colours: the colour most of the corners had (each welded vertex has the
// colour of the first input triangle that used it; three different: the first corner's).
std::vector<uint32_t> triangle_colours(const WeldedMesh& welded, const std::vector<uint32_t>& part_colour,
                                       const std::vector<uint32_t>& simplified) {
  constexpr uint32_t kNone = UINT32_MAX;
  std::vector<uint32_t> vertex_colour(welded.vertex_count(), kNone);
  for (size_t t = 0; t < welded.triangle_count(); ++t)
    for (size_t k = 0; k < 3; ++k) {
      uint32_t& colour = vertex_colour[welded.indices[3 * t + k]];
      if (colour == kNone) colour = part_colour[welded.triangle_part[t]];
    }
  std::vector<uint32_t> out(simplified.size() / 3);
  for (size_t t = 0; t < out.size(); ++t) {
    const uint32_t a = vertex_colour[simplified[3 * t]], b = vertex_colour[simplified[3 * t + 1]],
                   c = vertex_colour[simplified[3 * t + 2]];
    out[t] = (b == c && a != b) ? b : a;
  }
  return out;
}

Vec3 unit_normal_or_up(const Vec3& v) {
  const double length = norm(v);
  return length > 0 && std::isfinite(length) ? (1.0 / length) * v : Vec3{0, 0, 1};
}

void push_simplified_vec3(std::vector<float>& out, const Vec3& v) {
  out.insert(out.end(), {static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2])});
}

// The output mesh: triangles grouped into one part per colour, normals as asked.
Mesh build_simplified_mesh(const WeldedMesh& welded, const std::vector<uint32_t>& simplified,
                  const std::vector<uint32_t>& colour_of_triangle, const std::vector<SimplifyRgba>& colours,
                  ProxyNormals normals) {
  Mesh out;
  const size_t triangles = simplified.size() / 3;
  std::vector<size_t> order(triangles);
  for (size_t t = 0; t < triangles; ++t) order[t] = t;
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return colour_of_triangle[a] < colour_of_triangle[b]; });

  std::vector<uint32_t> new_index(welded.vertex_count(), UINT32_MAX);  // smooth: welded -> output vertex
  std::vector<Vec3> smooth_normal;
  if (normals == ProxyNormals::smooth) {
    for (size_t t = 0; t < triangles; ++t)
      for (size_t k = 0; k < 3; ++k) {
        uint32_t& index = new_index[simplified[3 * t + k]];
        if (index != UINT32_MAX) continue;
        index = static_cast<uint32_t>(out.vertex_count());
        push_simplified_vec3(out.positions, welded.position_of(simplified[3 * t + k]));
      }
    smooth_normal.assign(out.vertex_count(), Vec3{0, 0, 0});
  }
  for (size_t at = 0; at < triangles; ++at) {
    const size_t t = order[at];
    const uint32_t colour = colour_of_triangle[t];
    if (out.parts.empty() || out.parts.back().base_color != colours[colour])
      out.parts.push_back(MeshPart{static_cast<uint32_t>(out.indices.size()), 0, colours[colour]});
    const uint32_t a = simplified[3 * t], b = simplified[3 * t + 1], c = simplified[3 * t + 2];
    const Vec3 pa = welded.position_of(a), pb = welded.position_of(b), pc = welded.position_of(c);
    const Vec3 area_normal = cross(pb - pa, pc - pa);  // twice the area, outwards for counter-clockwise
    if (normals == ProxyNormals::smooth) {
      for (uint32_t v : {a, b, c}) {
        smooth_normal[new_index[v]] = smooth_normal[new_index[v]] + area_normal;
        out.indices.push_back(new_index[v]);
      }
    } else {
      const Vec3 n = unit_normal_or_up(area_normal);
      for (const Vec3& p : {pa, pb, pc}) {
        out.indices.push_back(static_cast<uint32_t>(out.vertex_count()));
        push_simplified_vec3(out.positions, p);
        push_simplified_vec3(out.normals, n);
      }
    }
    out.parts.back().index_count += 3;
  }
  if (normals == ProxyNormals::smooth)
    for (const Vec3& n : smooth_normal) push_simplified_vec3(out.normals, unit_normal_or_up(n));
  return out;
}

void check_simplify_settings(const MeshSimplifySettings& settings) {
  if (!std::isfinite(settings.ratio) || settings.ratio <= 1)
    throw std::invalid_argument(fmt::format("the ratio must be a finite number above 1, got {}", settings.ratio));
  if (!std::isfinite(settings.max_error) || settings.max_error <= 0)
    throw std::invalid_argument(fmt::format("the error bound must be a finite number above 0, got {}", settings.max_error));
  if (!std::isfinite(settings.weld_tolerance) || settings.weld_tolerance <= 0)
    throw std::invalid_argument(
        fmt::format("the weld tolerance must be a finite number above 0, got {}", settings.weld_tolerance));
}

}  // namespace

std::string_view simplify_method_name(SimplifyMethod method) {
  switch (method) {
    case SimplifyMethod::within_error_bound: return "meshopt_simplify within the error bound";
    case SimplifyMethod::error_bound_raised: return "meshopt_simplify with the error bound lifted";
    case SimplifyMethod::sloppy: return "meshopt_simplifySloppy (topology not kept)";
  }
  return "?";
}

namespace {

// The weld and meshopt's scale: what both kinds of simplification start from.
struct SimplifyStart {
  WeldedMesh welded;
  MeshSimplifyResult result;
};

SimplifyStart start_simplify(const Mesh& mesh, double weld_tolerance) {
  SimplifyStart start;
  MeshSimplifyResult& result = start.result;
  result.input_triangles = mesh.triangle_count();
  result.input_vertices = mesh.vertex_count();
  const Bounds box = mesh.bounds();
  const double size = std::max({box.max[0] - box.min[0], box.max[1] - box.min[1], box.max[2] - box.min[2]});
  start.welded = weld_by_position(mesh, weld_tolerance * size);  // checks the mesh
  result.welded_vertices = start.welded.vertex_count();
  result.welded_triangles = start.welded.triangle_count();
  result.input_unpaired_edges = count_unpaired_edges(start.welded);
  result.scale_m =
      meshopt_simplifyScale(start.welded.positions.data(), start.welded.vertex_count(), 3 * sizeof(float));
  return start;
}

// The simplified triangles made a mesh again: colours carried over, normals made.
void finish_simplify(const Mesh& mesh, const WeldedMesh& welded, const std::vector<uint32_t>& simplified,
                     ProxyNormals normals, MeshSimplifyResult& result,
                     std::chrono::steady_clock::time_point start) {
  WeldedMesh simplified_welded{welded.positions, simplified, {}};
  result.output_unpaired_edges = count_unpaired_edges(simplified_welded);
  std::vector<SimplifyRgba> colours;
  const std::vector<uint32_t> part_colour = colour_of_parts(mesh, colours);
  std::vector<uint32_t> colour_of_triangle = triangle_colours(welded, part_colour, simplified);
  std::vector<bool> used(colours.size(), false);
  for (uint32_t t : welded.triangle_part) used[part_colour[t]] = true;
  result.colours = static_cast<size_t>(std::count(used.begin(), used.end(), true));
  result.mesh = build_simplified_mesh(welded, simplified, colour_of_triangle, colours, normals);
  result.mesh.source = mesh.source;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

MeshSimplifyResult simplify_mesh(const Mesh& mesh, const MeshSimplifySettings& settings) {
  const auto start = std::chrono::steady_clock::now();
  check_simplify_settings(settings);
  SimplifyStart begun = start_simplify(mesh, settings.weld_tolerance);
  const WeldedMesh& welded = begun.welded;
  MeshSimplifyResult& result = begun.result;
  const double wanted = std::floor(double(result.input_triangles) / settings.ratio);
  if (wanted < 4)
    throw std::invalid_argument(fmt::format(
        "ratio {} leaves {} of {} triangles; a closed proxy needs at least 4 (a ratio of at most {})", settings.ratio,
        wanted, result.input_triangles, double(result.input_triangles) / 4));
  result.target_triangles = static_cast<size_t>(wanted);

  const size_t target_indices = 3 * result.target_triangles;
  std::vector<uint32_t> simplified(welded.indices.size());
  float error = 0;
  auto run_simplify = [&](float bound) {
    return meshopt_simplify(simplified.data(), welded.indices.data(), welded.indices.size(), welded.positions.data(),
                            welded.vertex_count(), 3 * sizeof(float), target_indices, bound, 0, &error);
  };
  size_t count = welded.indices.size();
  if (count > target_indices) count = run_simplify(static_cast<float>(settings.max_error));
  else simplified = welded.indices;  // the weld alone reached the target
  if (count > target_indices) {
    result.method = SimplifyMethod::error_bound_raised;
    count = run_simplify(kUnboundedSimplifyError);
  }
  if (count > target_indices) {
    result.method = SimplifyMethod::sloppy;
    count = meshopt_simplifySloppy(simplified.data(), welded.indices.data(), welded.indices.size(),
                                   welded.positions.data(), welded.vertex_count(), 3 * sizeof(float), target_indices,
                                   kUnboundedSimplifyError, &error);
  }
  if (count > target_indices || count == 0)
    throw std::runtime_error(fmt::format("{}: meshoptimizer left {} triangles, the target is at most {}",
                                         mesh.source.empty() ? std::string("the mesh") : mesh.source, count / 3,
                                         result.target_triangles));
  simplified.resize(count);
  result.error = error;
  finish_simplify(mesh, welded, simplified, settings.normals, result, start);
  return result;
}

MeshSimplifyResult simplify_mesh_within_error(const Mesh& mesh, double max_error, ProxyNormals normals,
                                              double weld_tolerance) {
  const auto start = std::chrono::steady_clock::now();
  if (!(std::isfinite(max_error) && max_error > 0))
    throw std::invalid_argument(fmt::format("max_error {} is not a finite number above 0", max_error));
  if (!(std::isfinite(weld_tolerance) && weld_tolerance > 0))
    throw std::invalid_argument(fmt::format("weld_tolerance {} is not a finite number above 0", weld_tolerance));
  SimplifyStart begun = start_simplify(mesh, weld_tolerance);
  const WeldedMesh& welded = begun.welded;
  MeshSimplifyResult& result = begun.result;
  std::vector<uint32_t> simplified(welded.indices.size());
  float error = 0;
  // Target: none (0 indices), so that only the error bound stops it.
  const size_t count = meshopt_simplify(simplified.data(), welded.indices.data(), welded.indices.size(),
                                        welded.positions.data(), welded.vertex_count(), 3 * sizeof(float), 0,
                                        static_cast<float>(max_error), 0, &error);
  if (count == 0) throw std::runtime_error(fmt::format("{}: meshoptimizer left no triangle", mesh.source));
  simplified.resize(count);
  result.target_triangles = count / 3;
  result.error = error;
  finish_simplify(mesh, welded, simplified, normals, result, start);
  return result;
}

}  // namespace arpipe
