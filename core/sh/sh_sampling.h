// Seed 002's sphere sampler: N x N stratified points in the unit square (jittered inside their
// cells, or the cell corners), mapped uniformly onto the sphere, with the SH basis precomputed.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "core/geometry/vec.h"
#include "core/sh/sh_basis.h"

namespace arpipe {

struct SphereSamples {
  int bands = 0;
  std::vector<Vec3> directions;  // unit
  std::vector<double> basis;     // bands^2 values per direction, direction-major
  double weight = 0;             // 4 pi / T: the solid angle each sample stands for

  size_t size() const { return directions.size(); }
  const double* basis_at(size_t sample) const { return basis.data() + sample * size_t(sh_count(bands)); }
};

// (a, b) = ((i + r_a) / N, (j + r_b) / N) with r uniform in [0, 1) from a generator seeded with
// `seed` (jittered), or r = 0.5 (cell centres; the seed's "regular grid" uses r = 0, which puts
// a sample exactly on a pole: the centre is the same stratification without that), then
// theta = 2 acos(sqrt(1 - a)), phi = 2 pi b. Throws std::invalid_argument for N < 1 or bands
// outside [1, kMaxShBands].
SphereSamples stratified_sphere_samples(int samples_per_axis, int bands, uint64_t seed, bool jitter = true);

// Monte Carlo projection c_i = 4 pi / T sum_j f(d_j) y_i(d_j) of an RGB function of direction.
ShRgb project_samples(const SphereSamples& samples, const std::function<Vec3(const Vec3&)>& function);

// A deterministic product rule for reference projections: Gauss-Legendre in z = cos(theta)
// (n_z nodes on [-1, 1], or n_z on each hemisphere when split_at_equator) times n_phi uniform
// azimuths. It integrates exactly every polynomial in (x, y, z) of degree <= min(2 n_z - 1,
// n_phi - 1) (split: every function that is such a polynomial on each hemisphere, e.g.
// max(0, z) times a basis function), so the Gram matrix of `bands` bands needs n_z >= bands and
// n_phi >= 2 bands - 1. Throws std::invalid_argument for n_z < 1 or n_phi < 1.
struct SphereQuadrature {
  std::vector<Vec3> directions;  // unit
  std::vector<double> weights;   // solid angle per direction; they sum to 4 pi
  size_t size() const { return directions.size(); }
};
SphereQuadrature sphere_product_quadrature(int n_z, int n_phi, bool split_at_equator = false);
// c_i = sum_j w_j f(d_j) y_i(d_j) with the rule above.
ShRgb project_quadrature(const SphereQuadrature& rule, int bands, const std::function<Vec3(const Vec3&)>& function);

}  // namespace arpipe
