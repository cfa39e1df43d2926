// The PRT bake: chunks of vertices handed to worker threads, each vertex summed over the shared
// sphere samples in a fixed order (so the bits do not depend on the thread count).
#include "render/prt/prt_bake.h"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <thread>
#include <vector>

#include "core/sh/sh_sampling.h"
#include "core/scene/asset_error.h"
#include "render/prt/prt_ray_scene.h"

namespace arpipe {
namespace {

constexpr size_t kChunkVertices = 64;  // small enough for a smooth progress bar, large enough to amortise the locking

// Runs work(first, last) over [0, count) in chunks on `threads` workers; progress on this thread.
void parallel_chunks(size_t count, int threads, const std::function<void(size_t, size_t)>& work,
                     const std::function<void(size_t)>& chunk_done) {
  const size_t chunks = (count + kChunkVertices - 1) / kChunkVertices;
  std::atomic<size_t> next{0};
  std::mutex mutex;
  std::condition_variable changed;
  size_t finished_vertices = 0, finished_workers = 0;
  std::exception_ptr failure;
  auto worker = [&] {
    for (;;) {
      const size_t chunk = next.fetch_add(1);
      if (chunk >= chunks) break;
      const size_t first = chunk * kChunkVertices, last = std::min(count, first + kChunkVertices);
      try {
        work(first, last);
      } catch (...) {
        std::lock_guard lock(mutex);
        if (!failure) failure = std::current_exception();
        next = chunks;  // the others stop after their chunk
      }
      std::lock_guard lock(mutex);
      finished_vertices += last - first;
      changed.notify_one();
    }
    std::lock_guard lock(mutex);
    ++finished_workers;
    changed.notify_one();
  };
  std::vector<std::thread> pool;
  for (int i = 0; i < threads; ++i) pool.emplace_back(worker);
  size_t reported = 0;
  std::unique_lock lock(mutex);
  for (;;) {
    changed.wait(lock, [&] { return finished_vertices != reported || finished_workers == size_t(threads); });
    if (finished_vertices != reported) {  // before the exit test: the last chunk is reported too
      reported = finished_vertices;
      if (!failure) {
        lock.unlock();
        chunk_done(reported);
        lock.lock();
      }
      continue;
    }
    if (finished_workers == size_t(threads)) break;
  }
  lock.unlock();
  for (std::thread& t : pool) t.join();
  if (failure) std::rethrow_exception(failure);
}

// The samples above a vertex's tangent plane (n.w > 0), in sampler order, with their cosines:
// the rays of one vertex, cast together.
struct Hemisphere {
  std::vector<size_t> sample;
  std::vector<double> cosine;
  std::vector<Vec3> directions;
  std::vector<uint8_t> blocked;  // filled by the shadow rays; all 0 without rays

  size_t size() const { return sample.size(); }
  void gather(const SphereSamples& samples, const Vec3& n) {
    sample.clear();
    cosine.clear();
    directions.clear();
    for (size_t j = 0; j < samples.size(); ++j) {
      const double c = dot(n, samples.directions[j]);
      if (!(c > 0)) continue;
      sample.push_back(j);
      cosine.push_back(c);
      directions.push_back(samples.directions[j]);
    }
    blocked.assign(sample.size(), 0);
  }
};

Vec3 vec_at(const std::vector<float>& xyz, size_t i) {
  return {double(xyz[3 * i]), double(xyz[3 * i + 1]), double(xyz[3 * i + 2])};
}

// Per vertex, the tangential direction into its own triangles, |u| <= 1: the sum of the vectors to
// the adjacent triangles' centroids over the sum of their lengths, minus its normal part. Near 0
// inside a surface (the centroids surround the vertex), towards the surface's interior on a seam
// or a border. Ray origins move by it too, so that a vertex where another surface meets its face
// (a floor vertex at the foot of a wall) does not start its rays in that surface's plane, where
// they would slip through it (Embree counts no hit at t = 0).
std::vector<Vec3> inward_directions(const Mesh& mesh, const std::vector<Vec3>& normals) {
  std::vector<Vec3> sum(mesh.vertex_count(), Vec3{0, 0, 0});
  std::vector<double> length(mesh.vertex_count(), 0.0);
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    const uint32_t* corner = &mesh.indices[3 * t];
    const Vec3 a = vec_at(mesh.positions, corner[0]), b = vec_at(mesh.positions, corner[1]),
               c = vec_at(mesh.positions, corner[2]);
    const Vec3 centroid = (1.0 / 3.0) * (a + b + c);
    for (int k = 0; k < 3; ++k) {
      const Vec3 to_centroid = centroid - vec_at(mesh.positions, corner[k]);
      sum[corner[k]] = sum[corner[k]] + to_centroid;
      length[corner[k]] += norm(to_centroid);
    }
  }
  for (size_t v = 0; v < sum.size(); ++v) {
    if (!(length[v] > 0)) {
      sum[v] = {0, 0, 0};
      continue;
    }
    const Vec3 u = (1.0 / length[v]) * sum[v];
    sum[v] = u - dot(u, normals[v]) * normals[v];
  }
  return sum;
}

void check_settings(const PrtBakeSettings& s) {
  if (s.bands < 1 || s.bands > kMaxShBands)
    throw std::invalid_argument(fmt::format("PRT bake: bands must be in [1, {}], got {}", kMaxShBands, s.bands));
  if (s.samples_per_axis < 1 || s.samples_per_axis > 4096)
    throw std::invalid_argument(
        fmt::format("PRT bake: samples per axis must be in [1, 4096], got {}", s.samples_per_axis));
  if (s.threads < 0 || s.threads > 1024)
    throw std::invalid_argument(fmt::format("PRT bake: threads must be in [0, 1024], got {}", s.threads));
  if (!std::isfinite(s.ray_offset) || s.ray_offset < 0)
    throw std::invalid_argument(fmt::format("PRT bake: ray offset must be finite and >= 0, got {}", s.ray_offset));
}

// "<mesh file>: PRT bake: <what>", so that a bad vertex is traced to its file.
AssetError mesh_error(const Mesh& mesh, const std::string& what) {
  return AssetError(mesh.source.empty() ? fmt::format("PRT bake: {}", what)
                                        : fmt::format("{}: PRT bake: {}", mesh.source, what));
}

}  // namespace

