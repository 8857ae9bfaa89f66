// SPDX-License-Identifier: MIT
// Implements metric_integrals.h: the quadratures behind the size budget.
#include "modules/metric/metric_integrals.h"

#include <algorithm>
#include <cmath>

#include "modules/base/parallel.h"

namespace plaf {
inline namespace metric {

namespace {

template <int Dim>
double density(const MetricField<Dim>& metric, const Eigen::Matrix<double, Dim, 1>& x) {
  return std::sqrt(std::max(0.0, metric.evaluate(x).matrix().determinant()));
}

// A tree cell: its box, the density at its centre and corners (0 outside the region), and how
// many of those samples lie inside.
template <int Dim>
struct TreeCell {
  Eigen::Matrix<double, Dim, 1> lo, hi;
  double sum = 0, min = 0, max = 0;
  int inside = 0, samples = 0;
};

}  // namespace

double metric_length(const SplineLoop& loop, const MetricField<2>& metric) {
  constexpr int per_piece = 16;  // midpoint rule in the parameter, per spline piece
  const int n = loop.num_points() * per_piece;
  const double dt = loop.period() / n;
  double length = 0;
  for (int i = 0; i < n; ++i) {
    const double t = (i + 0.5) * dt;
    length += metric.evaluate(loop.point(t)).length(loop.derivative(t)) * dt;
  }
  return length;
}

template <int Dim>
double metric_measure(const Eigen::Matrix<double, Dim, 1>& lo, const Eigen::Matrix<double, Dim, 1>& hi,
                      const std::function<bool(const Eigen::Matrix<double, Dim, 1>&)>& inside,
                      const MetricField<Dim>& metric, long max_evaluations) {
  return region_integral<Dim>(
      lo, hi, inside, [&metric](const Eigen::Matrix<double, Dim, 1>& x) { return density(metric, x); },
      max_evaluations);
}

template <int Dim>
double region_integral(const Eigen::Matrix<double, Dim, 1>& lo, const Eigen::Matrix<double, Dim, 1>& hi,
                       const std::function<bool(const Eigen::Matrix<double, Dim, 1>&)>& inside,
                       const std::function<double(const Eigen::Matrix<double, Dim, 1>&)>& f, long max_evaluations) {
  using Vec = Eigen::Matrix<double, Dim, 1>;
  long evaluations = 0;
  auto sample = [&](const Vec& a, const Vec& b) {
    TreeCell<Dim> c;
    c.lo = a;
    c.hi = b;
    c.min = std::numeric_limits<double>::infinity();
    auto add = [&](const Vec& x) {
      ++c.samples;
      if (!inside(x)) return;
      const double r = f(x);
      ++evaluations;
      ++c.inside;
      c.sum += r;
      c.min = std::min(c.min, r);
      c.max = std::max(c.max, r);
    };
    add(0.5 * (a + b));
    for (int corner = 0; corner < (1 << Dim); ++corner) {
      Vec x;
      for (int d = 0; d < Dim; ++d) x[d] = (corner >> d) & 1 ? b[d] : a[d];
      add(x);
    }
    return c;
  };
  auto volume = [](const TreeCell<Dim>& c) { return (c.hi - c.lo).prod(); };
  auto estimate = [&](const TreeCell<Dim>& c) {
    return c.inside == 0 ? 0.0 : volume(c) * (c.sum / c.inside) * c.inside / c.samples;
  };
  // Level by level: a cell is split while it crosses the boundary or its density varies by more
  // than a factor 2, as long as the evaluations last (16 levels at most).
  constexpr int min_depth = Dim == 2 ? 4 : 3;
  std::vector<TreeCell<Dim>> level{sample(lo, hi)};
  double done = 0;
  for (int depth = 0; depth < 16 && !level.empty(); ++depth) {
    std::vector<TreeCell<Dim>> next;
    for (const TreeCell<Dim>& c : level) {
      // The first levels are split whatever their samples say (a cell whose samples all miss the
      // region may still hold part of it); then where the boundary crosses or the density varies.
      const bool split =
          depth < min_depth || (c.inside > 0 && c.inside < c.samples) || (c.inside > 0 && c.max > 2 * c.min);
      if (!split || evaluations + (long{1} << Dim) * (1 + (1 << Dim)) > max_evaluations) {
        done += estimate(c);
        continue;
      }
      const Vec mid = 0.5 * (c.lo + c.hi);
      for (int child = 0; child < (1 << Dim); ++child) {
        Vec a, b;
        for (int d = 0; d < Dim; ++d) {
          a[d] = (child >> d) & 1 ? mid[d] : c.lo[d];
          b[d] = (child >> d) & 1 ? c.hi[d] : mid[d];
        }
        next.push_back(sample(a, b));
      }
    }
    level = std::move(next);
  }
  for (const TreeCell<Dim>& c : level) done += estimate(c);
  return done;
}

template double region_integral<2>(const Eigen::Vector2d&, const Eigen::Vector2d&,
                                   const std::function<bool(const Eigen::Vector2d&)>&,
                                   const std::function<double(const Eigen::Vector2d&)>&, long);
template double region_integral<3>(const Eigen::Vector3d&, const Eigen::Vector3d&,
                                   const std::function<bool(const Eigen::Vector3d&)>&,
                                   const std::function<double(const Eigen::Vector3d&)>&, long);
template double metric_measure<2>(const Eigen::Vector2d&, const Eigen::Vector2d&,
                                  const std::function<bool(const Eigen::Vector2d&)>&, const MetricField<2>&, long);
template double metric_measure<3>(const Eigen::Vector3d&, const Eigen::Vector3d&,
                                  const std::function<bool(const Eigen::Vector3d&)>&, const MetricField<3>&, long);

namespace {

// sqrt(det M_t) at x for the plane of unit normal n (M restricted to an orthonormal tangent basis).
double tangent_density(const MetricField<3>& metric, const Eigen::Vector3d& x, const Eigen::Vector3d& n) {
  const Eigen::Vector3d e1 = n.unitOrthogonal(), e2 = n.cross(e1);
  const Eigen::Matrix3d m = metric.evaluate(x).matrix();
  const double a = e1.dot(m * e1), b = e1.dot(m * e2), d = e2.dot(m * e2);
  return std::sqrt(std::max(0.0, a * d - b * b));
}

double triangle_integral(const MetricField<3>& metric, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                         const Eigen::Vector3d& c, int depth) {
  const Eigen::Vector3d cross = (b - a).cross(c - a);
  const double area = 0.5 * cross.norm();
  if (!(area > 0)) return 0.0;
  const Eigen::Vector3d n = cross.normalized();
  const double centre = tangent_density(metric, (a + b + c) / 3.0, n);
  if (depth == 0) return area * centre;
  const double ra = tangent_density(metric, a, n), rb = tangent_density(metric, b, n), rc = tangent_density(metric, c, n);
  const double lo = std::min({centre, ra, rb, rc}), hi = std::max({centre, ra, rb, rc});
  if (hi <= 2 * lo) return area * centre;
  const Eigen::Vector3d ab = 0.5 * (a + b), bc = 0.5 * (b + c), ca = 0.5 * (c + a);
  return triangle_integral(metric, a, ab, ca, depth - 1) + triangle_integral(metric, ab, b, bc, depth - 1) +
         triangle_integral(metric, ca, bc, c, depth - 1) + triangle_integral(metric, ab, bc, ca, depth - 1);
}

}  // namespace

double metric_surface_area(const std::vector<Eigen::Vector3d>& points, const std::vector<std::array<int, 3>>& triangles,
                           const MetricField<3>& metric, long max_evaluations) {
  // Worst-case evaluations per triangle at depth d: E(0) = 1, E(d) = 4 + 4 E(d - 1).
  const double n = static_cast<double>(triangles.size());
  int depth = 0;
  for (double e = 8; depth < 3 && n * e <= static_cast<double>(max_evaluations); e = 4 + 4 * e) ++depth;
  // Each triangle's integral on the worker threads (the metric fields keep no mutable state),
  // summed here in the triangles' order: the same sum as one thread's, bit for bit.
  std::vector<double> part(triangles.size());
  parallel_chunks(triangles.size(), 256, [&](unsigned, std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const std::array<int, 3>& t = triangles[i];
      part[i] = triangle_integral(metric, points[static_cast<std::size_t>(t[0])], points[static_cast<std::size_t>(t[1])],
                                  points[static_cast<std::size_t>(t[2])], depth);
    }
  });
  double total = 0;
  for (const double x : part) total += x;
  return total;
}

}  // namespace metric
}  // namespace plaf
