// SPDX-License-Identifier: MIT
// Throughput of the background-mesh metric (K. J. Fidkowski, *Anisotropic Metric-Based Curved
// Meshing Using Prismatic Layers*, Sec. II.D): tree build, locate only, and evaluation by the
// log-Euclidean and affine-invariant means, on a structured-split square of ~100k triangles (2D,
// a quadtree) or cube of ~100k tetrahedra (3D, a bounding-volume tree) carrying an anisotropic
// analytic metric. Also counts heap allocations inside the timed loops (the log-Euclidean
// evaluate should make none). Run by hand:
//   bench_background [cells_per_side] [evaluations]        2D, default 224 (100352 triangles)
//   bench_background 3d [cells_per_side] [evaluations]     3D, default 26 (105456 tetrahedra)
#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <random>
#include <string>
#include <string_view>
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

// A boundary-layer-like metric on the unit square or cube: size 1e-3 normal to a direction turning
// with x, growing to 0.05 away from the mid-plane y = 0.5; 0.05 along it (aspect ratio up to 50).
template <int Dim>
plaf::Metric<Dim> analytic_metric(const Eigen::Matrix<double, Dim, 1>& x) {
  const double angle = M_PI * x[0];
  const double h_normal = 1e-3 + 0.098 * std::abs(x[1] - 0.5);
  Eigen::Matrix<double, Dim, Dim> r = Eigen::Matrix<double, Dim, Dim>::Identity();
  r.template topLeftCorner<2, 2>() << std::cos(angle), -std::sin(angle), std::sin(angle), std::cos(angle);
  Eigen::Matrix<double, Dim, 1> sizes = Eigen::Matrix<double, Dim, 1>::Constant(0.05);
  sizes[1] = h_normal;
  return plaf::Metric<Dim>::from_directions(r, sizes);
}

// n^Dim squares on [0,1]^2, each split along its diagonal (2 n^2 triangles), or cubes on [0,1]^3,
// each split into the six tetrahedra around its main diagonal (6 n^3 tetrahedra).
template <int Dim>
plaf::BackgroundMesh<Dim> structured_mesh(int n) {
  plaf::BackgroundMesh<Dim> m;
  const int side = n + 1, layers = Dim == 3 ? side : 1;
  for (int k = 0; k < layers; ++k)
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) {
        typename plaf::BackgroundMesh<Dim>::Point x;
        x[0] = static_cast<double>(i) / n;
        x[1] = static_cast<double>(j) / n;
        if constexpr (Dim == 3) x[2] = static_cast<double>(k) / n;
        m.nodes.push_back(x);
        m.metrics.push_back(analytic_metric<Dim>(x));
      }
  auto id = [side](std::array<int, 3> c) { return static_cast<plaf::NodeId>((c[2] * side + c[1]) * side + c[0]); };
  std::array<int, Dim> axes;
  for (int d = 0; d < Dim; ++d) axes[static_cast<std::size_t>(d)] = d;
  std::vector<std::array<int, Dim>> paths;  // one simplex per path from corner 0...0 to 1...1
  do paths.push_back(axes);
  while (std::next_permutation(axes.begin(), axes.end()));
  for (int k = 0; k < layers - (Dim == 3 ? 1 : 0); ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        for (const auto& path : paths) {
          std::array<int, 3> c = {i, j, k};
          typename plaf::BackgroundMesh<Dim>::Simplex s;
          s[0] = id(c);
          for (std::size_t a = 0; a < static_cast<std::size_t>(Dim); ++a) {
            ++c[static_cast<std::size_t>(path[a])];
            s[a + 1] = id(c);
          }
          m.simplices.push_back(s);
        }
  return m;
}

struct Result {
  double seconds;
  long allocations;
  double checksum;  // keeps the loop from being optimised away
};

template <class Point, class F>
Result timed(const std::vector<Point>& points, F&& f) {
  const long a0 = allocations.load();
  const Clock::time_point t0 = Clock::now();
  double sum = 0;
  for (const Point& x : points) sum += f(x);
  return {seconds_since(t0), allocations.load() - a0, sum};
}