void validate_prt_mesh(const Mesh& mesh) {
  if (mesh.positions.size() % 3 != 0)
    throw mesh_error(mesh, fmt::format("{} position values is not a multiple of 3", mesh.positions.size()));
  if (mesh.normals.size() != mesh.positions.size())
    throw mesh_error(mesh, fmt::format("the mesh has {} normals for {} vertices (one normal per vertex needed)",
                                       mesh.normals.size() / 3, mesh.vertex_count()));
  if (mesh.indices.size() % 3 != 0)
    throw mesh_error(mesh, fmt::format("{} indices is not a multiple of 3 (triangle lists only)", mesh.indices.size()));
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    const Vec3 p = vec_at(mesh.positions, v), n = vec_at(mesh.normals, v);
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
      throw mesh_error(mesh, fmt::format("vertex {} has a non-finite position ({}, {}, {})", v, p[0], p[1], p[2]));
    if (!std::isfinite(n[0]) || !std::isfinite(n[1]) || !std::isfinite(n[2]))
      throw mesh_error(mesh, fmt::format("vertex {} has a non-finite normal ({}, {}, {})", v, n[0], n[1], n[2]));
    if (norm(n) < 1e-6)
      throw mesh_error(mesh, fmt::format("vertex {} has a zero-length normal", v));
  }
  for (size_t i = 0; i < mesh.indices.size(); ++i)
    if (mesh.indices[i] >= mesh.vertex_count())
      throw mesh_error(mesh, fmt::format("index {} (triangle {}) is {}, out of range for {} vertices", i, i / 3,
                                         mesh.indices[i], mesh.vertex_count()));
  for (size_t p = 0; p < mesh.parts.size(); ++p) {
    const MeshPart& part = mesh.parts[p];
    if (uint64_t(part.first_index) + part.index_count > mesh.indices.size())
      throw mesh_error(mesh, fmt::format("part {} covers indices [{}, {}), beyond the {} indices", p,
                                         part.first_index, uint64_t(part.first_index) + part.index_count,
                                         mesh.indices.size()));
  }
}

