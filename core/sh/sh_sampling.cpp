#include "core/sh/sh_sampling.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <utility>
#include <stdexcept>

#include <fmt/format.h>

namespace arpipe {
namespace {

// P_n(x) and its derivative by the three-term recurrence (|x| < 1).
std::pair<double, double> legendre_and_derivative(int n, double x) {
  double p0 = 1, p1 = x;
  for (int k = 2; k <= n; ++k) {
    const double p2 = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
    p0 = p1;
    p1 = p2;
  }
  return {p1, n * (x * p1 - p0) / (x * x - 1)};
}

// Nodes and weights of n-point Gauss-Legendre on [-1, 1]: Newton on P_n from the usual cosine
// initial guess, which converges to machine precision in a few steps for every n used here.
void gauss_legendre(int n, std::vector<double>& nodes, std::vector<double>& weights) {
  nodes.assign(size_t(n), 0);
  weights.assign(size_t(n), 0);
  for (int i = 0; i < (n + 1) / 2; ++i) {
    double x = std::cos(std::numbers::pi * (i + 0.75) / (n + 0.5));
    for (int iter = 0; iter < 100; ++iter) {
      const auto [p, dp] = legendre_and_derivative(n, x);
      const double dx = p / dp;
      x -= dx;
      if (std::abs(dx) < 1e-16) break;
    }
    const double dp = legendre_and_derivative(n, x).second;
    const double w = 2 / ((1 - x * x) * dp * dp);
    nodes[size_t(i)] = x;
    nodes[size_t(n - 1 - i)] = -x;
    weights[size_t(i)] = w;
    weights[size_t(n - 1 - i)] = w;
  }
  if (n % 2 == 1) nodes[size_t(n / 2)] = 0;
}

void check_bands(const char* where, int bands) {
  if (bands < 1 || bands > kMaxShBands)
    throw std::invalid_argument(
        fmt::format("core/sh/sh_sampling.cpp: {}: bands {} outside 1..{}", where, bands, kMaxShBands));
}

}  // namespace

SphereSamples stratified_sphere_samples(int n, int bands, uint64_t seed, bool jitter) {
  if (n < 1)
    throw std::invalid_argument(
        fmt::format("core/sh/sh_sampling.cpp: stratified_sphere_samples: {} samples per axis (need >= 1)", n));
  check_bands("stratified_sphere_samples", bands);
  SphereSamples s;
  s.bands = bands;
  const size_t count = size_t(n) * size_t(n);
  const size_t per = size_t(sh_count(bands));
  s.directions.reserve(count);
  s.basis.resize(count * per);
  s.weight = 4 * std::numbers::pi / double(count);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double ra = jitter ? uniform(rng) : 0.5;
      const double rb = jitter ? uniform(rng) : 0.5;
      const double a = (i + ra) / n, b = (j + rb) / n;
      // theta = 2 acos(sqrt(1 - a)) means cos(theta) = 1 - 2a and sin(theta) = 2 sqrt(a (1 - a)):
      // the same mapping without the round trip through the angle.
      const double z = 1 - 2 * a;
      const double r = 2 * std::sqrt(a * (1 - a));
      const double phi = 2 * std::numbers::pi * b;
      const Vec3 d{r * std::cos(phi), r * std::sin(phi), z};
      sh_basis(bands, d, std::span<double>(s.basis.data() + s.directions.size() * per, per));
      s.directions.push_back(d);
    }
  return s;
}

ShRgb project_samples(const SphereSamples& samples, const std::function<Vec3(const Vec3&)>& function) {
  ShRgb sh(samples.bands);
  const size_t per = size_t(sh_count(samples.bands));
  for (size_t j = 0; j < samples.size(); ++j) {
    const Vec3 f = function(samples.directions[j]);
    const double* y = samples.basis_at(j);
    for (size_t i = 0; i < per; ++i)
      for (size_t k = 0; k < 3; ++k) sh.c[i][k] += f[k] * y[i];
  }
  for (Vec3& c : sh.c) c = samples.weight * c;
  return sh;
}

SphereQuadrature sphere_product_quadrature(int n_z, int n_phi, bool split_at_equator) {
  if (n_z < 1 || n_phi < 1)
    throw std::invalid_argument(fmt::format(
        "core/sh/sh_sampling.cpp: sphere_product_quadrature: {} x {} nodes (need >= 1 each)", n_z, n_phi));
  std::vector<double> gx, gw;
  gauss_legendre(n_z, gx, gw);
  std::vector<double> z, wz;
  if (split_at_equator) {
    for (int h = 0; h < 2; ++h)  // [-1, 0] then [0, 1]
      for (size_t i = 0; i < gx.size(); ++i) {
        z.push_back((gx[i] + (h == 0 ? -1 : 1)) / 2);
        wz.push_back(gw[i] / 2);
      }
  } else {
    z = gx;
    wz = gw;
  }
  SphereQuadrature q;
  q.directions.reserve(z.size() * size_t(n_phi));
  q.weights.reserve(z.size() * size_t(n_phi));
  for (size_t i = 0; i < z.size(); ++i) {
    const double r = std::sqrt(std::max(0.0, 1 - z[i] * z[i]));
    for (int j = 0; j < n_phi; ++j) {
      const double phi = 2 * std::numbers::pi * (j + 0.5) / n_phi;
      q.directions.push_back({r * std::cos(phi), r * std::sin(phi), z[i]});
      q.weights.push_back(wz[i] * 2 * std::numbers::pi / n_phi);
    }
  }
  return q;
}

ShRgb project_quadrature(const SphereQuadrature& rule, int bands, const std::function<Vec3(const Vec3&)>& function) {
  check_bands("project_quadrature", bands);
  ShRgb sh(bands);
  for (size_t j = 0; j < rule.size(); ++j)
    sh_add_sample(sh, rule.directions[j], function(rule.directions[j]), rule.weights[j]);
  return sh;
}

}  // namespace arpipe
