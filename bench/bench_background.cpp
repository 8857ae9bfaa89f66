// SPDX-License-Identifier: MIT
// Throughput of the background-mesh metric (K. J. Fidkowski, *Anisotropic Metric-Based Curved
// Meshing Using Prismatic Layers*, Sec. II.D): quadtree build, locate only, and evaluation by
// the log-Euclidean and affine-invariant means, on a structured-split square of ~100k triangles
// carrying an anisotropic analytic metric. Also counts heap allocations inside the timed loops
// (evaluate should make none). Run by hand: bench_background [cells_per_side] [evaluations].
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "modules/metric/background_metric.h"

namespace {

std::atomic<long> allocations{0};

}  // namespace

// Counting global allocator (this executable only).
void* operator new(std::size_t size) {
  allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size ? size : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// A boundary-layer-like metric on [0,1]^2: size 1e-3 normal to a direction turning with x,
// growing to 0.05 away from y = 0.5; 0.05 along it (aspect ratio up to 50).
plaf::Metric<2> analytic_metric(const Eigen::Vector2d& x) {
  const double angle = M_PI * x[0];
  Eigen::Matrix2d r;
  r << std::cos(angle), -std::sin(angle), std::sin(angle), std::cos(angle);
  const double h_normal = 1e-3 + 0.098 * std::abs(x[1] - 0.5);
  return plaf::Metric<2>::from_directions(r, Eigen::Vector2d(0.05, h_normal));
}

// n x n squares on [0,1]^2, each split along its diagonal: 2 n^2 triangles.
plaf::BackgroundMesh<2> structured_square(int n) {
  plaf::BackgroundMesh<2> m;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      m.nodes.emplace_back(static_cast<double>(i) / n, static_cast<double>(j) / n);
      m.metrics.push_back(analytic_metric(m.nodes.back()));
    }
  auto id = [n](int i, int j) { return static_cast<plaf::NodeId>(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      m.simplices.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.simplices.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return m;
}

struct Result {
  double seconds;
  long allocations;
  double checksum;  // keeps the loop from being optimised away
};

template <class F>
Result timed(const std::vector<Eigen::Vector2d>& points, F&& f) {
  const long a0 = allocations.load();
  const Clock::time_point t0 = Clock::now();
  double sum = 0;
  for (const Eigen::Vector2d& x : points) sum += f(x);
  return {seconds_since(t0), allocations.load() - a0, sum};
}

void print(const char* what, std::size_t count, const Result& r) {
  std::printf("%-34s %9.3f s  %12.0f /s  %8.1f ns each  allocations %ld  (checksum %.6g)\n", what, r.seconds,
              static_cast<double>(count) / r.seconds, 1e9 * r.seconds / static_cast<double>(count), r.allocations,
              r.checksum);
}

}  // namespace

int main(int argc, char** argv) {
  const int n = argc > 1 ? std::atoi(argv[1]) : 224;  // 2 * 224^2 = 100352 triangles
  const std::size_t evaluations = argc > 2 ? std::strtoul(argv[2], nullptr, 10) : 1000000;
  if (n < 1 || evaluations < 1) {
    std::fprintf(stderr, "usage: bench_background [cells_per_side >= 1] [evaluations >= 1]\n");
    return 2;
  }

  // 1. The background mesh and the query points: uniformly random inside; along random
  //    segments of 1000 points each (coherent, as when a mesher walks along edges); and a tenth
  //    as many outside.
  const plaf::BackgroundMesh<2> mesh = structured_square(n);
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> u01(0.0, 1.0), around(-1.0, 2.0);
  std::vector<Eigen::Vector2d> inside(evaluations), outside;
  for (Eigen::Vector2d& x : inside) x = {u01(rng), u01(rng)};
  std::vector<Eigen::Vector2d> coherent;
  coherent.reserve(evaluations);
  constexpr std::size_t per_segment = 1000;
  while (coherent.size() < evaluations) {
    const Eigen::Vector2d a(u01(rng), u01(rng)), b(u01(rng), u01(rng));
    for (std::size_t k = 0; k < per_segment && coherent.size() < evaluations; ++k)
      coherent.push_back(a + (b - a) * (static_cast<double>(k) / per_segment));
  }
  while (outside.size() < evaluations / 10) {
    const Eigen::Vector2d x(around(rng), around(rng));
    if (x[0] < 0 || x[0] > 1 || x[1] < 0 || x[1] > 1) outside.push_back(x);
  }
  std::printf("background mesh: %zu nodes, %zu triangles; %zu evaluations inside, %zu outside\n", mesh.nodes.size(),
              mesh.simplices.size(), inside.size(), outside.size());

  // 2. Build (node logarithms and quadtree).
  Clock::time_point t0 = Clock::now();
  const plaf::BackgroundMetricField<2> le(mesh, plaf::MetricMean::LogEuclidean);
  std::printf("%-34s %9.3f s\n", "build (logs + quadtree)", seconds_since(t0));
  const plaf::BackgroundMetricField<2> ai(mesh, plaf::MetricMean::AffineInvariant);

  // 3. Throughput.
  for (const auto& [name, points] :
       {std::pair<const char*, const std::vector<Eigen::Vector2d>*>{"random", &inside}, {"coherent", &coherent}}) {
    std::printf("%s points:\n", name);
    print("  locate", points->size(), timed(*points, [&](const Eigen::Vector2d& x) { return le.locate(x); }));
    print("  evaluate, log-Euclidean", points->size(),
          timed(*points, [&](const Eigen::Vector2d& x) { return le.evaluate(x).matrix()(0, 0); }));
    print("  evaluate, affine-invariant", points->size(),
          timed(*points, [&](const Eigen::Vector2d& x) { return ai.evaluate(x).matrix()(0, 0); }));
  }
  print("evaluate outside, log-Euclidean", outside.size(),
        timed(outside, [&](const Eigen::Vector2d& x) { return le.evaluate(x).matrix()(0, 0); }));

  // 4. Interpolation error against the analytic metric (log-Euclidean, relative, Frobenius).
  double worst = 0, mean = 0;
  const std::size_t samples = std::min<std::size_t>(inside.size(), 100000);
  for (std::size_t k = 0; k < samples; ++k) {
    const Eigen::Matrix2d exact = analytic_metric(inside[k]).matrix();
    const double e = (le.evaluate(inside[k]).matrix() - exact).norm() / exact.norm();
    worst = std::max(worst, e);
    mean += e / static_cast<double>(samples);
  }
  std::printf("interpolation error vs the analytic metric: mean %.3g, max %.3g (relative)\n", mean, worst);
  return 0;
}