void print(const char* what, std::size_t count, const Result& r) {
  std::printf("%-34s %9.3f s  %12.0f /s  %8.1f ns each  allocations %ld  (checksum %.6g)\n", what, r.seconds,
              static_cast<double>(count) / r.seconds, 1e9 * r.seconds / static_cast<double>(count), r.allocations,
              r.checksum);
}

template <int Dim>
int run(int n, std::size_t evaluations) {
  using Point = typename plaf::BackgroundMesh<Dim>::Point;
  // 1. The background mesh and the query points: uniformly random inside; along random
  //    segments of 1000 points each (coherent, as when a mesher walks along edges); and a tenth
  //    as many outside.
  const plaf::BackgroundMesh<Dim> mesh = structured_mesh<Dim>(n);
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> u01(0.0, 1.0), around(-1.0, 2.0);
  auto random_point = [&](std::uniform_real_distribution<double>& u) {
    Point x;
    for (int d = 0; d < Dim; ++d) x[d] = u(rng);
    return x;
  };
  std::vector<Point> inside(evaluations), outside, coherent;
  for (Point& x : inside) x = random_point(u01);
  coherent.reserve(evaluations);
  constexpr std::size_t per_segment = 1000;
  while (coherent.size() < evaluations) {
    const Point a = random_point(u01), b = random_point(u01);
    for (std::size_t k = 0; k < per_segment && coherent.size() < evaluations; ++k)
      coherent.push_back(a + (b - a) * (static_cast<double>(k) / per_segment));
  }
  while (outside.size() < evaluations / 10) {
    const Point x = random_point(around);
    if ((x.array() < 0).any() || (x.array() > 1).any()) outside.push_back(x);
  }
  std::printf("background mesh (%dD): %zu nodes, %zu simplices; %zu evaluations inside, %zu outside\n", Dim,
              mesh.nodes.size(), mesh.simplices.size(), inside.size(), outside.size());

  // 2. Build (node logarithms and tree).
  Clock::time_point t0 = Clock::now();
  const plaf::BackgroundMetricField<Dim> le(mesh, plaf::MetricMean::LogEuclidean);
  std::printf("%-34s %9.3f s\n", "build (logs + tree)", seconds_since(t0));
  const plaf::BackgroundMetricField<Dim> ai(mesh, plaf::MetricMean::AffineInvariant);

  // 3. Throughput.
  for (const auto& [name, points] :
       {std::pair<const char*, const std::vector<Point>*>{"random", &inside}, {"coherent", &coherent}}) {
    std::printf("%s points:\n", name);
    print("  locate", points->size(), timed(*points, [&](const Point& x) { return le.locate(x); }));
    print("  evaluate, log-Euclidean", points->size(),
          timed(*points, [&](const Point& x) { return le.evaluate(x).matrix()(0, 0); }));
    print("  evaluate, affine-invariant", points->size(),
          timed(*points, [&](const Point& x) { return ai.evaluate(x).matrix()(0, 0); }));
  }
  print("evaluate outside, log-Euclidean", outside.size(),
        timed(outside, [&](const Point& x) { return le.evaluate(x).matrix()(0, 0); }));

  // 4. Interpolation error against the analytic metric (log-Euclidean, relative, Frobenius).
  double worst = 0, mean = 0;
  const std::size_t samples = std::min<std::size_t>(inside.size(), 100000);
  for (std::size_t k = 0; k < samples; ++k) {
    const auto exact = analytic_metric<Dim>(inside[k]).matrix();
    const double e = (le.evaluate(inside[k]).matrix() - exact).norm() / exact.norm();
    worst = std::max(worst, e);
    mean += e / static_cast<double>(samples);
  }
  std::printf("interpolation error vs the analytic metric: mean %.3g, max %.3g (relative)\n", mean, worst);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const bool three = argc > 1 && std::string_view(argv[1]) == "3d";
  const int first = three ? 2 : 1;
  const int n = argc > first ? std::atoi(argv[first]) : three ? 26 : 224;  // ~100k simplices
  const std::size_t evaluations = argc > first + 1 ? std::strtoul(argv[first + 1], nullptr, 10) : 1000000;
  if (n < 1 || evaluations < 1) {
    std::fprintf(stderr, "usage: bench_background [3d] [cells_per_side >= 1] [evaluations >= 1]\n");
    return 2;
  }
  return three ? run<3>(n, evaluations) : run<2>(n, evaluations);
}