PrtTransfer bake_prt(const Mesh& mesh, const PrtBakeSettings& settings,
                     const std::function<void(size_t, size_t)>& progress, PrtBakeStats* stats) {
  const auto started = std::chrono::steady_clock::now();
  check_settings(settings);
  validate_prt_mesh(mesh);
  PrtTransfer out;
  out.bands = settings.bands;
  out.kind = settings.kind;
  out.samples_per_axis = settings.samples_per_axis;
  const size_t vertices = mesh.vertex_count();
  const int threads = settings.threads > 0 ? settings.threads : std::max(1, int(std::thread::hardware_concurrency()));
  if (stats) *stats = PrtBakeStats{0, 0, threads};
  if (vertices == 0) return out;

  const SphereSamples samples = stratified_sphere_samples(settings.samples_per_axis, settings.bands, settings.seed);
  const size_t coefs = size_t(sh_count(settings.bands));
  const double scale = samples.weight / std::numbers::pi;  // the MC weight and the Lambertian 1/pi
  const Bounds box = mesh.bounds();
  const double offset = settings.ray_offset * norm(box.max - box.min);
  const bool rays = settings.kind != TransferKind::Unshadowed;
  const bool bounce = settings.kind == TransferKind::Interreflected;
  const size_t total = bounce ? 2 * vertices : vertices;
  std::optional<PrtRayScene> scene;
  if (rays) scene.emplace(mesh);
  std::atomic<uint64_t> ray_count{0};

  std::vector<Vec3> normals(vertices);
  for (size_t v = 0; v < vertices; ++v) normals[v] = normalized(vec_at(mesh.normals, v));
  const std::vector<Vec3> inward = inward_directions(mesh, normals);
  auto origin_of = [&](size_t v) { return vec_at(mesh.positions, v) + offset * (normals[v] + inward[v]); };

  // Pass 1: unshadowed or shadowed transfer.
  std::vector<float> direct(vertices * coefs);
  parallel_chunks(
      vertices, threads,
      [&](size_t first, size_t last) {
        std::vector<double> sum(coefs);
        Hemisphere h;
        uint64_t cast = 0;
        for (size_t v = first; v < last; ++v) {
          std::fill(sum.begin(), sum.end(), 0.0);
          h.gather(samples, normals[v]);
          if (rays) {
            scene->occluded(origin_of(v), h.directions, h.blocked);
            cast += h.size();
          }
          for (size_t k = 0; k < h.size(); ++k) {
            if (h.blocked[k]) continue;
            const double* y = samples.basis_at(h.sample[k]);
            for (size_t i = 0; i < coefs; ++i) sum[i] += h.cosine[k] * y[i];
          }
          for (size_t i = 0; i < coefs; ++i) direct[v * coefs + i] = float(scale * sum[i]);
        }
        ray_count += cast;
      },
      [&](size_t done) {
        if (progress) progress(done, total);
      });

  if (!bounce) {
    out.coefficients = std::move(direct);
  } else {
    // Pass 2: one diffuse bounce of the shadowed transfer (grey: the luminance of the hit part).
    std::vector<double> albedo(mesh.triangle_count(), 1.0);
    for (const MeshPart& part : mesh.parts) {
      const double rho = 0.2126 * part.base_color[0] + 0.7152 * part.base_color[1] + 0.0722 * part.base_color[2];
      for (size_t t = part.first_index / 3; t < (size_t(part.first_index) + part.index_count) / 3; ++t) albedo[t] = rho;
    }
    out.coefficients.resize(vertices * coefs);
    parallel_chunks(
        vertices, threads,
        [&](size_t first, size_t last) {
          std::vector<double> sum(coefs);
          Hemisphere h;
          std::vector<PrtRayHit> hits;
          uint64_t cast = 0;
          for (size_t v = first; v < last; ++v) {
            std::fill(sum.begin(), sum.end(), 0.0);
            h.gather(samples, normals[v]);
            hits.resize(h.size());
            scene->closest_hits(origin_of(v), h.directions, hits);
            cast += h.size();
            for (size_t k = 0; k < h.size(); ++k) {
              const PrtRayHit& hit = hits[k];
              if (!hit.hit || !hit.front_face) continue;
              const double w = albedo[hit.triangle] * h.cosine[k];
              const double b1 = hit.b1, b2 = hit.b2, b0 = 1.0 - b1 - b2;
              const float* t0 = &direct[mesh.indices[3 * size_t(hit.triangle)] * coefs];
              const float* t1 = &direct[mesh.indices[3 * size_t(hit.triangle) + 1] * coefs];
              const float* t2 = &direct[mesh.indices[3 * size_t(hit.triangle) + 2] * coefs];
              for (size_t i = 0; i < coefs; ++i) sum[i] += w * (b0 * t0[i] + b1 * t1[i] + b2 * t2[i]);
            }
            for (size_t i = 0; i < coefs; ++i)
              out.coefficients[v * coefs + i] = float(double(direct[v * coefs + i]) + scale * sum[i]);
          }
          ray_count += cast;
        },
        [&](size_t done) {
          if (progress) progress(vertices + done, total);
        });
  }
  if (stats) {
    stats->rays = ray_count;
    stats->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  }
  return out;
}

}  // namespace arpipe
