// arpipe proxy simplify: reduces a proxy mesh (an occluder and collider standing for real
// geometry, seed 003) to about 1/R of its triangles, writes it as a .glb and reports how far its
// silhouette moved as a camera sees it.
#include <fmt/format.h>

#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "apps/arpipe/commands.h"
#include "apps/cli/command_line.h"
#include "apps/cli/number_list.h"
#include "capture/sinks/output_path.h"
#include "core/geometry/camera_model.h"
#include "core/geometry/se3.h"
#include "core/pipeline/monotonic_clock.h"
#include "core/scene/builtin_meshes.h"
#include "core/scene/glb_writer.h"
#include "core/scene/gltf_loader.h"
#include "core/scene/mesh_simplify.h"
#include "core/scene/silhouette_views.h"

namespace arpipe {
namespace {

namespace fs = std::filesystem;

struct ProxySimplifyOptions {
  std::string input;
  fs::path out;
  MeshSimplifySettings settings;
  std::string normals = "flat";
  fs::path camera;
  double view_distance_m = 0;  // 0: the default
  std::string pose;
  int samples = 4;
  bool per_view = false;
};

// "RX,RY,RZ,TX,TY,TZ": six finite numbers, the mesh in the camera frame (rotation vector in
// radians, translation in metres): T_cam_mesh.
std::optional<SE3> parse_proxy_pose(std::string_view text) {
  const auto v = cli::parse_number_list<6>(text);
  if (!v) return std::nullopt;
  return SE3::from_rt({(*v)[0], (*v)[1], (*v)[2]}, {(*v)[3], (*v)[4], (*v)[5]});
}

bool is_glb_name(const fs::path& path) {
  std::string extension = path.extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return extension == ".glb" && !path.stem().empty();
}

Mesh load_proxy_input(const std::string& input) {
  if (!is_builtin_mesh_source(input)) return load_gltf_mesh(input);
  std::optional<Mesh> builtin = make_builtin_mesh(input);
  if (!builtin)
    throw std::runtime_error(fmt::format("unknown builtin mesh \"{}\" (known: {})", input, kBuiltinMeshNames));
  builtin->source = input;
  return std::move(*builtin);
}

std::string proxy_closed_text(size_t unpaired_edges) {
  return unpaired_edges == 0 ? std::string("yes") : fmt::format("no: {} unpaired edges", unpaired_edges);
}

int simplify_proxy(ProxySimplifyOptions options) {
  const auto start = std::chrono::steady_clock::now();
  const fs::path& out = options.out;
  // What can be said before any work: where the result goes.
  const fs::path folder = out.parent_path().empty() ? fs::path(".") : out.parent_path();
  std::error_code ec;
  if (!fs::is_directory(folder, ec))
    throw std::runtime_error(fmt::format("cannot write {}: the folder {} does not exist", out.string(), folder.string()));
  if (fs::is_directory(out, ec)) throw std::runtime_error(fmt::format("cannot write {}: it is a folder", out.string()));
  options.settings.normals = options.normals == "smooth" ? ProxyNormals::smooth : ProxyNormals::flat;

  const Mesh original = load_proxy_input(options.input);
  const bool default_camera = options.camera.empty();
  const CameraModel camera = default_camera ? default_silhouette_camera() : CameraModel::load(options.camera);
  const Bounds box = original.bounds();
  std::vector<SilhouetteView> views;
  std::string views_text;
  if (!options.pose.empty()) {
    views.push_back({"--pose", *parse_proxy_pose(options.pose)});  // checked when read
    views_text = "1: --pose " + options.pose;
  } else {
    double distance = options.view_distance_m;
    if (distance <= 0) {
      const std::optional<double> fitted = default_view_distance_m(box, camera);
      if (!fitted)
        cli::usage_error(fmt::format("{}: lens model {} has no focal length to fit the views to; give --view-distance-m or --pose",
                                     options.camera.string(), camera.lensmodel()));
      distance = *fitted;
    }
    const double radius = bounding_radius_m(box);
    if (distance <= radius)
      cli::usage_error(fmt::format("--view-distance-m {} puts the camera inside the mesh's bounding sphere (radius {:.4g} m)",
                                   distance, radius));
    views = cube_views_around(box, distance);
    views_text = fmt::format("{} at {:.4g} m from the bounding box's centre (cube faces, edges, corners){}",
                             views.size(), distance, options.view_distance_m > 0 ? "" : ", the mesh about half the picture");
  }

  MeshSimplifyResult result;
  try {
    result = simplify_mesh(original, options.settings);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(fmt::format("{}: {}", options.input, e.what()));
  }
  const SilhouetteComparison silhouettes = compare_silhouettes(original, result.mesh, camera, views, options.samples);
  if (silhouettes.views_measured == 0)
    throw std::runtime_error(fmt::format("{}: the mesh shows no silhouette edge in the picture from {}; nothing written",
                                         options.input, options.pose.empty() ? "any view" : "--pose " + options.pose));

  const auto write_start = std::chrono::steady_clock::now();
  const std::vector<uint8_t> glb = encode_glb(result.mesh, fmt::format("arpipe proxy simplify {}", cli::version()));
  if (const int error = replace_file(out, glb); error != 0)
    throw std::runtime_error(fmt::format("cannot write {}: {}", out.string(), std::strerror(error)));
  const double write_ms = milliseconds_since(write_start);

  const size_t after = result.mesh.triangle_count();
  std::printf("proxy            %s -> %s\n", options.input.c_str(), out.string().c_str());
  std::printf("                   triangles   vertices  closed\n");
  std::printf("  original        %10zu %10zu\n", result.input_triangles, result.input_vertices);
  std::printf("  welded          %10zu %10zu  %s\n", result.welded_triangles, result.welded_vertices,
              proxy_closed_text(result.input_unpaired_edges).c_str());
  std::printf("  simplified      %10zu %10zu  %s\n", after, result.mesh.vertex_count(),
              proxy_closed_text(result.output_unpaired_edges).c_str());
  std::printf("ratio            %.2f:1 (asked %g:1: at most %zu triangles)\n", double(result.input_triangles) / double(after),
              options.settings.ratio, result.target_triangles);
  std::printf("method           %s (--max-error %g)\n", std::string(simplify_method_name(result.method)).c_str(),
              options.settings.max_error);
  std::printf("meshopt error    %.3g of the mesh's size (%.4g m): %.3g mm\n", result.error, result.scale_m,
              result.error * result.scale_m * 1e3);
  std::printf("normals          %s\n", options.settings.normals == ProxyNormals::smooth
                                        ? "smooth (per vertex, area-weighted)"
                                        : "flat (per triangle)");
  std::printf("parts            %zu (%zu colour%s in the original)\n", result.mesh.parts.size(), result.colours,
              result.colours == 1 ? "" : "s");
  if (default_camera)
    std::printf("camera           none given (--camera): a 640x480 pinhole with a 60 degree horizontal field of view\n");
  else
    std::printf("camera           %s (%s, %dx%d)\n", options.camera.string().c_str(), camera.lensmodel().c_str(),
                camera.width(), camera.height());
  std::printf("views            %s, %dx%d samples per pixel\n", views_text.c_str(), options.samples, options.samples);
  if (options.per_view) {
    std::printf("  view         edge error px   difference px^2   edge px   triangles behind\n");
    for (const SilhouetteViewResult& view : silhouettes.views)
      std::printf("  %-12s %13.4f %17.2f %9.1f %18zu\n", view.name.c_str(), view.error.error_px,
                  view.error.difference_px2, view.error.edge_length_px, view.skipped_triangles);
  }
  std::printf("silhouette edge  error mean %.3f px, max %.3f px (view %s), over %zu view%s\n", silhouettes.mean_error_px,
              silhouettes.max_error_px, silhouettes.worst_view.c_str(), silhouettes.views_measured,
              silhouettes.views_measured == 1 ? "" : "s");
  size_t behind = 0;
  for (const SilhouetteViewResult& view : silhouettes.views) behind += view.skipped_triangles;
  if (behind > 0) std::printf("  (%zu triangles with a corner behind the camera were left out of the silhouettes)\n", behind);
  std::printf("time             simplify %.1f ms, silhouettes %.1f ms, write %.1f ms, total %.1f ms\n",
              result.seconds * 1e3, silhouettes.seconds * 1e3, write_ms, milliseconds_since(start));
  std::printf("wrote            %s (%zu bytes)\n", out.string().c_str(), glb.size());
  return 0;
}

}  // namespace

void add_proxy_command(CLI::App& arpipe) {
  CLI::App* proxy = arpipe.add_subcommand("proxy", "work on proxy meshes (occluders and colliders for real geometry)");
  proxy->require_subcommand(1);
  CLI::App* command = proxy->add_subcommand(
      "simplify", "reduce a mesh to about 1/R of its triangles (meshoptimizer), write it as a .glb and report how far "
                  "its silhouette moved");
  auto options = std::make_shared<ProxySimplifyOptions>();
  command->add_option("IN", options->input, "a glTF file (.gltf, .glb) or a builtin mesh (builtin:sphere, builtin:cube, ...)")
      ->required();
  command->add_option("--out", options->out, "the simplified mesh, binary glTF; replaced only once it is complete")
      ->type_name("OUT.glb")
      ->required()
      ->check(cli::accepted_by([](const std::string& t) { return is_glb_name(t); }, "a file name ending in .glb"));
  command->add_option("--ratio", options->settings.ratio, "keep at most 1/R of the triangles (the seed's proxies: 10)")
      ->type_name("R")
      ->check(cli::accepted_by(
          [](const std::string& t) {
            double v = 0;
            return CLI::detail::lexical_cast(t, v) && std::isfinite(v) && v > 1 && v <= 1e9;
          },
          "a number above 1 (and at most 1e9)"));
  command->add_option("--max-error", options->settings.max_error,
                      "meshopt's error bound for the first try, a fraction of the mesh's size (lifted, and said so, "
                      "when the ratio needs more)")
      ->type_name("E")
      ->check(cli::accepted_by(
          [](const std::string& t) {
            double v = 0;
            return CLI::detail::lexical_cast(t, v) && std::isfinite(v) && v > 0 && v <= 1;
          },
          "a number in (0, 1]"));
  command->add_option("--normals", options->normals, "flat (per triangle) or smooth (per vertex, area-weighted)")
      ->check(CLI::IsMember({"flat", "smooth"}));
  command->add_option("--camera", options->camera,
                      "the camera the silhouettes are measured through (default: 640x480 pinhole, 60 degrees across)")
      ->type_name("FILE.cameramodel");
  CLI::Option* distance = command->add_option("--view-distance-m", options->view_distance_m,
                      "distance of the 26 views from the mesh's centre (default: the mesh spans about half the picture)")
      ->type_name("D")
      ->check(cli::accepted_by(
          [](const std::string& t) {
            double v = 0;
            return CLI::detail::lexical_cast(t, v) && std::isfinite(v) && v > 0;
          },
          "a distance in metres above 0"));
  command->add_option("--pose", options->pose,
                      "one view instead of 26: the mesh in the camera frame, rotation vector (rad) and translation (m)")
      ->type_name("RX,RY,RZ,TX,TY,TZ")
      ->check(cli::accepted_by([](const std::string& t) { return parse_proxy_pose(t).has_value(); },
                               "six finite numbers separated by commas"))
      ->excludes(distance);
  command->add_option("--samples", options->samples, "silhouette samples per pixel axis (N x N per pixel)")
      ->type_name("N")
      ->check(CLI::Range(1, 16));
  command->add_flag("--per-view", options->per_view, "print every view's silhouette edge error");
  cli::on_run(command, [options] { return simplify_proxy(*options); },
              cli::Failure{.status = 1, .message = cli::Failure::Message::after_command_name});
}

}  // namespace arpipe
